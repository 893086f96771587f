// Fast checks of the finite-Re engine paths (the long ones: finite_re_stability_validation.cc).
//
// 1. Wall interpolation in Stokes flow. Set-up: simple-cubic array, phi = 0.125, d = 16 (one
//    sphere centred on a cell corner), Re = 0. Reference: Sangani & Acrivos 1982 (the 31-term
//    series, data/sangani_acrivos_sc_series.csv), F = (1 - phi) K. The automatic wall takes CLI in
//    Stokes flow: within 0.2 % at tau = 0.52 and 1.5 (measured -0.07 % at both; its steady state
//    does not depend on tau). BFL, the wall automatic runs take below tau = 0.52, is checked at
//    tau = 0.52, where it runs: within 0.2 % (measured -0.12 %; its wall moves with tau, by
//    -2.2 % at tau = 1.5, which is why it is not used there).
// 2. Refusal before any stepping: the case, a random packing at phi = 0.6 (27 spheres),
//    d = 10, Re = 30 with TRT: kappa Re / d = 12.8 x 30 / 10 = 38.5 is beyond the 35 every measured
//    TRT run diverged at; Error(kInvalidArgument) naming the cell Reynolds number and the d that
//    holds, thrown within a second (the run would take minutes).
// 3. Per-sphere drag in sub-node gaps (phi 0.6, 27 spheres, d 10, Stokes). TRT at fixed Lambda
//    has a steady state that hardly depends on tau, sphere by sphere: each sphere's F agrees at
//    tau = 1 and 2 to 1 % (measured 0.15 %: the fallback links and the mass correction of the
//    one-node gaps break the exact tau independence of open geometries slightly). A
//    reference-pressure part 2 w_i c_i left in a sphere's momentum exchange does not cancel where
//    links in a gap were given to the neighbour they cross first, and offsets that sphere's F by
//    a constant over nu U: by several units of F, and three times more at tau = 1 than at 2.
// 4. The velocity plan of a run: kappa measured by the Stokes run is the run's own (Stokes)
//    max|u|/U, the Mach number the run reaches stays near the target (at most 1.5x: the start-up
//    overshoots, and kappa falls with Re), and the achieved Re hits the target.
// 5. The automatic operator (Collision::kAuto, the default). Set-up: simple-cubic array, phi 0.3,
//    d 8, Re 40: kappa Re / d = 4.95 x 40 / 8 = 24.7, beyond the 23 TRT held in every measured
//    packing but below the 35 it is refused at, so TRT runs too. Auto must run rr with TRT's wall
//    and say why. Reference: TRT at the same lattice and tau (its wall is exact at Lambda 3/16).
//    The wall correction must remove most of rr's own wall shift: rr without it is 40 % above
//    TRT, with it 9.6 % (measured; the shift falls as 1/d^2, docs/validation.md); required: at
//    least 3x closer, and within the run's own error estimate.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "draglab/error.h"
#include "draglab/lbm/resolution.h"
#include "error_model.h"
#include "validation_support.h"

namespace draglab {
namespace lbm {
namespace validation {
namespace {

RunResult sc_stokes(double tau, WallInterpolation wall) {
  const ScArray sc = make_sc_array(0.125, 16.0);
  RunOptions o = stokes_options(Collision::kTrt, Boundary::kInterpolated, tau);
  o.interpolation = wall;
  o.tolerance = 1e-6;  // F to well below the 0.2 % checked
  o.threads = 1;
  return run(sc.grid, sc.packing.phi(), o);
}

TEST(FiniteReEngine, AutomaticWallIsCentralInStokesFlowAndBouzidiHoldsNearOneHalf) {
  const double reference = sangani_acrivos_F(0.125);
  for (double tau : {0.52, 1.5}) {
    const RunResult r = sc_stokes(tau, WallInterpolation::kAuto);
    ASSERT_TRUE(r.converged) << r.diagnosis;
    EXPECT_EQ(r.wall, "cli");
    EXPECT_NEAR(r.F / reference - 1.0, 0.0, 2e-3) << "tau " << tau << ": " << format_run(r);
  }
  const RunResult bfl = sc_stokes(0.52, WallInterpolation::kBouzidi);
  ASSERT_TRUE(bfl.converged) << bfl.diagnosis;
  EXPECT_EQ(bfl.wall, "bfl");
  EXPECT_NEAR(bfl.F / reference - 1.0, 0.0, 2e-3) << format_run(bfl);
}

TEST(FiniteReEngine, DensePackingBeyondTheCellReynoldsLimitIsRefusedBeforeStepping) {
  const arrays::Packing packing = make_random_packing(0.6, 27, 1);
  RunOptions o;
  o.collision = Collision::kTrt;
  o.re = 30.0;
  o.threads = 1;
  const auto start = std::chrono::steady_clock::now();
  try {
    run(packing, 10.0, o);
    FAIL() << "phi 0.6, d 10, Re 30 with TRT must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    const std::string what = e.what();
    EXPECT_NE(what.find("cell Reynolds number"), std::string::npos) << what;
    const VelocityPlan plan = plan_velocity(0.6, 30.0, 10.0, Collision::kTrt, 0.1, 0.0, false);
    EXPECT_NE(what.find("--d " + std::to_string(static_cast<int>(plan.d_stable))),
              std::string::npos)
        << what;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

TEST(FiniteReEngine, PerSphereDragInSubNodeGapsDoesNotDependOnTau) {
  const arrays::Packing packing = make_random_packing(0.6, 27, 1);
  std::vector<double> body_F[2];
  int k = 0;
  for (double tau : {1.0, 2.0}) {
    RunOptions o = stokes_options(Collision::kTrt, Boundary::kInterpolated, tau);
    o.tolerance = 1e-7;
    o.threads = 1;
    const RunResult r = run(packing, 10.0, o);
    ASSERT_TRUE(r.converged) << r.diagnosis;
    ASSERT_GT(r.narrow_gap_pairs, 0);
    body_F[k++] = r.body_F;
  }
  ASSERT_EQ(body_F[0].size(), 27u);
  for (std::size_t s = 0; s < body_F[0].size(); ++s) {
    EXPECT_NEAR(body_F[0][s], body_F[1][s], 1e-2 * std::abs(body_F[1][s])) << "sphere " << s;
  }
}

TEST(FiniteReEngine, AutoRunsRrWithTrtsWallBeyondTrtsStableCellReynolds) {
  const ScArray sc = make_sc_array(0.3, 8.0);
  auto run_with = [&sc](Collision collision, bool correction) {
    RunOptions o;
    o.collision = collision;
    o.rr_wall_correction = correction;
    o.re = 40.0;
    o.tolerance = 1e-6;
    o.threads = 1;
    return run(sc.grid, sc.packing.phi(), o);
  };
  const RunResult automatic = run_with(Collision::kAuto, true);
  EXPECT_EQ(automatic.collision, Collision::kRegularized);
  EXPECT_TRUE(automatic.wall_corrected);
  EXPECT_NE(automatic.collision_reason.find("> 23"), std::string::npos)
      << automatic.collision_reason;
  const RunResult trt = run_with(Collision::kTrt, true);
  EXPECT_EQ(trt.collision, Collision::kTrt);
  EXPECT_TRUE(trt.collision_reason.empty());
  const RunResult plain = run_with(Collision::kRegularized, false);
  EXPECT_FALSE(plain.wall_corrected);
  const double corrected_shift = std::abs(automatic.F / trt.F - 1.0);
  const double plain_shift = std::abs(plain.F / trt.F - 1.0);
  EXPECT_LT(corrected_shift, plain_shift / 3.0) << format_run(automatic) << format_run(plain);
  EXPECT_LT(corrected_shift, automatic.error_estimate) << format_run(automatic);
  // d 8 is below the boundary-layer rule here: both claim at least (layer / d)^2 - 1, which
  // hides the widening for what is left of rr's wall shift; that is checked on the model itself.
  EXPECT_GE(automatic.discretisation_error, 0.5);
  EXPECT_GE(trt.discretisation_error, 0.5);
  ErrorModelInput corrected;
  corrected.collision = Collision::kRegularized;
  corrected.wall_corrected = true;
  corrected.tau = automatic.tau;
  corrected.d = 8.0;
  corrected.phi = 0.3;
  corrected.re = 40.0;
  ErrorModelInput trt_wall = corrected;
  trt_wall.collision = Collision::kTrt;
  trt_wall.wall_corrected = false;
  EXPECT_GT(discretisation_error_estimate(corrected), discretisation_error_estimate(trt_wall));
}

TEST(FiniteReEngine, VelocityIsPlannedFromTheMeasuredPoreSpeedRatio) {
  const arrays::Packing packing = make_random_packing(0.4, 8, 3);
  RunOptions o;
  o.re = 10.0;
  o.tolerance = 1e-5;
  o.threads = 1;
  o.throw_on_failure = false;
  const RunResult r = run(packing, 12.0, o);
  ASSERT_TRUE(r.converged) << r.diagnosis;
  EXPECT_TRUE(r.pore_speed_ratio_measured);
  EXPECT_GT(r.pore_speed_ratio, 2.0);
  EXPECT_NEAR(r.re / 10.0, 1.0, o.re_tolerance);
  EXPECT_LT(r.mach_max, 1.5 * o.mach_target) << format_run(r);
  EXPECT_GT(r.mach_max, 0.5 * o.mach_target) << format_run(r);
  // The run's own max|u|/U at Re 10 is below the Stokes value it was planned with.
  EXPECT_LT(r.final_pore_speed_ratio, r.pore_speed_ratio * 1.02);
  EXPECT_NEAR(r.superficial_velocity, o.mach_target / std::sqrt(3.0) / r.pore_speed_ratio,
              0.02 * r.superficial_velocity);
}

}  // namespace
}  // namespace validation
}  // namespace lbm
}  // namespace draglab
