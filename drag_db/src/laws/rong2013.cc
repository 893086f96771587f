#include "laws/rong2013.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Rong2013::describe() {
  LawFormDescription d;
  d.key = "rong2013";
  d.title = "Rong, Dong & Yu (2013): LBM packed beds, Di Felice form with porosity-dependent chi";
  d.citation =
      "L. W. Rong, K. J. Dong, A. B. Yu, Lattice-Boltzmann simulation of fluid flow through packed "
      "beds of uniform spheres: effect of porosity, Chem. Eng. Sci. 99 (2013) 44-58";
  d.form_notes =
      "F = (C_d Re/24) eps^-chi, chi = 2.65 (eps + 1) - (5.3 - 3.5 eps) eps^2 exp(-(1.5 - log10 "
      "Re)^2/2), Dalla Valle C_d, Re superficial (PhasicFlowPlus Rong.hpp, Kratos rong_drag_law). "
      "Equal to di_felice at phi = 0. Validity range from memory of the paper (eps 0.4-0.9, Re <= "
      "1000), not verified.";
  d.parameters = {
      {"k1", 2.65, "1", "chi at Re -> 0 is k1 (eps + 1)"},
      {"k2", 5.3, "1", "constant part of the Gaussian dip amplitude (k2 - k3 eps) eps^2"},
      {"k3", 3.5, "1", "eps coefficient of the dip amplitude (k2 - k3 eps) eps^2"},
  };
  d.validity.phi = {0.1, 0.6};
  d.validity.re = {0.0, 1000.0};
  d.single_sphere_stokes_F = 0.96;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Rong2013;
DRAGLAB_REGISTER_LAW_FORM(Rong2013)
