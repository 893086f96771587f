// workflows::run_pipeline: campaign -> dataset -> fit of Eq. 6 -> published law, in process.
//
// Set-up: tests/support/data/tiny_campaign.toml, 3 phi (0.15, 0.25, 0.35) x 3 Re (0, 4, 10), one
// 8-sphere packing per phi at d = 8 (a few seconds of LBM); no report (no Python) and no regression
// check (the command line's test, tests/cli/pipeline_test.sh, runs both). References: the
// comparison table's "RMS vs data" of the fit is the fitter's own RMS relative error on the same
// points (two computations of one number, to round-off); a re-run resumes the campaign (no new
// unit) and reuses the identical published version (content hash and dataset equal); bad input is
// refused before any LBM (no campaign stored). A spec with [dataset] extend_with fits the
// campaign's 9 points and exactly the extension file's points outside the grid (3 of 4, by
// construction), and the law's validity box is the union.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "draglab/campaign/campaign.h"
#include "draglab/core/files.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"
#include "draglab/workflows/pipeline.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

const std::string kTinySpec = std::string(DRAGLAB_TEST_SUPPORT_DIR) + "/data/tiny_campaign.toml";

workflows::PipelineOptions tiny_options(const test::TempDir& dir) {
  workflows::PipelineOptions o;
  o.db_path = dir.file("p.db");
  o.spec_path = kTinySpec;
  o.jobs = 1;
  o.report = false;
  o.regress = false;
  return o;
}

TEST(Pipeline, PublishesTheFitAndReusesItOnARerun) {
  test::TempDir dir;
  const workflows::PipelineOptions o = tiny_options(dir);
  const workflows::PipelineSummary first = workflows::run_pipeline(o);
  EXPECT_EQ(first.campaign.units_total, 9);
  EXPECT_EQ(first.campaign.units_done, 9);
  EXPECT_EQ(first.dataset.points.size(), 9u);
  EXPECT_EQ(first.law.reference(), "eq6_tiny@1");
  EXPECT_EQ(first.law.status, LawStatus::kPublished);
  EXPECT_EQ(first.law.provenance.dataset_id, first.dataset.id);
  ASSERT_FALSE(first.comparison.empty());
  EXPECT_EQ(first.comparison.front().law, "eq6_tiny@1 (fit)");
  EXPECT_NEAR(first.comparison.front().rms_vs_data, first.fit.rms_rel_err,
              1e-12 + 1e-9 * first.fit.rms_rel_err);
  EXPECT_FALSE(first.checked);
  EXPECT_NE(first.FullReport().find("Regression check skipped"), std::string::npos);
  const nlohmann::json j = first.ToJson();
  EXPECT_EQ(j["law"], "eq6_tiny");
  EXPECT_EQ(j["version"], 1);
  EXPECT_TRUE(j["regress"].is_null());

  const workflows::PipelineSummary again = workflows::run_pipeline(o);
  EXPECT_EQ(again.campaign.id, first.campaign.id);
  EXPECT_EQ(again.campaign.units_total, 9);  // resumed: no new unit
  EXPECT_EQ(again.dataset.id, first.dataset.id);
  EXPECT_EQ(again.law.reference(), "eq6_tiny@1");  // the identical version, not @2
  Database db(o.db_path);
  EXPECT_EQ(db.list("eq6_tiny").size(), 1u);
}

TEST(Pipeline, BadInputIsRefusedBeforeAnyLbm) {
  test::TempDir dir;
  workflows::PipelineOptions o = tiny_options(dir);
  o.law_name = "_x";
  try {
    workflows::run_pipeline(o);
    FAIL() << "an invalid law name must be refused";
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input());
    EXPECT_NE(std::string(e.what()).find("--law-name"), std::string::npos) << e.what();
  }
  o.law_name.clear();
  o.regress_scene = kTinySpec;  // with regress = false
  EXPECT_THROW(workflows::run_pipeline(o), Error);
  o.regress = true;
  o.regress_scene = dir.file("missing.toml");
  EXPECT_THROW(workflows::run_pipeline(o), Error);
  EXPECT_FALSE(core::file_exists(o.db_path));  // nothing was stored
  EXPECT_THROW(workflows::preset_spec_path("nosuch"), Error);
  EXPECT_TRUE(core::file_exists(workflows::preset_spec_path("quick")));
}

// The tiny spec with an extension file beside it (a relative path, taken from the spec's folder):
// 3 points outside the grid's box phi [0.15, 0.35] x Re [0, 10] and one inside, whose F (999, far
// from any drag) must not enter the fit.
std::string write_extended_spec(const test::TempDir& dir, const std::string& id_line) {
  {
    std::ofstream csv(dir.file("ext.csv"));
    csv << "# an extension for the pipeline test (values near bvk2007, not measured)\n"
           "phi,re,F,F_uncertainty\n0.5,0,18.9,0.9\n0.5,30,31.5,1.6\n0.25,30,9.2,0.5\n"
           "0.25,4,999,1\n";
  }
  std::ifstream in(kTinySpec);
  std::string spec((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  spec += "extend_with = \"ext.csv\"\n" + id_line;
  const std::string path = dir.file("extended.toml");
  std::ofstream(path) << spec;
  return path;
}

TEST(Pipeline, FitsTheCampaignExtendedByTheSpecsDatasetOutsideItsGrid) {
  test::TempDir dir;
  workflows::PipelineOptions o = tiny_options(dir);
  o.spec_path = write_extended_spec(dir, "");
  const workflows::PipelineSummary s = workflows::run_pipeline(o);
  EXPECT_EQ(s.campaign.units_done, 9);
  EXPECT_EQ(s.extension_points, 3u);
  ASSERT_EQ(s.dataset.points.size(), 12u);
  for (const DatasetPoint& p : s.dataset.points) EXPECT_LT(p.F, 999.0);
  EXPECT_NE(s.campaign_dataset_id, s.dataset.id);
  EXPECT_EQ(s.law.provenance.dataset_id, s.dataset.id);
  EXPECT_DOUBLE_EQ(s.law.validity.phi.max, 0.5);
  EXPECT_DOUBLE_EQ(s.law.validity.re.max, 30.0);
  EXPECT_NE(s.FullReport().find("taken from dataset " + s.extension_id), std::string::npos)
      << s.FullReport();
  EXPECT_EQ(s.ToJson()["extended_with"]["points"], 3);
}

TEST(Pipeline, AnExtensionThatIsNotThePinnedOneIsRefusedBeforeAnyLbm) {
  test::TempDir dir;
  workflows::PipelineOptions o = tiny_options(dir);
  o.spec_path = write_extended_spec(dir, "extend_with_id = \"0123456789ab\"\n");
  try {
    workflows::run_pipeline(o);
    FAIL() << "an extension file with another id must be refused";
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input());
    EXPECT_NE(std::string(e.what()).find("expects 0123456789ab"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(core::file_exists(o.db_path));
}

}  // namespace
}  // namespace draglab
