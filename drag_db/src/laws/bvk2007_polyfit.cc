#include "laws/bvk2007_polyfit.h"

#include "laws/bvk2007.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Bvk2007Polyfit::describe() {
  LawFormDescription d = Bvk2007::describe();
  d.key = "bvk2007_polyfit";
  d.title = "bvk2007 with a fitted polydisperse size factor (p_a, p_b, g)";
  d.form_notes =
      "F_i = F_bvk2007(phi, Re) [p_a (1-phi) y + p_b phi y^2 + g (1-phi) y^3], y = d_i/<d> (Sauter "
      "mean), Re based on <d>; F_i normalised by 3 pi mu d_i eps u. p_a = p_b = 1, g = 0.064 is "
      "bvk2007_poly; a form for fitting (draglab fit --form bvk2007_polyfit), not a literature "
      "law.";
  d.parameters.push_back({"p_a", 1.0, "1", "scale of the (1-phi) y term of the size factor"});
  d.parameters.push_back({"p_b", 1.0, "1", "scale of the phi y^2 term of the size factor"});
  d.parameters.push_back({"g", 0.064, "1", "coefficient of the (1-phi) y^3 term"});
  d.validity.extra = {{"y",
                       "d_i/<d>: particle diameter over the Sauter mean diameter of the mixture",
                       {0.25, 4.0}}};
  d.single_sphere_stokes_F = 1.064;  // at y = 1 with the default coefficients
  d.has_inertia = true;
  d.literature = false;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Bvk2007Polyfit;
DRAGLAB_REGISTER_LAW_FORM(Bvk2007Polyfit)
