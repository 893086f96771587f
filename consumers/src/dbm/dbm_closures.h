// dbm/dbm_closures.h: the bubble-scale closures of the discrete bubble model (seed
// Section 5, Eqs. 18-19): the force model of one bubble in the emulsion and the bubble-size and
// hold-up relations the DBM is set up and checked with. Every coefficient is in
// consumers/src/dbm/dbm_closures.cc.
//
// Bubble (volume-equivalent diameter d_b, density rho_b) in an emulsion (density rho_e, local
// velocity u, pressure gradient grad p, material acceleration Du/Dt), Newton's second law with
// the virtual-mass force's own acceleration moved to the left:
//   (rho_b + C_VM rho_e) V dv/dt = rho_b V g - V grad p - 1/2 C_D rho_e (pi d_b^2/4) |v - u| (v -
//   u)
//                                  + C_VM rho_e V Du/Dt,
// with C_VM = 0.5 and C_D chosen so that an isolated bubble in a quiescent emulsion rises at the
// Davies-Taylor velocity u_br = 0.711 sqrt(g d_b): C_D = (4/3)(1 - rho_b/rho_e)/0.711^2, the same
// for every size (seed parameters: 2.47). Lift is left out (the seed's choice).
//
// Relations (SI unless stated): two-phase theory (the bubble gas flow (u0 - U_mf) A, hold-up
// (u0 - U_mf)/u_b); the Davidson-Harrison bubble volume at an orifice, 1.138 Q^1.2 g^-0.6; the
// bubble-size correlations of Darton et al. 1977 and Mori & Wen 1975 (freely bubbling beds, for
// comparison: they are correlations, not truth).
//
// Limits: spherical bubbles of one diameter each, no wake or cloud model, no wall effect on the
// rise velocity.
#pragma once

#include <Eigen/Core>

#include <string>

namespace draglab {
namespace consumers {

/// Davies & Taylor 1950: the rise velocity of an isolated bubble [m/s], 0.711 sqrt(g d_b).
double davies_taylor_rise_velocity(double bubble_diameter_m, double gravity_m_s2 = 9.81);

/// The emulsion and bubble properties the force model needs.
struct BubbleForceOptions {
  double emulsion_density_kg_m3 = 400.0;     ///< rho_e, > rho_b.
  double bubble_density_kg_m3 = 25.0;        ///< rho_b (the gas and the particles it carries), > 0.
  double virtual_mass_coefficient = 0.5;     ///< C_VM, >= 0.
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  ///< [m/s^2], not zero.
  bool IsValid(std::string* error) const;
};

/// One bubble's force balance and its time step. Units SI; vectors (x, y, z) with gravity as
/// given (the DBM's z up).
class BubbleForceModel {
 public:
  /// Throws Error(kInvalidArgument) naming the field for invalid options.
  explicit BubbleForceModel(const BubbleForceOptions& options);

  /// C_D that makes an isolated bubble rise at the Davies-Taylor velocity.
  double drag_coefficient() const { return drag_coefficient_; }
  /// The effective inertia per volume, rho_b + C_VM rho_e [kg/m^3].
  double inertia_density() const;

  /// The bubble velocity after a step dt > 0 from v, in an emulsion of velocity u, pressure
  /// gradient grad_p [Pa/m] and material acceleration du_dt [m/s^2] (the emulsion quantities at
  /// the bubble, held over the step). The drag is implicit (linearised in |v - u| at the old
  /// slip), so any step is stable; at a steady state the balance is exact.
  Eigen::Vector3d Step(const Eigen::Vector3d& v, const Eigen::Vector3d& u,
                       const Eigen::Vector3d& grad_p, const Eigen::Vector3d& du_dt,
                       double diameter_m, double dt_s) const;

 private:
  BubbleForceOptions opt_;
  double drag_coefficient_ = 0.0;
};

/// Two-phase theory: the hold-up of bubbles rising at u_b through a bed fed at u0 with
/// minimum-fluidization velocity umf, (u0 - umf)/u_b (0 when u0 <= umf).
double two_phase_holdup(double u0_m_s, double umf_m_s, double bubble_rise_m_s);

/// Davidson & Harrison 1963: the volume [m^3] of the bubble an orifice fed with Q [m^3/s] forms,
/// 1.138 Q^1.2 g^-0.6, and its volume-equivalent diameter [m].
double davidson_harrison_bubble_volume(double orifice_flow_m3_s, double gravity_m_s2 = 9.81);
double davidson_harrison_bubble_diameter(double orifice_flow_m3_s, double gravity_m_s2 = 9.81);

/// Darton et al. 1977: bubble diameter [m] at height h [m] above the distributor,
/// 0.54 (u0 - umf)^0.4 (h + 4 sqrt(A0))^0.8 g^-0.2, A0 the distributor area per orifice [m^2]
/// (0 for a porous plate).
double darton_bubble_diameter(double excess_velocity_m_s, double height_m,
                              double area_per_orifice_m2, double gravity_m_s2 = 9.81);

/// Mori & Wen 1975 for a porous plate: d_bm = 0.65 [A_t (u0 - umf)]^0.4 and d_b0 =
/// (2.78/g)(u0 - umf)^2 (the correlation's CGS units: cm, cm/s, cm^2, g = 981 cm/s^2),
/// d_b(h) = d_bm - (d_bm - d_b0) exp(-0.3 h/D_t). Arguments and result in SI; D_t the bed
/// diameter [m] (for a square bed, the diameter of the same area).
double mori_wen_bubble_diameter(double excess_velocity_m_s, double height_m, double bed_area_m2,
                                double bed_diameter_m);

}  // namespace consumers
}  // namespace draglab
