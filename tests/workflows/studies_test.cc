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
// A study with a state folder (SensitivityOptions::state_directory) stopped part-way (here: one
// run's file removed, as a kill before it finished would leave it) goes on from what it kept:
// the kept run is taken as it was, the missing one runs from the kept packing, and every number
// is that of the uninterrupted study, bit for bit (the DPM is deterministic for one seed); a
// damaged packing file is settled again; another duration finds no kept run.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

/// The files of `dir` whose names start with `prefix`.
std::vector<std::string> FilesStartingWith(const std::string& dir, const std::string& prefix) {
  std::vector<std::string> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) out.push_back(entry.path().string());
  }
  return out;
}

void ExpectSameRun(const workflows::SensitivityRun& a, const workflows::SensitivityRun& b) {
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.bubble_diameter_m, b.bubble_diameter_m);  // bit for bit
  EXPECT_EQ(a.gas_steps, b.gas_steps);
  EXPECT_EQ(a.dem_steps, b.dem_steps);
  EXPECT_EQ(a.momentum_mismatch, b.momentum_mismatch);
  ASSERT_EQ(a.series.size(), b.series.size());
  for (std::size_t k = 0; k < a.series.size(); ++k) {
    EXPECT_EQ(a.series[k].bubble_diameter_m, b.series[k].bubble_diameter_m) << k;
    EXPECT_EQ(a.series[k].bed_height_m, b.series[k].bed_height_m) << k;
  }
}

TEST(SensitivityStudy, ResumedStudyGoesOnFromItsStateFolderToTheSameBits) {
  test::TempDir dir;
  Database db(dir.file("s.db"));
  const consumers::Scene scene = consumers::load_scene(kTinyScene);
  workflows::SensitivityOptions options;
  options.laws = {"ergun@1"};
  options.realizations = 2;
  options.state_directory = dir.file("out/state");
  workflows::StudyOutput output;
  output.out_dir = dir.file("out");
  output.figure = false;
  const workflows::SensitivitySummary first =
      workflows::run_sensitivity_study(db, scene, options, output).summary;
  ASSERT_EQ(first.laws.at(0).runs.size(), 2u);
  for (const auto& r : first.laws[0].runs) EXPECT_FALSE(r.reused);
  for (const auto& p : first.packings) EXPECT_FALSE(p.reused);
  const std::string state = options.state_directory;
  const std::string second_seed = "seed" + std::to_string(scene.seed + 1);
  ASSERT_EQ(FilesStartingWith(state, "ergun_1_").size(), 2u);
  ASSERT_EQ(FilesStartingWith(state, "packing_").size(), 2u);

  // Stopped before the second packing's run had finished.
  const std::vector<std::string> second_run = FilesStartingWith(state, "ergun_1_" + second_seed);
  ASSERT_EQ(second_run.size(), 1u);
  std::filesystem::remove(second_run[0]);
  const workflows::SensitivitySummary resumed =
      workflows::run_sensitivity_study(db, scene, options, output).summary;
  ASSERT_EQ(resumed.laws.at(0).runs.size(), 2u);
  EXPECT_TRUE(resumed.laws[0].runs[0].reused);
  EXPECT_FALSE(resumed.laws[0].runs[1].reused);
  EXPECT_TRUE(resumed.packings.at(0).reused);  // not needed: its only run was kept
  EXPECT_TRUE(resumed.packings.at(1).reused);  // read back, not settled again
  EXPECT_EQ(resumed.packings[1].particles, first.packings[1].particles);
  EXPECT_EQ(resumed.packings[1].settled_bed_height_m, first.packings[1].settled_bed_height_m);
  for (int k = 0; k < 2; ++k) ExpectSameRun(resumed.laws[0].runs[k], first.laws[0].runs[k]);
  EXPECT_EQ(resumed.laws[0].diameter.total_m, first.laws[0].diameter.total_m);
  EXPECT_EQ(resumed.laws[0].umf_m_s, first.laws[0].umf_m_s);
  ASSERT_TRUE(resumed.laws[0].has_snapshot);
  EXPECT_EQ(resumed.laws[0].snapshot.x, first.laws[0].snapshot.x);
  EXPECT_EQ(resumed.laws[0].snapshot.void_fraction.values,
            first.laws[0].snapshot.void_fraction.values);

  // A damaged packing file is settled again, to the same packing.
  std::filesystem::remove(FilesStartingWith(state, "ergun_1_" + second_seed).at(0));
  const std::string packing = FilesStartingWith(state, "packing_" + second_seed).at(0);
  std::filesystem::resize_file(packing, std::filesystem::file_size(packing) / 2);
  const workflows::SensitivitySummary resettled =
      workflows::run_sensitivity_study(db, scene, options, output).summary;
  EXPECT_FALSE(resettled.packings.at(1).reused);
  ExpectSameRun(resettled.laws.at(0).runs.at(1), first.laws[0].runs[1]);

  // Another duration is another study: no run is kept for it, the packings are.
  options.run.duration_s = 0.05;
  const workflows::SensitivitySummary shorter =
      workflows::run_sensitivity_study(db, scene, options, output).summary;
  for (const auto& r : shorter.laws.at(0).runs) EXPECT_FALSE(r.reused);
  for (const auto& p : shorter.packings) EXPECT_TRUE(p.reused);
  EXPECT_EQ(FilesStartingWith(state, "ergun_1_").size(), 4u);
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
