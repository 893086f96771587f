// Scene files: TOML parsing (toml++), validation and the quantities a scene implies
// (docs/scenes.md).
#include "draglab/consumers/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/core/toml_schema.h"

#include "draglab/consumers/bed_model.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fail;
using scene_util::fmt;
using scene_util::kPi;

[[noreturn]] void bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

using scene_util::in_range;

/// One key of a section and how to store it into the Scene.
struct Key {
  std::string name;
  std::function<void(Scene&, const toml::node&, const std::string& field, const std::string& at)>
      read;
};

double as_number(const toml::node& n, const std::string& field, const std::string& at) {
  return core::toml_schema::number(n, field, at);
}
std::int64_t as_integer(const toml::node& n, const std::string& field, const std::string& at) {
  return core::toml_schema::integer(n, field, at);
}
std::string as_text(const toml::node& n, const std::string& field, const std::string& at) {
  return core::toml_schema::text(n, field, at);
}
bool as_bool(const toml::node& n, const std::string& field, const std::string& at) {
  return core::toml_schema::boolean(n, field, at);
}

template <typename Member>
Key num(const std::string& name, Member member) {
  return {name, [member](Scene& s, const toml::node& n, const std::string& f,
                         const std::string& at) { member(s) = as_number(n, f, at); }};
}

/// A number whose absence selects a default (held as -1 in the Scene): a value written in the
/// file must be >= 0, so that the default is never taken from a typo.
template <typename Member>
Key num_or_default(const std::string& name, Member member) {
  return {name,
          [member](Scene& s, const toml::node& n, const std::string& f, const std::string& at) {
            const double v = as_number(n, f, at);
            if (!(v >= 0.0)) {
              bad(at + ": " + f + " = " + core::format_number(v) + " must be >= 0 (leave " + f +
                  " out for its default)");
            }
            member(s) = v;
          }};
}

// The sections and keys a scene file accepts, in documentation order.
const std::vector<std::pair<std::string, std::vector<Key>>>& sections() {
  using S = Scene;
  static const std::vector<std::pair<std::string, std::vector<Key>>>
      table =
          {
              {"scene",
               {{"name", [](S& s, const toml::node& n, const std::string& f,
                            const std::string& at) { s.name = as_text(n, f, at); }},
                {"description", [](S& s, const toml::node& n, const std::string& f,
                                   const std::string& at) { s.description = as_text(n, f, at); }},
                {"solver", [](S& s, const toml::node& n, const std::string& f,
                              const std::string& at) { s.solver = as_text(n, f, at); }},
                {"seed",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   const std::int64_t v = as_integer(n, f, at);
                   if (v < 0)
                     bad(at + ": " + f + " = " + std::to_string(v) + " is outside [0, 2^63 - 1]");
                   s.seed = static_cast<std::uint64_t>(v);
                 }}}},
              {"geometry",
               {num("width_m", [](S& s) -> double& { return s.geometry.width_m; }),
                num("height_m", [](S& s) -> double& { return s.geometry.height_m; }),
                num("depth_m", [](S& s) -> double& { return s.geometry.depth_m; })}},
              {"particles",
               {num("diameter_m", [](S& s) -> double& { return s.particles.diameter_m; }),
                num("density_kg_m3", [](S& s) -> double& { return s.particles.density_kg_m3; }),
                num("restitution", [](S& s) -> double& { return s.particles.restitution; }),
                {"count",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.particles.count = as_integer(n, f, at);
                   if (s.particles.count <= 0) {
                     bad(at + ": " + f + " = " + std::to_string(s.particles.count) +
                         " is outside [1, 10000000]");
                   }
                 }},
                num("bed_height_mf_m", [](S& s) -> double& { return s.particles.bed_height_mf_m; }),
                {"diameters_m",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.particles.diameters_m = SceneValue(&n, f, at).numbers("diameters in m");
                 }},
                {"volume_fractions",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.particles.volume_fractions =
                       SceneValue(&n, f, at).numbers("volume shares in (0, 1]");
                 }}}},
              {"gas",
               {num("density_kg_m3", [](S& s) -> double& { return s.gas.density_kg_m3; }),
                num("viscosity_pa_s", [](S& s) -> double& { return s.gas.viscosity_pa_s; }),
                num("gravity_m_s2", [](S& s) -> double& { return s.gas.gravity_m_s2; })}},
              {"distributor",
               {{"background",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   const std::string v = as_text(n, f, at);
                   if (v == "umf") {
                     s.distributor.mode = BackgroundMode::kUmf;
                   } else if (v == "fixed") {
                     s.distributor.mode = BackgroundMode::kFixed;
                   } else if (v == "umf_packing") {
                     s.distributor.mode = BackgroundMode::kUmfPacking;
                   } else {
                     bad(at + ": " + f + " = '" + v + "' is not one of umf, umf_packing, fixed");
                   }
                 }},
                num("umf_factor", [](S& s) -> double& { return s.distributor.umf_factor; }),
                num("velocity_m_s", [](S& s) -> double& { return s.distributor.velocity_m_s; })}},
              {"jet",
               {num("slot_width_m", [](S& s) -> double& { return s.jet.slot_width_m; }),
                num("velocity_m_s", [](S& s) -> double& { return s.jet.velocity_m_s; }),
                num_or_default("center_m", [](S& s) -> double& { return s.jet.center_m; }),
                num("start_s", [](S& s) -> double& { return s.jet.start_s; }),
                num("duration_s", [](S& s) -> double& { return s.jet.duration_s; }),
                num("ramp_s", [](S& s) -> double& { return s.jet.ramp_s; })}},
              {"time",
               {num("duration_s", [](S& s) -> double& { return s.time.duration_s; }),
                num("t_ref_s", [](S& s) -> double& { return s.time.t_ref_s; }),
                num("gas_dt_s", [](S& s) -> double& { return s.time.gas_dt_s; })}},
              {"grid",
               {{"cells_x",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   const std::int64_t v = as_integer(n, f, at);
                   if (v < 2 || v > 100000)
                     bad(at + ": " + f + " = " + std::to_string(v) +
                         " is outside [2, 100000] (the gas solver needs two cells across)");
                   s.grid.cells_x = static_cast<int>(v);
                 }},
                {"cells_y",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   const std::int64_t v = as_integer(n, f, at);
                   if (v < 2 || v > 100000)
                     bad(at + ": " + f + " = " + std::to_string(v) +
                         " is outside [2, 100000] (the gas solver needs two cells across)");
                   s.grid.cells_y = static_cast<int>(v);
                 }},
                {"cells_z",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   const std::int64_t v = as_integer(n, f, at);
                   if (v < 1 || v > 100000)
                     bad(at + ": " + f + " = " + std::to_string(v) + " is outside [1, 100000]");
                   s.grid.cells_z = static_cast<int>(v);
                 }}}},
              {"bubble",
               {num("eps_threshold", [](S& s) -> double& { return s.bubble.eps_threshold; }),
                num("sample_interval_s",
                    [](S& s) -> double& { return s.bubble.sample_interval_s; })}},
              {"outputs",
               {{"directory",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.outputs.directory = as_text(n, f, at);
                 }},
                {"fields", [](S& s, const toml::node& n, const std::string& f,
                              const std::string& at) { s.outputs.fields = as_bool(n, f, at); }},
                {"particles",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.outputs.particles = as_bool(n, f, at);
                 }},
                num("interval_s", [](S& s) -> double& { return s.outputs.interval_s; })}},
              {"drag",
               {{"laws",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.laws.clear();
                   if (const toml::array* a = n.as_array()) {
                     for (std::size_t i = 0; i < a->size(); ++i) {
                       s.laws.push_back(as_text(*a->get(i), f + "[" + std::to_string(i) + "]", at));
                     }
                   } else {
                     s.laws.push_back(as_text(n, f, at));
                   }
                 }},
                num("eps_mf", [](S& s) -> double& { return s.eps_mf; }),
                {"range_policy",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.range_policy = as_text(n, f, at);
                 }}}},
          };
  return table;
}

/// A key of a model's table, read into the model's section.
Key model_key(const SceneTable* table, const SceneKey& key) {
  return {key.first, [table, read = key.second](Scene& s, const toml::node& n, const std::string& f,
                                                const std::string& at) {
            read(s.sections.Get(table->name, table->make), SceneValue(&n, f, at));
          }};
}

/// The sections of a scene file: the shared ones, then each registered model's own table
/// (BedModel::scene_table) before [drag]; a model's keys in their older places
/// (SceneTable::older_places) join those shared tables.
std::vector<std::pair<std::string, std::vector<Key>>> all_sections() {
  std::vector<std::pair<std::string, std::vector<Key>>> out = sections();
  std::vector<std::pair<std::string, std::vector<Key>>> tables;
  for (const std::string& model : bed_model_keys()) {
    const SceneTable* table = find_bed_model(model).scene_table();
    if (table == nullptr) continue;
    std::vector<Key> keys;
    for (const SceneKey& key : table->keys) keys.push_back(model_key(table, key));
    for (const auto& [name, older] : table->older_places) {
      const auto key = std::find_if(table->keys.begin(), table->keys.end(),
                                    [&name = name](const SceneKey& k) { return k.first == name; });
      const auto shared = std::find_if(
          out.begin(), out.end(), [&older = older](const auto& s) { return s.first == older; });
      if (key == table->keys.end() || shared == out.end()) {
        throw Error(ErrorCode::kInternal, "scene table [" + table->name + "]: " + name +
                                              " has no key or older table [" + older + "]");
      }
      shared->second.push_back(model_key(table, *key));
    }
    tables.push_back({table->name, std::move(keys)});
  }
  const auto drag =
      std::find_if(out.begin(), out.end(), [](const auto& s) { return s.first == "drag"; });
  out.insert(drag, tables.begin(), tables.end());
  return out;
}

/// A model's table that gives a key the file also gives in its older place: refused.
void refuse_keys_in_two_places(const SceneTable& table, const toml::table& given,
                               const toml::table& root, const std::string& at) {
  for (const auto& [name, older] : table.older_places) {
    const toml::table* old = root[older].as_table();
    if (given.contains(name) && old != nullptr && old->contains(name)) {
      bad(at + ": " + name + " is given in [" + table.name + "] and in [" + older +
          "]: keep it in [" + table.name + "] only");
    }
  }
}

/// The model tables' checks, for every scene.
bool model_tables_are_valid(const Scene& s, std::string* error) {
  for (const std::string& model : bed_model_keys()) {
    const SceneTable* table = find_bed_model(model).scene_table();
    if (table != nullptr && table->is_valid && !table->is_valid(s, error)) return false;
  }
  return true;
}

}  // namespace

SceneSections::SceneSections(const SceneSections& other) {
  for (const auto& [name, section] : other.sections_) sections_[name] = section->Clone();
}

SceneSections& SceneSections::operator=(const SceneSections& other) {
  if (this != &other) {
    SceneSections copy(other);
    sections_.swap(copy.sections_);
  }
  return *this;
}

SceneSection& SceneSections::Get(const std::string& table,
                                 const std::function<std::unique_ptr<SceneSection>()>& make) {
  std::unique_ptr<SceneSection>& s = sections_[table];
  if (!s) s = make();
  return *s;
}

const SceneSection* SceneSections::Find(const std::string& table) const {
  const auto it = sections_.find(table);
  return it == sections_.end() ? nullptr : it->second.get();
}

namespace {
const toml::node& node_of(const void* node) { return *static_cast<const toml::node*>(node); }
}  // namespace

double SceneValue::number() const { return as_number(node_of(node_), field_, at_); }

double SceneValue::number_or_default() const {
  const double v = number();
  if (!(v >= 0.0)) {
    bad(at_ + ": " + field_ + " = " + core::format_number(v) + " must be >= 0 (leave " + field_ +
        " out for its default)");
  }
  return v;
}

std::int64_t SceneValue::integer() const { return as_integer(node_of(node_), field_, at_); }

int SceneValue::integer_in(int lo, int hi, const std::string& what) const {
  const std::int64_t v = integer();
  if (v < lo || v > hi) {
    bad(at_ + ": " + field_ + " = " + std::to_string(v) + " is outside [" + std::to_string(lo) +
        ", " + std::to_string(hi) + "]" + (what.empty() ? "" : " (" + what + ")"));
  }
  return static_cast<int>(v);
}
std::string SceneValue::text() const { return as_text(node_of(node_), field_, at_); }
bool SceneValue::boolean() const { return as_bool(node_of(node_), field_, at_); }

std::vector<double> SceneValue::numbers(const std::string& what) const {
  const toml::array* a = node_of(node_).as_array();
  if (!a) bad(at_ + ": " + field_ + " must be an array of " + what);
  std::vector<double> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    out.push_back(as_number(*a->get(i), field_ + "[" + std::to_string(i) + "]", at_));
  }
  return out;
}

const char* to_string(BackgroundMode mode) {
  switch (mode) {
    case BackgroundMode::kUmf:
      return "umf";
    case BackgroundMode::kUmfPacking:
      return "umf_packing";
    case BackgroundMode::kFixed:
      break;
  }
  return "fixed";
}

namespace {

/// Size classes: checked as written, then diameter_m becomes their Sauter mean.
void set_size_classes(Scene& s, const std::string& origin) {
  SceneParticles& p = s.particles;
  if (p.diameters_m.empty() && p.volume_fractions.empty()) return;
  if (p.diameter_m != 0.0) {
    bad(origin +
        ": [particles] give diameter_m (one size) or diameters_m with volume_fractions "
        "(size classes), not both");
  }
  if (p.diameters_m.size() != p.volume_fractions.size()) {
    bad(origin + ": [particles] diameters_m has " + std::to_string(p.diameters_m.size()) +
        " values and volume_fractions " + std::to_string(p.volume_fractions.size()) +
        ": give one volume share per size class");
  }
  if (p.diameters_m.size() < 2 || p.diameters_m.size() > 8) {
    bad(origin + ": [particles] diameters_m has " + std::to_string(p.diameters_m.size()) +
        " size classes, outside [2, 8] (one size: diameter_m)");
  }
  double sum = 0.0, inverse = 0.0;
  for (std::size_t i = 0; i < p.diameters_m.size(); ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (!(p.diameters_m[i] >= 1e-6 && p.diameters_m[i] <= 0.1)) {
      bad(origin + ": [particles] diameters_m" + at + " = " + fmt(p.diameters_m[i]) +
          " m is outside [1e-06, 0.1] m");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (p.diameters_m[j] == p.diameters_m[i]) {
        bad(origin + ": [particles] diameters_m lists " + fmt(p.diameters_m[i]) +
            " m twice (each size class once)");
      }
    }
    if (!(p.volume_fractions[i] > 0.0 && p.volume_fractions[i] <= 1.0)) {
      bad(origin + ": [particles] volume_fractions" + at + " = " + fmt(p.volume_fractions[i]) +
          " is outside (0, 1]");
    }
    sum += p.volume_fractions[i];
    inverse += p.volume_fractions[i] / p.diameters_m[i];
  }
  if (std::fabs(sum - 1.0) > 1e-6) {
    bad(origin + ": [particles] volume_fractions sum to " + fmt(sum) +
        ", not 1 (each is a size class's share of the solids volume)");
  }
  p.diameter_m = 1.0 / inverse;
}

}  // namespace

Scene parse_scene(const std::string& toml_text, const std::string& origin) {
  namespace ts = core::toml_schema;
  const toml::table root = ts::parse(toml_text, origin);
  // Built per file: a model registered at run time brings its table.
  const std::vector<std::pair<std::string, std::vector<Key>>> tables = all_sections();
  ts::Schema names;
  for (const auto& [section, keys] : tables) {
    names.push_back({section, {}});
    std::vector<std::string>& listed = names.back().second;
    for (const Key& k : keys) {
      if (std::find(listed.begin(), listed.end(), k.name) == listed.end()) listed.push_back(k.name);
    }
  }
  Scene s;
  s.origin = origin;
  s.source_text = toml_text;
  const auto on_section = [&](const std::string& section, const toml::table& table,
                              const std::string& at) {
    for (const std::string& model : bed_model_keys()) {
      const SceneTable* own = find_bed_model(model).scene_table();
      if (own == nullptr || own->name != section) continue;
      s.sections.Get(own->name, own->make).present = true;
      refuse_keys_in_two_places(*own, table, root, at);
    }
    s.tables.push_back(section);
  };
  ts::visit(root, origin, names, on_section, [&](const ts::Entry& e) {
    for (const auto& [section, keys] : tables) {
      if (section != e.section) continue;
      for (const Key& k : keys) {
        if (k.name == e.key) k.read(s, e.node, e.field, e.at);
      }
    }
  });
  // Tables every model needs: named as missing, not through a default value the user never
  // wrote ("width_m = 0").
  for (const char* required : {"geometry", "particles"}) {
    if (std::find(s.tables.begin(), s.tables.end(), required) == s.tables.end()) {
      bad(origin + ": the [" + required + "] table is missing (docs/scenes.md lists its keys)");
    }
  }
  set_size_classes(s, origin);
  std::string error;
  if (!s.IsValid(&error)) bad(origin + ": " + error);
  return s;
}

Scene load_scene(const std::string& path) {
  return parse_scene(core::read_text_input(path, "scene file"), path);
}

namespace {

/// The scene's name and solver.
bool name_and_solver_are_valid(const Scene& s, std::string* error) {
  if (s.name.empty()) return fail(error, "[scene] name is missing or empty");
  for (char c : s.name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) {
      return fail(error, "[scene] name '" + s.name +
                             "' may contain only letters, digits, '_', '-' and '.'");
    }
  }
  {
    const std::vector<std::string> models = bed_model_keys();
    if (std::find(models.begin(), models.end(), s.solver) == models.end()) {
      std::string known;
      for (const std::string& k : models) known += (known.empty() ? "" : ", ") + k;
      return fail(error, "[scene] solver = '" + s.solver + "' is not a registered bed model (" +
                             known + ")");
    }
  }
  return true;
}

/// Geometry, particles and gas: the materials of every model.
bool materials_are_valid(const Scene& s, std::string* error) {
  // Geometry: a laboratory pseudo-2D bed, millimetres to metres.
  if (!in_range(s.geometry.width_m, 0.0, 10.0, true, false, "[geometry] width_m", "m", error) ||
      !in_range(s.geometry.height_m, 0.0, 10.0, true, false, "[geometry] height_m", "m", error) ||
      !in_range(s.geometry.depth_m, 0.0, 10.0, true, false, "[geometry] depth_m", "m", error)) {
    return false;
  }
  const double d = s.particles.diameter_m;
  // From fine powders (Geldart C, tens of microns) to coarse beads; below a micron the drag laws'
  // minimum fluidization has no root the solvers can find.
  if (!in_range(d, 1e-6, 0.1, false, false, "[particles] diameter_m", "m", error)) return false;
  if (s.polydisperse() && !find_bed_model(s.solver).polydisperse()) {
    return fail(error, "[particles] diameters_m: the " + s.solver +
                           " model runs one particle size (give diameter_m, e.g. the Sauter mean " +
                           fmt(d) + " m); size classes run with solver = \"dpm\"");
  }
  const double largest = s.polydisperse() ? *std::max_element(s.particles.diameters_m.begin(),
                                                              s.particles.diameters_m.end())
                                          : d;
  if (!in_range(s.particles.density_kg_m3, 0.0, 30000.0, true, false, "[particles] density_kg_m3",
                "kg/m^3", error) ||
      !in_range(s.particles.restitution, 0.0, 1.0, true, false, "[particles] restitution", "",
                error)) {
    return false;
  }
  const double min_box = std::min({s.geometry.width_m, s.geometry.height_m, s.geometry.depth_m});
  if (largest > min_box) {
    return fail(error, std::string(s.polydisperse() ? "[particles] the largest of diameters_m, "
                                                    : "[particles] diameter_m = ") +
                           fmt(largest) +
                           " does not fit the box: it must be <= the smallest box size " +
                           fmt(min_box) + " m");
  }
  if (!in_range(s.gas.density_kg_m3, 0.0, 1000.0, true, false, "[gas] density_kg_m3", "kg/m^3",
                error) ||
      !in_range(s.gas.viscosity_pa_s, 0.0, 1.0, true, false, "[gas] viscosity_pa_s", "Pa s",
                error) ||
      !in_range(s.gas.gravity_m_s2, 0.0, 100.0, true, false, "[gas] gravity_m_s2", "m/s^2",
                error)) {
    return false;
  }
  if (!(s.particles.density_kg_m3 > s.gas.density_kg_m3)) {
    return fail(error, "[particles] density_kg_m3 = " + fmt(s.particles.density_kg_m3) +
                           " must exceed [gas] density_kg_m3 = " + fmt(s.gas.density_kg_m3) +
                           " (the bed would not settle)");
  }
  if (!in_range(s.eps_mf, 0.26, 0.9, false, true, "[drag] eps_mf", "(random packings: 0.36-0.5)",
                error)) {
    return false;
  }
  return true;
}

/// A particle bed's inventory: a count or a settled height that fits the box.
bool particle_inventory_is_valid(const Scene& s, std::string* error) {
  const double d = s.particles.diameter_m;
  const bool has_count = s.particles.count > 0;
  const bool has_height = s.particles.bed_height_mf_m != 0.0;
  if (has_count == has_height) {
    // A 0 typed in the file reads as "not given": say so with the ranges.
    return fail(
        error,
        "[particles] give exactly one of count, in [1, 10000000], and bed_height_mf_m, "
        "in (0, " +
            fmt(s.geometry.height_m) + "] m (the box height)" +
            (has_count ? std::string(": both are given")
                       : std::string(": neither has a usable value (count = " +
                                     std::to_string(s.particles.count) + ", bed_height_mf_m = " +
                                     fmt(s.particles.bed_height_mf_m) + ")")));
  }
  if (has_height && !in_range(s.particles.bed_height_mf_m, 0.0, s.geometry.height_m, true, false,
                              "[particles] bed_height_mf_m", "m (the box height)", error)) {
    return false;
  }
  if (has_count && s.particles.count > 10000000) {
    return fail(error, "[particles] count = " + std::to_string(s.particles.count) +
                           " is outside [1, 10000000]");
  }
  const double h_mf = s.bed_height_mf_m();
  if (h_mf > s.geometry.height_m) {
    return fail(error, "[particles] count = " + std::to_string(s.particles.count) +
                           " makes a bed " + fmt(h_mf) + " m high at eps_mf = " + fmt(s.eps_mf) +
                           ": it does not fit the box ([geometry] height_m = " +
                           fmt(s.geometry.height_m) + " m)");
  }
  if (h_mf < d) {
    return fail(error, "[particles] the bed at eps_mf is " + fmt(h_mf) +
                           " m high, less than one particle diameter (give more particles)");
  }
  return true;
}

/// A particle bed's gas inflow: the distributor's background and the jet.
bool inflow_is_valid(const Scene& s, std::string* error) {
  if (s.distributor.mode != BackgroundMode::kFixed) {
    if (!in_range(s.distributor.umf_factor, 0.0, 10.0, false, false, "[distributor] umf_factor", "",
                  error)) {
      return false;
    }
  } else if (!in_range(s.distributor.velocity_m_s, 0.0, 100.0, true, false,
                       "[distributor] velocity_m_s", "m/s (background = \"fixed\")", error)) {
    return false;
  }
  // Jet.
  if (!in_range(s.jet.slot_width_m, 0.0, s.geometry.width_m, true, false, "[jet] slot_width_m",
                "m (0 < slot <= the bed width)", error) ||
      !in_range(s.jet.velocity_m_s, 0.0, 300.0, false, false, "[jet] velocity_m_s",
                "m/s (incompressible gas: Mach < 0.9)", error) ||
      !in_range(s.jet.start_s, 0.0, 1e4, false, false, "[jet] start_s", "s", error) ||
      !in_range(s.jet.duration_s, 0.0, 1e4, false, false, "[jet] duration_s", "s", error) ||
      !in_range(s.jet.ramp_s, 0.0, 1.0, false, false, "[jet] ramp_s", "s", error)) {
    return false;
  }
  if (s.jet.center_m != -1.0) {  // -1: the default, the bed's centre line
    const double half = 0.5 * s.jet.slot_width_m;
    if (!in_range(s.jet.center_m, half, s.geometry.width_m - half, false, false, "[jet] center_m",
                  "m (the slot must lie inside the bottom)", error)) {
      return false;
    }
  }
  return true;
}

/// A particle bed's times and steps.
bool times_are_valid(const Scene& s, std::string* error) {
  if (!in_range(s.time.duration_s, 0.0, 1e4, true, false, "[time] duration_s", "s", error) ||
      !in_range(s.time.t_ref_s, 0.0, 1e4, false, false, "[time] t_ref_s", "s", error) ||
      !in_range(s.time.gas_dt_s, 0.0, 1.0, false, false, "[time] gas_dt_s", "s (0 = auto)",
                error)) {
    return false;
  }
  if (s.jet.start_s + s.time.t_ref_s > s.time.duration_s * (1.0 + 1e-12)) {
    return fail(error, "[time] t_ref_s = " + fmt(s.time.t_ref_s) + " after the jet start " +
                           fmt(s.jet.start_s) + " s is beyond [time] duration_s = " +
                           fmt(s.time.duration_s) + " s (t_ref_s <= duration_s - jet.start_s)");
  }
  // A positive step so small that the run could never finish is a typo, not a choice.
  constexpr double kMaxSteps = 1e9;
  if (s.time.gas_dt_s > 0.0 && s.time.duration_s / s.time.gas_dt_s > kMaxSteps) {
    return fail(error, "[time] gas_dt_s = " + fmt(s.time.gas_dt_s) + " s would take " +
                           fmt(s.time.duration_s / s.time.gas_dt_s) +
                           " gas steps for duration_s (more than 1e9): use 0 = auto, or a step "
                           ">= duration_s / 1e9 = " +
                           fmt(s.time.duration_s / kMaxSteps) + " s");
  }
  return true;
}

/// The grid, the bubble criterion, the outputs and the drag laws.
bool grid_outputs_and_laws_are_valid(const Scene& s, std::string* error) {
  // Grid: the void fraction needs cells at least one particle wide.
  const double d = s.particles.diameter_m;
  if (s.grid.cells_x < 2 || s.grid.cells_y < 2) {
    return fail(error, "[grid] cells_x and cells_y must be >= 2 (got " +
                           std::to_string(s.grid.cells_x) + ", " + std::to_string(s.grid.cells_y) +
                           ")");
  }
  const double dx = s.geometry.width_m / s.grid.cells_x, dy = s.geometry.height_m / s.grid.cells_y;
  if (dx < d || dy < d) {
    return fail(error, "[grid] cells of " + fmt(dx) + " x " + fmt(dy) +
                           " m are smaller than a particle (" + fmt(d) +
                           " m): use at most width/d = " +
                           std::to_string(static_cast<int>(s.geometry.width_m / d)) +
                           " cells_x and height/d = " +
                           std::to_string(static_cast<int>(s.geometry.height_m / d)) + " cells_y");
  }
  // The bubble criterion is a void fraction of a particle bed (a model whose bed fills the
  // column, the DBM, tracks its bubbles itself).
  const bool bubble_criterion = find_bed_model(s.solver).particle_bed();
  if ((bubble_criterion && !in_range(s.bubble.eps_threshold, s.eps_mf, 1.0, true, true,
                                     "[bubble] eps_threshold", "(eps_mf, 1)", error)) ||
      (bubble_criterion &&
       !in_range(s.bubble.sample_interval_s, 0.0, s.time.duration_s, true, false,
                 "[bubble] sample_interval_s", "s (0, duration_s]", error)) ||
      !in_range(s.outputs.interval_s, 0.0, s.time.duration_s, false, false, "[outputs] interval_s",
                "s [0, duration_s]", error)) {
    return false;
  }
  if (s.laws.empty()) return fail(error, "[drag] laws is missing or empty (e.g. [\"ergun@1\"])");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < s.laws.size(); ++i) {
    if (s.laws[i].empty() || s.laws[i].find_first_of(" \t,") != std::string::npos) {
      return fail(error, "[drag] laws[" + std::to_string(i) + "] = '" + s.laws[i] +
                             "' is not a law reference (name@version, e.g. ergun@1)");
    }
    if (!seen.insert(s.laws[i]).second) {
      return fail(error, "[drag] laws lists '" + s.laws[i] + "' twice");
    }
  }
  if (s.range_policy != "clamp" && s.range_policy != "extrapolate" && s.range_policy != "error") {
    return fail(error, "[drag] range_policy = '" + s.range_policy +
                           "' is not one of clamp, extrapolate, error");
  }
  return true;
}

}  // namespace

bool Scene::IsValid(std::string* error) const {
  if (!name_and_solver_are_valid(*this, error) || !materials_are_valid(*this, error) ||
      !model_tables_are_valid(*this, error)) {
    return false;
  }
  if (find_bed_model(solver).particle_bed() &&
      (!particle_inventory_is_valid(*this, error) || !inflow_is_valid(*this, error) ||
       !times_are_valid(*this, error))) {
    return false;
  }
  return grid_outputs_and_laws_are_valid(*this, error);
}

void Scene::Validate() const {
  std::string error;
  if (!IsValid(&error)) bad((origin.empty() ? "" : origin + ": ") + error);
}

double Scene::particle_volume_m3() const {
  if (polydisperse()) {
    double per_volume = 0.0;  // particles per unit solids volume, times pi/6
    for (std::size_t i = 0; i < particles.diameters_m.size(); ++i) {
      per_volume += particles.volume_fractions[i] / std::pow(particles.diameters_m[i], 3);
    }
    return kPi / 6.0 / per_volume;
  }
  const double d = particles.diameter_m;
  return kPi * d * d * d / 6.0;
}

double Scene::particle_mass_kg() const { return particles.density_kg_m3 * particle_volume_m3(); }

std::vector<double> Scene::number_fractions() const {
  if (!polydisperse()) return {1.0};
  std::vector<double> f;
  double sum = 0.0;
  for (std::size_t i = 0; i < particles.diameters_m.size(); ++i) {
    f.push_back(particles.volume_fractions[i] / std::pow(particles.diameters_m[i], 3));
    sum += f.back();
  }
  for (double& v : f) v /= sum;
  return f;
}

double Scene::smallest_particle_mass_kg() const {
  if (!polydisperse()) return particle_mass_kg();
  const double d = *std::min_element(particles.diameters_m.begin(), particles.diameters_m.end());
  return particles.density_kg_m3 * (kPi * d * d * d / 6.0);
}

std::int64_t Scene::particle_count() const {
  if (particles.count > 0) return particles.count;
  const double solids = (1.0 - eps_mf) * geometry.width_m * geometry.depth_m * bed_height_mf_m();
  return static_cast<std::int64_t>(std::llround(solids / particle_volume_m3()));
}

double Scene::bed_height_mf_m() const {
  // A model whose bed fills the column (a solver the scene refuses counts as a particle bed).
  const std::vector<std::string> models = bed_model_keys();
  if (std::find(models.begin(), models.end(), solver) != models.end() &&
      !find_bed_model(solver).particle_bed())
    return geometry.height_m;
  if (particles.count <= 0) return particles.bed_height_mf_m;
  return static_cast<double>(particles.count) * particle_volume_m3() /
         ((1.0 - eps_mf) * geometry.width_m * geometry.depth_m);
}

double Scene::jet_center_m() const {
  return jet.center_m == -1.0 ? 0.5 * geometry.width_m : jet.center_m;
}

std::string Scene::hash() const { return sha256_hex(source_text); }

}  // namespace consumers
}  // namespace draglab
