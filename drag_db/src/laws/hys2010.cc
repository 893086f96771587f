#include "laws/hys2010.h"

#include "laws/bvk2007.h"

#include "law_registration.h"

namespace draglab {
namespace laws {

LawFormDescription Hys2010::describe() {
  LawFormDescription d = Bvk2007::describe();
  d.key = "hys2010";
  d.title = "Yin & Sundaresan (2009) polydisperse drag with Beetstra et al.'s inertia (MFiX HYS)";
  d.citation =
      "X. Yin, S. Sundaresan, Fluid-particle drag in low-Reynolds-number polydisperse gas-solid "
      "suspensions, AIChE J. 55 (2009) 1352-1368, doi:10.1002/aic.11800; as extended to finite Re "
      "in MFiX DRAG_HYS (B. Holloway, X. Yin, S. Sundaresan, AIChE J. 56 (2010) 1995-2004, "
      "doi:10.1002/aic.12127) with R. Beetstra, M. A. van der Hoef, J. A. M. Kuipers, AIChE J. 53 "
      "(2007) 489-501";
  d.form_notes =
      "F_i = 1/eps + (F_bvk2007(phi, Re) - 1/eps) [a y + (1-a) y^2], a = 1 - 2.66 phi + 9.096 "
      "phi^2 - 11.338 phi^3, y = d_i/<d> (Sauter mean), Re based on <d>; F_i normalised by 3 pi "
      "mu d_i eps u. Without MFiX's lubrication cross term (a solid-solid friction with no net "
      "gas-particle drag).";
  d.parameters.push_back({"k1", 2.66, "1", "a(phi) = 1 - k1 phi + k2 phi^2 - k3 phi^3"});
  d.parameters.push_back({"k2", 9.096, "1", "coefficient of phi^2 in a(phi)"});
  d.parameters.push_back({"k3", 11.338, "1", "coefficient of phi^3 in a(phi)"});
  d.validity.extra = {size_ratio_input()};
  d.single_sphere_stokes_F = 1.0;  // at y = 1 it is bvk2007
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::Hys2010;
DRAGLAB_REGISTER_LAW_FORM(Hys2010)
