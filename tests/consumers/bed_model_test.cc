// The bed-model family (bed_model.h): the registry (built-in "dpm", an unknown key and a repeated
// one are clear errors), scene validation that accepts exactly the registered keys, dispatch by
// the scene's solver to a model registered from outside the library, and the DPM through the
// registry giving bit-identical results to a direct DpmSimulation run of the same scene, law and
// thread count (the family changes no DPM number). The realization hook: a DPM packing settled
// once and passed to several runs gives each run bit-identical results to a run that settles its
// own (the studies reuse one packing across laws and grids), a packing of another seed is
// refused, and the time-resolution hook sets the value that sets each model's step. A model
// registered from the test with its own scene table ([toy]) has it read, type-checked and checked
// by the model, refused in another model's scene, and copied with the scene.
#include <algorithm>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "dpm/dpm_scene.h"
#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/dpm.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"
#include "support/toml_edit.h"

namespace draglab {
namespace consumers {
namespace {

/// The tiny DPM bed (data/scenes/dpm_tiny.toml), with its solver replaced (and for another
/// model without the DPM's own [dem] table, which scenes of other models may not have).
std::string scene_text(const std::string& solver) {
  std::string text = test::read_text(std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_tiny.toml");
  if (solver != "dpm") text = test::toml_without_table(text, "dem");
  return test::toml_edit(text, "scene.solver=\"" + solver + "\"");
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
  BedModelSettings Settings(const Scene&) const override { return {"echo", {{"x", 1.0}}}; }
  TimeResolution time_resolution() const override {
    return {"steps", "test steps", "[1, 10]", true, true};
  }
  double time_resolution_of(const Scene&) const override { return 1.0; }
  Scene WithTimeResolution(const Scene& scene, double) const override { return scene; }
  BedResult Run(const Scene& scene, std::shared_ptr<const Law> law, const BedRunOptions& options,
                const BedProgress&, const BedRealization*) const override {
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
  EXPECT_EQ(r.scene, "dpm_tiny");
  EXPECT_EQ(r.law, "ergun@1");
  EXPECT_EQ(r.wall_s, 0.25);
  options.duration_s = -1.0;
  EXPECT_THROW(run_bed_model(scene, ergun(), options), Error);
}

/// The section of a model registered from the test: one number, checked by the model.
struct ToySection : SceneSection {
  double speed_m_s = 1.0;
  std::unique_ptr<SceneSection> Clone() const override {
    return std::make_unique<ToySection>(*this);
  }
};

/// A model with its own scene table, [toy]: required by its scenes, refused by the others.
class ToyModel : public EchoModel {
 public:
  std::string key() const override { return "toy_test"; }
  const SceneTable* scene_table() const override {
    static const SceneTable table = [] {
      SceneTable t;
      t.name = "toy";
      t.make = [] { return std::make_unique<ToySection>(); };
      t.keys = {{"speed_m_s", [](SceneSection& s, const SceneValue& v) {
                   static_cast<ToySection&>(s).speed_m_s = v.number();
                 }}};
      t.is_valid = [](const Scene& scene, std::string* error) {
        const SceneSection* s = scene.sections.Find("toy");
        const bool present = s != nullptr && s->present;
        std::string why;
        if (scene.solver == "toy_test" && !present) why = "[toy] table is missing";
        if (scene.solver != "toy_test" && present) why = "[toy] is read only with toy_test";
        if (present && !(static_cast<const ToySection*>(s)->speed_m_s > 0.0))
          why = "[toy] speed_m_s must be > 0";
        if (why.empty()) return true;
        if (error) *error = why;
        return false;
      };
      return t;
    }();
    return &table;
  }
};

TEST(BedModel, AModelRegisteredOutsideTheLibraryBringsItsOwnSceneTable) {
  const std::string toy = scene_text("toy_test") + "\n[toy]\nspeed_m_s = 2.5\n";
  // Before registration neither the solver nor the table is known.
  EXPECT_THROW(parse_scene(toy, "toy"), Error);
  register_bed_model(std::make_unique<ToyModel>());
  const Scene scene = parse_scene(toy, "toy");
  const auto* section = dynamic_cast<const ToySection*>(scene.sections.Find("toy"));
  ASSERT_NE(section, nullptr);
  EXPECT_TRUE(section->present);
  EXPECT_EQ(section->speed_m_s, 2.5);
  // A copy of the scene owns its own section (a study's variant changes only the copy).
  Scene copy = scene;
  static_cast<ToySection&>(copy.sections.Get("toy", nullptr)).speed_m_s = 4.0;
  EXPECT_EQ(static_cast<const ToySection*>(scene.sections.Find("toy"))->speed_m_s, 2.5);
  // The model's keys, type checks and checks, through the scene's messages.
  auto refused = [](const std::string& text, const std::string& expected) {
    try {
      parse_scene(text, "toy");
      ADD_FAILURE() << "expected: " << expected;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused(scene_text("toy_test") + "\n[toy]\nspeed = 2.5\n", "unknown key 'speed' in [toy]");
  refused(scene_text("toy_test") + "\n[toy]\nspeed_m_s = \"fast\"\n", "speed_m_s");
  refused(scene_text("toy_test") + "\n[toy]\nspeed_m_s = -1.0\n", "[toy] speed_m_s must be > 0");
  refused(scene_text("toy_test"), "[toy] table is missing");
  refused(scene_text("dpm") + "\n[toy]\nspeed_m_s = 2.5\n", "[toy] is read only with toy_test");
  // A scene of another model never has it.
  EXPECT_EQ(parse_scene(scene_text("dpm"), "dpm").sections.Find("toy"), nullptr);
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

TEST(BedModel, DpmRunsFromOnePackingAsFromTheirOwnSettling) {
  const Scene scene = parse_scene(scene_text("dpm"), "tiny");
  const BedModel& dpm = find_bed_model("dpm");
  EXPECT_EQ(dpm.realization_kind(), "packing");
  const std::shared_ptr<const BedRealization> packing = dpm.Realize(scene, ergun(), nullptr, {});
  ASSERT_TRUE(packing);
  EXPECT_EQ(packing->seed, scene.seed);
  EXPECT_GT(packing->particles, 0);
  EXPECT_GT(packing->bed_height_m, 0.0);
  const BedResult own = run_bed_model(scene, ergun());
  // Twice from the same packing: the packing is not consumed or changed by a run.
  for (int pass = 0; pass < 2; ++pass) {
    const BedResult reused = run_bed_model(scene, ergun(), BedRunOptions(), nullptr, packing.get());
    ASSERT_EQ(reused.series.size(), own.series.size()) << pass;
    for (std::size_t i = 0; i < own.series.size(); ++i) {
      EXPECT_EQ(reused.series[i].bubble_diameter_m, own.series[i].bubble_diameter_m) << i;
      EXPECT_EQ(reused.series[i].bed_height_m, own.series[i].bed_height_m) << i;
      EXPECT_EQ(reused.series[i].pressure_drop_pa, own.series[i].pressure_drop_pa) << i;
    }
    EXPECT_EQ(reused.inner_steps, own.inner_steps);
    EXPECT_GT(reused.inner_steps, 0);
    EXPECT_EQ(reused.momentum_mismatch, own.momentum_mismatch);
  }
  Scene other = scene;
  other.seed = scene.seed + 1;
  try {
    run_bed_model(other, ergun(), BedRunOptions(), nullptr, packing.get());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("seed"), std::string::npos) << e.what();
  }
}

TEST(BedModel, TimeResolutionHooksSetTheValueThatSetsTheStep) {
  const Scene scene = parse_scene(scene_text("dpm"), "tiny");
  const BedModel& dpm = find_bed_model("dpm");
  EXPECT_EQ(dpm.time_resolution().name, "contact_steps");
  EXPECT_TRUE(dpm.time_resolution().whole_number);
  const Scene finer = dpm.WithTimeResolution(scene, 40);
  EXPECT_EQ(dpm.time_resolution_of(finer), 40.0);
  EXPECT_EQ(dem_section(finer).dem_dt_s, 0.0);  // so that contact_steps alone sets the DEM step
  EXPECT_TRUE(finer.IsValid(nullptr));
  EXPECT_FALSE(dpm.WithTimeResolution(scene, 10).IsValid(nullptr));  // below the DEM limit 20

  const BedModel& tfm = find_bed_model("tfm");
  EXPECT_EQ(tfm.realization_kind(), "");  // deterministic
  EXPECT_THROW(tfm.Realize(scene, ergun(), nullptr, {}), Error);
  EXPECT_EQ(tfm.time_resolution().name, "cfl");
  EXPECT_FALSE(tfm.time_resolution().larger_is_finer);
  EXPECT_EQ(tfm.time_resolution_of(tfm.WithTimeResolution(scene, 0.15)), 0.15);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
