#include "laws/gidaspow_blend.h"

#include <cmath>

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription GidaspowBlend::describe() {
  LawFormDescription d;
  d.key = "gidaspow_blend";
  d.title = "Gidaspow blended (Lathouwers & Bellan 2000): arctan switch between Ergun and Wen & Yu";
  d.citation =
      "D. Lathouwers, J. Bellan, Modeling of biomass pyrolysis for hydrogen production: the "
      "fluidized bed reactor, Proc. 2000 U.S. DOE Hydrogen Program Review, NREL/CP-570-28890 "
      "(2000); switch function as in MFiX DRAG_GIDASPOW_BLEND";
  d.form_notes =
      "psi = atan(262.5 (eps - 0.8))/pi + 1/2, beta = (1 - psi) beta_Ergun + psi beta_WenYu with "
      "the ergun and wen_yu forms (Re superficial, Schiller-Naumann C_d with Re <= 1000). The "
      "slope 262.5 = 150 * 1.75 is fixed. psi(eps = 1) = 0.99394, so F(0, 0) = 0.99394, not 1.";
  d.parameters = {
      {"a", 150.0, "1", "Ergun viscous coefficient"},
      {"b", 1.75, "1", "Ergun inertial coefficient"},
      {"n", 2.65, "1", "Wen-Yu voidage exponent (beta carries eps^-n)"},
  };
  d.validity.phi = {0.0, 0.65};
  d.validity.re = {0.0, 1.0e4};
  RegimeSwitch newton;
  newton.description = "Wen-Yu arm: Schiller-Naumann C_d -> 0.44 at Re = 1000";
  newton.axis = RegimeSwitch::Axis::kRe;
  newton.location = [](double, const double*) { return 1000.0; };
  newton.documented_relative_jump = 3.701e-3;  // at phi = 0.1, where psi = 0.988
  newton.documented_at_other = 0.1;
  d.switches = {newton};
  // Ergun vanishes at phi = 0, Re = 0 and Wen-Yu gives 1: F = psi(1) = atan(52.5)/pi + 1/2.
  d.single_sphere_stokes_F = wen_yu_weight(1.0);
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::GidaspowBlend;
DRAGLAB_REGISTER_LAW_FORM(GidaspowBlend)
