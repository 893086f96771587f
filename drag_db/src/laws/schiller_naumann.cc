#include "laws/schiller_naumann.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription SchillerNaumann::describe() {
  LawFormDescription d;
  d.key = "schiller_naumann";
  d.title = "Schiller & Naumann (1933): isolated sphere, no voidage correction";
  d.citation =
      "L. Schiller, A. Naumann, Ueber die grundlegenden Berechnungen bei der "
      "Schwerkraftaufbereitung, Z. Ver. Dtsch. Ing. 77 (1933) 318-320";
  d.form_notes =
      "C_d Re_p = 24 (1 + 0.15 Re_p^0.687) for Re_p <= 1000 (MFiX inclusivity; OpenFOAM and "
      "waLBerla use <), 0.44 Re_p above; Re_p = rho d u/mu interstitial. Returned as the force "
      "F = (C_d Re_p/24)/eps (normalisation 'force', interstitial Re) instead of C_d, so that Re = "
      "0 is finite (Stokes drag, F = 1 at phi = 0). No voidage function: meant for phi -> 0.";
  d.parameters = {};
  d.validity.phi = {0.0, 0.01};
  d.validity.re = {0.0, 2.0e5};
  RegimeSwitch newton;
  newton.description = "Schiller-Naumann -> Newton regime (C_d = 0.44) at Re_p = 1000";
  newton.axis = RegimeSwitch::Axis::kRe;
  // Re_p = Re/eps = 1000  <=>  canonical Re = 1000 (1 - phi).
  newton.location = [](double phi, const double*) { return 1000.0 * (1.0 - phi); };
  newton.documented_relative_jump = 3.906e-3;  // 0.44*1000/24 / (1 + 0.15*1000^0.687) - 1
  newton.documented_at_other = 0.0;
  d.switches = {newton};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::SchillerNaumann;
DRAGLAB_REGISTER_LAW_FORM(SchillerNaumann)
