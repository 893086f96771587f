#include "laws/bvk2007_polyfit.h"

#include "laws/bvk2007.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Bvk2007Polyfit::describe() {
  LawFormDescription d = Bvk2007::describe();
  d.key = "bvk2007_polyfit";
  d.title = "bvk2007 with a fitted polydisperse size factor a(phi) y + b(phi) y^2 + c(phi) y^3";
  d.form_notes =
      "F_i = F_bvk2007(phi, Re) [(a0 + a1 phi) y + (b0 + b1 phi) y^2 + (c0 + c1 phi) y^3], y = "
      "d_i/<d> (Sauter mean), Re based on <d>; F_i normalised by 3 pi mu d_i eps u. The defaults "
      "(1, -1, 0, 1, 0.064, -0.064) are bvk2007_poly; a form for fitting (draglab fit --form "
      "bvk2007_polyfit), not a literature law.";
  d.parameters.push_back({"a0", 1.0, "1", "a(phi) = a0 + a1 phi, the coefficient of y"});
  d.parameters.push_back({"a1", -1.0, "1", "slope of a(phi)"});
  d.parameters.push_back({"b0", 0.0, "1", "b(phi) = b0 + b1 phi, the coefficient of y^2"});
  d.parameters.push_back({"b1", 1.0, "1", "slope of b(phi)"});
  d.parameters.push_back({"c0", 0.064, "1", "c(phi) = c0 + c1 phi, the coefficient of y^3"});
  d.parameters.push_back({"c1", -0.064, "1", "slope of c(phi)"});
  d.validity.extra = {size_ratio_input()};
  d.single_sphere_stokes_F = 1.064;  // at y = 1 with the default coefficients
  d.has_inertia = true;
  d.literature = false;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Bvk2007Polyfit;
DRAGLAB_REGISTER_LAW_FORM(Bvk2007Polyfit)
