// workflows::run_sensitivity_study: a DPM law study run, saved and read back, in process.
//
// Set-up: the shared tiny DPM scene (data/scenes/dpm_tiny.toml: ~320 glass beads, a 2 cm bed, a
// 10 m/s jet for 0.02 s, D read at t_ref = 0.03 s), law ergun@1, two packings (seeds of the
// scene's realizations), no figure (no Python).
// References: the study's uncertainty for two realizations is the standard error of their mean,
// |D1 - D2| / 2 (sample standard deviation / sqrt(2)), combined with the grid bound; the saved
// bundle holds exactly the numbers of the summary; the two runs' bubbles are those of
// `scene run` with the same seed (determinism, checked by the command line's test); bad input
// (an unknown law) is refused before any run and leaves no folder.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "draglab/consumers/scene.h"
#include "draglab/core/files.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"
#include "draglab/workflows/studies.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

const std::string kTinyScene = std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_tiny.toml";

TEST(SensitivityStudy, TwoPackingsOneLawSavedAsRun) {
  test::TempDir dir;
  Database db(dir.file("s.db"));
  const consumers::Scene scene = consumers::load_scene(kTinyScene);
  workflows::SensitivityOptions options;
  options.laws = {"ergun@1"};
  options.realizations = 2;
  workflows::StudyOutput output;
  output.out_dir = dir.file("out");
  output.figure = false;
  int progress_calls = 0;
  double last_fraction = 0.0;
  const workflows::SensitivityStudy study = workflows::run_sensitivity_study(
      db, scene, options, output, {}, [&](double f, const std::string&) {
        ++progress_calls;
        last_fraction = f;
      });
  EXPECT_GT(progress_calls, 0);
  EXPECT_LE(last_fraction, 1.0);
  ASSERT_EQ(study.summary.laws.size(), 1u);
  const workflows::SensitivityLawResult& law = study.summary.laws[0];
  ASSERT_EQ(law.runs.size(), 2u);
  EXPECT_NE(law.runs[0].seed, law.runs[1].seed);  // two packings
  const double d1 = law.runs[0].bubble_diameter_m, d2 = law.runs[1].bubble_diameter_m;
  EXPECT_NEAR(law.diameter.mean_m, 0.5 * (d1 + d2), 1e-15);
  EXPECT_NEAR(law.diameter.spread_m, 0.5 * std::fabs(d1 - d2), 1e-15);
  EXPECT_GE(law.diameter.total_m, law.diameter.spread_m);  // the grid bound adds to it
  EXPECT_TRUE(study.figure_path.empty());

  ASSERT_TRUE(core::file_exists(study.bundle_path));
  std::ifstream in(study.bundle_path);
  const nlohmann::json b = nlohmann::json::parse(in);
  EXPECT_EQ(b["format"], "draglab_sensitivity");
  EXPECT_EQ(b["laws"][0]["law"], "ergun@1");
  EXPECT_EQ(b["laws"][0]["d_mean_m"].get<double>(), law.diameter.mean_m);
  EXPECT_EQ(b["laws"][0]["uncertainty_m"].get<double>(), law.diameter.total_m);
  EXPECT_EQ(b["laws"][0]["runs"].size(), 2u);
  EXPECT_EQ(study.ToJson(scene, output.out_dir)["data"], study.bundle_path);
}

TEST(SensitivityStudy, BadInputLeavesNoFolder) {
  test::TempDir dir;
  Database db(dir.file("s.db"));
  const consumers::Scene scene = consumers::load_scene(kTinyScene);
  workflows::SensitivityOptions options;
  options.laws = {"nosuch@1"};
  workflows::StudyOutput output;
  output.out_dir = dir.file("out");
  output.figure = false;
  EXPECT_THROW(workflows::run_sensitivity_study(db, scene, options, output), Error);
  EXPECT_FALSE(core::directory_exists(output.out_dir));
  output.beside = dir.file("missing.json");
  output.figure = true;
  options.laws = {"ergun@1"};
  try {
    workflows::run_sensitivity_study(db, scene, options, output);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--beside"), std::string::npos) << e.what();
  }
  workflows::WorkPrecisionOptions wp;
  wp.law = "ergun@1";
  EXPECT_THROW(workflows::run_work_precision_study(db, scene, wp, output), Error);  // --beside
  EXPECT_FALSE(core::directory_exists(output.out_dir));
}

}  // namespace
}  // namespace draglab
