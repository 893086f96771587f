#include "laws/bvk2007.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Bvk2007::describe() {
  LawFormDescription d;
  d.key = "bvk2007";
  d.title = "Beetstra, van der Hoef & Kuipers (2007): LBM random arrays, monodisperse, finite Re";
  d.citation =
      "R. Beetstra, M. A. van der Hoef, J. A. M. Kuipers, Drag force of intermediate Reynolds "
      "number flow past mono- and bidisperse arrays of spheres, AIChE J. 53 (2007) 489-501, "
      "doi:10.1002/aic.11065";
  d.form_notes =
      "Monodisperse form as in MFiX DRAG_BVK and OpenFOAM Beetstra (Re^-(1+4phi)/2 in the "
      "denominator, Stokes part of van der Hoef et al. 2005 with eps^2 (1 + 1.5 sqrt(phi))).";
  d.parameters = {
      {"a", 10.0, "1", "Carman-Kozeny coefficient of the Stokes term a phi/eps^2"},
      {"b", 1.5, "1", "coefficient of sqrt(phi) in the dilute Stokes term"},
      {"c", 0.413, "1", "inertial prefactor (Turton-Levenspiel 0.413)"},
      {"d", 8.4, "1", "coefficient of Re^-e in the inertial numerator"},
      {"e", 0.343, "1", "exponent of Re in the inertial numerator"},
  };
  d.validity.phi = {0.1, 0.6};
  d.validity.re = {0.0, 1000.0};
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Bvk2007;
DRAGLAB_REGISTER_LAW_FORM(Bvk2007)
