// syamlal_obrien: Syamlal & O'Brien (1988) drag from the terminal-velocity ratio V_r of a
// multiparticle system (Richardson-Zaki-type correlation of Garside & Al-Dibouni), Dalla Valle C_d.
//
//   Re_p = rho d u/mu (interstitial, no eps);  A = eps^4.14;
//   B = C1 eps^1.28 (eps <= 0.85),  eps^D1 (eps > 0.85);   C1 = 0.8, D1 = 2.65
//   V_r = [A - 0.06 Re_p + sqrt((0.06 Re_p)^2 + 0.12 Re_p (2B - A) + A^2)] / 2
//       (evaluated without cancellation at large Re_p, see velocity_ratio)
//   beta d^2/(mu phi) = (3/4) eps (0.63 sqrt(Re_p/V_r) + 4.8)^2 / V_r
//
// Native convention: beta d^2/(mu phi), interstitial Re, TFM model A, exactly as MFiX
// DRAG_SYAM_OBRIEN (drag_c1, drag_d1 are its tunable parameters, used to match a measured minimum
// fluidization velocity) and OpenFOAM SyamlalOBrien (CdRe = (0.63 sqrt(Re) + 4.8 sqrt(V_r))^2
// alpha_c/V_r^2, the same law). MFiX-Exa's port puts DPA and ROPg into Re (a port detail, not
// followed). The published defaults make B nearly continuous at eps = 0.85 (0.8 * 0.85^1.28 =
// 0.6498 vs 0.85^2.65 = 0.6502); the switch is kept as published (jump <= 0.1 % in F).
// At phi = 0: A = B = 1, V_r(Re = 0) = 1 and F = 0.75 * 4.8^2/18 = 0.96 (Dalla Valle's C_d is 4 %
// below Stokes). Validity: fluidized suspensions, eps from packing to 1 (indicative: 0.4-1);
// Re_p up to the Dalla Valle range (~1e4, indicative).
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct SyamlalOBrien {
  static constexpr int kNumParameters = 2;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{
      ForceKind::kDragOnly, Normalisation::kBetaD2OverMuPhi,
      ReynoldsDefinition::kInterstitialDiameter, TfmModel::kModelA};
  static LawFormDescription describe();

  /// Gas fraction at and below which B = C1 eps^1.28.
  static constexpr double kSwitchEps = 0.85;

  /// Terminal-velocity ratio V_r(eps, Re_p) > 0; p = {C1, D1}.
  /// With x = 0.06 Re_p and s the square root, A - x + s cancels once x >> A (at Re_p = 1e4 it is
  /// 600 - 600 + 0.3: three digits lost). Since (s + (A - x)) (s - (A - x)) = 4 B x, the same value
  /// is 4 B x/(s + x - A) there, which has no cancellation; both arms are equal where they meet.
  template <typename T>
  static T velocity_ratio(const T& eps, const T& re_p, const T* p) {
    const T a = pow(eps, 4.14);
    const T b = select(eps <= kSwitchEps, p[0] * pow(eps, 1.28), pow(eps, p[1]));
    const T x = re_p * 0.06;
    const T s = sqrt(x * x + x * 2.0 * (b * 2.0 - a) + a * a);
    return select(x > a, b * x * 2.0 / (s + x - a), (a - x + s) * 0.5);
  }

  /// beta d^2/(mu phi); `re_p` interstitial, p = {C1, D1}.
  template <typename T>
  static T native(const T& phi, const T& re_p, const T* /*extra*/, const T* p) {
    const T eps = T(1.0) - phi;
    const T v_r = velocity_ratio(eps, re_p, p);
    return eps * dalla_valle_cd_re_nonneg<T>(re_p / v_r) * 0.75 / v_r;
  }
};

}  // namespace laws
}  // namespace draglab
