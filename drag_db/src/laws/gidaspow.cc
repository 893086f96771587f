#include "laws/gidaspow.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Gidaspow::describe() {
  LawFormDescription d;
  d.key = "gidaspow";
  d.title = "Ding & Gidaspow (1990): Ergun for eps <= 0.8, Wen & Yu above (hard switch, model A)";
  d.citation =
      "J. Ding, D. Gidaspow, A bubbling fluidization model using kinetic theory of granular flow, "
      "AIChE J. 36 (1990) 523-538; D. Gidaspow, Multiphase Flow and Fluidization, Academic Press, "
      "1994";
  d.form_notes =
      "As MFiX DRAG_GIDASPOW: Ergun (150 phi/eps + 1.75 Re_p in beta d^2/(mu phi)) for eps <= 0.8, "
      "Wen-Yu (0.75 C_d Re eps^-2.65, Schiller-Naumann C_d with Re <= 1000) above; Re superficial. "
      "Equal to the ergun and wen_yu forms on either side. The switch at eps = 0.8 is "
      "discontinuous (documented jump of the published law); see gidaspow_blend.";
  d.parameters = {
      {"a", 150.0, "1", "Ergun viscous coefficient"},
      {"b", 1.75, "1", "Ergun inertial coefficient"},
      {"n", 2.65, "1", "Wen-Yu voidage exponent (beta carries eps^-n)"},
  };
  d.validity.phi = {0.0, 0.65};
  d.validity.re = {0.0, 1.0e4};
  RegimeSwitch ergun;
  ergun.description = "Wen & Yu (eps > 0.8) -> Ergun (eps <= 0.8)";
  ergun.axis = RegimeSwitch::Axis::kPhi;
  ergun.location = [](double, const double*) { return 1.0 - kSwitchEps; };
  // Ergun 150*0.2/(18*0.64) = 2.6042 against Wen-Yu 0.8^-3.65 = 2.2585 at Re = 0.
  ergun.documented_relative_jump = 0.1533;
  ergun.documented_at_other = 0.0;
  RegimeSwitch newton;
  newton.description = "Wen-Yu arm: Schiller-Naumann C_d -> 0.44 at Re = 1000 (eps > 0.8 only)";
  newton.axis = RegimeSwitch::Axis::kRe;
  newton.location = [](double, const double*) { return 1000.0; };
  newton.documented_relative_jump = 3.906e-3;
  newton.documented_at_other = 0.1;
  d.switches = {ergun, newton};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Gidaspow;
DRAGLAB_REGISTER_LAW_FORM(Gidaspow)
