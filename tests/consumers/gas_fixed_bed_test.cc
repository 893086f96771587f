// Gas phase validation 3: uniform fixed bed, pressure gradient against the force balance
// (consumers/gas_phase.h).
//
// Set-up: a 5 cm x 20 cm column (5 x 40 cells, free-slip side walls so the flow is 1-D), uniform
// eps = 0.4, particles at rest (u_p = 0), 2.5 mm glass in air (rho_g = 1.2 kg/m^3,
// mu = 1.8e-5 Pa s), superficial inflow U = 0.5 m/s, gravity on, started from rest.
// beta from Ergun in closed form with the interstitial slip u = U/eps (the draglab convention:
// drag on the gas per volume = beta (u_p - u_g)):
//   beta = 150 phi^2 mu / (eps d^2) + 1.75 phi rho |u| / d.
// Reference (derived from seed Eq. 9 at steady uniform flow): 0 = -eps dp/dz - beta u +
// eps rho g_z, so -dp/dz = beta U / eps^2 + rho_g g. The drag part, beta U / eps^2, is Ergun's
// packed-bed pressure gradient 150 phi^2 mu U/(eps^3 d^2) + 1.75 phi rho U^2/(eps^3 d) =
// 3183.75 Pa/m (shared/reference/consumers.md §6 quotes 3 184 Pa/m for this case).
// Tolerance: the discrete solution of a uniform 1-D flow is exact, so 1e-9 relative (round-off
// of an LDLT solve on 200 unknowns); the gas velocity must be U/eps to 1e-12.
// A second case with no-slip walls checks that wall friction changes the result only by its
// small physical amount (viscous/drag ratio ~ mu eps / (beta dx^2) ~ 1e-4).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "draglab/consumers/gas_phase.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kEps = 0.4, kPhi = 0.6, kD = 2.5e-3, kMu = 1.8e-5, kRho = 1.2, kU = 0.5;

double ErgunBeta(double slip) {
  return 150.0 * kPhi * kPhi * kMu / (kEps * kD * kD) + 1.75 * kPhi * kRho * std::abs(slip) / kD;
}

GasPhase RunBed(WallSlip walls) {
  GasOptions o;
  o.nx = 5;
  o.nz = 40;
  o.width_m = 0.05;
  o.height_m = 0.20;
  o.rho_g = kRho;
  o.mu_g = kMu;
  o.side_walls = walls;
  o.background_velocity_m_s = kU;
  GasPhase gas(o);
  const Eigen::ArrayXXd eps = Eigen::ArrayXXd::Constant(o.nx, o.nz, kEps);
  const Eigen::ArrayXXd beta = Eigen::ArrayXXd::Constant(o.nx, o.nz, ErgunBeta(kU / kEps));
  const Eigen::ArrayXXd zero = Eigen::ArrayXXd::Zero(o.nx, o.nz);
  gas.SetVoidFraction(eps);
  gas.SetSolids(eps, beta, zero, zero);
  for (int s = 0; s < 50; ++s) gas.Step(1e-3);
  return gas;
}

TEST(GasFixedBed, PressureGradientMatchesErgunForceBalance) {
  const GasPhase gas = RunBed(WallSlip::kFreeSlip);
  const double drag_gradient = ErgunBeta(kU / kEps) * kU / (kEps * kEps);
  EXPECT_NEAR(drag_gradient, 3183.75, 1e-9 * 3183.75) << "closed-form Ergun check";
  const double expected = drag_gradient + kRho * 9.81;
  const double measured = gas.PressureDrop(0.05, 0.15) / 0.10;
  std::printf("fixed bed: -dp/dz = %.6f Pa/m, force balance %.6f Pa/m (Ergun drag part %.2f)\n",
              measured, expected, drag_gradient);
  EXPECT_NEAR(measured, expected, 1e-9 * expected);
  // Whole bed: outlet at 0 Pa, so p at the bottom face is the full column drop.
  EXPECT_NEAR(gas.PressureDrop(0.0, 0.20), expected * 0.20, 1e-9 * expected * 0.20);
  EXPECT_NEAR((gas.w() - kU / kEps).abs().maxCoeff(), 0.0, 1e-12);
  EXPECT_LT(gas.u().abs().maxCoeff(), 1e-12);
  // The particle-side view: the gradient sampled at a point agrees.
  EXPECT_NEAR(-gas.PressureGradientAt(0.025, 0.1).y(), expected, 1e-9 * expected);
}

TEST(GasFixedBed, NoSlipWallsChangeThePressureDropOnlySlightly) {
  const GasPhase gas = RunBed(WallSlip::kNoSlip);
  const double expected = ErgunBeta(kU / kEps) * kU / (kEps * kEps) + kRho * 9.81;
  const double measured = gas.PressureDrop(0.05, 0.15) / 0.10;
  EXPECT_NEAR(measured, expected, 1e-3 * expected);
  EXPECT_NE(measured, expected) << "wall friction must act";
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
