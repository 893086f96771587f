// draglab/drag_db/conventions.h: the one place where drag conventions are converted.
//
// Canonical convention of draglab (docs/conventions.md, brief "The one convention for drag"):
//   phi  solids volume fraction, eps = 1 - phi gas volume fraction
//   u    interstitial slip velocity |u_g - u_s|; superficial U = eps u
//   Re   = rho eps d u / mu                      (superficial, diameter based)
//   F    = F_d / (3 pi mu d eps u)               (drag only: mean-pressure part excluded)
//   beta = 18 mu phi eps F / d^2                 (beta d^2/mu = 18 phi eps F)
//   K    = F / (1 - phi)                         (total force incl. mean pressure gradient)
//   Cd   = F_d / (rho u^2/2 * pi d^2/4)          (interstitial u), so Cd Re_p = 24 eps F
//          with Re_p = rho d u / mu = Re / eps.
//
// Literature laws are written in their native convention (NativeConvention) and converted here,
// once. All conversions are templates on the scalar type so the same code serves double,
// automatic differentiation (ceres::Jet) and code export (codegen::Expr).
#pragma once

#include <string>

namespace draglab {

/// Does the native force include the mean-pressure-gradient (buoyancy-like) part?
enum class ForceKind {
  kDragOnly,  ///< F_d: van der Hoef, Beetstra, Tang, Ergun, Wen-Yu, ...
  kTotal,     ///< F_tot = F_d / (1 - phi): Zick-Homsy, Hill-Koch-Ladd, Tenneti-Garg-Subramaniam.
};

/// Which dimensionless quantity the native formula returns.
enum class Normalisation {
  kForce,            ///< F_x / (3 pi mu d U), U = eps u superficial (F or K family).
  kBetaD2OverMuPhi,  ///< beta d^2 / (mu phi), MFiX's DgA d^2/mu (beta per unit solids fraction).
  kDragCoefficient,  ///< C_d of an isolated sphere at the interstitial slip (single-sphere laws).
};

/// Which Reynolds number the native formula takes.
enum class ReynoldsDefinition {
  kSuperficialDiameter,   ///< Re = rho eps d u / mu (canonical).
  kInterstitialDiameter,  ///< Re_p = rho d u / mu = Re / eps (Syamlal-O'Brien, Ergun in beta form).
  kSuperficialRadius,     ///< Re_a = rho eps a u / mu = Re / 2 (Hill-Koch-Ladd).
};

/// Two-fluid-model pressure-force formulation the law was written for (metadata only: the
/// per-particle F is the same; MFiX's model-B coefficient is the model-A one divided by eps).
enum class TfmModel { kNotApplicable, kModelA, kModelB };

/// Native convention of a law form: stored with every law version.
struct NativeConvention {
  ForceKind force = ForceKind::kDragOnly;
  Normalisation normalisation = Normalisation::kForce;
  ReynoldsDefinition reynolds = ReynoldsDefinition::kSuperficialDiameter;
  TfmModel tfm_model = TfmModel::kNotApplicable;
};

// String forms used in the database, JSON and exported code. Parsing throws draglab::Error.
const char* to_string(ForceKind v);
const char* to_string(Normalisation v);
const char* to_string(ReynoldsDefinition v);
const char* to_string(TfmModel v);
ForceKind force_kind_from_string(const std::string& s);
Normalisation normalisation_from_string(const std::string& s);
ReynoldsDefinition reynolds_definition_from_string(const std::string& s);
TfmModel tfm_model_from_string(const std::string& s);

namespace conventions {

/// Canonical Re (rho eps d u / mu) -> the Re a native formula expects.
template <typename T>
T native_reynolds(ReynoldsDefinition def, const T& phi, const T& re) {
  switch (def) {
    case ReynoldsDefinition::kInterstitialDiameter:
      return re / (T(1.0) - phi);
    case ReynoldsDefinition::kSuperficialRadius:
      return re * 0.5;
    case ReynoldsDefinition::kSuperficialDiameter:
    default:
      return re;
  }
}

/// A native value -> canonical drag-only F. `re_native` is the Reynolds number in the law's own
/// definition (needed for single-sphere C_d laws).
template <typename T>
T canonical_F_from_native(const NativeConvention& c, const T& phi, const T& re_native,
                          const T& value) {
  const T eps = T(1.0) - phi;
  T force;  // F_x / (3 pi mu d U) in the native force kind
  switch (c.normalisation) {
    case Normalisation::kBetaD2OverMuPhi:
      force = value / (eps * 18.0);  // beta d^2/mu = 18 phi eps F
      break;
    case Normalisation::kDragCoefficient: {
      // C_d Re_p = 24 eps F with Re_p the interstitial Reynolds number.
      const T re_p = (c.reynolds == ReynoldsDefinition::kInterstitialDiameter) ? re_native
                     : (c.reynolds == ReynoldsDefinition::kSuperficialRadius)
                         ? re_native * 2.0 / eps
                         : re_native / eps;
      force = value * re_p / (eps * 24.0);
      break;
    }
    case Normalisation::kForce:
    default:
      force = value;
      break;
  }
  return c.force == ForceKind::kTotal ? force * eps : force;  // F_d = (1 - phi) F_tot
}

/// beta d^2 / mu from canonical F.
template <typename T>
T beta_d2_over_mu(const T& phi, const T& F) {
  return phi * (T(1.0) - phi) * F * 18.0;
}

/// Friction coefficient beta [kg m^-3 s^-1] from canonical F; mu [Pa s], d [m].
template <typename T>
T beta(const T& phi, const T& F, double mu, double d) {
  return beta_d2_over_mu(phi, F) * (mu / (d * d));
}

/// Per-particle drag coefficient gamma [kg/s] of CFD-DEM codes, the drag on one particle being
/// gamma (u_f - u_p) with the interstitial slip: gamma = 3 pi mu d eps F, with d the particle's
/// own diameter (F is normalised by 3 pi mu d_i eps u). Equals beta V_p / phi for equal spheres.
template <typename T>
T particle_drag_coefficient(const T& phi, const T& F, double mu, double d) {
  return (T(1.0) - phi) * F * (3.0 * 3.14159265358979323846 * mu * d);
}

/// Total-force K = F / (1 - phi) (Zick-Homsy / Hill-Koch-Ladd normalisation).
template <typename T>
T total_force_K(const T& phi, const T& F) {
  return F / (T(1.0) - phi);
}

/// C_d Re_p = 24 eps F (finite at Re = 0; OpenFOAM's "CdRe").
template <typename T>
T drag_coefficient_times_re_p(const T& phi, const T& F) {
  return (T(1.0) - phi) * F * 24.0;
}

/// C_d = 24 eps^2 F / Re (interstitial slip in the dynamic pressure). Undefined at Re = 0.
template <typename T>
T drag_coefficient(const T& phi, const T& re, const T& F) {
  const T eps = T(1.0) - phi;
  return eps * eps * F * 24.0 / re;
}

/// Canonical F from beta d^2/mu (inverse of beta_d2_over_mu; phi > 0).
template <typename T>
T F_from_beta_d2_over_mu(const T& phi, const T& b) {
  return b / (phi * (T(1.0) - phi) * 18.0);
}

/// Canonical Re from dimensional inputs: rho eps d u / mu.
inline double reynolds(double eps_g, double mu_g, double rho_g, double slip, double d_p) {
  return rho_g * eps_g * d_p * slip / mu_g;
}

}  // namespace conventions
}  // namespace draglab
