// Validations 2 and 3: Stokes drag on simple-cubic (SC) arrays of spheres.
//
// Set-up: one sphere of diameter d (lattice units) in a periodic cube of edge L = d (pi/(6 phi))^
// (1/3), from arrays::generate_ordered_packing, centred on a lattice cell corner (see
// make_sc_array), flow along x driven by a uniform body force on the fluid, Re = 0 (Stokes mode,
// linear equilibrium).
//
// Reference: Sangani & Acrivos 1982 (IJMF 8:343, Eq. 60), the 31-term series
// K = F_tot/(6 pi mu a U) = sum q_s chi^s, chi = (6 phi/pi)^(1/3), U superficial, F_tot including
// the mean-pressure-gradient part; data/sangani_acrivos_sc_series.csv. It agrees with the exact
// Zick & Homsy 1982 values to 0.1 % for phi <= 0.216 (checked in validation_short_test.cc). The
// engine's F is drag-only, F = <F_d>/(3 pi mu d U) = (1 - phi) K.
//
// What is checked:
//  2a. TRT + interpolated bounce-back (IBB), Lambda = 3/16, is within 1 % of the series at
//      phi = 0.027, 0.064, 0.125, 0.216 with d <= 24 (the accuracy goal; the reference's
//      own error, 0.1 %, is ten times smaller).
//  2b. Measured convergence orders from a d sweep, d = 10 ... 56 in steps of sqrt(2). The error of
//      a voxelized sphere has an erratic part that depends on how the sphere sits on the lattice
//      (at one placement the error can even change sign between neighbouring d), so at each d
//      the error is sampled over six sub-node placements of the centre (placement_offset: a
//      low-discrepancy sequence) and the order is minus the least-squares slope of ln(rms error)
//      against ln d. Expected: 2 for IBB (second-order wall location), 1 for halfway
//      bounce-back (BB). Accepted windows: IBB (1.4, 3.0), BB (0.4, 1.5); they separate the two
//      orders while allowing the sampling error of an rms over six placements (about 30 % per
//      point, +-0.25 on a slope over a factor 5.6 in d) and, for BB, a pre-asymptotic range: the
//      staircase's hydrodynamic-radius offset delta (rms error x a / (d ln F/d ln a)) still
//      grows over this sweep before it settles (about 0.08 cell at d = 14 to 0.15 at d = 56 for
//      phi = 0.125), which lowers the apparent order below 1. First order proper is asserted
//      as its defining property: delta stays below half a cell at every d (the staircase of
//      solid-node centres lies within half a cell of the true surface). At every placement with
//      16 <= d <= 24, IBB is within 1 %.
//  3.  At fixed Lambda the steady TRT solution depends on tau only through Lambda (Ginzburg &
//      d'Humieres 2003), so F is the same at tau = 0.6, 1.0, 1.5, 3.0 to the convergence tolerance
//      (runs at tolerance 1e-10; accepted spread 1e-6). This holds for BB and for the engine's
//      interpolation, Ginzburg's central linear interpolation (CLI), whose closure combines
//      post-collision values along one link line with tau-free weights (1 - 2q)/(1 + 2q), i.e.
//      is parametrized by Lambda alone (Ginzburg, Verhaeghe & d'Humieres 2008); a closure that
//      mixed tau into its weights would not pass. BGK
//      (Lambda = (tau - 1/2)^2) moves the bounce-back wall with tau: the Poiseuille analogue
//      (poiseuille_validation.cc) gives a relative flow-rate change of (16 Delta Lambda)/(2 H^2)
//      between tau = 0.6 and 1.5, i.e. 3 % for a 16-node channel (19 % up to tau = 3); the pores
//      of this array (phi = 0.125, d = 16: gaps of 10 nodes) are narrower, so BGK must show a
//      spread > 1 %, with F falling as tau grows (the wall slips more as Lambda rises from 0.01
//      to 6.25).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "validation_support.h"

namespace draglab {
namespace lbm {
namespace validation {
namespace {

struct ScRun {
  double phi = 0.0;
  double d = 0.0;
  RunResult result;
  double relative_error = NAN;  ///< F/F_SA - 1.
};

ScRun run_sc(double phi, double requested_d, const RunOptions& options) {
  ScRun run;
  run.phi = phi;
  const ScArray sc = make_sc_array(phi, requested_d);
  run.d = sc.d;
  run.result = lbm::run(sc.grid, sc.packing.phi(), options);
  run.relative_error = run.result.F / sangani_acrivos_F(phi) - 1.0;
  char label[128];
  std::snprintf(label, sizeof(label), "sc stokes %s-%s phi=%.3f d=%.2f tau=%.3g",
                to_string(options.collision), to_string(options.boundary), phi, sc.d,
                run.result.tau);
  char text[128];
  std::snprintf(text, sizeof(text), "F_SA=%.6g rel.error=%+.4e | ", sangani_acrivos_F(phi),
                run.relative_error);
  report(label, text + format_run(run.result));
  return run;
}

void expect_sound(const ScRun& run) {
  ASSERT_TRUE(run.result.converged) << run.result.diagnosis;
  // A run converged to a relative drag change of 1e-6 per characteristic time leaves a momentum
  // imbalance of the same order (the balance is exact only in the steady state).
  EXPECT_LT(run.result.momentum_balance_rel, 1e-5);
  EXPECT_NEAR(run.result.phi, run.phi, 1e-12);  // the exact solids fraction is reported
}

// ---- 2a: within 1 % at d <= 24 ------------------------------------------------------------------

class ScAccuracy : public ::testing::TestWithParam<double> {};

TEST_P(ScAccuracy, TrtInterpolatedWithinOnePercentAtDiameter24) {
  const double phi = GetParam();
  const ScRun ibb =
      run_sc(phi, 24.0, stokes_options(Collision::kTrt, Boundary::kInterpolated, kFastStokesTau));
  expect_sound(ibb);
  EXPECT_LE(ibb.d, 24.0);
  EXPECT_LT(std::fabs(ibb.relative_error), 0.01);
}

INSTANTIATE_TEST_SUITE_P(ScStokesValidation, ScAccuracy,
                         ::testing::Values(0.027, 0.064, 0.125, 0.216));

// ---- 2b: convergence orders ---------------------------------------------------------------------

struct OrderCase {
  double phi;
  Boundary boundary;
  std::vector<double> diameters;
  int placements;
  double min_order, max_order;
};
void PrintTo(const OrderCase& c, std::ostream* out) {
  *out << "phi = " << c.phi << ", " << to_string(c.boundary);
}

class ScOrder : public ::testing::TestWithParam<OrderCase> {};

TEST_P(ScOrder, RmsErrorOverPlacementsConvergesAtTheExpectedOrder) {
  const OrderCase c = GetParam();
  const double sensitivity = sangani_acrivos_radius_sensitivity(c.phi);
  std::vector<double> d, rms;
  for (double requested : c.diameters) {
    double sum_squares = 0.0, worst = 0.0, d_used = 0.0;
    for (int k = 0; k < c.placements; ++k) {
      const ScArray sc = make_sc_array(c.phi, requested, placement_offset(k));
      const RunResult r = lbm::run(sc.grid, sc.packing.phi(),
                                   stokes_options(Collision::kTrt, c.boundary, kFastStokesTau));
      ASSERT_TRUE(r.converged) << r.diagnosis;
      EXPECT_LT(r.momentum_balance_rel, 1e-5);
      const double error = r.F / sangani_acrivos_F(c.phi) - 1.0;
      sum_squares += error * error;
      worst = std::max(worst, std::fabs(error));
      d_used = sc.d;
      char label[128];
      std::snprintf(label, sizeof(label), "sc stokes sweep trt-%s phi=%.3f d=%.2f placement=%d",
                    to_string(c.boundary), c.phi, sc.d, k);
      report(label, "rel.error=" + scientific(error) + " | " + format_run(r));
      // The accuracy goal (1 % at d <= 24; lbm.md 4.6: at d >= 20) holds at every placement.
      if (c.boundary == Boundary::kInterpolated && sc.d >= 16.0 && sc.d <= 24.0) {
        EXPECT_LT(std::fabs(error), 0.01);
      }
    }
    d.push_back(d_used);
    rms.push_back(std::sqrt(sum_squares / c.placements));
    // Hydrodynamic-radius offset that this rms error amounts to, in lattice units.
    const double offset_cells = rms.back() * (d_used / 2.0) / sensitivity;
    char text[128];
    std::snprintf(text, sizeof(text),
                  "d=%.2f rms error=%.4e max error=%.4e (wall offset %.3f cells)", d_used,
                  rms.back(), worst, offset_cells);
    report(std::string("sc stokes sweep summary trt-") + to_string(c.boundary) +
               " phi=" + std::to_string(c.phi),
           text);
    // A first-order wall stays within a bounded distance of the true surface: the staircase of
    // solid-node centres lies within half a cell of it.
    EXPECT_LT(offset_cells, 0.5);
  }
  const double order = -log_log_slope(d, rms);
  char text[128];
  std::snprintf(text, sizeof(text),
                "observed order %.3f (rms over %d placements, d = %.1f .. %.1f)", order,
                c.placements, d.front(), d.back());
  report(
      std::string("sc stokes order trt-") + to_string(c.boundary) + " phi=" + std::to_string(c.phi),
      text);
  EXPECT_GT(order, c.min_order);
  EXPECT_LT(order, c.max_order);
}

// Diameters from 10 to 56 in steps of sqrt(2); six placements per diameter. Windows: see the
// file comment (2b).
const std::vector<double> kSweep = {10, 14, 20, 28, 40, 56};
INSTANTIATE_TEST_SUITE_P(
    ScStokesValidation, ScOrder,
    ::testing::Values(OrderCase{0.125, Boundary::kInterpolated, kSweep, 6, 1.4, 3.0},
                      OrderCase{0.125, Boundary::kHalfwayBounceBack, kSweep, 6, 0.4, 1.5},
                      OrderCase{0.216, Boundary::kInterpolated, kSweep, 6, 1.4, 3.0},
                      OrderCase{0.216, Boundary::kHalfwayBounceBack, kSweep, 6, 0.4, 1.5}));

// ---- 3: tau independence at fixed Lambda --------------------------------------------------------

TEST(ScStokesValidation, TrtDragIsIndependentOfTauAtFixedLambdaBgkIsNot) {
  const double phi = 0.125;
  const double d = 16.0;
  const std::vector<double> taus = {0.6, 1.0, 1.5, 3.0};
  for (Collision collision : {Collision::kTrt, Collision::kBgk}) {
    for (Boundary boundary : {Boundary::kHalfwayBounceBack, Boundary::kInterpolated}) {
      if (collision == Collision::kBgk && boundary == Boundary::kInterpolated) continue;
      std::vector<double> F;
      for (double tau : taus) {
        RunOptions options = stokes_options(collision, boundary, tau);
        options.tolerance = 1e-10;
        options.max_steps = 2000000;
        const ScRun run = run_sc(phi, d, options);
        expect_sound(run);
        F.push_back(run.result.F);
      }
      const double spread =
          (*std::max_element(F.begin(), F.end()) - *std::min_element(F.begin(), F.end())) /
          mean_of(F);
      char text[160];
      std::snprintf(text, sizeof(text),
                    "F(tau=0.6, 1.0, 1.5, 3.0) = %.8g %.8g %.8g %.8g, spread %.3e", F[0], F[1],
                    F[2], F[3], spread);
      report(std::string("sc stokes tau dependence ") + to_string(collision) + "-" +
                 to_string(boundary),
             text);
      if (collision == Collision::kTrt) {
        EXPECT_LT(spread, 1e-6);
      } else {
        EXPECT_GT(spread, 0.01);
        for (std::size_t i = 1; i < F.size(); ++i) EXPECT_GT(F[i - 1], F[i]);
      }
    }
  }
}

}  // namespace
}  // namespace validation
}  // namespace lbm
}  // namespace draglab
