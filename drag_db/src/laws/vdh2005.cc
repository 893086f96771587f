#include "laws/vdh2005.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Vdh2005::describe() {
  LawFormDescription d;
  d.key = "vdh2005";
  d.title = "van der Hoef, Beetstra & Kuipers (2005): LBM random arrays, Stokes limit";
  d.citation =
      "M. A. van der Hoef, R. Beetstra, J. A. M. Kuipers, Lattice-Boltzmann simulations of "
      "low-Reynolds-number flow past mono- and bidisperse arrays of spheres: results for the "
      "permeability and drag force, J. Fluid Mech. 528 (2005) 233-254, "
      "doi:10.1017/S0022112004003295";
  d.form_notes =
      "F = 10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi)), drag-only, Re -> 0 (MFiX DRAG_BVK's Stokes "
      "part, OpenFOAM Beetstra F0, waLBerla Tang, Kratos). Identical to bvk2007 and tang2015 at "
      "Re = 0. Re is ignored; the validity box allows Re <= 0.1.";
  d.parameters = {
      {"a", 10.0, "1", "Carman-Kozeny coefficient of a phi/eps^2"},
      {"b", 1.5, "1", "coefficient of sqrt(phi) in the dilute term eps^2 (1 + b sqrt(phi))"},
  };
  d.validity.phi = {0.1, 0.6};
  d.validity.re = {0.0, 0.1};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = false;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Vdh2005;
DRAGLAB_REGISTER_LAW_FORM(Vdh2005)
