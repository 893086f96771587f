// di_felice: Di Felice (1994) voidage function with the Dalla Valle single-sphere C_d.
//
//   F_d = (1/8) C_d rho pi d^2 eps^2 u^2 eps^-chi,   C_d = (0.63 + 4.8/sqrt(Re))^2   (Dalla Valle)
//   chi = chi_0 - chi_1 exp[-(1.5 - log10 Re)^2 / 2],  chi_0 = 3.7, chi_1 = 0.65
//   F   = (C_d Re / 24) eps^-chi,   Re = rho eps d u/mu (superficial)
//
// Native convention = canonical (drag-only F, superficial Re). Implemented with Dalla Valle's C_d
// as in the original paper, CFDEM DiFeliceDrag, PhasicFlowPlus and Kratos. Known deviations, NOT
// implemented: MFiX DRAG_DIFELICE and Grains3D use Schiller-Naumann's C_d; waLBerla dragForceFelice
// computes chi = 3.7 - 0.65^(-(1.5 - log10 Re)^2/2) (a power instead of 0.65 exp, a bug).
// Re -> 0: the exponential term vanishes (chi -> 3.7) and F -> 0.96 eps^-3.7; it is written with a
// select so that Re = 0 needs no log10(0). F(phi -> 0, Re -> 0) = 4.8^2/24 = 0.96: Dalla Valle's
// C_d is 4 % below Stokes drag. Validity (Di Felice's data base, indicative): eps 0.4-1, Re up to
// 1e4.
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct DiFelice {
  static constexpr int kNumParameters = 2;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// exp[-(1.5 - log10 Re)^2 / 2] for Re > 0, continued by its limit 0 at Re = 0. Shared with
  /// rong2013, which modulates its exponent by the same Gaussian in log10 Re.
  template <typename T>
  static T log_gaussian(const T& re) {
    const T x = T(1.5) - log10(re);
    return select(re > 0.0, exp(x * x * -0.5), T(0.0));
  }

  /// F = (C_d Re/24) eps^-chi; p = {chi_0, chi_1}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T chi = p[0] - p[1] * log_gaussian(re);
    return dalla_valle_cd_re_nonneg(re) / 24.0 * pow(T(1.0) - phi, -chi);
  }
};

}  // namespace laws
}  // namespace draglab
