// Fast versions of the LBM physics validations (the long ones are tests/lbm/*_validation.cc,
// label `validation`): each solver path against its reference at a small resolution.
//
// Set-ups and references (details and derivations in the long versions):
//  1. Body-force Poiseuille flow between plane walls with halfway bounce-back (q = 1/2 links of
//     two hand-built wall bodies, H = 16 fluid rows). Exact lattice solution: the parabola
//     g/(2 nu)(y - y0)(y1 - y) plus a uniform slip g (16 Lambda - 3)/(24 nu), Lambda the TRT magic
//     parameter, (tau - 1/2)^2 for BGK, (tau - 1/2)/2 for the regularized collision
//     (validation_support.h, run_plates). TRT with Lambda = 3/16 is exact; BGK's error depends on
//     tau exactly as predicted. Tolerance 1e-10 on the superficial velocity: round-off plus a
//     transient bounded by the convergence tolerance 1e-11.
//  2. Stokes drag on a simple-cubic array, phi = 0.125, d = 12, against the Sangani & Acrivos
//     1982 series, in the drag-only convention F = (1 - phi) K. Tolerances per scheme:
//       TRT + interpolated bounce-back (IBB): 2 % (the short-test bound). Second order
//         with an erratic, placement-dependent term; the long sweep (six placements) measures at
//         most 1.8 % at d = 10 and 0.3 % at d = 14 for this phi.
//       TRT + halfway bounce-back (BB): 8 %. First order: the staircase surface shifts the
//         hydrodynamic radius by a fraction of a cell (up to ~0.2 dx, i.e. 3 % of a = 6 nodes),
//         which moves F by d ln F/d ln a = 3 phi d ln F/d phi = 2.0 times that, 6 %; the long
//         sweep measures up to 4.2 % at d = 10 and 3 % at d = 14 for this phi.
//       BGK + BB at tau = 1 (the seed's method): 8 %, as for TRT + BB: at tau = 1 the BGK wall
//         (Lambda = 1/4) is within (16/4 - 3)/(2 H^2) ~ 0.2 % of the TRT one for pores of H ~ 16.
//       Regularized + IBB at tau = 1: 3 %: its Lambda_eff = (tau - 1/2)/2 = 1/4 instead of 3/16
//         moves the interpolated wall too (by about 1 % of F at this d), on top of the 2 % IBB
//         bound.
//       TRT + IBB in float storage: same 2 % (float costs ~1e-6, LbmEngineSmoke checks that).
//  3. TRT drag at fixed Lambda does not depend on tau (0.6, 1.0, 1.5): spread < 1e-6 at
//     convergence tolerance 1e-10, for BB and IBB (central linear interpolation is parametrized
//     by Lambda); BGK's spread exceeds 1 % (Poiseuille analogue: 3 % for a 16-node channel).
//  4. Random arrays, phi = 0.3, five packings of 27 spheres, d = 12: the mean F within 6 % + 2
//     standard errors of van der Hoef 2005 (7.015), as in the long test (the fit's own ~3 %,
//     discretisation with near contacts ~2 %, finite size ~1-2 %, realization scatter).
//  5. Finite Re: the same simple-cubic array at Re = 10, d = 12: converges, hits the target Re
//     within 1 %, and inertia raises F above the Stokes value.
//  6. Sub-node gaps, run (not refused) by default. (a) Touching simple-cubic spheres (phi = pi/6)
//     at d = 12 and 16: every run converges with the momentum balance at round-off, the three
//     contacts per sphere are reported as sub-node gaps, and K changes by under 2 % between the
//     two resolutions (the long version measures under 0.3 % over d = 24 ... 64: the contact
//     region, where links fall back to bounce-back, is a small part of the surface). (b) Random
//     packings at phi = 0.6 (hard-sphere structure, no forced gap, three packings of 54 spheres,
//     d = 12): the mean F within 6 % + 2 standard errors of van der Hoef 2005 (37.85), the
//     tolerance of 4, with the discretisation of near contacts at d = 12 (the long version,
//     dense_stokes_validation.cc, extrapolates d = 12 ... 24).
// Reference data: data/sangani_acrivos_sc_series.csv and data/zick_homsy_sc_dilute.csv (whose
// agreement, <= 0.1 % for phi <= 0.216, is checked first), data/random_array_stokes_table.csv.
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

// ---- reference data -----------------------------------------------------------------------------

TEST(LbmValidationShort, SanganiAcrivosSeriesMatchesZickHomsy) {
  const auto rows = read_data_csv("zick_homsy_sc_dilute.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) {
    // Z&H print 4 significant figures (half a unit: <= 2.5e-4 relative); the series agrees to
    // 0.1 % up to phi = 0.216 (Sangani & Acrivos 1982).
    EXPECT_NEAR(sangani_acrivos_K(row[0]), row[1], 1e-3 * row[1]) << "phi = " << row[0];
  }
}

TEST(LbmValidationShort, VanDerHoefFormulaMatchesTabulatedValues) {
  const auto rows = read_data_csv("random_array_stokes_table.csv");
  ASSERT_GE(rows.size(), 5u);
  for (const auto& row : rows) {
    // The table prints 4 significant figures: half a unit of the last digit is <= 4.1e-4 of the
    // value for values >= 1.2.
    EXPECT_NEAR(van_der_hoef_2005_F(row[0]), row[1], 4.1e-4 * row[1]) << "phi = " << row[0];
  }
}

// ---- 1. Poiseuille ------------------------------------------------------------------------------

RunOptions plates_options(Collision collision, double tau, double re) {
  RunOptions options;
  options.collision = collision;
  options.boundary = Boundary::kHalfwayBounceBack;
  options.tau = tau;
  options.re = re;
  options.tolerance = 1e-11;
  options.max_steps = 1000000;
  options.throw_on_failure = false;
  return options;
}

TEST(LbmValidationShort, PoiseuilleTrtExactBgkDependsOnTau) {
  const int H = 16;
  for (double tau : {0.6, 1.5}) {
    const PlatesOutcome o = run_plates(H, plates_options(Collision::kTrt, tau, 0.0));
    report("short poiseuille trt tau=" + std::to_string(tau), describe(o));
    ASSERT_TRUE(o.result.converged) << o.result.diagnosis;
    EXPECT_LT(std::fabs(o.mean_error_vs_parabola), 1e-10);
    EXPECT_LT(o.profile_error_vs_parabola, 2e-6);  // single-precision fields
    EXPECT_LT(o.result.momentum_balance_rel, 1e-10);
  }
  // Full equilibrium (target Re = 10): Poiseuille flow has no convective term, still exact.
  {
    const PlatesOutcome o = run_plates(H, plates_options(Collision::kTrt, 0.0, 10.0));
    report("short poiseuille trt Re=10", describe(o));
    ASSERT_TRUE(o.result.converged) << o.result.diagnosis;
    EXPECT_LT(std::fabs(o.mean_error_vs_parabola), 1e-10);
  }
  std::vector<double> bgk_errors;
  for (double tau : {0.6, 1.0, 1.5}) {
    const PlatesOutcome o = run_plates(H, plates_options(Collision::kBgk, tau, 0.0));
    report("short poiseuille bgk tau=" + std::to_string(tau), describe(o));
    ASSERT_TRUE(o.result.converged) << o.result.diagnosis;
    const double lambda = (tau - 0.5) * (tau - 0.5);
    EXPECT_NEAR(o.mean_error_vs_parabola, (16.0 * lambda - 3.0) / (2.0 * H * H + 1.0), 1e-10);
    EXPECT_GT(std::fabs(o.mean_error_vs_parabola), 1e-3);  // >= 1/513 = 1.9e-3 predicted
    bgk_errors.push_back(o.mean_error_vs_parabola);
  }
  EXPECT_LT(bgk_errors[0], bgk_errors[1]);
  EXPECT_LT(bgk_errors[1], bgk_errors[2]);
  {
    const PlatesOutcome o = run_plates(H, plates_options(Collision::kRegularized, 1.0, 0.0));
    ASSERT_TRUE(o.result.converged) << o.result.diagnosis;
    EXPECT_LT(std::fabs(o.mean_error_vs_lattice_solution), 1e-10);
  }
}

// rr's wall correction (lbm.h, Numerics), on the same plates with interpolated walls (every link
// has q = 1/2, so the plain closure is halfway bounce-back through the link pass): uncorrected,
// rr slips as TRT with Lambda = (tau - 1/2)/2; corrected, it must give TRT's exact solution at
// Lambda = 3/16, the no-slip parabola to round-off, at every tau below 7/8 (above it c <= 0 and
// nothing is corrected). Linear equilibrium: the correction is derived for it (with the full
// one, the even equilibrium varies along a link as u^2, which the correction does not carry).
TEST(LbmValidationShort, RegularizedWallCorrectionGivesTrtsExactPoiseuille) {
  const int H = 8;
  for (double tau : {0.51, 0.6, 0.75}) {
    SCOPED_TRACE("tau = " + std::to_string(tau));
    RunOptions options = plates_options(Collision::kRegularized, tau, 0.0);
    options.boundary = Boundary::kInterpolated;
    options.rr_wall_correction = false;
    const PlatesOutcome plain = run_plates(H, options);
    ASSERT_TRUE(plain.result.converged) << plain.result.diagnosis;
    EXPECT_FALSE(plain.result.wall_corrected);
    EXPECT_LT(std::fabs(plain.mean_error_vs_lattice_solution), 1e-10);
    EXPECT_GT(std::fabs(plain.mean_error_vs_parabola), 1e-3);
    options.rr_wall_correction = true;
    const PlatesOutcome corrected = run_plates(H, options);
    report("short poiseuille rr corrected tau=" + std::to_string(tau), describe(corrected));
    ASSERT_TRUE(corrected.result.converged) << corrected.result.diagnosis;
    EXPECT_TRUE(corrected.result.wall_corrected);
    EXPECT_LT(std::fabs(corrected.mean_error_vs_parabola), 1e-10);
    EXPECT_LT(corrected.profile_error_vs_parabola, 2e-6);  // single-precision fields
    EXPECT_LT(corrected.result.momentum_balance_rel, 1e-10);
  }
}

// ---- 2. simple-cubic Stokes drag, each scheme ---------------------------------------------------

struct SchemeCase {
  const char* name;
  Collision collision;
  Boundary boundary;
  double tau;
  Precision precision;
  double tolerance;  ///< Relative, against Sangani-Acrivos (see the file comment).
};

class ShortSimpleCubic : public ::testing::TestWithParam<SchemeCase> {};

TEST_P(ShortSimpleCubic, StokesDragAgainstSanganiAcrivos) {
  const SchemeCase c = GetParam();
  const double phi = 0.125;
  const ScArray sc = make_sc_array(phi, 12.0);
  RunOptions options = stokes_options(c.collision, c.boundary, c.tau);
  options.precision = c.precision;
  const RunResult r = lbm::run(sc.grid, sc.packing.phi(), options);
  const double error = r.F / sangani_acrivos_F(phi) - 1.0;
  report(std::string("short sc ") + c.name,
         "rel.error " + scientific(error) + " | " + format_run(r));
  ASSERT_TRUE(r.converged) << r.diagnosis;
  EXPECT_LT(std::fabs(error), c.tolerance);
  EXPECT_LT(r.momentum_balance_rel, c.precision == Precision::kFloat ? 1e-4 : 1e-5);
  EXPECT_NEAR(r.K, r.F / (1.0 - phi), 1e-12 * r.K);
  EXPECT_NEAR(r.beta_d2_over_mu, 18.0 * phi * (1.0 - phi) * r.F, 1e-12 * r.beta_d2_over_mu);
}

void PrintTo(const SchemeCase& c, std::ostream* out) { *out << c.name; }

INSTANTIATE_TEST_SUITE_P(
    LbmValidationShort, ShortSimpleCubic,
    ::testing::Values(SchemeCase{"trt-ibb", Collision::kTrt, Boundary::kInterpolated,
                                 kFastStokesTau, Precision::kDouble, 0.02},
                      SchemeCase{"trt-bb", Collision::kTrt, Boundary::kHalfwayBounceBack,
                                 kFastStokesTau, Precision::kDouble, 0.08},
                      SchemeCase{"bgk-bb", Collision::kBgk, Boundary::kHalfwayBounceBack, 1.0,
                                 Precision::kDouble, 0.08},
                      SchemeCase{"rr-ibb", Collision::kRegularized, Boundary::kInterpolated, 1.0,
                                 Precision::kDouble, 0.03},
                      SchemeCase{"trt-ibb-float", Collision::kTrt, Boundary::kInterpolated,
                                 kFastStokesTau, Precision::kFloat, 0.02}));

// ---- 3. tau independence ------------------------------------------------------------------------

TEST(LbmValidationShort, TrtDragIndependentOfTauBgkNot) {
  const ScArray sc = make_sc_array(0.125, 12.0);
  const std::vector<double> taus = {0.6, 1.0, 1.5};
  struct Path {
    Collision collision;
    Boundary boundary;
  };
  for (const Path& p : {Path{Collision::kTrt, Boundary::kHalfwayBounceBack},
                        Path{Collision::kTrt, Boundary::kInterpolated},
                        Path{Collision::kBgk, Boundary::kHalfwayBounceBack}}) {
    std::vector<double> F;
    for (double tau : taus) {
      RunOptions options = stokes_options(p.collision, p.boundary, tau);
      options.tolerance = 1e-10;
      options.max_steps = 1000000;
      const RunResult r = lbm::run(sc.grid, sc.packing.phi(), options);
      ASSERT_TRUE(r.converged) << r.diagnosis;
      F.push_back(r.F);
    }
    const double spread =
        (*std::max_element(F.begin(), F.end()) - *std::min_element(F.begin(), F.end())) /
        mean_of(F);
    report(
        std::string("short tau dependence ") + to_string(p.collision) + "-" + to_string(p.boundary),
        "spread " + scientific(spread));
    if (p.collision == Collision::kTrt) {
      EXPECT_LT(spread, 1e-6);
    } else {
      EXPECT_GT(spread, 0.01);
    }
  }
}

// ---- 4. random array ----------------------------------------------------------------------------

TEST(LbmValidationShort, RandomArraysNearVanDerHoef2005) {
  const double phi = 0.3;
  const double reference = van_der_hoef_2005_F(phi);
  std::vector<double> F;
  for (int seed = 1; seed <= 5; ++seed) {
    const arrays::Packing packing = make_random_packing(phi, 27, seed);
    RunOptions options = stokes_options(Collision::kTrt, Boundary::kInterpolated, kFastStokesTau);
    options.min_gap_nodes = 0.0;  // hard-sphere packings have near contacts at any resolution
    const RunResult r = lbm::run(packing, 12.0, options);
    report("short random phi=0.3 seed=" + std::to_string(seed),
           "F/F_vdH - 1 = " + scientific(r.F / reference - 1.0) + " | " + format_run(r));
    ASSERT_TRUE(r.converged) << r.diagnosis;
    ASSERT_EQ(r.body_F.size(), 27u);
    EXPECT_NEAR(mean_of(r.body_F), r.F, 1e-9 * r.F);
    EXPECT_LT(r.momentum_balance_rel, 1e-5);
    F.push_back(r.F);
  }
  const double mean = mean_of(F), standard_error = standard_error_of(F);
  report("short random phi=0.3 summary", "mean " + std::to_string(mean) + " +- " +
                                             std::to_string(standard_error) + ", vdH05 " +
                                             std::to_string(reference));
  EXPECT_LT(std::fabs(mean - reference), 0.06 * reference + 2.0 * standard_error);
}

// ---- 5. finite Re -------------------------------------------------------------------------------

TEST(LbmValidationShort, FiniteReRaisesDragAndHitsTarget) {
  const double phi = 0.125;
  const ScArray sc = make_sc_array(phi, 12.0);
  RunOptions options;  // TRT + IBB, full equilibrium, tau from the engine
  options.re = 10.0;
  const RunResult r = lbm::run(sc.grid, sc.packing.phi(), options);
  report("short finite re sc Re=10", format_run(r));
  ASSERT_TRUE(r.converged) << r.diagnosis;
  EXPECT_FALSE(r.stokes_mode);
  EXPECT_NEAR(r.re, 10.0, 0.1);
  EXPECT_GT(r.F, sangani_acrivos_F(phi));
  EXPECT_LT(r.momentum_balance_rel, 1e-5);
}

// ---- 6. sub-node gaps ---------------------------------------------------------------------------

TEST(LbmValidationShort, TouchingSimpleCubicConvergesAndReportsContacts) {
  const double phi = kPi / 6.0;
  std::vector<double> K;
  for (double d : {12.0, 16.0}) {
    const ScArray sc = make_sc_array(phi, d);
    const RunResult r =
        lbm::run(sc.grid, sc.packing.phi(),
                 stokes_options(Collision::kTrt, Boundary::kInterpolated, kFastStokesTau));
    report("short touching sc d=" + std::to_string(static_cast<int>(d)),
           "K=" + std::to_string(r.K) + " narrow pairs " + std::to_string(r.narrow_gap_pairs) +
               " | " + format_run(r));
    ASSERT_TRUE(r.converged) << r.diagnosis;
    EXPECT_LT(r.momentum_balance_rel, 1e-9);
    EXPECT_EQ(r.narrow_gap_pairs, 3);  // the sphere touches its images along x, y and z
    EXPECT_GT(r.narrow_gap_fluid_fraction, 0.0);
    EXPECT_GT(r.fallback_links, 0);
    bool warned = false;
    for (const std::string& w : r.warnings)
      warned = warned || w.find("sub-node") != w.npos || w.find("below one lattice") != w.npos;
    EXPECT_TRUE(warned);
    K.push_back(r.K);
  }
  EXPECT_NEAR(K[0], K[1], 0.02 * K[1]);
  // Denser than the densest series point (phi = 0.216, K = 7.44): far more drag.
  EXPECT_GT(K[1], 4.0 * sangani_acrivos_K(0.216));
}

TEST(LbmValidationShort, DenseRandomArraysNearVanDerHoef2005) {
  const double phi = 0.6;
  const double reference = van_der_hoef_2005_F(phi);
  std::vector<double> F;
  for (int seed = 1; seed <= 3; ++seed) {
    const arrays::Packing packing = make_random_packing(phi, 54, seed);
    const RunResult r = lbm::run(
        packing, 12.0, stokes_options(Collision::kTrt, Boundary::kInterpolated, kFastStokesTau));
    report("short dense random phi=0.6 seed=" + std::to_string(seed),
           "F/F_vdH - 1 = " + scientific(r.F / reference - 1.0) + ", narrow pairs " +
               std::to_string(r.narrow_gap_pairs) + " | " + format_run(r));
    ASSERT_TRUE(r.converged) << r.diagnosis;
    EXPECT_LT(r.momentum_balance_rel, 1e-6);
    EXPECT_GT(r.narrow_gap_pairs, 0);
    F.push_back(r.F);
  }
  const double mean = mean_of(F), standard_error = standard_error_of(F);
  report("short dense random phi=0.6 summary", "mean " + std::to_string(mean) + " +- " +
                                                   std::to_string(standard_error) + ", vdH05 " +
                                                   std::to_string(reference));
  EXPECT_LT(std::fabs(mean - reference), 0.06 * reference + 2.0 * standard_error);
}

}  // namespace
}  // namespace validation
}  // namespace lbm
}  // namespace draglab
