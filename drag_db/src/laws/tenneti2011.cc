#include "laws/tenneti2011.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Tenneti2011::describe() {
  LawFormDescription d;
  d.key = "tenneti2011";
  d.title = "Tenneti, Garg & Subramaniam (2011): PR-DNS of fixed random arrays (total force)";
  d.citation =
      "S. Tenneti, R. Garg, S. Subramaniam, Drag law for monodisperse gas-solid systems using "
      "particle-resolved direct numerical simulation of flow past fixed assemblies of spheres, "
      "Int. J. Multiphase Flow 37 (2011) 1072-1092, doi:10.1016/j.ijmultiphaseflow.2011.05.010";
  d.form_notes =
      "Stored as a total-force law: F_TGS = (1 + 0.15 Re^0.687)/eps^3 + 5.81 phi/eps^3 + 0.48 "
      "phi^(1/3)/eps^4 + phi^3 Re (0.95 + 0.61 phi^3/eps^2), canonical F = (1 - phi) F_TGS "
      "(waLBerla reading; phi^3 as OpenFOAM and waLBerla). Not implemented: MFiX-21.3.2 (phi^(1/3) "
      "in the last bracket, no (1 - phi)) and OpenFOAM (isolated term smaller by eps).";
  d.parameters = {
      {"a1", 5.81, "1", "coefficient of phi/eps^3 in F_phi"},
      {"a2", 0.48, "1", "coefficient of phi^(1/3)/eps^4 in F_phi"},
      {"b1", 0.95, "1", "constant in the F_phiRe bracket"},
      {"b2", 0.61, "1", "coefficient of phi^3/eps^2 in the F_phiRe bracket"},
  };
  d.validity.phi = {0.1, 0.5};
  d.validity.re = {0.0, 300.0};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Tenneti2011;
DRAGLAB_REGISTER_LAW_FORM(Tenneti2011)
