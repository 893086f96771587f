#include "laws/vdh2004.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Vdh2004::describe() {
  LawFormDescription d;
  d.key = "vdh2004";
  d.title = "van der Hoef, van Sint Annaland & Kuipers (2004): seed paper Eq. 6 as printed (eps^3)";
  d.citation =
      "M. A. van der Hoef, M. van Sint Annaland, J. A. M. Kuipers, Computational fluid dynamics "
      "for dense gas-solid fluidized beds: a multi-scale modeling strategy, Chem. Eng. Sci. 59 "
      "(2004) 5157-5165";
  d.form_notes =
      "beta d^2/mu = [A + C0] phi^2/eps + [B + C1] (phi/eps) Re with C0 = 18 eps^3 (1 + 1.5 "
      "sqrt(phi))/phi and C1 = -1.3 + 1.9 phi - 1.6 phi^2 exactly as printed in the seed paper "
      "(Re superficial). The later published form (bvk2007) has eps^4 in C0: set n0 = 4 for it. "
      "Preliminary fit: the paper says the coefficients may change with more data.";
  d.parameters = {
      {"A", 180.0, "1", "Carman-Kozeny coefficient (Ergun's 150 -> 180)"},
      {"B", 1.75, "1", "Ergun inertial coefficient"},
      {"k0", 18.0, "1", "C0 = k0 eps^n0 (1 + k1 sqrt(phi))/phi: prefactor"},
      {"n0", 3.0, "1", "C0: exponent of eps (3 as printed in 2004, 4 in Beetstra et al. 2007)"},
      {"k1", 1.5, "1", "C0: coefficient of sqrt(phi)"},
      {"c10", -1.3, "1", "C1 = c10 + c11 phi + c12 phi^2: constant term"},
      {"c11", 1.9, "1", "C1: coefficient of phi"},
      {"c12", -1.6, "1", "C1: coefficient of phi^2"},
  };
  d.validity.phi = {0.1, 0.6};
  d.validity.re = {0.0, 1000.0};
  d.single_sphere_stokes_F = 1.0;  // (k0/18) eps^(n0-2) -> 1 at phi = 0
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Vdh2004;
DRAGLAB_REGISTER_LAW_FORM(Vdh2004)
