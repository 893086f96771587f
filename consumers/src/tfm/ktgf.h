// tfm/ktgf.h: closures of the kinetic theory of granular flow (KTGF) for the
// solids phase of the two-fluid model (tfm.h, seed Eqs. 14-15), and the frictional stresses
// added near packing.
//
// Notation: phi = eps_s the solids volume fraction, theta the granular temperature [m^2/s^2]
// (seed Eq. 14: theta = <C.C>/3), e the normal restitution coefficient, eta = (1 + e)/2, g0 the
// radial distribution function at contact, rho_s the particle density, d the diameter.
//
// Closure sets (every coefficient in one place, this file's .cc):
//  - kNieuwland (Nieuwland, Kuipers & van Swaaij 1996, the Kuipers group's set the seed's TFM
//    uses; shared/reference/consumers.md section 3.2):
//      P_s    = [1 + 4 eta phi g0] phi rho_s theta
//      mu_s   = 1.01600 (5/96) rho_s d sqrt(pi theta) (1 + (8/5) eta phi g0)^2 / (eta g0)
//               + (8/5) eta phi^2 rho_s d g0 sqrt(theta/pi)
//      lambda = (4/3) phi^2 rho_s d g0 (1 + e) sqrt(theta/pi)
//      kappa  = 1.02513 (75/384) rho_s d sqrt(pi theta) (1 + (12/5) eta phi g0)^2 / (eta g0)
//               + 2 phi^2 rho_s d g0 (1 + e) sqrt(theta/pi)
//      gamma  = 3 (1 - e^2) phi^2 rho_s g0 theta [(4/d) sqrt(theta/pi) - div v]
//  - kGidaspow (Ding & Gidaspow 1990, Gidaspow 1994): the same P_s and lambda; mu_s and kappa
//    without the Chapman-Cowling factors 1.016 and 1.02513; gamma without the - div v term
//    (12 (1 - e^2) phi^2 rho_s g0 theta^1.5 / (d sqrt(pi))).
// Radial distribution functions (phi_max = the packing limit):
//  - kMaAhmadi: [1 + 2.5 phi + 4.5904 phi^2 + 4.515439 phi^3] / [1 - (phi/phi_max)^3]^0.67802
//  - kCarnahanStarling: (1 - phi/2) / (1 - phi)^3 (no packing limit)
//  - kSinclairJackson: 1 / [1 - (phi/phi_max)^(1/3)]
//  - kLunSavage: (1 - phi/phi_max)^(-2.5 phi_max)
// The functions with a packing limit are singular there; g0 is evaluated at
// min(phi, phi_max - g0_margin) (as OpenFOAM caps it), so it stays finite while the two-fluid
// model's flux limiter keeps phi <= phi_max.
// Friction (off by default): Johnson & Jackson 1987 pressure
//      P_f = Fr (phi - phi_min)^n / max(phi_max - phi, delta)^p  for phi > phi_min,
// with, for kJohnsonJacksonSchaeffer, Schaeffer's 1987 viscosity
//      mu_f = P_f sin(angle) / (2 sqrt(I_2D)),
// or, for kJohnsonJacksonOpenFoam, the viscosity of OpenFOAM's JohnsonJackson frictional stress
// model (v1912: kinematic nu_f = 0.5 s P_f / rho_s sin(angle), in a stress alpha rho_s nu_f):
//      mu_f = phi (0.5 s) P_f sin(angle),
// which does not depend on the shear rate (so benchmarks against OpenFOAM can use its closure);
// either capped at mu_f_max.
//
// Units SI. Limits: monodisperse, dense-gas (Enskog) kinetic theory, no gas-phase effect on the
// transport coefficients (the -3 beta theta sink of Eq. 15 lives in the TFM).
#pragma once

#include <string>

namespace draglab {
namespace consumers {

enum class KtgfClosureSet { kNieuwland, kGidaspow };
enum class RadialDistribution { kMaAhmadi, kCarnahanStarling, kSinclairJackson, kLunSavage };
enum class FrictionModel { kNone, kJohnsonJacksonSchaeffer, kJohnsonJacksonOpenFoam };

const char* to_string(KtgfClosureSet set);
const char* to_string(RadialDistribution radial);
const char* to_string(FrictionModel friction);
/// Parse the names to_string gives; false for an unknown name.
bool parse_closure_set(const std::string& name, KtgfClosureSet* out);
bool parse_radial_distribution(const std::string& name, RadialDistribution* out);
bool parse_friction_model(const std::string& name, FrictionModel* out);

/// The closure choice and its parameters. IsValid names the field and range.
struct KtgfOptions {
  KtgfClosureSet closures = KtgfClosureSet::kNieuwland;
  RadialDistribution radial = RadialDistribution::kMaAhmadi;
  double restitution = 0.97;    ///< Particle-particle normal restitution e, (0, 1].
  double packing_limit = 0.64;  ///< phi_max, (0.3, 0.74].
  double g0_margin = 0.01;      ///< g0 evaluated at most at phi_max - margin, (0, 0.1].
  /// Knudsen limiter [m], >= 0 (0: off): the dilute (kinetic) parts of mu_s and kappa are
  /// multiplied by L / (L + lambda_mfp), lambda_mfp = d / (6 sqrt(2) phi g0) the mean free path,
  /// so transport never reaches further than L (the cell size in the TFM). In dense cells the
  /// factor is 1; in dilute ones it makes the kinetic viscosity proportional to phi instead of
  /// independent of it (Enskog theory fails once the mean free path exceeds the cell).
  double knudsen_length_m = 0.0;
  FrictionModel friction = FrictionModel::kNone;
  double friction_min_solids = 0.5;           ///< phi_min of Johnson-Jackson, (0, phi_max).
  double friction_angle_deg = 28.5;           ///< Internal friction angle, (0, 90).
  double friction_fr_pa = 0.05;               ///< Fr [Pa], > 0.
  double friction_n = 2.0;                    ///< Exponent n, > 0.
  double friction_p = 5.0;                    ///< Exponent p, > 0.
  double friction_delta = 0.02;               ///< delta, (0, 0.1].
  double friction_max_viscosity_pa_s = 10.0;  ///< mu_f cap [Pa s], > 0.

  bool IsValid(std::string* error) const;
};

/// Transport coefficients at one state.
struct KtgfCoefficients {
  double g0 = 0.0;
  double pressure_pa = 0.0;  ///< P_s (kinetic + collisional) + friction [Pa].
  double frictional_pressure_pa = 0.0;
  /// dP_s/dphi at fixed theta [Pa]: with rho_s it sets the granular pressure wave speed
  /// sqrt(dP/dphi / rho_s) that bounds the explicit time step.
  double pressure_derivative_pa = 0.0;
  double shear_viscosity_pa_s = 0.0;       ///< mu_s (+ mu_f) [Pa s].
  double frictional_viscosity_pa_s = 0.0;  ///< mu_f, the part of shear_viscosity from friction.
  /// Kinetic-collisional P_s / theta = (1 + 4 eta phi g0) phi rho_s [kg/m^3]: the expansion work
  /// -P_s div v of Eq. 15 is linear in theta.
  double kinetic_pressure_per_theta = 0.0;
  double bulk_viscosity_pa_s = 0.0;  ///< lambda_s [Pa s].
  double conductivity = 0.0;         ///< kappa_s [kg m^-1 s^-1].
  /// gamma = dissipation_rate_coefficient * theta [W/m^3]; the coefficient [kg m^-3 s^-1]
  /// already includes sqrt(theta) and the -div v term of the Nieuwland set.
  double dissipation_rate_coefficient = 0.0;
};

/// The closures of one particle kind.
class KtgfClosures {
 public:
  /// Throws Error(kInvalidArgument) for invalid options or particle properties.
  KtgfClosures(const KtgfOptions& options, double diameter_m, double density_kg_m3);

  /// g0(phi) with the margin cap; phi in [0, 1).
  double RadialDistributionAt(double phi) const;
  /// All coefficients at (phi, theta >= 0), div_v the solids velocity divergence [1/s] and
  /// shear_rate = sqrt(I_2D) [1/s] for the Schaeffer viscosity.
  KtgfCoefficients Evaluate(double phi, double theta, double div_v, double shear_rate) const;

  /// Granular temperature in local equilibrium, the algebraic alternative to transporting it
  /// (Eq. 15 without its convection and conduction): production by the kinetic-collisional
  /// shear and bulk viscosities equals expansion work, collisional dissipation and the drag
  /// sink, 2 mu_k D':D' + lambda (div v)^2 = P_s max(div v, 0) + gamma + drag_sink theta.
  /// Compression heating (div v < 0) is left to the transported theta: in equilibrium it would
  /// heat a compressing dense cell at once to (P_s/theta |div v| / dissipation)^2, a pressure
  /// the explicit solids stress cannot follow (the step collapses), whereas transported it grows
  /// only over the compression's duration. Every kinetic coefficient is sqrt(theta) times a
  /// function of phi, so this is a quadratic in sqrt(theta) with one non-negative root. dev2 =
  /// D':D' [1/s^2], div_v [1/s], drag_sink_kg_m3_s = 3 beta (0 without gas). Frictional stresses
  /// produce no fluctuations (they are not in the balance). Throws Error(kInvalidArgument) where
  /// nothing bounds theta (e = 1 and no drag sink, sheared).
  double EquilibriumTheta(double phi, double div_v, double dev2, double drag_sink_kg_m3_s) const;

  const KtgfOptions& options() const { return opt_; }

 private:
  KtgfOptions opt_;
  double d_, rho_;
};

}  // namespace consumers
}  // namespace draglab
