// workflows::write_report and report_law_json: the numbers behind `draglab report`.
//
// Set-up: synthetic datasets built from the literature Ergun law itself (Ergun 1952, as stored
// in a fresh database), at phi in {0.3, 0.4, 0.5} and Re in {1, 10, 100}.
// References (exact, no tolerance beyond round-off):
//  - data equal to the law: every relative difference |F_law/F_data - 1| is 0;
//  - data equal to (1 + a) times the law: every relative difference is a/(1 + a), so the maximum
//    and the RMS both equal it;
//  - a point at phi = 0.1, outside Ergun's validity box phi in [0.2, 0.65], is evaluated
//    (extrapolate policy) and counted outside.
// The bundle is checked for the fields scripts/draglab_report.py reads; bad input is refused
// before anything is written.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <string>
#include <vector>

#include "draglab/core/files.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "draglab/workflows/report.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

using workflows::ReportLawStatistics;
using workflows::ReportOptions;

Dataset scaled_dataset(const Law& law, double scale, std::vector<double> phis) {
  Dataset ds;
  ds.name = "synthetic";
  for (double phi : phis) {
    for (double re : {1.0, 10.0, 100.0}) {
      DatasetPoint p;
      p.phi = phi;
      p.re = p.re_target = re;
      p.F = scale * law.evaluate(phi, re).F;
      p.F_uncertainty = 0.01 * p.F;
      p.realizations = 1;
      p.extrapolation = "finest";
      ds.points.push_back(p);
    }
  }
  return ds;
}

void write_csv(const Dataset& ds, const std::string& path) {
  std::ofstream out(path);
  out.precision(17);
  out << "phi,re,F,F_uncertainty\n";
  for (const DatasetPoint& p : ds.points)
    out << p.phi << ',' << p.re << ',' << p.F << ',' << p.F_uncertainty << '\n';
}

TEST(ReportLawJson, DataEqualToTheLawDifferByRoundOffOnly) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  auto law = db.load("ergun@1", RangePolicy::kExtrapolate);
  ReportLawStatistics s;
  const nlohmann::json j = workflows::report_law_json(
      *law, "reference", "Ergun", scaled_dataset(*law, 1.0, {0.3, 0.4, 0.5}), &s);
  EXPECT_EQ(s.n_evaluated, 9);
  EXPECT_EQ(s.n_outside_validity, 0);
  EXPECT_LT(s.max_rel_diff, 1e-14);
  EXPECT_LT(s.rms_rel_diff, 1e-14);
  EXPECT_EQ(j["stats"]["n_evaluated"], 9);
  EXPECT_EQ(j["reference"], "ergun@1");
  EXPECT_EQ(j["role"], "reference");
  EXPECT_EQ(j["label"], "Ergun");
}

TEST(ReportLawJson, ScaledDataGiveTheExactRelativeDifference) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  auto law = db.load("ergun@1", RangePolicy::kExtrapolate);
  const double a = 0.25;
  ReportLawStatistics s;
  workflows::report_law_json(*law, "fit", "Ergun", scaled_dataset(*law, 1.0 + a, {0.3, 0.4}), &s);
  const double expected = a / (1.0 + a);  // |1/(1 + a) - 1|
  EXPECT_NEAR(s.max_rel_diff, expected, 1e-14);
  EXPECT_NEAR(s.rms_rel_diff, expected, 1e-14);
  EXPECT_EQ(s.role, "fit");
}

TEST(ReportLawJson, PointsOutsideTheValidityBoxAreEvaluatedAndCounted) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  auto law = db.load("ergun@1", RangePolicy::kExtrapolate);
  ReportLawStatistics s;
  const nlohmann::json j = workflows::report_law_json(*law, "reference", "Ergun",
                                                      scaled_dataset(*law, 1.0, {0.1, 0.4}), &s);
  EXPECT_EQ(s.n_evaluated, 6);
  EXPECT_EQ(s.n_outside_validity, 3);  // the three Re at phi = 0.1
  const auto& outside = j["at_points"]["outside_validity"];
  ASSERT_EQ(outside.size(), 6u);
  EXPECT_TRUE(outside[0].get<bool>());
  EXPECT_FALSE(outside[3].get<bool>());
}

TEST(ReportLawJson, CurvesSpanTheDataOnALogGridPerPhi) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  auto law = db.load("ergun@1", RangePolicy::kExtrapolate);
  const nlohmann::json j = workflows::report_law_json(
      *law, "reference", "Ergun", scaled_dataset(*law, 1.0, {0.3, 0.4, 0.5}), nullptr);
  ASSERT_EQ(j["curves"].size(), 3u);  // one per phi of the data
  for (const auto& curve : j["curves"]) {
    const std::vector<double> re = curve["re"].get<std::vector<double>>();
    ASSERT_GE(re.size(), 10u);
    EXPECT_NEAR(re.front(), 1.0 / 1.5, 1e-12);  // the data's Re range widened by 1.5
    EXPECT_NEAR(re.back(), 100.0 * 1.5, 1e-9);
    const double ratio = re[1] / re[0];
    for (std::size_t i = 1; i < re.size(); ++i) EXPECT_NEAR(re[i] / re[i - 1], ratio, 1e-9);
    // Each curve value is the law at (phi, Re).
    const double phi = curve["phi"];
    EXPECT_NEAR(curve["F"][5].get<double>(), law->evaluate(phi, re[5]).F, 1e-12);
  }
  EXPECT_FALSE(j["stokes_curve"]["phi"].empty());
}

TEST(WriteReport, BundleHoldsTheDataTheLawsAndTheirStatistics) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  auto law = db.load("ergun@1", RangePolicy::kExtrapolate);
  write_csv(scaled_dataset(*law, 1.1, {0.3, 0.4}), dir.file("data.csv"));
  ReportOptions o;
  o.data_csv = dir.file("data.csv");
  o.compare = "ergun@1,wen_yu@1";
  o.compare_given = true;
  o.out_dir = dir.file("out/nested/");
  o.render_figures = false;
  std::vector<std::string> infos;
  workflows::Messages messages;
  messages.on_info = [&](const std::string& m) { infos.push_back(m); };
  const workflows::ReportSummary r = workflows::write_report(db, o, messages);
  EXPECT_EQ(r.out_dir, dir.file("out/nested"));
  ASSERT_TRUE(core::file_exists(r.bundle_path));
  EXPECT_TRUE(r.report_path.empty());  // no figures asked for
  std::ifstream in(r.bundle_path);
  const nlohmann::json b = nlohmann::json::parse(in);
  EXPECT_EQ(b["format"], "draglab_report_bundle");
  EXPECT_EQ(b["dataset"]["points"].size(), 6u);
  ASSERT_EQ(b["laws"].size(), 2u);
  ASSERT_EQ(r.laws.size(), 2u);
  EXPECT_EQ(r.laws[0].reference, "ergun@1");
  EXPECT_NEAR(r.laws[0].max_rel_diff, 0.1 / 1.1, 1e-12);
  EXPECT_EQ(b["laws"][0]["stats"]["max_rel_diff"].get<double>(), r.laws[0].max_rel_diff);
  EXPECT_TRUE(b.contains("form_comparison"));
  EXPECT_NE(r.FullReport().find("9.09 %"), std::string::npos) << r.FullReport();
  EXPECT_NE(r.BriefReport().find("2 law(s)"), std::string::npos);
  EXPECT_FALSE(infos.empty());  // "bundle written to ..."
}

TEST(WriteReport, AMissingDefaultComparisonIsSkippedWithAWarning) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  auto law = db.load("ergun@1", RangePolicy::kExtrapolate);
  write_csv(scaled_dataset(*law, 1.0, {0.3}), dir.file("data.csv"));
  ReportOptions o;
  o.data_csv = dir.file("data.csv");
  o.laws = {"ergun@1"};
  o.out_dir = dir.file("out");
  o.render_figures = false;
  // The defaults are the literature laws, all in a fresh database: nothing to skip.
  std::vector<std::string> warnings;
  workflows::Messages messages;
  messages.on_warning = [&](const std::string& m) { warnings.push_back(m); };
  const workflows::ReportSummary r = workflows::write_report(db, o, messages);
  EXPECT_EQ(r.laws.size(), 4u);  // ergun (fit) drawn once, vdh2004, hill_koch_ladd, bvk2007
  EXPECT_TRUE(warnings.empty());
  // An explicit comparison that does not exist is bad input, not a warning.
  o.compare = "nosuch@1";
  o.compare_given = true;
  try {
    workflows::write_report(db, o, messages);
    FAIL() << "a missing --compare law must be refused";
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input());
    EXPECT_NE(std::string(e.what()).find("--compare nosuch@1"), std::string::npos) << e.what();
  }
}

TEST(WriteReport, BadInputIsRefusedBeforeAnythingIsWritten) {
  test::TempDir dir;
  Database db(dir.file("r.db"));
  ReportOptions o;
  o.out_dir = dir.file("out");
  o.render_figures = false;
  EXPECT_NE(o.Invalid().find("--dataset"), std::string::npos);  // no data given
  o.data_csv = dir.file("missing.csv");
  try {
    workflows::write_report(db, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input());
    EXPECT_NE(std::string(e.what()).find("--data"), std::string::npos) << e.what();
  }
  { std::ofstream(dir.file("empty.csv")) << "phi,re,F,F_uncertainty\n"; }
  o.data_csv = dir.file("empty.csv");
  EXPECT_THROW(workflows::write_report(db, o), Error);
  { std::ofstream(dir.file("file")) << "x"; }
  o.out_dir = dir.file("file");
  EXPECT_NE(o.Invalid().find("is a file"), std::string::npos);
  EXPECT_FALSE(core::directory_exists(dir.file("out")));
  o.out_dir = dir.file("out");
  o.dataset_id = "abcdef";
  EXPECT_NE(o.Invalid().find("exclude"), std::string::npos);
  o.data_csv.clear();
  try {
    workflows::write_report(db, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  }
  EXPECT_FALSE(core::directory_exists(dir.file("out")));
}

}  // namespace
}  // namespace draglab
