#include "laws/bvk2007_poly.h"

#include "laws/bvk2007.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Bvk2007Poly::describe() {
  // Same paper, coefficients and validity as the monodisperse form, plus the size factor.
  LawFormDescription d = Bvk2007::describe();
  d.key = "bvk2007_poly";
  d.title = "Beetstra, van der Hoef & Kuipers (2007): polydisperse random arrays, finite Re";
  d.form_notes =
      "F_i = F_bvk2007(phi, Re) [(1-phi) y + phi y^2 + 0.064 (1-phi) y^3] with y = d_i/<d> (Sauter "
      "mean), phi the total solids fraction and Re = rho eps <d> u/mu based on <d>; F_i normalised "
      "by 3 pi mu d_i eps u. At y = 1 it is bvk2007 times 1 + 0.064 (1-phi), not bvk2007 itself, "
      "so F(0, 0) = 1.064 at y = 1. MFiX's per-phase variant (no y^3 term for phase 1, F_cor = y "
      "for model A) is not implemented.";
  d.parameters.push_back(
      {"g", 0.064, "1", "coefficient of the (1-phi) y^3 term of the size factor"});
  d.validity.extra = {size_ratio_input()};
  d.single_sphere_stokes_F = 1.064;  // at the representative y = 1: 1 * (1 + 0.064)
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Bvk2007Poly;
DRAGLAB_REGISTER_LAW_FORM(Bvk2007Poly)
