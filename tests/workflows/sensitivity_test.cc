// The arithmetic and the input checks of draglab/workflows/sensitivity.h (no DPM run: the runs
// themselves are tested end to end by tests/cli/sensitivity_test.sh), and the studies of a model
// with headline numbers on data/scenes/dbm_tiny.toml (the DBM runs a 6 s bed in about a second).
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
//  e. combined_uncertainty and headline_uncertainty worked by hand (1e-15): both = the fine
//     mean, s/sqrt(n) of the fine runs, |mean_f - mean_c|/(r - 1) (+ the cell bound for D).
//  f. DBM (dbm_tiny, 6 s, average from 4 s): every law reports the model's four headline numbers
//     (hold-up, mean bubble diameter at 0.3 and 0.7 m, circulation upflow), finite, with the
//     estimate and its parts recomputed from the runs' values (1e-12 relative: the same
//     arithmetic); the hold-up and circulation differ between injection seeds, so their
//     uncertainty is > 0. "both" runs every seed on 4x10x4 and 6x15x6 (1.5 x, depth too).
//     Work-precision on an "AxB" grid keeps the scene's depth cells and takes the finest
//     configuration as the reference of the headline differences.
//  g. A bed of several sizes: the report gives each run's segregation index at the sample nearest
//     t_ref and its change over the run (last minus first sample), and per law the mean change
//     with its standard error over the runs (s/sqrt(n)), worked by hand; a bed of one size (every
//     index 0) gets no segregation text.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "draglab/drag_db/database.h"
#include "draglab/error.h"
#include "draglab/workflows/sensitivity.h"

namespace draglab {
namespace workflows {
namespace {

using namespace consumers;  // the bed models and scenes the studies run

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
  const std::vector<GridSize> g3 = parse_grid_list("4x10x4,6x15", "--grids");
  ASSERT_EQ(g3.size(), 2u);
  EXPECT_EQ(g3[0].cells_x, 4);
  EXPECT_EQ(g3[0].cells_y, 10);
  EXPECT_EQ(g3[0].cells_z, 4);
  EXPECT_EQ(g3[1].cells_z, 1);  // AxB: the scene's depth cells
  EXPECT_EQ(to_string(g3[0]), "4x10x4");
  EXPECT_EQ(to_string(g3[1]), "6x15");
  EXPECT_EQ(to_string(GridSize{6, 15, 1}), "6x15");
  for (const char* bad : {"8x", "x24", "8*24", "0x5", "8x24,", "8x24x0", "8x24x3x2", "8xx24",
                          "4x10x", "x4x10", "-8x24", "4x10x-1", "4x10x1234567", ""}) {
    try {
      parse_grid_list(bad, "--grids");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find("--grids"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(uncertainty_method_from_string("grids"), UncertaintyMethod::kGrids);
  EXPECT_EQ(uncertainty_method_from_string("both"), UncertaintyMethod::kRealizationsAndGrids);
  EXPECT_STREQ(to_string(UncertaintyMethod::kRealizationsAndGrids), "both");
  try {
    uncertainty_method_from_string("bootstrap");
    ADD_FAILURE() << "accepted 'bootstrap'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("realizations, grids or both"), std::string::npos)
        << e.what();
  }

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
  w.grids = {{4, 10, 4}, {4, 10, 6}};  // differ by their depth only
  EXPECT_TRUE(w.IsValid(&why)) << why;
  w.grids = {{4, 10, 0}};
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("cells_z"), std::string::npos) << why;
}

TEST(SensitivityArithmetic, BothUsesTheFineMeanItsStandardErrorAndTheGridChangeOfTheMeans) {
  // Fine runs 0.026, 0.030 (mean 0.028, SE 0.002); coarse mean 0.031; r = 1.5: E = 0.003 / 0.5.
  const DiameterUncertainty u = combined_uncertainty({0.030, 0.032}, 0.0075, {0.026, 0.030}, 0.005);
  EXPECT_NEAR(u.estimate_m, 0.028, 1e-15);
  EXPECT_NEAR(u.mean_m, 0.028, 1e-15);
  EXPECT_NEAR(u.spread_m, 0.002, 1e-15);
  EXPECT_NEAR(u.grid_m, 0.006, 1e-15);
  EXPECT_NEAR(u.boundary_m, 0.005, 1e-15);
  EXPECT_NEAR(u.total_m, std::sqrt(0.002 * 0.002 + 0.006 * 0.006 + 0.005 * 0.005), 1e-15);
  EXPECT_THROW(combined_uncertainty({0.03}, 0.0075, {0.026, 0.030}, 0.005), Error);
  EXPECT_THROW(combined_uncertainty({0.03, 0.03}, 0.005, {0.026, 0.030}, 0.005), Error);

  // Headline numbers: the same sources without a cell bound.
  const HeadlineUncertainty r = headline_uncertainty("holdup", {}, 0.0, {0.010, 0.014}, 0.1);
  EXPECT_EQ(r.name, "holdup");
  EXPECT_NEAR(r.estimate, 0.012, 1e-15);
  EXPECT_NEAR(r.spread, 0.002, 1e-15);
  EXPECT_EQ(r.grid, 0.0);
  EXPECT_NEAR(r.total, 0.002, 1e-15);
  const HeadlineUncertainty g = headline_uncertainty("holdup", {0.010}, 0.1, {0.012}, 0.05);
  EXPECT_NEAR(g.estimate, 0.012, 1e-15);
  EXPECT_EQ(g.spread, 0.0);
  EXPECT_NEAR(g.grid, 0.002, 1e-15);  // r = 2
  EXPECT_NEAR(g.total, 0.002, 1e-15);
  const HeadlineUncertainty b =
      headline_uncertainty("x", {0.010, 0.012}, 0.15, {0.012, 0.016}, 0.1);  // r = 1.5
  EXPECT_NEAR(b.estimate, 0.014, 1e-15);
  EXPECT_NEAR(b.spread, 0.002, 1e-15);
  EXPECT_NEAR(b.grid, 0.003 / 0.5, 1e-15);
  EXPECT_NEAR(b.total, std::hypot(0.002, 0.006), 1e-15);
  for (const auto& [coarse, fine] :
       {std::pair<std::vector<double>, std::vector<double>>{{}, {0.01}},
        {{0.01}, {0.01, 0.02}},
        {{}, {0.01, NAN}}}) {
    try {
      headline_uncertainty("holdup", coarse, 0.15, fine, 0.1);
      ADD_FAILURE() << "accepted " << coarse.size() << " and " << fine.size() << " values";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("holdup"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(headline_uncertainty("holdup", {0.01}, 0.1, {0.01}, 0.1), Error);  // h_f = h_c
}

// (g) in the file comment.
TEST(SensitivityReport, BedsOfSeveralSizesReportTheirSegregation) {
  SensitivitySummary summary;
  summary.scene = "binary";
  summary.t_ref_s = 0.1;
  SensitivityLawResult law;
  law.law = "hys2010@1";
  auto run_with = [](std::vector<std::pair<double, double>> samples) {
    SensitivityRun run;
    for (const auto& [t, index] : samples) {
      BedSample s;
      s.t_s = t;
      s.segregation_index = index;
      run.series.push_back(s);
    }
    return run;
  };
  // Changes +0.02 and +0.04: mean 0.03, SE |0.04 - 0.02| / 2 = 0.01.
  law.runs.push_back(run_with({{0.0, -0.03}, {0.09, -0.02}, {0.12, -0.025}, {0.3, -0.01}}));
  law.runs.push_back(run_with({{0.0, -0.02}, {0.1, 0.005}, {0.3, 0.02}}));
  summary.laws.push_back(law);
  const std::string brief = summary.BriefReport(), full = summary.FullReport();
  EXPECT_NE(brief.find("segregation change over the run 0.03 +- 0.01"), std::string::npos) << brief;
  EXPECT_NE(full.find("segregation index -0.02 at t_ref (change over the run 0.02)"),
            std::string::npos)
      << full;
  EXPECT_NE(full.find("segregation index 0.005 at t_ref (change over the run 0.04)"),
            std::string::npos)
      << full;
  SensitivitySummary mono = summary;
  for (SensitivityRun& r : mono.laws[0].runs) {
    for (BedSample& s : r.series) s.segregation_index = 0.0;
  }
  EXPECT_EQ(mono.FullReport().find("segregation"), std::string::npos) << mono.FullReport();
}

TEST(SensitivityRunner, RefusesBadLawsAndGridsBeforeAnySettling) {
  const std::string path =
      ::testing::TempDir() + "/sensitivity_test_" + std::to_string(::getpid()) + ".db";
  std::remove(path.c_str());
  {
    Database db(path);
    const LawLoader loader = [&](const std::string& ref) {
      return std::shared_ptr<const Law>(db.load(ref, RangePolicy::kClamp));
    };
    // data/scenes/dpm_tiny.toml: a 3 x 9 x 0.75 cm bed on 4 x 12 cells of 7.5 mm (3 d); the finer
    // grid at 4 x refinement has 1.9 mm cells, smaller than a 2.5 mm particle, which it refuses.
    const Scene scene = load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_tiny.toml");
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
    // A depth on a pseudo-2D scene: the scene names [grid] cells_z.
    wp.grids = {{4, 12, 2}};
    try {
      run_work_precision(scene, loader, wp, count);
      ADD_FAILURE() << "a 3-D grid was accepted for a dpm scene";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find("cells_z"), std::string::npos) << e.what();
    }
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

// The DBM studies on data/scenes/dbm_tiny.toml (reference f): a database with the literature
// laws, runs of 6 s (the scene averages from 4 s).
class SensitivityDbm : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "/sensitivity_dbm_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".db";
    std::remove(path_.c_str());
    db_ = std::make_unique<Database>(path_);
    loader_ = [this](const std::string& ref) {
      return std::shared_ptr<const Law>(db_->load(ref, RangePolicy::kClamp));
    };
    scene_ = load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dbm_tiny.toml");
  }
  void TearDown() override {
    db_.reset();
    std::remove(path_.c_str());
  }
  static BedRunOptions SixSeconds() {
    BedRunOptions run;
    run.duration_s = 6.0;
    return run;
  }
  /// Per headline number n, the runs' values on grid g of `grids` (runs: seed-major).
  static std::vector<double> Values(const SensitivityLawResult& lr, std::size_t n, std::size_t g,
                                    std::size_t grids) {
    std::vector<double> v;
    for (std::size_t k = g; k < lr.runs.size(); k += grids)
      v.push_back(lr.runs[k].headline[n].second);
    return v;
  }
  static double Mean(const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return sum / static_cast<double>(v.size());
  }

  std::string path_;
  std::unique_ptr<Database> db_;
  LawLoader loader_;
  Scene scene_;
};

const std::vector<std::string> kDbmHeadline = {"holdup", "mean_diameter_at_0.3_m",
                                               "mean_diameter_at_0.7_m", "circulation_upflow_m_s"};

TEST_F(SensitivityDbm, TwoLawsTwoInjectionSeedsGiveEachHeadlineNumberWithItsUncertainty) {
  SensitivityOptions o;
  o.laws = {"gidaspow@1", "bvk2007@1"};
  o.realizations = 2;
  o.run = SixSeconds();
  const SensitivitySummary s = run_sensitivity(scene_, loader_, o);
  EXPECT_EQ(s.method, UncertaintyMethod::kRealizations);
  EXPECT_EQ(s.realization_kind, "injection seed");
  ASSERT_EQ(s.grids.size(), 1u);
  EXPECT_EQ(to_string(s.grids[0]), "4x10x4");
  ASSERT_TRUE(s.has_headline());
  ASSERT_EQ(s.laws.size(), 2u);
  for (const SensitivityLawResult& lr : s.laws) {
    ASSERT_EQ(lr.runs.size(), 2u) << lr.law;
    EXPECT_EQ(lr.runs[0].seed, 1u);
    EXPECT_EQ(lr.runs[1].seed, 2u);
    EXPECT_EQ(lr.runs[0].cells_z, 4);
    ASSERT_EQ(lr.headline.size(), kDbmHeadline.size()) << lr.law;
    for (std::size_t n = 0; n < kDbmHeadline.size(); ++n) {
      const HeadlineUncertainty& h = lr.headline[n];
      EXPECT_EQ(h.name, kDbmHeadline[n]);
      EXPECT_TRUE(std::isfinite(h.estimate) && std::isfinite(h.total)) << lr.law << " " << h.name;
      EXPECT_GT(h.estimate, 0.0) << lr.law << " " << h.name;
      const std::vector<double> v = Values(lr, n, 0, 1);
      EXPECT_NEAR(h.estimate, Mean(v), 1e-12 * std::abs(h.estimate)) << h.name;
      EXPECT_NEAR(h.spread, std::abs(v[0] - v[1]) / 2, 1e-12 * std::abs(h.estimate)) << h.name;
      EXPECT_EQ(h.grid, 0.0);
      EXPECT_EQ(h.total, h.spread);
    }
    // The injection phases change the hold-up and the circulation.
    EXPECT_GT(lr.headline[0].total, 0.0) << lr.law;
    EXPECT_GT(lr.headline[3].total, 0.0) << lr.law;
    EXPECT_LT(lr.headline[0].estimate, 0.1) << lr.law;  // a hold-up, not a percentage
  }
  // The laws differ in U_mf, so in the bubble gas flow and the hold-up.
  EXPECT_NE(s.laws[0].umf_m_s, s.laws[1].umf_m_s);
  EXPECT_NE(s.laws[0].headline[0].estimate, s.laws[1].headline[0].estimate);
  const std::string full = s.FullReport();
  EXPECT_NE(full.find("holdup = "), std::string::npos) << full;
  EXPECT_NE(full.find("circulation_upflow_m_s"), std::string::npos) << full;
  EXPECT_EQ(full.find("t_ref"), std::string::npos) << full;  // no jet bubble in the report
  EXPECT_NE(s.method_description.find("injection seed"), std::string::npos) << s.method_description;
}

TEST_F(SensitivityDbm, BothRunsEverySeedOnTheSceneGridAndTheRefinedOne) {
  SensitivityOptions o;
  o.laws = {"gidaspow@1"};
  o.uncertainty = UncertaintyMethod::kRealizationsAndGrids;
  o.realizations = 2;
  o.grid_refinement = 1.5;
  o.run = SixSeconds();
  const SensitivitySummary s = run_sensitivity(scene_, loader_, o);
  EXPECT_EQ(s.method, UncertaintyMethod::kRealizationsAndGrids);
  ASSERT_EQ(s.grids.size(), 2u);
  EXPECT_EQ(to_string(s.grids[0]), "4x10x4");
  EXPECT_EQ(to_string(s.grids[1]), "6x15x6");  // the depth is refined too
  const SensitivityLawResult& lr = s.laws.at(0);
  ASSERT_EQ(lr.runs.size(), 4u);
  const std::vector<std::pair<std::uint64_t, int>> order = {{1, 4}, {1, 6}, {2, 4}, {2, 6}};
  for (std::size_t k = 0; k < order.size(); ++k) {
    EXPECT_EQ(lr.runs[k].seed, order[k].first);
    EXPECT_EQ(lr.runs[k].cells_x, order[k].second);
    EXPECT_EQ(lr.runs[k].cells_z, order[k].second);
  }
  const double r = lr.runs[0].cell_size_m / lr.runs[1].cell_size_m;
  EXPECT_NEAR(r, 1.5, 1e-12);  // 10 cm to 6.67 cm cells
  ASSERT_EQ(lr.headline.size(), kDbmHeadline.size());
  for (std::size_t n = 0; n < lr.headline.size(); ++n) {
    const HeadlineUncertainty& h = lr.headline[n];
    const std::vector<double> coarse = Values(lr, n, 0, 2), fine = Values(lr, n, 1, 2);
    const double tol = 1e-12 * std::abs(h.estimate);
    EXPECT_NEAR(h.estimate, Mean(fine), tol) << h.name;
    EXPECT_NEAR(h.spread, std::abs(fine[0] - fine[1]) / 2, tol) << h.name;
    EXPECT_NEAR(h.grid, std::abs(Mean(fine) - Mean(coarse)) / (r - 1.0), tol) << h.name;
    EXPECT_NEAR(h.total, std::hypot(h.spread, h.grid), tol) << h.name;
    EXPECT_TRUE(std::isfinite(h.total));
  }
  EXPECT_GT(lr.headline[0].total, lr.headline[0].spread);  // the grid changes the hold-up
  // D (the DBM's mean bubble size) gets the same treatment, with the finer grid's cell bound.
  EXPECT_NEAR(lr.diameter.boundary_m, lr.runs[1].cell_size_m, 1e-15);
  EXPECT_NE(s.method_description.find("6x15x6"), std::string::npos) << s.method_description;
}

TEST_F(SensitivityDbm, WorkPrecisionKeepsTheDepthAndComparesWithTheFinestConfiguration) {
  WorkPrecisionOptions o;
  o.law = "gidaspow@1";
  o.grids = parse_grid_list("4x10", "--grids");  // the scene's 4 depth cells
  o.time_resolutions = {1e-2, 5e-3};
  o.run.duration_s = 5.0;
  const WorkPrecisionResult w = run_work_precision(scene_, loader_, o);
  EXPECT_EQ(w.time_resolution_name, "dt_s");
  EXPECT_FALSE(w.finer_time_is_larger);
  EXPECT_EQ(w.reference_method, "finest as reference");
  ASSERT_EQ(w.rows.size(), 2u);
  ASSERT_TRUE(w.has_headline());
  EXPECT_EQ(w.reference_headline.size(), kDbmHeadline.size());
  for (const WorkPrecisionRow& row : w.rows) {
    EXPECT_EQ(row.cells_z, 4);
    ASSERT_EQ(row.headline.size(), kDbmHeadline.size());
    ASSERT_EQ(row.headline_difference.size(), kDbmHeadline.size());
    EXPECT_GT(row.wall_s, 0.0);
  }
  EXPECT_FALSE(w.rows[0].is_reference);
  EXPECT_TRUE(w.rows[1].is_reference);  // dt 5e-3 is the finer step
  EXPECT_EQ(w.rows[1].gas_steps, 2 * w.rows[0].gas_steps);
  for (std::size_t n = 0; n < kDbmHeadline.size(); ++n) {
    EXPECT_TRUE(std::isnan(w.rows[1].headline_difference[n]));
    EXPECT_EQ(w.rows[0].headline_difference[n],
              w.rows[0].headline[n].second - w.rows[1].headline[n].second);
  }
  EXPECT_NE(w.FullReport().find("holdup"), std::string::npos) << w.FullReport();
}

}  // namespace
}  // namespace workflows
}  // namespace draglab
