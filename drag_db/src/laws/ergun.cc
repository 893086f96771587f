#include "laws/ergun.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Ergun::describe() {
  LawFormDescription d;
  d.key = "ergun";
  d.title = "Ergun (1952): packed-bed pressure drop as a friction coefficient (TFM model A)";
  d.citation = "S. Ergun, Fluid flow through packed columns, Chem. Eng. Prog. 48 (1952) 89-94";
  d.form_notes =
      "beta d^2/(mu phi) = 150 phi/eps + 1.75 Re_p with the interstitial Re_p = rho d u/mu, i.e. "
      "F = (150 phi + 1.75 Re)/(18 eps^2): the form of MFiX DRAG_GIDASPOW (dense branch), OpenFOAM "
      "Ergun and waLBerla, consistent with Ergun's dP/L in a model-A momentum balance. Variants "
      "with other eps powers (Grains3D) are not implemented. No isolated-sphere limit: F(0, 0) = 0.";
  d.parameters = {
      {"a", 150.0, "1", "viscous (Blake-Kozeny) coefficient of a phi/eps in beta d^2/(mu phi)"},
      {"b", 1.75, "1", "inertial (Burke-Plummer) coefficient of b Re_p"},
  };
  d.validity.phi = {0.2, 0.65};
  d.validity.re = {0.0, 1000.0};
  d.single_sphere_stokes_F = 0.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Ergun;
DRAGLAB_REGISTER_LAW_FORM(Ergun)
