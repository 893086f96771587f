// rong2013: Rong, Dong & Yu (2013), lattice-Boltzmann packed beds of uniform spheres: Di Felice's
// structure with a porosity-dependent exponent.
//
//   chi = k1 (eps + 1) - (k2 - k3 eps) eps^2 exp[-(1.5 - log10 Re)^2 / 2],  k1 = 2.65, k2 = 5.3,
//         k3 = 3.5
//   F   = (C_d Re / 24) eps^-chi,  C_d = Dalla Valle,  Re = rho eps d u/mu (superficial)
//
// Native convention = canonical. As PhasicFlow/PhasicFlowPlus Rong.hpp and Kratos rong_drag_law
// (which writes 0.63 as 2.654/(1 + 3.213)). Re -> 0: chi -> k1 (eps + 1) (select, no log10(0)).
// At phi = 0, eps^-chi = 1 for any chi, so rong2013 and di_felice coincide there (both give the
// isolated-sphere Dalla Valle drag; F(0, 0) = 0.96). Validity (not verified against the paper):
// eps about 0.4-0.9, Re up to about 1000.
#pragma once

#include "laws/di_felice.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Rong2013 {
  static constexpr int kNumParameters = 3;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// F = (C_d Re/24) eps^-chi; p = {k1, k2, k3}.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T eps = T(1.0) - phi;
    const T chi = p[0] * (eps + 1.0) - (p[1] - p[2] * eps) * eps * eps * DiFelice::log_gaussian(re);
    return dalla_valle_cd_re_nonneg(re) / 24.0 * pow(eps, -chi);
  }
};

}  // namespace laws
}  // namespace draglab
