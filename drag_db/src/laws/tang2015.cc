#include "laws/tang2015.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Tang2015::describe() {
  LawFormDescription d;
  d.key = "tang2015";
  d.title = "Tang, Peters, Kuipers, Kriebitzsch & van der Hoef (2015): static random arrays";
  d.citation =
      "Y. Tang, E. A. J. F. Peters, J. A. M. Kuipers, S. H. L. Kriebitzsch, M. A. van der Hoef, A "
      "new drag correlation from fully resolved simulations of flow past monodisperse static "
      "arrays of spheres, AIChE J. 61 (2015) 688-698, doi:10.1002/aic.14645";
  d.form_notes =
      "Eq. (21): F = 10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi)) + [0.11 phi (1 + phi) - "
      "0.00456/eps^4 "
      "+ (0.169 eps + 0.0644/eps^4) Re^-0.343] Re, drag-only, Re superficial (MFiX DRAG_TPKKV, "
      "waLBerla dragForceTang, MFiX-Exa 'BVK2'). Equal to bvk2007 and vdh2005 at Re = 0. The "
      "moving-"
      "particle (granular temperature) extension of Tang et al. 2016 is not included.";
  d.parameters = {
      {"a", 10.0, "1", "Carman-Kozeny coefficient of the Stokes term a phi/eps^2"},
      {"b", 1.5, "1", "coefficient of sqrt(phi) in the dilute Stokes term"},
      {"c1", 0.11, "1", "coefficient of phi (1 + phi) Re"},
      {"c2", 0.00456, "1", "coefficient of -Re/eps^4"},
      {"c3", 0.169, "1", "coefficient of eps Re^(1-e)"},
      {"c4", 0.0644, "1", "coefficient of Re^(1-e)/eps^4"},
      {"e", 0.343, "1", "Re^-e exponent of the power-law inertial term"},
  };
  d.validity.phi = {0.1, 0.6};
  d.validity.re = {0.0, 1000.0};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Tang2015;
DRAGLAB_REGISTER_LAW_FORM(Tang2015)
