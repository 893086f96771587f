// KTGF closures (consumers/src/tfm/ktgf.h): every coefficient of the solids stress, the
// granular conductivity and the collisional dissipation, in one place.
#include "tfm/ktgf.h"

#include <algorithm>
#include <cmath>

#include "draglab/error.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fmt;
using scene_util::kPi;

// Chapman-Cowling second-approximation factors of the Nieuwland set (Enskog dense gas).
constexpr double kViscosityFactor = 1.01600;
constexpr double kConductivityFactor = 1.02513;

bool bad(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

bool open_range(double x, double lo, double hi) { return std::isfinite(x) && x > lo && x < hi; }

}  // namespace

const char* to_string(KtgfClosureSet set) {
  return set == KtgfClosureSet::kGidaspow ? "gidaspow" : "nieuwland";
}
const char* to_string(RadialDistribution radial) {
  switch (radial) {
    case RadialDistribution::kCarnahanStarling:
      return "carnahan_starling";
    case RadialDistribution::kSinclairJackson:
      return "sinclair_jackson";
    case RadialDistribution::kLunSavage:
      return "lun_savage";
    case RadialDistribution::kMaAhmadi:
      break;
  }
  return "ma_ahmadi";
}
const char* to_string(FrictionModel friction) {
  switch (friction) {
    case FrictionModel::kJohnsonJacksonSchaeffer:
      return "johnson_jackson_schaeffer";
    case FrictionModel::kJohnsonJacksonOpenFoam:
      return "johnson_jackson_openfoam";
    case FrictionModel::kNone:
      break;
  }
  return "none";
}
bool parse_closure_set(const std::string& name, KtgfClosureSet* out) {
  for (auto v : {KtgfClosureSet::kNieuwland, KtgfClosureSet::kGidaspow}) {
    if (name == to_string(v)) return *out = v, true;
  }
  return false;
}
bool parse_radial_distribution(const std::string& name, RadialDistribution* out) {
  for (auto v : {RadialDistribution::kMaAhmadi, RadialDistribution::kCarnahanStarling,
                 RadialDistribution::kSinclairJackson, RadialDistribution::kLunSavage}) {
    if (name == to_string(v)) return *out = v, true;
  }
  return false;
}
bool parse_friction_model(const std::string& name, FrictionModel* out) {
  for (auto v : {FrictionModel::kNone, FrictionModel::kJohnsonJacksonSchaeffer,
                 FrictionModel::kJohnsonJacksonOpenFoam}) {
    if (name == to_string(v)) return *out = v, true;
  }
  return false;
}

bool KtgfOptions::IsValid(std::string* error) const {
  if (!(std::isfinite(restitution) && restitution > 0.0 && restitution <= 1.0))
    return bad(error, "[tfm] restitution = " + fmt(restitution) + " is outside (0, 1]");
  if (!(std::isfinite(packing_limit) && packing_limit > 0.3 && packing_limit <= 0.74))
    return bad(error, "[tfm] packing_limit = " + fmt(packing_limit) +
                          " is outside (0.3, 0.74] (random close packing ~0.64)");
  if (!(std::isfinite(g0_margin) && g0_margin > 0.0 && g0_margin <= 0.1))
    return bad(error, "[tfm] g0_margin = " + fmt(g0_margin) + " is outside (0, 0.1]");
  if (!(std::isfinite(knudsen_length_m) && knudsen_length_m >= 0.0 && knudsen_length_m < 10.0))
    return bad(error,
               "[tfm] knudsen_length_m = " + fmt(knudsen_length_m) + " is outside [0, 10) m");
  if (friction != FrictionModel::kNone) {
    if (!open_range(friction_min_solids, 0.0, packing_limit))
      return bad(error, "[tfm] friction_min_solids = " + fmt(friction_min_solids) +
                            " is outside (0, packing_limit = " + fmt(packing_limit) + ")");
    if (!open_range(friction_angle_deg, 0.0, 90.0))
      return bad(error,
                 "[tfm] friction_angle_deg = " + fmt(friction_angle_deg) + " is outside (0, 90)");
    if (!open_range(friction_fr_pa, 0.0, 1e6))
      return bad(error, "[tfm] friction_fr_pa = " + fmt(friction_fr_pa) + " is outside (0, 1e6)");
    if (!open_range(friction_n, 0.0, 20.0) || !open_range(friction_p, 0.0, 20.0))
      return bad(error, "[tfm] friction_n and friction_p must be in (0, 20)");
    if (!(std::isfinite(friction_delta) && friction_delta > 0.0 && friction_delta <= 0.1))
      return bad(error, "[tfm] friction_delta = " + fmt(friction_delta) + " is outside (0, 0.1]");
    if (!open_range(friction_max_viscosity_pa_s, 0.0, 1e4))
      return bad(error, "[tfm] friction_max_viscosity_pa_s = " + fmt(friction_max_viscosity_pa_s) +
                            " is outside (0, 1e4)");
  }
  return true;
}

KtgfClosures::KtgfClosures(const KtgfOptions& options, double diameter_m, double density_kg_m3)
    : opt_(options), d_(diameter_m), rho_(density_kg_m3) {
  std::string why;
  if (!opt_.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, why);
  if (!(std::isfinite(d_) && d_ > 0.0) || !(std::isfinite(rho_) && rho_ > 0.0))
    throw Error(ErrorCode::kInvalidArgument,
                "KTGF closures: particle diameter and density must be > 0");
}

double KtgfClosures::RadialDistributionAt(double phi) const {
  const double pmax = opt_.packing_limit;
  const double x = std::clamp(phi, 0.0, pmax - opt_.g0_margin);
  switch (opt_.radial) {
    case RadialDistribution::kCarnahanStarling:
      return (1.0 - 0.5 * x) / std::pow(1.0 - x, 3);
    case RadialDistribution::kSinclairJackson:
      return 1.0 / (1.0 - std::cbrt(x / pmax));
    case RadialDistribution::kLunSavage:
      return std::pow(1.0 - x / pmax, -2.5 * pmax);
    case RadialDistribution::kMaAhmadi:
      break;
  }
  const double r = x / pmax;
  return (1.0 + 2.5 * x + 4.5904 * x * x + 4.515439 * x * x * x) /
         std::pow(1.0 - r * r * r, 0.67802);
}

KtgfCoefficients KtgfClosures::Evaluate(double phi, double theta, double div_v,
                                        double shear_rate) const {
  KtgfCoefficients c;
  phi = std::max(phi, 0.0);
  theta = std::max(theta, 0.0);
  const double e = opt_.restitution, eta = 0.5 * (1.0 + e);
  const bool nieuwland = opt_.closures == KtgfClosureSet::kNieuwland;
  const double g0 = RadialDistributionAt(phi);
  c.g0 = g0;
  const double sqrt_theta_pi = std::sqrt(theta / kPi);
  auto kinetic_pressure = [&](double x) {
    return (1.0 + 4.0 * eta * x * RadialDistributionAt(x)) * x * rho_ * theta;
  };
  auto frictional_pressure = [&](double x) {
    if (opt_.friction == FrictionModel::kNone || x <= opt_.friction_min_solids) return 0.0;
    return opt_.friction_fr_pa * std::pow(x - opt_.friction_min_solids, opt_.friction_n) /
           std::pow(std::max(opt_.packing_limit - x, opt_.friction_delta), opt_.friction_p);
  };
  c.kinetic_pressure_per_theta = (1.0 + 4.0 * eta * phi * g0) * phi * rho_;
  c.frictional_pressure_pa = frictional_pressure(phi);
  c.pressure_pa = kinetic_pressure(phi) + c.frictional_pressure_pa;
  const double h = 1e-6;
  const double lo = std::max(phi - h, 0.0), hi = phi + h;
  c.pressure_derivative_pa = (kinetic_pressure(hi) + frictional_pressure(hi) -
                              kinetic_pressure(lo) - frictional_pressure(lo)) /
                             (hi - lo);
  // Dilute (kinetic) parts: rho d sqrt(pi theta) (5/96 for mu, 75/384 for kappa) / (eta g0).
  double dilute = rho_ * d_ * std::sqrt(kPi * theta) / (eta * g0);
  if (opt_.knudsen_length_m > 0.0) {
    const double collisions = 6.0 * std::sqrt(2.0) * phi * g0 * opt_.knudsen_length_m;  // L/mfp d
    dilute *= collisions / (collisions + d_);
  }
  const double mu_factor = nieuwland ? kViscosityFactor : 1.0;
  const double kappa_factor = nieuwland ? kConductivityFactor : 1.0;
  const double collisional = phi * phi * rho_ * d_ * g0 * sqrt_theta_pi;
  const double mu_dilute_term = 1.0 + 1.6 * eta * phi * g0;
  const double kappa_dilute_term = 1.0 + 2.4 * eta * phi * g0;
  c.shear_viscosity_pa_s =
      mu_factor * (5.0 / 96.0) * dilute * mu_dilute_term * mu_dilute_term + 1.6 * eta * collisional;
  c.bulk_viscosity_pa_s = (4.0 / 3.0) * (1.0 + e) * collisional;
  c.conductivity = kappa_factor * (75.0 / 384.0) * dilute * kappa_dilute_term * kappa_dilute_term +
                   2.0 * (1.0 + e) * collisional;
  const double base = 3.0 * (1.0 - e * e) * phi * phi * rho_ * g0;
  c.dissipation_rate_coefficient = base * ((4.0 / d_) * sqrt_theta_pi - (nieuwland ? div_v : 0.0));
  if (c.frictional_pressure_pa > 0.0) {
    const double sin_angle = std::sin(opt_.friction_angle_deg * kPi / 180.0);
    // OpenFOAM's model: its 0.5 s time scale stands where Schaeffer has 1 / (2 sqrt(I_2D)).
    constexpr double kOpenFoamFrictionTime = 0.5;  // [s]
    const double mu_f =
        opt_.friction == FrictionModel::kJohnsonJacksonOpenFoam
            ? phi * kOpenFoamFrictionTime * c.frictional_pressure_pa * sin_angle
            : c.frictional_pressure_pa * sin_angle / (2.0 * std::max(shear_rate, 1e-30));
    c.frictional_viscosity_pa_s = std::min(mu_f, opt_.friction_max_viscosity_pa_s);
    c.shear_viscosity_pa_s += c.frictional_viscosity_pa_s;
  }
  return c;
}

double KtgfClosures::EquilibriumTheta(double phi, double div_v, double dev2,
                                      double drag_sink_kg_m3_s) const {
  if (!(std::isfinite(phi) && std::isfinite(div_v) && std::isfinite(dev2) && dev2 >= 0.0 &&
        std::isfinite(drag_sink_kg_m3_s) && drag_sink_kg_m3_s >= 0.0))
    throw Error(ErrorCode::kInvalidArgument,
                "KtgfClosures::EquilibriumTheta: phi, div_v, dev2 >= 0 and drag_sink >= 0 must "
                "be finite (phi = " +
                    fmt(phi) + ", div_v = " + fmt(div_v) + ", dev2 = " + fmt(dev2) +
                    ", drag_sink = " + fmt(drag_sink_kg_m3_s) + ")");
  if (phi <= 0.0) return 0.0;
  // Coefficients per sqrt(theta) (their values at theta = 1) and the theta-independent part of
  // the dissipation coefficient (Nieuwland's -div v term).
  const KtgfCoefficients one = Evaluate(phi, 1.0, div_v, 1.0);
  const KtgfCoefficients zero = Evaluate(phi, 0.0, div_v, 1.0);
  const double mu_kinetic = one.shear_viscosity_pa_s - one.frictional_viscosity_pa_s;
  const double source = 2.0 * mu_kinetic * dev2 + one.bulk_viscosity_pa_s * div_v * div_v;
  const double a = one.dissipation_rate_coefficient - zero.dissipation_rate_coefficient;
  // Expansion work cools; compression heating is left out (see the header).
  const double b = one.kinetic_pressure_per_theta * std::max(div_v, 0.0) +
                   zero.dissipation_rate_coefficient + drag_sink_kg_m3_s;
  // a x^2 + b x - source = 0 for x = sqrt(theta) >= 0; the form without cancellation.
  const double disc = b * b + 4.0 * a * source;
  double x = 0.0;
  if (b > 0.0) {
    x = 2.0 * source / (b + std::sqrt(disc));
  } else if (a > 0.0) {
    x = (-b + std::sqrt(disc)) / (2.0 * a);
  } else if (source > 0.0 || b < 0.0) {
    throw Error(ErrorCode::kInvalidArgument,
                "no local equilibrium of the granular temperature at phi = " + fmt(phi) +
                    ": nothing dissipates (restitution = 1, no drag sink) what the shear or "
                    "compression produces; remedy: restitution < 1 or the transported theta");
  }
  return x * x;
}

}  // namespace consumers
}  // namespace draglab
