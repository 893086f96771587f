// The arithmetic and the input checks of draglab/consumers/sensitivity.h (no DPM run: the runs
// themselves are tested end to end by tests/cli/sensitivity_test.sh).
//
// References:
//  a. realization_uncertainty: the standard error of the mean s/sqrt(n) with the sample standard
//     deviation s (n - 1), which for two values is |D1 - D2|/2, combined in quadrature with the
//     cell bound h; values worked by hand below. Tolerance 1e-15 m (a few ulps of centimetres).
//  b. grid_uncertainty: the finer value with |D_f - D_c|/(r - 1), r = h_c/h_f, the Richardson
//     error of the finer value for first-order convergence; by hand, 1e-15 m.
//  c. richardson_extrapolate on exact power laws D(h) = D0 + C h^p (p = 1 with r = 2, p = 2 with
//     r = 1.5): the observed order and D0 are recovered to 1e-9 relative (the round-off of
//     ln(e21/e32) on differences of order 1e-4 m); non-monotone data and unequal ratios are
//     refused with a reason.
//  d. Fail-fast: an unknown law or a finer grid that the scene cannot take is refused before
//     any settling starts (no progress report), with the field named.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "draglab/consumers/sensitivity.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/error.h"

namespace draglab {
namespace consumers {
namespace {

TEST(SensitivityArithmetic, TwoRealizationsGiveHalfTheDifferenceInQuadratureWithTheCell) {
  const DiameterUncertainty u = realization_uncertainty({0.030, 0.026}, 0.0075);
  EXPECT_NEAR(u.mean_m, 0.028, 1e-15);
  EXPECT_NEAR(u.estimate_m, 0.028, 1e-15);
  EXPECT_NEAR(u.spread_m, 0.002, 1e-15);  // |D1 - D2| / 2
  EXPECT_NEAR(u.boundary_m, 0.0075, 1e-15);
  EXPECT_NEAR(u.total_m, std::sqrt(0.002 * 0.002 + 0.0075 * 0.0075), 1e-15);
}

TEST(SensitivityArithmetic, FourRealizationsUseTheSampleStandardDeviation) {
  // Mean 0.025; squared deviations 9, 1, 1, 9 (x 1e-6): s^2 = 20e-6 / 3, SE = sqrt(s^2 / 4).
  const DiameterUncertainty u = realization_uncertainty({0.022, 0.024, 0.026, 0.028}, 0.005);
  EXPECT_NEAR(u.mean_m, 0.025, 1e-15);
  EXPECT_NEAR(u.spread_m, std::sqrt(20e-6 / 3.0 / 4.0), 1e-15);
  EXPECT_NEAR(u.total_m, std::hypot(std::sqrt(20e-6 / 12.0), 0.005), 1e-15);
}

TEST(SensitivityArithmetic, GridsGiveTheFinerValueWithTheFirstOrderRichardsonError) {
  const DiameterUncertainty u = grid_uncertainty(0.030, 0.0075, 0.027, 0.005);
  EXPECT_NEAR(u.estimate_m, 0.027, 1e-15);
  EXPECT_NEAR(u.mean_m, 0.0285, 1e-15);
  EXPECT_NEAR(u.spread_m, 0.003 / 0.5, 1e-15);  // r = 1.5
  EXPECT_NEAR(u.boundary_m, 0.005, 1e-15);
  EXPECT_NEAR(u.total_m, std::hypot(0.006, 0.005), 1e-15);
}

TEST(SensitivityArithmetic, BadInputIsRefused) {
  EXPECT_THROW(realization_uncertainty({0.03}, 0.005), Error);
  EXPECT_THROW(realization_uncertainty({0.03, 0.02}, 0.0), Error);
  EXPECT_THROW(realization_uncertainty({0.03, NAN}, 0.005), Error);
  EXPECT_THROW(grid_uncertainty(0.03, 0.005, 0.02, 0.005), Error);  // h_fine must be smaller
  EXPECT_THROW(grid_uncertainty(0.03, 0.005, 0.02, 0.0075), Error);
}

TEST(SensitivityArithmetic, RichardsonRecoversOrderAndLimitOfExactPowerLaws) {
  for (const auto& [p, r] : {std::pair<double, double>{1.0, 2.0}, {2.0, 1.5}}) {
    const double d0 = 0.04, c = -0.5, h1 = 0.01;
    const std::vector<double> h = {h1, h1 / r, h1 / (r * r)};
    std::vector<double> d;
    for (double hk : h) d.push_back(d0 + c * std::pow(hk, p));
    const RichardsonEstimate e = richardson_extrapolate(h, d);
    ASSERT_TRUE(e.valid) << e.reason;
    EXPECT_NEAR(e.order, p, 1e-9 * p);
    EXPECT_NEAR(e.extrapolated_m, d0, 1e-9 * d0);
  }
}

TEST(SensitivityArithmetic, RichardsonRefusesWhatItCannotExtrapolate) {
  const std::vector<double> h = {0.01, 0.005, 0.0025};
  const RichardsonEstimate oscillating = richardson_extrapolate(h, {0.03, 0.032, 0.031});
  EXPECT_FALSE(oscillating.valid);
  EXPECT_NE(oscillating.reason.find("monoton"), std::string::npos) << oscillating.reason;
  const RichardsonEstimate ratios =
      richardson_extrapolate({0.01, 0.005, 0.004}, {0.03, 0.032, 0.033});
  EXPECT_FALSE(ratios.valid);
  EXPECT_NE(ratios.reason.find("ratio"), std::string::npos) << ratios.reason;
  EXPECT_FALSE(richardson_extrapolate({0.01, 0.005}, {0.03, 0.032}).valid);
}

TEST(SensitivityOptionsTest, ParsesGridsAndMethodsAndNamesBadFields) {
  const std::vector<GridSize> g = parse_grid_list("8x24,12x36", "--grids");
  ASSERT_EQ(g.size(), 2u);
  EXPECT_EQ(g[1].cells_x, 12);
  EXPECT_EQ(g[1].cells_y, 36);
  for (const char* bad : {"8x", "x24", "8*24", "0x5", "8x24,", "8x24x3", "-8x24", ""}) {
    try {
      parse_grid_list(bad, "--grids");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find("--grids"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(uncertainty_method_from_string("grids"), UncertaintyMethod::kGrids);
  EXPECT_THROW(uncertainty_method_from_string("bootstrap"), Error);

  SensitivityOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.laws = {"ergun@1", "ergun@1"};
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("laws"), std::string::npos) << why;
  o.laws = {"ergun@1"};
  o.realizations = 1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("realizations"), std::string::npos) << why;
  o.realizations = 2;
  o.grid_refinement = 1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("grid_refinement"), std::string::npos) << why;

  WorkPrecisionOptions w;
  w.law = "ergun@1";
  w.time_resolutions = {20, 20};
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("time_resolutions"), std::string::npos) << why;
  w.time_resolutions = {20, -1};
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("positive"), std::string::npos) << why;
  w.time_resolutions = {20};
  w.grids = {{4, 12}, {4, 12}};
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("twice"), std::string::npos) << why;
}

// A 3 x 9 x 0.75 cm bed on 4 x 12 cells of 7.5 mm (3 d): the finer grid at 4 x refinement has
// 1.9 mm cells, smaller than a 2.5 mm particle, which the scene refuses.
const char* kTinyScene = R"(
[scene]
name = "sensitivity_unit_test"
seed = 3
[geometry]
width_m = 0.03
height_m = 0.09
depth_m = 0.0075
[particles]
diameter_m = 2.5e-3
density_kg_m3 = 2526.0
bed_height_mf_m = 0.03
[gas]
density_kg_m3 = 1.2
viscosity_pa_s = 1.8e-5
[jet]
slot_width_m = 0.0075
velocity_m_s = 10.0
start_s = 0.01
duration_s = 0.03
[time]
duration_s = 0.06
t_ref_s = 0.05
[grid]
cells_x = 4
cells_y = 12
[drag]
laws = ["gidaspow@1", "vdh2004@1"]
)";

TEST(SensitivityRunner, RefusesBadLawsAndGridsBeforeAnySettling) {
  const std::string path =
      ::testing::TempDir() + "/sensitivity_test_" + std::to_string(::getpid()) + ".db";
  std::remove(path.c_str());
  {
    Database db(path);
    const LawLoader loader = [&](const std::string& ref) {
      return std::shared_ptr<const Law>(db.load(ref, RangePolicy::kClamp));
    };
    const Scene scene = parse_scene(kTinyScene, "sensitivity_unit_test");
    int reports = 0;
    const SensitivityProgress count = [&](double, const std::string&) { ++reports; };

    SensitivityOptions unknown;
    unknown.laws = {"gidaspow@1", "nosuchlaw@1"};
    try {
      run_sensitivity(scene, loader, unknown, count);
      ADD_FAILURE() << "an unknown law was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kNotFound) << e.what();
    }

    SensitivityOptions too_fine;
    too_fine.uncertainty = UncertaintyMethod::kGrids;
    too_fine.grid_refinement = 4.0;
    try {
      run_sensitivity(scene, loader, too_fine, count);
      ADD_FAILURE() << "a finer grid with cells below a particle was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find("[grid]"), std::string::npos) << e.what();
    }

    WorkPrecisionOptions wp;
    wp.law = "gidaspow@1";
    wp.grids = {{4, 12}, {20, 60}};
    EXPECT_THROW(run_work_precision(scene, loader, wp, count), Error);
    // The DPM's time resolution is its contact steps: below the DEM limit, or not whole.
    wp.grids = {{4, 12}};
    for (double bad : {10.0, 20.5}) {
      wp.time_resolutions = {20, bad};
      try {
        run_work_precision(scene, loader, wp, count);
        ADD_FAILURE() << "contact_steps " << bad << " was accepted";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
        EXPECT_NE(std::string(e.what()).find("contact_steps"), std::string::npos) << e.what();
      }
    }
    EXPECT_EQ(reports, 0) << "a run started before the input was checked";
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
