#include "laws/syamlal_obrien.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription SyamlalOBrien::describe() {
  LawFormDescription d;
  d.key = "syamlal_obrien";
  d.title = "Syamlal & O'Brien (1988): terminal-velocity-ratio drag, Dalla Valle C_d (model A)";
  d.citation =
      "M. Syamlal, T. J. O'Brien, Simulation of granular layer inversion in liquid fluidized beds, "
      "Int. J. Multiphase Flow 14 (1988) 473-481";
  d.form_notes =
      "As MFiX DRAG_SYAM_OBRIEN: Re_p = rho d u/mu (interstitial), A = eps^4.14, B = C1 eps^1.28 "
      "for eps <= 0.85 else eps^D1, V_r = [A - 0.06 Re_p + sqrt((0.06 Re_p)^2 + 0.12 Re_p (2B - A) + "
      "A^2)]/2, beta d^2/(mu phi) = 0.75 eps (0.63 sqrt(Re_p/V_r) + 4.8)^2/V_r. Dalla Valle C_d: "
      "F(0, 0) = 0.96. C1, D1 are the usual U_mf tuning parameters.";
  d.parameters = {
      {"C1", 0.8, "1", "prefactor of B = C1 eps^1.28 for eps <= 0.85 (MFiX drag_c1)"},
      {"D1", 2.65, "1", "exponent of B = eps^D1 for eps > 0.85 (MFiX drag_d1)"},
  };
  d.validity.phi = {0.0, 0.6};
  d.validity.re = {0.0, 1.0e4};
  RegimeSwitch b_switch;
  b_switch.description = "B = eps^D1 (eps > 0.85) -> C1 eps^1.28 (eps <= 0.85)";
  b_switch.axis = RegimeSwitch::Axis::kPhi;
  b_switch.location = [](double, const double*) { return 1.0 - kSwitchEps; };
  // Vanishes at Re = 0 (V_r = A there); grows with Re towards the 0.06 % jump of B.
  b_switch.documented_relative_jump = 9.026e-4;
  b_switch.documented_at_other = 1000.0;
  d.switches = {b_switch};
  d.single_sphere_stokes_F = 0.96;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::SyamlalOBrien;
DRAGLAB_REGISTER_LAW_FORM(SyamlalOBrien)
