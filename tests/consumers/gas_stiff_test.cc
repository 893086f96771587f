// Gas phase validation 4: stiff drag coupling, implicit vs explicit (consumers/gas_phase.h).
//
// Set-up: a 10 cm x 10 cm box of gas, periodic in z, free-slip side walls, gravity off, uniform
// eps = 0.4, rho_g = 1.2 kg/m^3, particles moving at a fixed u_p = (0, 1) m/s, gas initially at
// rest, beta = eps rho_g / tau with tau = 1e-4 s (the gas-side relaxation time of the seed's bed
// at U_mf, shared/reference/consumers.md §4.3; beta = 4 800 kg m^-3 s^-1).
// Reference: the gas obeys eps rho dw/dt = beta (u_p - w), so w(t) = u_p (1 - exp(-t / tau)).
//  - Implicit (backward Euler) at dt = 100 tau: the discrete solution is exactly
//    w_n = u_p (1 - (1 + dt/tau)^-n); required to 1e-12 (round-off), and it is monotone/stable.
//  - Implicit at dt = tau/100 against the exact exponential at t = 1..5 tau: backward Euler's
//    error is <= (dt / 2 tau) (t / tau) exp(-t / tau) u_p <= 1.9e-3 u_p; tolerance 2e-3.
//  - Explicit (forward Euler, test-only option) at dt = 100 tau: the error is multiplied by
//    (1 - dt/tau) = -99 per step, so after one step |w - u_p| = 99 m/s, and the next step must
//    stop with a diagnosis (CFL far above its limit, naming the explicit coupling as the cause).
//  - Explicit at dt = tau / 2 is stable and within 0.15 u_p of the exponential (its error bound
//    at that step is ~ (dt/2tau)(t/tau) e^{-t/tau} <= 0.1).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "draglab/consumers/gas_phase.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kTau = 1e-4, kEps = 0.4, kRho = 1.2, kUp = 1.0;

GasPhase Box(DragCoupling coupling) {
  GasOptions o;
  o.nx = 4;
  o.nz = 4;
  o.width_m = 0.1;
  o.height_m = 0.1;
  o.rho_g = kRho;
  o.gravity_z = 0.0;
  o.side_walls = WallSlip::kFreeSlip;
  o.vertical = VerticalBoundary::kPeriodic;
  o.drag = coupling;
  GasPhase gas(o);
  const Eigen::ArrayXXd eps = Eigen::ArrayXXd::Constant(4, 4, kEps);
  const Eigen::ArrayXXd beta = Eigen::ArrayXXd::Constant(4, 4, kEps * kRho / kTau);
  gas.SetVoidFraction(eps);
  gas.SetSolids(eps, beta, Eigen::ArrayXXd::Zero(4, 4), Eigen::ArrayXXd::Constant(4, 4, kUp));
  return gas;
}

TEST(GasStiff, ImplicitIsStableAtHundredTauAndIsBackwardEulerExactly) {
  GasPhase gas = Box(DragCoupling::kImplicit);
  const double dt = 100 * kTau;
  double previous = 0.0, first = 0.0;
  for (int n = 1; n <= 5; ++n) {
    gas.Step(dt);
    if (n == 1) first = gas.w()(0, 0);
    const double discrete = kUp * (1.0 - std::pow(1.0 + dt / kTau, -n));
    EXPECT_NEAR(gas.w().maxCoeff(), discrete, 1e-12);
    EXPECT_NEAR(gas.w().minCoeff(), discrete, 1e-12);
    EXPECT_GE(gas.w()(0, 0), previous) << "monotone approach";
    EXPECT_LE(gas.w()(0, 0), kUp + 1e-12) << "no overshoot";
    previous = gas.w()(0, 0);
  }
  std::printf("implicit dt = 100 tau: w after 1 step %.6f m/s (1 - 1/101 = %.6f)\n", first,
              1.0 - 1.0 / 101.0);
}

TEST(GasStiff, ImplicitMatchesExponentialAtSmallStep) {
  GasPhase gas = Box(DragCoupling::kImplicit);
  const double dt = kTau / 100;
  double worst = 0.0;
  for (int n = 1; n <= 500; ++n) {
    gas.Step(dt);
    if (n % 100 == 0) {
      const double exact = kUp * (1.0 - std::exp(-n * dt / kTau));
      worst = std::max(worst, std::abs(gas.w()(1, 1) - exact));
    }
  }
  std::printf("implicit dt = tau/100: max |w - exact| at t = 1..5 tau: %.3e m/s\n", worst);
  EXPECT_LT(worst, 2e-3);
  EXPECT_GT(worst, 1e-6) << "first-order scheme: a zero error would mean the test is vacuous";
}

TEST(GasStiff, ExplicitBlowsUpAtHundredTau) {
  GasPhase gas = Box(DragCoupling::kExplicit);
  const double dt = 100 * kTau;
  gas.Step(dt);
  EXPECT_NEAR(gas.w()(0, 0) - kUp, -kUp * (1.0 - dt / kTau), 1e-9) << "amplification -99";
  std::printf("explicit dt = 100 tau: |w - u_p| after 1 step = %.3f m/s (implicit: %.5f)\n",
              std::abs(gas.w()(0, 0) - kUp), kUp / 101.0);
  try {
    gas.Step(dt);
    ADD_FAILURE() << "explicit coupling at dt = 100 tau was not stopped";
  } catch (const Error& e) {
    const std::string what = e.what();
    std::printf("stopped: %s\n", what.c_str());
    EXPECT_NE(what.find("CFL"), std::string::npos) << what;
    EXPECT_NE(what.find("implicit"), std::string::npos) << what;
  }
}

TEST(GasStiff, ExplicitIsStableBelowTwoTau) {
  GasPhase gas = Box(DragCoupling::kExplicit);
  const double dt = kTau / 2;
  for (int n = 1; n <= 10; ++n) gas.Step(dt);
  const double exact = kUp * (1.0 - std::exp(-10 * dt / kTau));
  EXPECT_NEAR(gas.w()(2, 2), exact, 0.15 * kUp);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
