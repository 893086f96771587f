// Work-precision helpers (lbm/convergence.h): Richardson extrapolation with a measured order,
// the fitted convergence order, scheme names, and the choice of the analytical reference.
//
// Set-up: synthetic sequences F(d) = F_inf + C d^-p with known F_inf and p (the model Richardson
// extrapolation assumes), at unequal resolution ratios such as a real sweep uses (8, 12, 16, 24);
// and packings for which the analytical reference does or does not exist (Sangani-Acrivos
// series: one sphere in a cube, Stokes flow, phi <= 0.22; checked against Zick & Homsy 1982,
// data/zick_homsy_sc_dilute.csv).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/error.h"
#include "draglab/lbm/convergence.h"

namespace draglab {
namespace lbm {
namespace {

std::vector<double> model(const std::vector<double>& d, double F_inf, double C, double p) {
  std::vector<double> F;
  for (double x : d) F.push_back(F_inf + C * std::pow(x, -p));
  return F;
}

TEST(Richardson, RecoversLimitAndOrderAtUnequalRatios) {
  const std::vector<double> d{8.0, 12.0, 16.0, 24.0};
  for (double p : {1.0, 1.5, 2.0, 3.0}) {
    for (double C : {-5.0, 3.0}) {
      const RichardsonEstimate e = richardson_extrapolate(d, model(d, 4.0, C, p));
      ASSERT_TRUE(e.ok) << e.note;
      // Exact model: only the bisection tolerance (1e-12 in p) and round-off remain.
      EXPECT_NEAR(e.order, p, 1e-8);
      EXPECT_NEAR(e.F_inf, 4.0, 1e-9);
    }
  }
}

TEST(Richardson, UsesTheThreeFinestPointsInAnyOrder) {
  // A coarse point off the model must not matter; input order must not matter either.
  std::vector<double> d{24.0, 6.0, 16.0, 12.0};
  std::vector<double> F = model(d, 2.0, 1.0, 2.0);
  F[1] = 100.0;  // d = 6: far off
  const RichardsonEstimate e = richardson_extrapolate(d, F);
  ASSERT_TRUE(e.ok) << e.note;
  EXPECT_NEAR(e.order, 2.0, 1e-8);
  EXPECT_NEAR(e.F_inf, 2.0, 1e-10);
}

TEST(Richardson, FallsBackToLeastSquaresWhenTheFinestPointsAreIrregular) {
  // F = 4 - 20 d^-2 with a staircase-like bump of +0.02 at d = 20: the three finest points no
  // longer converge monotonically, but the five together still show the trend.
  const std::vector<double> d{8.0, 12.0, 16.0, 20.0, 24.0};
  std::vector<double> F = model(d, 4.0, -20.0, 2.0);
  F[3] += 0.02;
  const RichardsonEstimate e = richardson_extrapolate(d, F);
  ASSERT_TRUE(e.ok) << e.note;
  EXPECT_NE(e.note.find("least-squares"), std::string::npos) << e.note;
  // A 0.02 bump on one of five points moves the fitted limit by a similar amount, not more than
  // 0.05 (2.5 bumps); the order stays near 2.
  EXPECT_NEAR(e.F_inf, 4.0, 0.05);
  EXPECT_NEAR(e.order, 2.0, 1.0);
  // Without the bump the exact three-point estimate is used.
  EXPECT_TRUE(richardson_extrapolate(d, model(d, 4.0, -20.0, 2.0)).note.empty());
}

TEST(Richardson, RefusesWhatItCannotExtrapolate) {
  EXPECT_FALSE(richardson_extrapolate({8.0, 16.0}, {1.0, 1.1}).ok);  // two points
  // Non-monotone: the differences change sign (staircase bounce-back can do this).
  const RichardsonEstimate e = richardson_extrapolate({8.0, 12.0, 16.0}, {1.0, 1.2, 1.1});
  EXPECT_FALSE(e.ok);
  EXPECT_FALSE(e.note.empty());
  // NaN (failed runs) are skipped, leaving too few points.
  EXPECT_FALSE(richardson_extrapolate({8.0, 12.0, 16.0}, {1.0, std::nan(""), 1.1}).ok);
}

TEST(FittedOrder, SlopeOfTheErrors) {
  const std::vector<double> d{8.0, 12.0, 16.0, 24.0};
  std::vector<double> e;
  for (double x : d) e.push_back(-0.3 * std::pow(x, -1.7));  // sign does not matter
  EXPECT_NEAR(fitted_order(d, e), 1.7, 1e-12);
  EXPECT_TRUE(std::isnan(fitted_order({8.0}, {0.1})));
}

TEST(Schemes, NamesRoundTrip) {
  for (const Scheme& s : default_schemes()) {
    const Scheme t = scheme_from_string(s.name());
    EXPECT_EQ(t.collision, s.collision);
    EXPECT_EQ(t.boundary, s.boundary);
  }
  ASSERT_EQ(default_schemes().size(), 3u);
  EXPECT_EQ(default_schemes()[0].collision, Collision::kBgk);
  EXPECT_EQ(default_schemes()[0].boundary, Boundary::kHalfwayBounceBack);
  try {
    scheme_from_string("mrt-bb");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("trt-ibb"), std::string::npos) << e.what();
  }
  EXPECT_THROW(scheme_from_string("trt"), Error);
}

TEST(AnalyticalReference, OnlyForStokesFlowThroughSimpleCubicArrays) {
  arrays::OrderedPackingOptions o;
  o.lattice = arrays::Lattice::kSimpleCubic;
  o.phi = 0.125;
  const arrays::Packing sc = arrays::generate_ordered_packing(o);
  // Zick & Homsy: K = 4.292 at phi = 0.125 (4 digits; the series agrees to 0.1 %).
  EXPECT_NEAR(analytical_reference_F(sc, 0.0) / ((1.0 - 0.125) * 4.292), 1.0, 1e-3);
  EXPECT_TRUE(std::isnan(analytical_reference_F(sc, 10.0)));  // finite Re: no exact value
  o.phi = 0.3;                                                // beyond the series' range
  EXPECT_TRUE(std::isnan(analytical_reference_F(arrays::generate_ordered_packing(o), 0.0)));
  o.lattice = arrays::Lattice::kFaceCentredCubic;
  o.phi = 0.125;
  EXPECT_TRUE(std::isnan(analytical_reference_F(arrays::generate_ordered_packing(o), 0.0)));
}

TEST(ConvergenceOptions, BadInputIsNamed) {
  ConvergenceOptions o;
  arrays::OrderedPackingOptions sc;
  sc.phi = 0.1;
  o.packing = arrays::generate_ordered_packing(sc);
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.resolutions = {8.0, 1000.0};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("1000"), std::string::npos) << error;
  o.resolutions = {8.0};
  o.schemes.clear();
  EXPECT_FALSE(o.IsValid(&error));
  // Gaps (opt-in check): SC near close packing leaves less than a lattice unit between spheres at
  // d = 8.
  ConvergenceOptions dense;
  dense.run.min_gap_nodes = 1.0;
  sc.phi = 0.52;
  dense.packing = arrays::generate_ordered_packing(sc);
  dense.resolutions = {8.0};
  try {
    run_convergence(dense);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("gap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
