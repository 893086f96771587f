// The discrete bubble model's bubble-scale closures (consumers/src/dbm/dbm_closures.h).
#include "dbm/dbm_closures.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDaviesTaylor = 0.711;

std::string Num(double x) { return core::format_number(x, 6); }

[[noreturn]] void Bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

void RequirePositive(double x, const char* what) {
  if (!(std::isfinite(x) && x > 0.0)) Bad(std::string(what) + " must be > 0, got " + Num(x));
}

}  // namespace

double davies_taylor_rise_velocity(double bubble_diameter_m, double gravity_m_s2) {
  RequirePositive(bubble_diameter_m, "davies_taylor_rise_velocity: bubble diameter");
  RequirePositive(gravity_m_s2, "davies_taylor_rise_velocity: gravity");
  return kDaviesTaylor * std::sqrt(gravity_m_s2 * bubble_diameter_m);
}

bool BubbleForceOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!(std::isfinite(bubble_density_kg_m3) && bubble_density_kg_m3 > 0.0))
    return fail("bubble_density_kg_m3 must be > 0, got " + Num(bubble_density_kg_m3));
  if (!(std::isfinite(emulsion_density_kg_m3) && emulsion_density_kg_m3 > bubble_density_kg_m3))
    return fail("emulsion_density_kg_m3 must be above the bubble density " +
                Num(bubble_density_kg_m3) + " kg/m^3 (bubbles rise), got " +
                Num(emulsion_density_kg_m3));
  if (!(std::isfinite(virtual_mass_coefficient) && virtual_mass_coefficient >= 0.0))
    return fail("virtual_mass_coefficient must be >= 0, got " + Num(virtual_mass_coefficient));
  if (!gravity.allFinite() || gravity.norm() == 0.0)
    return fail("gravity must be finite and not 0");
  return true;
}

BubbleForceModel::BubbleForceModel(const BubbleForceOptions& options) : opt_(options) {
  std::string why;
  if (!opt_.IsValid(&why)) Bad("BubbleForceOptions: " + why);
  // Terminal balance (rho_e - rho_b) V g = 1/2 C_D rho_e (pi d^2/4) u_br^2 with u_br = 0.711
  // sqrt(g d): C_D = (4/3)(1 - rho_b/rho_e)/0.711^2, independent of d and g.
  drag_coefficient_ = 4.0 / 3.0 * (1.0 - opt_.bubble_density_kg_m3 / opt_.emulsion_density_kg_m3) /
                      (kDaviesTaylor * kDaviesTaylor);
}

double BubbleForceModel::inertia_density() const {
  return opt_.bubble_density_kg_m3 + opt_.virtual_mass_coefficient * opt_.emulsion_density_kg_m3;
}

Eigen::Vector3d BubbleForceModel::Step(const Eigen::Vector3d& v, const Eigen::Vector3d& u,
                                       const Eigen::Vector3d& grad_p, const Eigen::Vector3d& du_dt,
                                       double diameter_m, double dt_s) const {
  RequirePositive(diameter_m, "BubbleForceModel::Step: bubble diameter");
  RequirePositive(dt_s, "BubbleForceModel::Step: time step");
  // Per bubble volume: inertia m dv/dt = f - k (v - u), k = (3/4) C_D rho_e |v - u| / d
  // (1/2 C_D rho_e pi d^2/4 divided by pi d^3/6).
  const double m = inertia_density();
  const Eigen::Vector3d f = opt_.bubble_density_kg_m3 * opt_.gravity - grad_p +
                            opt_.virtual_mass_coefficient * opt_.emulsion_density_kg_m3 * du_dt;
  const double k =
      0.75 * drag_coefficient_ * opt_.emulsion_density_kg_m3 * (v - u).norm() / diameter_m;
  return (m * v + dt_s * (f + k * u)) / (m + dt_s * k);
}

double two_phase_holdup(double u0_m_s, double umf_m_s, double bubble_rise_m_s) {
  RequirePositive(bubble_rise_m_s, "two_phase_holdup: bubble rise velocity");
  if (!std::isfinite(u0_m_s) || !std::isfinite(umf_m_s) || umf_m_s < 0.0)
    Bad("two_phase_holdup: u0 and umf must be finite, umf >= 0");
  return std::max(u0_m_s - umf_m_s, 0.0) / bubble_rise_m_s;
}

double davidson_harrison_bubble_volume(double orifice_flow_m3_s, double gravity_m_s2) {
  RequirePositive(orifice_flow_m3_s, "davidson_harrison_bubble_volume: orifice flow");
  RequirePositive(gravity_m_s2, "davidson_harrison_bubble_volume: gravity");
  return 1.138 * std::pow(orifice_flow_m3_s, 1.2) * std::pow(gravity_m_s2, -0.6);
}

double davidson_harrison_bubble_diameter(double orifice_flow_m3_s, double gravity_m_s2) {
  return std::cbrt(6.0 * davidson_harrison_bubble_volume(orifice_flow_m3_s, gravity_m_s2) / kPi);
}

double darton_bubble_diameter(double excess_velocity_m_s, double height_m,
                              double area_per_orifice_m2, double gravity_m_s2) {
  RequirePositive(excess_velocity_m_s, "darton_bubble_diameter: u0 - umf");
  RequirePositive(gravity_m_s2, "darton_bubble_diameter: gravity");
  if (!(height_m >= 0.0) || !(area_per_orifice_m2 >= 0.0))
    Bad("darton_bubble_diameter: height and area per orifice must be >= 0");
  return 0.54 * std::pow(excess_velocity_m_s, 0.4) *
         std::pow(height_m + 4.0 * std::sqrt(area_per_orifice_m2), 0.8) *
         std::pow(gravity_m_s2, -0.2);
}

double mori_wen_bubble_diameter(double excess_velocity_m_s, double height_m, double bed_area_m2,
                                double bed_diameter_m) {
  RequirePositive(excess_velocity_m_s, "mori_wen_bubble_diameter: u0 - umf");
  RequirePositive(bed_area_m2, "mori_wen_bubble_diameter: bed area");
  RequirePositive(bed_diameter_m, "mori_wen_bubble_diameter: bed diameter");
  if (!(height_m >= 0.0)) Bad("mori_wen_bubble_diameter: height must be >= 0");
  // The correlation's own units: cm, cm/s, cm^2, g = 981 cm/s^2.
  const double excess_cm_s = 100.0 * excess_velocity_m_s, area_cm2 = 1e4 * bed_area_m2;
  const double maximum_cm = 0.65 * std::pow(area_cm2 * excess_cm_s, 0.4);
  const double initial_cm = 2.78 / 981.0 * excess_cm_s * excess_cm_s;
  const double d_cm =
      maximum_cm - (maximum_cm - initial_cm) * std::exp(-0.3 * height_m / bed_diameter_m);
  return d_cm / 100.0;
}

}  // namespace consumers
}  // namespace draglab
