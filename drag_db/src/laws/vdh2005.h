// vdh2005: van der Hoef, Beetstra & Kuipers (2005), lattice-Boltzmann random monodisperse arrays
// in the Stokes limit.
//
//   F(phi) = a phi/eps^2 + eps^2 (1 + b sqrt(phi)),   a = 10, b = 1.5     (Re -> 0)
//
// Native convention = canonical (drag-only F, superficial normalisation). It is the Re -> 0 part
// of bvk2007 and tang2015 (the same code, Bvk2007::stokes_part, so the three agree bit for bit at
// Re = 0); labelled "eq(9) BVK J. Fluid Mech. 528, 2005" in MFiX DRAG_BVK. The a phi/eps^2 term is
// Carman-Kozeny; eps^2 (1 + b sqrt(phi)) carries the dilute limit (F -> 1 as phi -> 0). Stokes law
// only (has_inertia = false): Re is accepted but ignored. Validity: phi 0.1-0.6 (the LBM data;
// not verified), Re <= 0.1, where bvk2007's inertial term adds < 0.2 % at phi = 0.1.
// The polydisperse Stokes factor (1 - phi) y + phi y^2 of the same paper is not part of this form.
#pragma once

#include "laws/bvk2007.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct Vdh2005 {
  static constexpr int kNumParameters = 2;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kDragOnly, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialDiameter,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  /// F(phi), independent of Re; p = {a, b}.
  template <typename T>
  static T native(const T& phi, const T& /*re*/, const T* /*extra*/, const T* p) {
    return Bvk2007::stokes_part(phi, p[0], p[1]);
  }
};

}  // namespace laws
}  // namespace draglab
