#include "laws/vdh2005_poly.h"

#include "laws/vdh2005.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Vdh2005Poly::describe() {
  // Same paper, coefficients and box as the monodisperse form, plus the size factor.
  LawFormDescription d = Vdh2005::describe();
  d.key = "vdh2005_poly";
  d.title = "van der Hoef, Beetstra & Kuipers (2005): bidisperse random arrays, Stokes limit";
  d.form_notes =
      "F_i = F_vdh2005(phi) [(1-phi) y + phi y^2] with y = d_i/<d> (Sauter mean) and phi the total "
      "solids fraction; F_i normalised by 3 pi mu d_i eps u. The mixture's F (sum x_i F_i/y_i^2) "
      "is F_vdh2005(phi) for any size distribution. Re is ignored; the validity box allows "
      "Re <= 0.1.";
  d.validity.extra = {size_ratio_input()};
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Vdh2005Poly;
DRAGLAB_REGISTER_LAW_FORM(Vdh2005Poly)
