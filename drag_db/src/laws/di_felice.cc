#include "laws/di_felice.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription DiFelice::describe() {
  LawFormDescription d;
  d.key = "di_felice";
  d.title = "Di Felice (1994): voidage function eps^-chi with the Dalla Valle C_d";
  d.citation =
      "R. Di Felice, The voidage function for fluid-particle interaction systems, Int. J. "
      "Multiphase Flow 20 (1994) 153-159, doi:10.1016/0301-9322(94)90011-6";
  d.form_notes =
      "F = (C_d Re/24) eps^-chi, chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2/2), C_d = (0.63 + "
      "4.8/sqrt(Re))^2 (Dalla Valle, as in the original paper, CFDEM and PhasicFlow), Re "
      "superficial. Not implemented: MFiX/Grains3D (Schiller-Naumann C_d) and waLBerla (0.65^(...) "
      "instead of 0.65 exp(...)). F(0, 0) = 0.96 (Dalla Valle).";
  d.parameters = {
      {"chi_0", 3.7, "1", "voidage exponent far from Re = 10^1.5"},
      {"chi_1", 0.65, "1", "depth of the Gaussian dip of chi around log10 Re = 1.5"},
  };
  d.validity.phi = {0.0, 0.6};
  d.validity.re = {0.0, 1.0e4};
  d.single_sphere_stokes_F = 0.96;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::DiFelice;
DRAGLAB_REGISTER_LAW_FORM(DiFelice)
