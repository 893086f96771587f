#include "laws/hill_koch_ladd.h"

#include "law_registration.h"

namespace draglab {
namespace laws {
namespace {

// Canonical Re (= 2 Re_a) of the Re_a crossovers, for the continuity tests and the docs.
double oseen_crossover_re(double phi, const double* params) {
  return 2.0 * HillKochLadd::re_a_transition_1(HillKochLadd::coefficients(phi, params));
}
double inertial_crossover_re(double phi, const double* params) {
  return 2.0 * HillKochLadd::re_a_transition_2(HillKochLadd::coefficients(phi, params));
}

}  // namespace

LawFormDescription HillKochLadd::describe() {
  LawFormDescription d;
  d.key = "hill_koch_ladd";
  d.title = "Hill, Koch & Ladd (2001) LBM random arrays, Benyahia et al. (2006) extension (MFiX)";
  d.citation =
      "R. J. Hill, D. L. Koch, A. J. C. Ladd, The first effects of fluid inertia on flows in "
      "ordered and random arrays of spheres, J. Fluid Mech. 448 (2001) 213-241, "
      "doi:10.1017/S0022112001005936; Moderate-Reynolds-number flows in ordered and random arrays "
      "of spheres, J. Fluid Mech. 448 (2001) 243-278, doi:10.1017/S0022112001005948; extension: S. "
      "Benyahia, M. Syamlal, T. J. O'Brien, Powder Technol. 162 (2006) 166-174";
  d.form_notes =
      "MFiX DRAG_KOCH_HILL: total-force K with the radius-based Re_a = Re/2, F = (1 - phi) K; F0 "
      "with 17.14 phi (CFDEM's 16.14 and its F0 + F3 Re_a-only form are not implemented), w "
      "blending towards Carman-Kozeny 10 phi/eps^3, F1/F2/F3 and the Re_t1/Re_t2 crossovers. "
      "Discontinuous in phi at 0.01 (+28 % at Re = 0), and by ~1e-5 at 0.0953 and 0.1, as "
      "published.";
  d.parameters = {
      {"c0", 17.14, "1", "coefficient of phi in the numerator of the Stokes fit F0"},
      {"c2", 17.89, "1", "coefficient of phi in the numerator of the inertial fit F2"},
  };
  d.validity.phi = {0.0, 0.6};
  d.validity.re = {0.0, 300.0};

  RegimeSwitch oseen_phi;
  oseen_phi.description = "phi = 0.01: Oseen branch 1 + 3/8 Re_a -> F0 + F1 Re_a^2";
  oseen_phi.axis = RegimeSwitch::Axis::kPhi;
  oseen_phi.location = [](double, const double*) { return kOseenPhi; };
  oseen_phi.documented_relative_jump = 0.2788;  // F0(0.01) - 1 at Re = 0
  oseen_phi.documented_at_other = 0.0;

  RegimeSwitch f3_phi;
  f3_phi.description =
      "phi = 0.0953: F3 = 0.9351 phi + 0.03667 -> 0.0673 + 0.212 phi + 0.0232/eps^5";
  f3_phi.axis = RegimeSwitch::Axis::kPhi;
  f3_phi.location = [](double, const double*) { return kF3Phi; };
  f3_phi.documented_relative_jump = 1.102e-5;  // the two F3 fits differ by 1.1e-5 at 0.0953
  f3_phi.documented_at_other = 100.0;

  RegimeSwitch f1_phi;
  f1_phi.description = "phi = 0.1: F1 = sqrt(2/phi)/40 -> 0.11 + 5.1e-4 exp(11.6 phi)";
  f1_phi.axis = RegimeSwitch::Axis::kPhi;
  f1_phi.location = [](double, const double*) { return kF1Phi; };
  f1_phi.documented_relative_jump = 1.494e-5;
  f1_phi.documented_at_other = 1.0;

  RegimeSwitch dense_phi;
  dense_phi.description = "phi = 0.4: w-blended fits -> Carman-Kozeny 10 phi/eps^3 (w(0.4) = 1)";
  dense_phi.axis = RegimeSwitch::Axis::kPhi;
  dense_phi.location = [](double, const double*) { return kDensePhi; };
  dense_phi.documented_relative_jump = 0.0;
  dense_phi.documented_at_other = 10.0;

  RegimeSwitch oseen_re;
  oseen_re.description = "Re_a = Re_t1 (phi <= 0.01): 1 + 3/8 Re_a -> F2 + F3 Re_a";
  oseen_re.axis = RegimeSwitch::Axis::kRe;
  oseen_re.location = &oseen_crossover_re;
  oseen_re.documented_relative_jump = 0.0;
  oseen_re.documented_at_other = 0.005;

  RegimeSwitch inertial_re;
  inertial_re.description = "Re_a = Re_t2 (phi > 0.01): F0 + F1 Re_a^2 -> F2 + F3 Re_a";
  inertial_re.axis = RegimeSwitch::Axis::kRe;
  inertial_re.location = &inertial_crossover_re;
  inertial_re.documented_relative_jump = 0.0;
  inertial_re.documented_at_other = 0.2;

  d.switches = {oseen_phi, f3_phi, f1_phi, dense_phi, oseen_re, inertial_re};
  d.single_sphere_stokes_F = 1.0;
  d.has_inertia = true;
  return d;
}

}  // namespace laws
}  // namespace draglab

using draglab::laws::HillKochLadd;
DRAGLAB_REGISTER_LAW_FORM(HillKochLadd)
