// The bed-model family (bed_model.h): the registry (built-in "dpm", an unknown key and a repeated
// one are clear errors), scene validation that accepts exactly the registered keys, dispatch by
// the scene's solver to a model registered from outside the library, and the DPM through the
// registry giving bit-identical results to a direct DpmSimulation run of the same scene, law and
// thread count (the family changes no DPM number).
#include <algorithm>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/dpm.h"
#include "draglab/consumers/regress.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/error.h"
#include "draglab/drag_db/law_form.h"

namespace draglab {
namespace consumers {
namespace {

const char* kTinyScene = R"(
[scene]
name = "bed_model_tiny"
solver = "SOLVER"
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
settle_s = 0.3
duration_s = 0.06
t_ref_s = 0.04
[grid]
cells_x = 4
cells_y = 12
[drag]
laws = ["ergun@1"]
eps_mf = 0.42
)";

std::string scene_text(const std::string& solver) {
  std::string text = kTinyScene;
  text.replace(text.find("SOLVER"), 6, solver);
  return text;
}

std::shared_ptr<const Law> ergun() {
  LawRecord record;
  record.name = "ergun";
  record.version = 1;
  record.form = "ergun";
  const LawForm& form = find_law_form("ergun");
  const auto values = form.default_parameters();
  for (std::size_t k = 0; k < values.size(); ++k) {
    record.parameters.push_back(
        {form.description.parameters[k].name, values[k], form.description.parameters[k].unit});
  }
  record.convention = form.convention;
  record.validity = form.description.validity;
  return std::make_shared<const Law>(record, RangePolicy::kClamp);
}

/// A model that only reports what it was given: dispatch is observable without a solver.
class EchoModel : public BedModel {
 public:
  std::string key() const override { return "echo_test"; }
  std::string description() const override { return "test model"; }
  BedResult Run(const Scene& scene, std::shared_ptr<const Law> law, const BedRunOptions& options,
                const BedProgress&) const override {
    BedResult r;
    r.model = key();
    r.scene = scene.name;
    r.law = law->reference();
    r.wall_s = options.duration_s;
    r.result_json = R"({"solver": "echo_test"})";
    return r;
  }
};

/// A second "dpm": registering it must fail.
class DuplicateDpm : public EchoModel {
 public:
  std::string key() const override { return "dpm"; }
};

TEST(BedModel, RegistryHasTheDpmAndNamesTheKeysOnAMiss) {
  const auto keys = bed_model_keys();
  EXPECT_NE(std::find(keys.begin(), keys.end(), "dpm"), keys.end());
  EXPECT_EQ(find_bed_model("dpm").key(), "dpm");
  try {
    find_bed_model("tfm_not_yet");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("dpm"), std::string::npos) << e.what();
  }
  EXPECT_THROW(register_bed_model(std::make_unique<DuplicateDpm>()), Error);
  EXPECT_THROW(register_bed_model(nullptr), Error);
}

TEST(BedModel, ScenesNameRegisteredModelsAndRunsDispatchToThem) {
  // Before registration the solver is unknown to scene validation, naming the known ones.
  try {
    parse_scene(scene_text("echo_test"), "echo");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    const std::string what = e.what();
    EXPECT_NE(what.find("echo_test"), std::string::npos) << what;
    EXPECT_NE(what.find("dpm"), std::string::npos) << what;
  }
  register_bed_model(std::make_unique<EchoModel>());
  const Scene scene = parse_scene(scene_text("echo_test"), "echo");
  BedRunOptions options;
  options.duration_s = 0.25;
  const BedResult r = run_bed_model(scene, ergun(), options);
  EXPECT_EQ(r.model, "echo_test");
  EXPECT_EQ(r.scene, "bed_model_tiny");
  EXPECT_EQ(r.law, "ergun@1");
  EXPECT_EQ(r.wall_s, 0.25);
  options.duration_s = -1.0;
  EXPECT_THROW(run_bed_model(scene, ergun(), options), Error);
}

TEST(BedModel, DpmThroughTheRegistryIsBitIdenticalToADirectRun) {
  const Scene scene = parse_scene(scene_text("dpm"), "tiny");
  DpmSimulation direct_sim(scene, ergun(), DpmOptions());
  const DpmResult direct = direct_sim.Run();
  const BedResult via = run_bed_model(scene, ergun());
  EXPECT_EQ(via.model, "dpm");
  const ConsumerMetrics m = consumer_metrics_of(direct);
  EXPECT_EQ(via.metrics.umf_m_s, m.umf_m_s);
  EXPECT_EQ(via.metrics.background_m_s, m.background_m_s);
  EXPECT_EQ(via.metrics.bubble_present, m.bubble_present);
  EXPECT_EQ(via.metrics.bubble_diameter_m, m.bubble_diameter_m);
  EXPECT_EQ(via.metrics.bubble_centroid_m, m.bubble_centroid_m);
  EXPECT_EQ(via.metrics.max_bed_height_m, m.max_bed_height_m);
  ASSERT_EQ(via.series.size(), direct.series.size());
  ASSERT_FALSE(direct.series.empty());
  for (std::size_t i = 0; i < direct.series.size(); ++i) {
    EXPECT_EQ(via.series[i].t_s, direct.series[i].t_s) << i;
    EXPECT_EQ(via.series[i].bubble_diameter_m, direct.series[i].bubble_diameter_m) << i;
    EXPECT_EQ(via.series[i].bed_height_m, direct.series[i].bed_height_m) << i;
    EXPECT_EQ(via.series[i].pressure_drop_pa, direct.series[i].pressure_drop_pa) << i;
  }
  EXPECT_EQ(via.momentum_mismatch, direct.momentum_mismatch);
  EXPECT_EQ(via.max_relative_mass_imbalance, direct.max_relative_mass_imbalance);
  // The stored JSON is the DPM's own, identical but for the run times.
  nlohmann::json a = nlohmann::json::parse(via.result_json);
  nlohmann::json b = nlohmann::json::parse(dpm_result_json(direct));
  for (const char* timing : {"wall_s", "settle_wall_s"}) {
    a.erase(timing);
    b.erase(timing);
  }
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.at("solver"), "dpm");
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
