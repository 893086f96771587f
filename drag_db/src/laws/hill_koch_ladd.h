// hill_koch_ladd: Hill, Koch & Ladd (2001a,b) lattice-Boltzmann random arrays, as extended to all
// Re and phi by Benyahia, Syamlal & O'Brien (2006) and coded in MFiX DRAG_KOCH_HILL.
//
// Total-force law: K = F_tot/(3 pi mu d U) with U superficial (the Zick-Homsy / HKL normalisation,
// beta = 18 mu phi eps^2 K/d^2 in MFiX), and the RADIUS based Re_a = rho U a/mu = Re/2.
//   w  = exp[-10 (0.4 - phi)/phi]
//   F0 = (1-w) [1 + 3 sqrt(phi/2) + (135/64) phi ln phi + c0 phi]
//              / [1 + 0.681 phi - 8.48 phi^2 + 8.16 phi^3] + w 10 phi/eps^3    (phi < 0.4)
//      = 10 phi/eps^3                                                         (phi >= 0.4)
//   F1 = sqrt(2/phi)/40 (phi <= 0.1);  0.11 + 5.1e-4 exp(11.6 phi) (phi > 0.1)
//   F2 = as F0 with c2 phi and [1 + 0.681 phi - 11.03 phi^2 + 15.41 phi^3]     (phi < 0.4)
//   F3 = 0.9351 phi + 0.03667 (phi < 0.0953);  0.0673 + 0.212 phi + 0.0232/eps^5 (phi >= 0.0953)
//   Re_t1 = (F2 - 1)/(3/8 - F3),   Re_t2 = [F3 + sqrt(F3^2 - 4 F1 (F0 - F2))]/(2 F1)
//   phi <= 0.01: K = 1 + (3/8) Re_a (Re_a <= Re_t1), F2 + F3 Re_a otherwise
//   phi >  0.01: K = F0 + F1 Re_a^2 (Re_a <= Re_t2), F2 + F3 Re_a otherwise
// c0 = 17.14, c2 = 17.89. Canonical F = (1 - phi) K.
//
// Variant choice: MFiX's 17.14 phi in F0 (CFDEM KochHillDrag uses 16.14, no w blending and only
// F0 + F3 Re_a; 17.14 is the value consistent with the Kim & Russel dilute expansion). The Re_t
// crossovers make K continuous in Re; in phi the published law jumps at phi = 0.01 (Oseen branch vs
// F0: +28 % at Re = 0) and by ~1e-5 at the F1 (0.1) and F3 (0.0953) branch points; it is continuous
// at phi = 0.4 (w = 1 there). Where MFiX would take a negative square root in Re_t2 (not reached
// with the published coefficients) the comparison with NaN is false and F2 + F3 Re_a is used
// (MFiX returns zero drag). Note also that phi -> 0 gives Re_t1 -> 0: an isolated sphere at Re > 0
// gets F2 + F3 Re_a = 1 + 0.0183 Re (C_d -> 0.44 at high Re, Benyahia's choice of F3).
// Validity: random arrays phi <= 0.6, Re_d up to a few hundred (300 here; not verified).
#pragma once

#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct HillKochLadd {
  static constexpr int kNumParameters = 2;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{ForceKind::kTotal, Normalisation::kForce,
                                                ReynoldsDefinition::kSuperficialRadius,
                                                TfmModel::kNotApplicable};
  static LawFormDescription describe();

  static constexpr double kOseenPhi = 0.01;  ///< phi at and below which the Oseen branch applies
  static constexpr double kF3Phi = 0.0953;   ///< F3 branch point
  static constexpr double kF1Phi = 0.1;      ///< F1 branch point
  static constexpr double kDensePhi = 0.4;   ///< Carman-Kozeny (w = 1) from here on

  template <typename T>
  struct Coefficients {
    T f0, f1, f2, f3;
  };

  /// F0..F3 of the header; p = {c0, c2}.
  template <typename T>
  static Coefficients<T> coefficients(const T& phi, const T* p) {
    const T eps = T(1.0) - phi;
    const T w = select(phi > 0.0, exp((phi - kDensePhi) * 10.0 / phi), T(0.0));
    const T carman_kozeny = phi * 10.0 / (eps * eps * eps);
    const T dilute_head = T(1.0) + sqrt_nonneg(phi * 0.5) * 3.0 + x_log_x(phi) * (135.0 / 64.0);
    const T phi2 = phi * phi;
    const T phi3 = phi2 * phi;
    const T f0_dilute =
        (dilute_head + p[0] * phi) / (T(1.0) + phi * 0.681 - phi2 * 8.48 + phi3 * 8.16);
    const T f2_dilute =
        (dilute_head + p[1] * phi) / (T(1.0) + phi * 0.681 - phi2 * 11.03 + phi3 * 15.41);
    Coefficients<T> c;
    c.f0 = select(phi < kDensePhi, (T(1.0) - w) * f0_dilute + w * carman_kozeny, carman_kozeny);
    c.f2 = select(phi < kDensePhi, (T(1.0) - w) * f2_dilute + w * carman_kozeny, carman_kozeny);
    c.f1 = select(phi <= kF1Phi, sqrt(T(2.0) / phi) / 40.0, exp(phi * 11.6) * 5.1e-4 + 0.11);
    const T eps2 = eps * eps;
    c.f3 = select(phi < kF3Phi, phi * 0.9351 + 0.03667,
                  phi * 0.212 + 0.0673 + T(0.0232) / (eps2 * eps2 * eps));
    return c;
  }

  /// Re_a where the Oseen branch meets F2 + F3 Re_a (used for phi <= 0.01).
  template <typename T>
  static T re_a_transition_1(const Coefficients<T>& c) {
    return (c.f2 - 1.0) / (T(0.375) - c.f3);
  }

  /// Re_a where F0 + F1 Re_a^2 meets F2 + F3 Re_a (used for phi > 0.01).
  template <typename T>
  static T re_a_transition_2(const Coefficients<T>& c) {
    return (c.f3 + sqrt(c.f3 * c.f3 - c.f1 * (c.f0 - c.f2) * 4.0)) / (c.f1 * 2.0);
  }

  /// K(phi, Re_a); `re_a` = rho U a/mu (radius, superficial), p = {c0, c2}.
  template <typename T>
  static T native(const T& phi, const T& re_a, const T* /*extra*/, const T* p) {
    const Coefficients<T> c = coefficients(phi, p);
    const T inertial = c.f2 + c.f3 * re_a;
    const T oseen = select(re_a <= re_a_transition_1(c), T(1.0) + re_a * 0.375, inertial);
    const T dense = select(re_a <= re_a_transition_2(c), c.f0 + c.f1 * re_a * re_a, inertial);
    return select(phi <= kOseenPhi, oseen, dense);
  }
};

}  // namespace laws
}  // namespace draglab
