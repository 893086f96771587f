#include "study_state.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "draglab/core/files.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"

namespace draglab {
namespace workflows {
namespace detail {
namespace {

using nlohmann::json;

constexpr const char* kRunFormat = "draglab_study_run";
constexpr int kRunFormatVersion = 1;

/// x with the digits that give it back (a key must not round two values together).
std::string Exact(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", x);
  return buffer;
}

std::string GridText(const consumers::Scene& s) {
  return std::to_string(s.grid.cells_x) + "x" + std::to_string(s.grid.cells_y) + "x" +
         std::to_string(s.grid.cells_z);
}

// Numbers: JSON writes doubles with the digits that round trip; a value that is not finite is
// null and reads back as NaN.
json Number(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }
double Number(const json& j, const char* name) {
  const json& v = j.at(name);
  return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>();
}
json Numbers(const std::vector<double>& values) {
  json out = json::array();
  for (double x : values) out.push_back(Number(x));
  return out;
}
std::vector<double> Numbers(const json& j, const char* name) {
  std::vector<double> out;
  for (const json& v : j.at(name))
    out.push_back(v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>());
  return out;
}

json SampleJson(const consumers::BedSample& s) {
  return {{"t_s", Number(s.t_s)},
          {"bubble_diameter_m", Number(s.bubble_diameter_m)},
          {"bubble_centroid_m", Number(s.bubble_centroid_m)},
          {"bed_height_m", Number(s.bed_height_m)},
          {"pressure_drop_pa", Number(s.pressure_drop_pa)},
          {"segregation_index", Number(s.segregation_index)}};
}
consumers::BedSample SampleFrom(const json& j) {
  consumers::BedSample s;
  s.t_s = Number(j, "t_s");
  s.bubble_diameter_m = Number(j, "bubble_diameter_m");
  s.bubble_centroid_m = Number(j, "bubble_centroid_m");
  s.bed_height_m = Number(j, "bed_height_m");
  s.pressure_drop_pa = Number(j, "pressure_drop_pa");
  s.segregation_index = Number(j, "segregation_index");
  return s;
}

json BubbleJson(const consumers::BubbleMetrics& b) {
  return {{"found", b.found},
          {"cells", b.cells},
          {"area_m2", Number(b.area_m2)},
          {"diameter_m", Number(b.diameter_m)},
          {"centroid_x_m", Number(b.centroid_x_m)},
          {"centroid_y_m", Number(b.centroid_y_m)},
          {"top_m", Number(b.top_m)},
          {"bottom_m", Number(b.bottom_m)},
          {"touches_surface", b.touches_surface},
          {"regions_above_threshold", b.regions_above_threshold},
          {"bed_height_m", Number(b.bed_height_m)},
          {"bed_expansion", Number(b.bed_expansion)}};
}
consumers::BubbleMetrics BubbleFrom(const json& j) {
  consumers::BubbleMetrics b;
  b.found = j.at("found").get<bool>();
  b.cells = j.at("cells").get<int>();
  b.area_m2 = Number(j, "area_m2");
  b.diameter_m = Number(j, "diameter_m");
  b.centroid_x_m = Number(j, "centroid_x_m");
  b.centroid_y_m = Number(j, "centroid_y_m");
  b.top_m = Number(j, "top_m");
  b.bottom_m = Number(j, "bottom_m");
  b.touches_surface = j.at("touches_surface").get<bool>();
  b.regions_above_threshold = j.at("regions_above_threshold").get<int>();
  b.bed_height_m = Number(j, "bed_height_m");
  b.bed_expansion = Number(j, "bed_expansion");
  return b;
}

json SnapshotJson(const consumers::BedSnapshot& s) {
  const consumers::GridField2D& f = s.void_fraction;
  return {{"t_s", Number(s.t_s)},
          {"x", Numbers(s.x)},
          {"y", Numbers(s.y)},
          {"z", Numbers(s.z)},
          {"diameter", Numbers(s.diameter)},
          {"layer", s.layer},
          {"layers", s.layers},
          {"void_fraction",
           {{"nx", f.nx},
            {"ny", f.ny},
            {"width_m", Number(f.width_m)},
            {"height_m", Number(f.height_m)},
            {"values", Numbers(f.values)}}},
          {"bubble", BubbleJson(s.bubble)}};
}
consumers::BedSnapshot SnapshotFrom(const json& j) {
  consumers::BedSnapshot s;
  s.t_s = Number(j, "t_s");
  s.x = Numbers(j, "x");
  s.y = Numbers(j, "y");
  s.z = Numbers(j, "z");
  s.diameter = Numbers(j, "diameter");
  s.layer = j.at("layer").get<std::vector<int>>();
  s.layers = j.at("layers").get<int>();
  const json& f = j.at("void_fraction");
  s.void_fraction.nx = f.at("nx").get<int>();
  s.void_fraction.ny = f.at("ny").get<int>();
  s.void_fraction.width_m = Number(f, "width_m");
  s.void_fraction.height_m = Number(f, "height_m");
  s.void_fraction.values = Numbers(f, "values");
  s.bubble = BubbleFrom(j.at("bubble"));
  return s;
}

json RunJson(const SensitivityRun& r) {
  json series = json::array();
  for (const consumers::BedSample& s : r.series) series.push_back(SampleJson(s));
  json headline = json::array();
  for (const auto& [name, value] : r.headline) headline.push_back({name, Number(value)});
  return {{"seed", r.seed},
          {"cells_x", r.cells_x},
          {"cells_y", r.cells_y},
          {"cells_z", r.cells_z},
          {"cell_size_m", Number(r.cell_size_m)},
          {"bubble_diameter_m", Number(r.bubble_diameter_m)},
          {"bubble_found", r.bubble_found},
          {"reached_t_ref", r.reached_t_ref},
          {"background_m_s", Number(r.background_m_s)},
          {"wall_s", Number(r.wall_s)},
          {"gas_steps", r.gas_steps},
          {"dem_steps", r.dem_steps},
          {"gas_dt_s", Number(r.gas_dt_s)},
          {"dem_dt_s", Number(r.dem_dt_s)},
          {"momentum_mismatch", Number(r.momentum_mismatch)},
          {"max_relative_mass_imbalance", Number(r.max_relative_mass_imbalance)},
          {"void_fraction_clamps", r.void_fraction_clamps},
          {"drag_out_of_range", r.drag_out_of_range},
          {"series", series},
          {"headline", headline}};
}
SensitivityRun RunFrom(const json& j) {
  SensitivityRun r;
  r.seed = j.at("seed").get<std::uint64_t>();
  r.cells_x = j.at("cells_x").get<int>();
  r.cells_y = j.at("cells_y").get<int>();
  r.cells_z = j.at("cells_z").get<int>();
  r.cell_size_m = Number(j, "cell_size_m");
  r.bubble_diameter_m = Number(j, "bubble_diameter_m");
  r.bubble_found = j.at("bubble_found").get<bool>();
  r.reached_t_ref = j.at("reached_t_ref").get<bool>();
  r.background_m_s = Number(j, "background_m_s");
  r.wall_s = Number(j, "wall_s");
  r.gas_steps = j.at("gas_steps").get<long>();
  r.dem_steps = j.at("dem_steps").get<std::int64_t>();
  r.gas_dt_s = Number(j, "gas_dt_s");
  r.dem_dt_s = Number(j, "dem_dt_s");
  r.momentum_mismatch = Number(j, "momentum_mismatch");
  r.max_relative_mass_imbalance = Number(j, "max_relative_mass_imbalance");
  r.void_fraction_clamps = j.at("void_fraction_clamps").get<std::int64_t>();
  r.drag_out_of_range = j.at("drag_out_of_range").get<std::uint64_t>();
  for (const json& s : j.at("series")) r.series.push_back(SampleFrom(s));
  for (const json& h : j.at("headline")) {
    r.headline.emplace_back(
        h.at(0).get<std::string>(),
        h.at(1).is_null() ? std::numeric_limits<double>::quiet_NaN() : h.at(1).get<double>());
  }
  return r;
}

json PackingJson(const SensitivityPacking& p) {
  return {{"seed", p.seed},
          {"particles", p.particles},
          {"settled_bed_height_m", Number(p.settled_bed_height_m)},
          {"settle_wall_s", Number(p.settle_wall_s)}};
}
SensitivityPacking PackingFrom(const json& j) {
  SensitivityPacking p;
  p.seed = j.at("seed").get<std::uint64_t>();
  p.particles = j.at("particles").get<std::int64_t>();
  p.settled_bed_height_m = Number(j, "settled_bed_height_m");
  p.settle_wall_s = Number(j, "settle_wall_s");
  return p;
}

}  // namespace

std::string run_key(const consumers::BedModel& model, const consumers::Scene& scene,
                    const std::string& law, const consumers::BedRunOptions& run) {
  return std::string(kRunFormat) + " " + std::to_string(kRunFormatVersion) + "\nmodel " +
         model.key() + "\nscene " + scene.hash() + "\nseed " + std::to_string(scene.seed) +
         "\ngrid " + GridText(scene) + "\nlaw " + law + "\ntime_resolution " +
         Exact(model.time_resolution_of(scene)) + "\nduration_s " + Exact(run.duration_s) +
         "\nt_ref_s " + Exact(scene.time.t_ref_s) + "\n";
}

std::string realization_key(const consumers::BedModel& model, const consumers::Scene& scene,
                            const std::string& law) {
  return "draglab_study_realization 1\nmodel " + model.key() + "\nscene " + scene.hash() +
         "\nseed " + std::to_string(scene.seed) + "\nlaw " + law + "\n";
}

StudyState::StudyState(std::string directory) : directory_(std::move(directory)) {}

std::string StudyState::Path(const std::string& label, const std::string& key,
                             const std::string& extension) const {
  std::string name = label;
  for (char& c : name)
    if (c == '@' || c == '/' || c == ' ') c = '_';
  return directory_ + "/" + name + "_" + sha256_hex(key).substr(0, 16) + extension;
}

bool StudyState::LoadRun(const std::string& label, const std::string& key, StoredRun* out) const {
  if (!enabled()) return false;
  std::ifstream in(Path(label, key, ".json"));
  if (!in) return false;
  try {
    const json j = json::parse(in);
    if (j.at("format") != kRunFormat || j.at("version") != kRunFormatVersion || j.at("key") != key)
      return false;
    StoredRun stored;
    stored.run = RunFrom(j.at("run"));
    stored.packing = PackingFrom(j.at("packing"));
    stored.umf_m_s = Number(j, "umf_m_s");
    stored.background_m_s = Number(j, "background_m_s");
    stored.background_mode = j.at("background_mode").get<std::string>();
    stored.has_snapshot = j.at("has_snapshot").get<bool>();
    if (stored.has_snapshot) stored.snapshot = SnapshotFrom(j.at("snapshot"));
    stored.run.reused = true;
    *out = std::move(stored);
    return true;
  } catch (const json::exception&) {
    return false;  // not a run file of this version: the run is done again
  }
}

void StudyState::SaveRun(const std::string& label, const std::string& key,
                         const StoredRun& stored) const {
  if (!enabled()) return;
  core::make_directories(directory_, "the study's state folder");
  json j = {{"format", kRunFormat},
            {"version", kRunFormatVersion},
            {"key", key},
            {"run", RunJson(stored.run)},
            {"packing", PackingJson(stored.packing)},
            {"umf_m_s", Number(stored.umf_m_s)},
            {"background_m_s", Number(stored.background_m_s)},
            {"background_mode", stored.background_mode},
            {"has_snapshot", stored.has_snapshot}};
  if (stored.has_snapshot) j["snapshot"] = SnapshotJson(stored.snapshot);
  core::write_file_atomically(Path(label, key, ".json"), j.dump(), "the study's state folder");
}

std::shared_ptr<const consumers::BedRealization> StudyState::LoadRealization(
    const consumers::BedModel& model, const std::string& label, const std::string& key) const {
  if (!enabled()) return nullptr;
  const std::string path = Path(label, key, ".bin");
  return core::file_exists(path) ? model.LoadRealization(path) : nullptr;
}

void StudyState::SaveRealization(const consumers::BedModel& model, const std::string& label,
                                 const std::string& key,
                                 const consumers::BedRealization& realization) const {
  if (!enabled()) return;
  core::make_directories(directory_, "the study's state folder");
  model.SaveRealization(realization, Path(label, key, ".bin"));
}

std::string StudyState::RealizationCheckpoint(const std::string& label,
                                              const std::string& key) const {
  if (!enabled()) return "";
  core::make_directories(directory_, "the study's state folder");
  return Path(label, key, ".checkpoint");
}

}  // namespace detail
}  // namespace workflows
}  // namespace draglab
