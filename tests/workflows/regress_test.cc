// Regression-check logic (workflows/regress.h) without consumer runs.
//
// Set-up: a fresh database per test (literature laws seeded: ergun@1), the tiny DPM scene
// data/scenes/dpm_tiny.toml registered, and hand-written stored results (the DPM itself is
// exercised by tests/cli/regress_test.sh). New versions of ergun are made from ergun@1's record.
// What is checked, and the reference:
//  - compare_metrics against hand-computed limits: |delta| equal to the tolerance is ok, just
//    above it moved (U_mf relative, diameter absolute + relative to the baseline), a bubble that
//    appears or disappears moved, the diameter compared only when both runs have one, NaN moved;
//  - the default tolerances of the tiny scene: 2 cells of 7.5 mm = 15 mm, 10 %, 1 %;
//  - run_regression plans from the stored data: versions newer than the baseline's (published;
//    drafts only on request), a stored result of the same law content is reused (no run), the
//    comparison uses the baseline's stored tolerances;
//  - a run that fails (a version whose validity box excludes the bed: minimum_fluidization
//    refuses it before the DPM starts) is reported as failed, not moved, and stores nothing;
//  - single-law mode: unknown law (kNotFound), a draft without include_drafts
//    (kInvalidArgument), and a published version without a baseline whose stored result becomes
//    the baseline;
//  - compare_headline against hand-computed limits: a bubble size by the diameter tolerances,
//    the others 10 % of the baseline, inclusive; a number missing from the new result moved; no
//    comparison when the baseline has no headline numbers (the dpm and tfm results);
//  - a DBM scene end to end (data/scenes/dbm_tiny.toml, runs of 6 s, about a second each): the
//    default tolerances (no cell part); registering a baseline stores the four headline numbers;
//    a new version with the same content compares equal (the DBM run is deterministic: delta
//    0 exactly); one with every coefficient scaled by 1.1 (the Ergun branch at eps_mf 0.45: 10 %
//    more drag) moves U_mf (measured -7 %, 0.0369 to 0.0343 m/s) and with it the hold-up
//    (+36 %: the bubble gas flow u0 - U_mf grows by half) and the circulation (+27 %).
#include "draglab/workflows/regress.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "draglab/drag_db/database.h"
#include "draglab/error.h"

namespace draglab {
namespace workflows {
namespace {

using namespace consumers;  // the bed models and scenes the studies run

Scene TinyScene() { return load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_tiny.toml"); }

ConsumerMetrics metrics(double umf, bool bubble, double diameter) {
  ConsumerMetrics m;
  m.umf_m_s = umf;
  m.background_m_s = umf;
  m.t_ref_s = 0.05;
  m.bubble_present = bubble;
  m.bubble_diameter_m = bubble ? diameter : 0.0;
  m.bubble_centroid_m = bubble ? 0.03 : 0.0;
  m.max_bed_height_m = 0.04;
  return m;
}

const MetricComparison* find(const std::vector<MetricComparison>& c, const std::string& metric) {
  for (const MetricComparison& m : c) {
    if (m.metric == metric) return &m;
  }
  return nullptr;
}

TEST(RegressCompare, TolerancesAreInclusiveAndBubblePresenceCounts) {
  RegressionTolerances tol;
  tol.diameter_abs_m = 0.01;
  tol.diameter_rel = 0.1;
  tol.umf_rel = 0.01;
  // Baseline U_mf 2.0 (limit 0.02), D 0.05 (limit 0.01 + 0.005 = 0.015). Values chosen exactly
  // representable so that "at the limit" is exact.
  const ConsumerMetrics base = metrics(2.0, true, 0.0625);
  // D limit: 0.01 + 0.1 * 0.0625 = 0.01625.
  auto c = compare_metrics(base, metrics(2.0 + 0.015625, true, 0.0625 + 0.015625), tol);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_FALSE(find(c, "umf_m_s")->moved);  // 0.015625 < 0.02
  EXPECT_FALSE(find(c, "bubble_diameter_m")->moved);
  EXPECT_NEAR(find(c, "bubble_diameter_m")->tolerance, 0.01625, 1e-15);
  c = compare_metrics(base, metrics(2.0 * 1.0101, true, 0.0625 - 0.0163), tol);
  EXPECT_TRUE(find(c, "umf_m_s")->moved);
  EXPECT_TRUE(find(c, "bubble_diameter_m")->moved);
  EXPECT_NEAR(find(c, "umf_m_s")->delta, 0.0202, 1e-12);
  // Exactly at the tolerance is not a move.
  RegressionTolerances exact;
  exact.umf_rel = 0.25;  // 0.25 * 2.0 = 0.5 exactly
  exact.diameter_abs_m = 0.125;
  exact.diameter_rel = 0.0;
  c = compare_metrics(base, metrics(2.5, true, 0.1875), exact);
  EXPECT_FALSE(find(c, "umf_m_s")->moved);
  EXPECT_FALSE(find(c, "bubble_diameter_m")->moved);
  // A bubble that disappears (or appears) moved; no diameter comparison then.
  c = compare_metrics(base, metrics(2.0, false, 0.0), tol);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_TRUE(find(c, "bubble_present")->moved);
  EXPECT_EQ(find(c, "bubble_diameter_m"), nullptr);
  c = compare_metrics(metrics(2.0, false, 0.0), metrics(2.0, true, 0.03), tol);
  EXPECT_TRUE(find(c, "bubble_present")->moved);
  // Both without bubble: ok.
  c = compare_metrics(metrics(2.0, false, 0.0), metrics(2.0, false, 0.0), tol);
  EXPECT_FALSE(find(c, "bubble_present")->moved);
  // NaN never passes.
  c = compare_metrics(base, metrics(std::numeric_limits<double>::quiet_NaN(), true, 0.0625), tol);
  EXPECT_TRUE(find(c, "umf_m_s")->moved);
}

TEST(RegressCompare, DefaultTolerancesOfTheTinyScene) {
  const Scene scene = TinyScene();
  const RegressionTolerances t = default_regression_tolerances(scene);
  EXPECT_NEAR(t.diameter_abs_m, 2 * 0.0075, 1e-15);  // cells of 3 cm / 4 = 9 cm / 12 = 7.5 mm
  EXPECT_EQ(t.diameter_rel, 0.1);
  EXPECT_EQ(t.umf_rel, 0.01);
  RegressOptions o;
  o.tol_diameter_rel = 0.2;
  const RegressionTolerances overridden = baseline_tolerances(scene, o);
  EXPECT_EQ(overridden.diameter_rel, 0.2);
  EXPECT_EQ(overridden.diameter_abs_m, t.diameter_abs_m);
  std::string why;
  o.tol_umf_rel = 20.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("tol_umf_rel"), std::string::npos) << why;
}

class RegressPlan : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "/regress_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".db";
    std::remove(path_.c_str());
    db_ = std::make_unique<Database>(path_);
    scene_ = TinyScene();
    tolerances_ = default_regression_tolerances(scene_);
    // Baseline: a hand-written ergun@1 result (U_mf 1.2 m/s, D 2 cm).
    baseline_ =
        store_consumer_baseline_run(*db_, scene_.name, scene_.source_text,
                                    Result(db_->resolve("ergun@1"), 1.2, 0.02), tolerances_, false);
  }
  void TearDown() override {
    db_.reset();
    std::remove(path_.c_str());
  }
  ConsumerResult Result(const LawRecord& law, double umf, double diameter) const {
    ConsumerResult r;
    r.scene_name = scene_.name;
    r.scene_hash = scene_.hash();
    r.law_name = law.name;
    r.law_version = law.version;
    r.law_content_hash = law.content_hash;
    r.metrics = metrics(umf, diameter > 0, diameter);
    return r;
  }
  // A new version of ergun: coefficients scaled, optionally a phi box that excludes the bed
  // (phi = 1 - eps_mf = 0.58), published or left a draft.
  LawRecord NewErgun(double scale, bool exclude_bed, bool publish) {
    LawRecord r = db_->resolve("ergun@1");
    for (LawParameter& p : r.parameters) p.value *= scale;
    if (exclude_bed) r.validity.phi.max = 0.5;
    r.status = LawStatus::kDraft;
    return publish ? db_->add_published(r) : db_->add_draft(r);
  }
  std::int64_t Results() const { return list_consumer_results(*db_).size(); }

  std::string path_;
  std::unique_ptr<Database> db_;
  Scene scene_;
  RegressionTolerances tolerances_;
  ConsumerBaseline baseline_;
};

TEST_F(RegressPlan, StoredResultsOfNewerVersionsAreComparedWithoutRunning) {
  const LawRecord same = NewErgun(1.0, false, true);    // ergun@2
  const LawRecord moved = NewErgun(1.5, false, true);   // ergun@3
  const LawRecord draft = NewErgun(2.0, false, false);  // ergun@4, draft
  // Stored results: @2 within tolerance (U_mf +0.5 %, D +1 cm < 1.5 cm + 2 mm), @3 U_mf -20 %,
  // the draft with no bubble.
  store_consumer_result(*db_, Result(same, 1.2 * 1.005, 0.03));
  store_consumer_result(*db_, Result(moved, 0.96, 0.02));
  store_consumer_result(*db_, Result(draft, 1.2, 0.0));
  const std::int64_t before = Results();

  int progress_calls = 0;
  RegressSummary s = run_regression(
      *db_, RegressOptions(), [&](int, int, double, const std::string&) { ++progress_calls; });
  EXPECT_EQ(s.runs, 0);
  EXPECT_EQ(progress_calls, 0);
  EXPECT_EQ(Results(), before);
  ASSERT_EQ(s.entries.size(), 2u);  // @2 and @3; the draft is not checked by default
  EXPECT_EQ(s.entries[0].law, "ergun@2");
  EXPECT_EQ(s.entries[0].baseline_law, "ergun@1");
  EXPECT_EQ(s.entries[0].outcome, RegressOutcome::kOk);
  EXPECT_FALSE(s.entries[0].ran);
  EXPECT_EQ(s.entries[1].law, "ergun@3");
  EXPECT_EQ(s.entries[1].outcome, RegressOutcome::kMoved);
  EXPECT_TRUE(s.any_moved());
  EXPECT_NE(s.FullReport().find("MOVED"), std::string::npos) << s.FullReport();
  EXPECT_NE(s.BriefReport().find("1 moved, 1 ok, 0 failed"), std::string::npos) << s.BriefReport();

  RegressOptions with_drafts;
  with_drafts.include_drafts = true;
  s = run_regression(*db_, with_drafts);
  ASSERT_EQ(s.entries.size(), 3u);
  EXPECT_EQ(s.entries[2].law, "ergun@4");
  EXPECT_EQ(s.entries[2].outcome, RegressOutcome::kMoved);  // the bubble disappeared
  EXPECT_TRUE(find(s.entries[2].comparisons, "bubble_present")->moved);

  // The baseline's own tolerances are used: with a wider U_mf tolerance @3 is within it.
  RegressionTolerances wide = tolerances_;
  wide.umf_rel = 0.25;
  replace_consumer_baseline(*db_, baseline_.result_id, wide);
  s = run_regression(*db_, RegressOptions());
  ASSERT_EQ(s.entries.size(), 2u);
  EXPECT_EQ(s.entries[1].outcome, RegressOutcome::kOk);
  EXPECT_EQ(s.entries[1].tolerances.umf_rel, 0.25);
}

TEST_F(RegressPlan, ASceneOutsideTheLawsValidityBoxIsNotApplicableAndStoresNothing) {
  NewErgun(1.0, true, true);  // ergun@2: its phi box ends at 0.5, the bed is at 0.58
  const std::int64_t before = Results();
  int planned = -1;
  const RegressSummary s = run_regression(
      *db_, RegressOptions(), [&](int, int runs, double, const std::string&) { planned = runs; });
  ASSERT_EQ(s.entries.size(), 1u);
  EXPECT_EQ(s.entries[0].outcome, RegressOutcome::kOutsideValidity);
  EXPECT_FALSE(s.any_moved());
  EXPECT_EQ(s.entries[0].result_id, 0);
  EXPECT_NE(s.entries[0].error.find("validity"), std::string::npos) << s.entries[0].error;
  EXPECT_EQ(s.runs, 1);
  EXPECT_EQ(Results(), before);
  EXPECT_NE(s.FullReport().find("NOT APPLICABLE"), std::string::npos);
  EXPECT_NE(s.BriefReport().find("1 outside the law's validity box"), std::string::npos);
  EXPECT_TRUE(planned == -1 || planned == 1);  // it fails before the DPM reports progress

  // Single-law mode: the same failure, and no baseline is registered for a new name either.
  RegressOptions single;
  single.law = "ergun@2";
  EXPECT_EQ(run_regression(*db_, single).entries[0].outcome, RegressOutcome::kOutsideValidity);
  EXPECT_EQ(Results(), before);
}

TEST_F(RegressPlan, SingleLawModeRegistersMissingBaselinesAndRefusesBadReferences) {
  RegressOptions single;
  single.law = "nosuchlaw@1";
  try {
    run_regression(*db_, single);
    FAIL() << "unknown law accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  }
  NewErgun(1.1, false, false);  // ergun@2, draft
  single.law = "ergun@2";
  try {
    run_regression(*db_, single);
    FAIL() << "draft accepted without include_drafts";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("draft"), std::string::npos) << e.what();
  }

  // bvk2007@1 has no baseline on the scene: its stored result becomes the baseline.
  const LawRecord bvk = db_->resolve("bvk2007@1");
  const ConsumerResult stored = store_consumer_result(*db_, Result(bvk, 1.4, 0.025));
  single.law = "bvk2007@1";
  single.tol_umf_rel = 0.05;
  RegressSummary s = run_regression(*db_, single);
  ASSERT_EQ(s.entries.size(), 1u);
  EXPECT_EQ(s.entries[0].outcome, RegressOutcome::kBaselineRegistered);
  EXPECT_EQ(s.entries[0].result_id, stored.id);
  EXPECT_EQ(s.runs, 0);
  const auto b = active_consumer_baseline(*db_, scene_.hash(), "bvk2007");
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->result_id, stored.id);
  EXPECT_EQ(b->tolerances.umf_rel, 0.05);
  EXPECT_EQ(b->tolerances.diameter_abs_m, tolerances_.diameter_abs_m);
  // Checking it again compares it with itself.
  s = run_regression(*db_, single);
  EXPECT_EQ(s.entries[0].outcome, RegressOutcome::kOk);
  EXPECT_EQ(s.entries[0].baseline_law, "bvk2007@1");

  // An unknown scene filter is refused.
  RegressOptions filtered;
  filtered.scene_hashes = {std::string(64, 'e')};
  try {
    run_regression(*db_, filtered);
    FAIL() << "unknown scene accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  }
}

TEST(RegressCompare, HeadlineNumbersUseTheDiameterOrTheHeadlineTolerance) {
  RegressionTolerances tol;
  tol.diameter_abs_m = 0.0;
  tol.diameter_rel = 0.125;
  tol.umf_rel = 0.01;
  // Exactly representable: hold-up 0.5 (limit 0.05), size 0.25 (limit 0.03125), upflow 2.0.
  const std::string base =
      R"({"solver": "dbm", "headline": {"holdup": 0.5, "mean_diameter_at_0.3_m": 0.25, )"
      R"("circulation_upflow_m_s": 2.0}})";
  EXPECT_EQ(headline_of_result_json(base).size(), 3u);
  EXPECT_NEAR(headline_tolerance("holdup", 0.5, tol), 0.05, 1e-15);
  EXPECT_EQ(headline_tolerance("mean_diameter_at_0.3_m", 0.25, tol), 0.03125);
  auto c = compare_headline(base,
                            R"({"headline": {"holdup": 0.54, "mean_diameter_at_0.3_m": 0.28125, )"
                            R"("circulation_upflow_m_s": 1.75}})",
                            tol);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_FALSE(find(c, "holdup")->moved);                  // 0.04 < 0.05
  EXPECT_FALSE(find(c, "mean_diameter_at_0.3_m")->moved);  // at the limit
  EXPECT_TRUE(find(c, "circulation_upflow_m_s")->moved);   // 0.25 > 0.2
  EXPECT_NEAR(find(c, "circulation_upflow_m_s")->delta, -0.25, 1e-15);
  EXPECT_NEAR(find(c, "circulation_upflow_m_s")->tolerance, 0.2, 1e-15);
  // A number the new result lacks (or holds as null) moved.
  c = compare_headline(base, R"({"headline": {"holdup": null}})", tol);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_TRUE(find(c, "holdup")->moved);
  EXPECT_TRUE(std::isnan(find(c, "mean_diameter_at_0.3_m")->value));
  EXPECT_TRUE(find(c, "mean_diameter_at_0.3_m")->moved);
  // Nothing to compare without a baseline headline (dpm, tfm, or results stored before).
  EXPECT_TRUE(compare_headline("{}", base, tol).empty());
  EXPECT_TRUE(compare_headline("not json", base, tol).empty());
  EXPECT_TRUE(headline_of_result_json(R"({"headline": 3})").empty());
}

class RegressDbm : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "/regress_dbm_test_" + std::to_string(::getpid()) + ".db";
    std::remove(path_.c_str());
    db_ = std::make_unique<Database>(path_);
    scene_ = load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dbm_tiny.toml");
    options_.run.duration_s = 6.0;  // the scene averages from 4 s
  }
  void TearDown() override {
    db_.reset();
    std::remove(path_.c_str());
  }
  // A new published version of gidaspow with every coefficient scaled.
  LawRecord NewGidaspow(double scale) {
    LawRecord r = db_->resolve("gidaspow@1");
    for (LawParameter& p : r.parameters) p.value *= scale;
    r.status = LawStatus::kDraft;
    return db_->add_published(r);
  }
  std::string path_;
  std::unique_ptr<Database> db_;
  Scene scene_;
  RegressOptions options_;
};

TEST_F(RegressDbm, RunsOnADbmSceneAndComparesItsHeadlineNumbers) {
  const RegressionTolerances defaults = default_regression_tolerances(scene_);
  EXPECT_EQ(defaults.diameter_abs_m, 0.0);  // Lagrangian bubbles: no cell part
  EXPECT_EQ(defaults.diameter_rel, 0.1);
  EXPECT_EQ(defaults.umf_rel, 0.01);

  options_.law = "gidaspow@1";
  const RegressSummary reg = register_regression_baseline(*db_, scene_, options_);
  ASSERT_EQ(reg.entries.size(), 1u);
  const RegressEntry& base = reg.entries[0];
  EXPECT_EQ(base.outcome, RegressOutcome::kBaselineRegistered);
  EXPECT_TRUE(base.ran);
  EXPECT_GT(base.metrics.umf_m_s, 0.0);
  EXPECT_TRUE(base.metrics.bubble_present);
  ASSERT_EQ(base.headline.size(), 4u);  // alphabetical, as stored
  for (const auto& [name, value] : base.headline) {
    EXPECT_TRUE(std::isfinite(value) && value > 0.0) << name << " " << value;
  }
  EXPECT_NE(reg.FullReport().find("holdup"), std::string::npos) << reg.FullReport();

  NewGidaspow(1.0);  // gidaspow@2: the same content
  NewGidaspow(1.1);  // gidaspow@3: 10 % more drag
  RegressOptions check;
  check.run.duration_s = 6.0;
  int planned = 0;
  const RegressSummary s = run_regression(
      *db_, check, [&](int, int runs, double, const std::string&) { planned = runs; });
  EXPECT_EQ(planned, 2);
  EXPECT_EQ(s.runs, 2);
  ASSERT_EQ(s.entries.size(), 2u);
  const RegressEntry& same = s.entries[0];
  EXPECT_EQ(same.law, "gidaspow@2");
  EXPECT_EQ(same.outcome, RegressOutcome::kOk) << s.FullReport();
  ASSERT_EQ(same.comparisons.size(), 3u + 4u);  // U_mf, bubble present, D, 4 headline numbers
  for (const MetricComparison& c : same.comparisons) EXPECT_EQ(c.delta, 0.0) << c.metric;
  ASSERT_NE(find(same.comparisons, "holdup"), nullptr);
  EXPECT_NEAR(find(same.comparisons, "holdup")->tolerance,
              0.1 * find(same.comparisons, "holdup")->baseline, 1e-15);

  const RegressEntry& more_drag = s.entries[1];
  EXPECT_EQ(more_drag.law, "gidaspow@3");
  EXPECT_EQ(more_drag.outcome, RegressOutcome::kMoved) << s.FullReport();
  EXPECT_TRUE(find(more_drag.comparisons, "umf_m_s")->moved);
  EXPECT_LT(find(more_drag.comparisons, "umf_m_s")->delta, 0.0);
  EXPECT_TRUE(find(more_drag.comparisons, "holdup")->moved) << s.FullReport();
  EXPECT_GT(find(more_drag.comparisons, "holdup")->delta, 0.0);
  EXPECT_NE(s.FullReport().find("MOVED"), std::string::npos);
}

}  // namespace
}  // namespace workflows
}  // namespace draglab
