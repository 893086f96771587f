// vdh2005_poly: van der Hoef, Beetstra & Kuipers (2005), bidisperse random arrays, Stokes limit.
//
// clang-format off
//   F_i(phi, y_i) = F_vdh2005(phi) [(1 - phi) y_i + phi y_i^2],   y_i = d_i/<d>, <d> the Sauter mean
// clang-format on
//
// Native convention = canonical: drag-only F_i = F_d,i/(3 pi mu d_i eps u), normalised with the
// particle's own diameter (drag_laws.md 1.9: the form as recalled and as MFiX and Grains3D use it;
// the paper's tables were not found in a public copy). The factor sums to the mixture's F: with
// sum_i x_i/y_i = 1 for the Sauter mean, sum_i x_i F_i/y_i^2 = F_vdh2005(phi), so the mixture
// drags as a monodisperse array of <d>. Beetstra et al. (2007) added 0.064 (1 - phi) y^3 for
// finite Re (bvk2007_poly). Stokes only (has_inertia = false). Validity: phi 0.1-0.6 (as vdh2005),
// diameter ratios 1:1 to 1:4 (y in about [0.25, 4]).
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Vdh2005Poly {
  static constexpr int kNumParameters = 2;
  static constexpr int kNumExtraInputs = 1;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// extra = {y}; p = {a, b} of vdh2005; Re is ignored.
  template <typename T>
  static T native(const T& phi, const T& /*re*/, const T* extra, const T* p) {
    const T& y = extra[0];
    return Bvk2007::stokes_part(phi, p[0], p[1]) * ((T(1.0) - phi) * y + phi * y * y);
  }
};

}  // namespace laws
}  // namespace draglab
