#include "laws/wen_yu.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription WenYu::describe() {
  LawFormDescription d;
  d.key = "wen_yu";
  d.title =
      "Wen & Yu (1966): Schiller-Naumann C_d with the eps^-2.65 voidage function (TFM model A)";
  d.citation =
      "C. Y. Wen, Y. H. Yu, Mechanics of fluidization, Chem. Eng. Prog. Symp. Ser. 62 (1966) "
      "100-111";
  d.form_notes =
      "beta d^2/(mu phi) = 0.75 C_d Re eps^-2.65 with Re = rho eps d u/mu (superficial) and the "
      "Schiller-Naumann C_d switched to 0.44 above Re = 1000 (<=, as MFiX DRAG_WEN_YU; OpenFOAM "
      "uses <), i.e. F = (C_d Re/24) eps^-3.65. Grains3D's eps^-2.7 variant is not implemented.";
  d.parameters = {
      {"n", 2.65, "1", "voidage exponent: beta carries eps^-n (F carries eps^-(n+1))"},
  };
  d.validity.phi = {0.0, 0.2};
  d.validity.re = {0.0, 1.0e4};
  RegimeSwitch newton;
  newton.description = "Schiller-Naumann C_d -> 0.44 (Newton regime) at Re = 1000";
  newton.axis = RegimeSwitch::Axis::kRe;
  newton.location = [](double, const double*) { return 1000.0; };
  newton.documented_relative_jump = 3.906e-3;  // independent of phi
  newton.documented_at_other = 0.1;
  d.switches = {newton};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::WenYu;
DRAGLAB_REGISTER_LAW_FORM(WenYu)
