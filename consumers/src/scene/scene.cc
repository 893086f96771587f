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
#include "draglab/drag_db/error.h"
#include "scene/scene_ktgf.h"
#include "scene/scene_util.h"
#include "tfm/ktgf.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fail;
using scene_util::fmt;
using scene_util::kPi;

[[noreturn]] void bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

/// lo < x <= hi (open_lo) or lo <= x <= hi, finite; else a message naming field and range.
bool in_range(double x, double lo, double hi, bool open_lo, bool open_hi, const std::string& field,
              const std::string& unit, std::string* error) {
  const bool ok = std::isfinite(x) && (open_lo ? x > lo : x >= lo) && (open_hi ? x < hi : x <= hi);
  if (ok) return true;
  return fail(error, field + " = " + fmt(x) + " is outside " + (open_lo ? "(" : "[") + fmt(lo) +
                         ", " + fmt(hi) + (open_hi ? ")" : "]") + (unit.empty() ? "" : " " + unit));
}

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

void read_contact_steps(Scene& s, const toml::node& n, const std::string& f,
                        const std::string& at) {
  const std::int64_t v = as_integer(n, f, at);
  if (v < 20 || v > 1000) {
    bad(at + ": " + f + " = " + std::to_string(v) +
        " is outside [20, 1000] (DEM steps per contact time)");
  }
  s.time.contact_steps = static_cast<int>(v);
}

/// The DEM's keys: read from [dem] (the per-model table), or, in older scene files, from
/// [particles] (restitution, friction, spring_stiffness_n_m) and [time] (settle_s, dem_dt_s,
/// contact_steps). A key may stand in one of the two places only.
const char* const kDemKeys[][2] = {
    {"restitution", "particles"}, {"friction", "particles"}, {"spring_stiffness_n_m", "particles"},
    {"settle_s", "time"},         {"dem_dt_s", "time"},      {"contact_steps", "time"}};

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
                num("friction", [](S& s) -> double& { return s.particles.friction; }),
                num("spring_stiffness_n_m",
                    [](S& s) -> double& { return s.particles.spring_stiffness_n_m; }),
                {"count",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.particles.count = as_integer(n, f, at);
                   if (s.particles.count <= 0) {
                     bad(at + ": " + f + " = " + std::to_string(s.particles.count) +
                         " is outside [1, 10000000]");
                   }
                 }},
                num("bed_height_mf_m",
                    [](S& s) -> double& { return s.particles.bed_height_mf_m; })}},
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
                num("settle_s", [](S& s) -> double& { return s.time.settle_s; }),
                num("dem_dt_s", [](S& s) -> double& { return s.time.dem_dt_s; }),
                {"contact_steps", read_contact_steps},
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
              {"dem",
               {num("restitution", [](S& s) -> double& { return s.particles.restitution; }),
                num("friction", [](S& s) -> double& { return s.particles.friction; }),
                num("spring_stiffness_n_m",
                    [](S& s) -> double& { return s.particles.spring_stiffness_n_m; }),
                num("settle_s", [](S& s) -> double& { return s.time.settle_s; }),
                num("dem_dt_s", [](S& s) -> double& { return s.time.dem_dt_s; }),
                {"contact_steps", read_contact_steps}}},
              {"tfm",
               {{"closures", [](S& s, const toml::node& n, const std::string& f,
                                const std::string& at) { s.tfm.closures = as_text(n, f, at); }},
                {"radial_distribution",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.tfm.radial_distribution = as_text(n, f, at);
                 }},
                num_or_default("restitution", [](S& s) -> double& { return s.tfm.restitution; }),
                num("packing_limit", [](S& s) -> double& { return s.tfm.packing_limit; }),
                {"friction", [](S& s, const toml::node& n, const std::string& f,
                                const std::string& at) { s.tfm.friction = as_text(n, f, at); }},
                num("friction_min_solids",
                    [](S& s) -> double& { return s.tfm.friction_min_solids; }),
                num("friction_angle_deg", [](S& s) -> double& { return s.tfm.friction_angle_deg; }),
                num("friction_delta", [](S& s) -> double& { return s.tfm.friction_delta; }),
                num("friction_max_viscosity_pa_s",
                    [](S& s) -> double& { return s.tfm.friction_max_viscosity_pa_s; }),
                num("theta_initial_m2_s2",
                    [](S& s) -> double& { return s.tfm.theta_initial_m2_s2; }),
                num("residual_solids", [](S& s) -> double& { return s.tfm.residual_solids; }),
                num("cfl", [](S& s) -> double& { return s.tfm.cfl; }),
                num("dt_max_s", [](S& s) -> double& { return s.tfm.dt_max_s; }),
                {"solids_walls",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.tfm.solids_walls = as_text(n, f, at);
                 }},
                {"fraction_scheme",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.tfm.fraction_scheme = as_text(n, f, at);
                 }},
                {"solids_viscosity",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.tfm.solids_viscosity = as_text(n, f, at);
                 }},
                {"solids_pressure",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.tfm.solids_pressure = as_text(n, f, at);
                 }},
                {"granular_temperature",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.tfm.granular_temperature = as_text(n, f, at);
                 }}}},
              {"dbm",
               {num("superficial_velocity_m_s",
                    [](S& s) -> double& { return s.dbm.superficial_velocity_m_s; }),
                num("emulsion_density_kg_m3",
                    [](S& s) -> double& { return s.dbm.emulsion_density_kg_m3; }),
                num("emulsion_viscosity_pa_s",
                    [](S& s) -> double& { return s.dbm.emulsion_viscosity_pa_s; }),
                num("bubble_density_kg_m3",
                    [](S& s) -> double& { return s.dbm.bubble_density_kg_m3; }),
                num("bubble_diameter_m", [](S& s) -> double& { return s.dbm.bubble_diameter_m; }),
                {"nozzles_per_side",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   const std::int64_t v = as_integer(n, f, at);
                   if (v < 1 || v > 100)
                     bad(at + ": " + f + " = " + std::to_string(v) + " is outside [1, 100]");
                   s.dbm.nozzles_per_side = static_cast<int>(v);
                 }},
                num("nozzle_pitch_m", [](S& s) -> double& { return s.dbm.nozzle_pitch_m; }),
                num("virtual_mass_coefficient",
                    [](S& s) -> double& { return s.dbm.virtual_mass_coefficient; }),
                {"lift", [](S& s, const toml::node& n, const std::string& f,
                            const std::string& at) { s.dbm.lift = as_bool(n, f, at); }},
                num("lift_coefficient", [](S& s) -> double& { return s.dbm.lift_coefficient; }),
                num("coupling_width_m", [](S& s) -> double& { return s.dbm.coupling_width_m; }),
                {"coalescence",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.dbm.coalescence = as_bool(n, f, at);
                 }},
                num("film_drainage_s", [](S& s) -> double& { return s.dbm.film_drainage_s; }),
                {"collisions",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.dbm.collisions = as_bool(n, f, at);
                 }},
                num("dt_s", [](S& s) -> double& { return s.dbm.dt_s; }),
                num("injection_ramp_s", [](S& s) -> double& { return s.dbm.injection_ramp_s; }),
                num("cfl", [](S& s) -> double& { return s.dbm.cfl; }),
                {"walls", [](S& s, const toml::node& n, const std::string& f,
                             const std::string& at) { s.dbm.walls = as_text(n, f, at); }},
                num("average_from_s", [](S& s) -> double& { return s.dbm.average_from_s; }),
                num("sample_interval_s", [](S& s) -> double& { return s.dbm.sample_interval_s; }),
                {"size_heights_m",
                 [](S& s, const toml::node& n, const std::string& f, const std::string& at) {
                   s.dbm.size_heights_m.clear();
                   const toml::array* a = n.as_array();
                   if (!a) bad(at + ": " + f + " must be an array of heights in m");
                   for (std::size_t i = 0; i < a->size(); ++i)
                     s.dbm.size_heights_m.push_back(
                         as_number(*a->get(i), f + "[" + std::to_string(i) + "]", at));
                 }}}},
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

}  // namespace

namespace internal {
KtgfOptions scene_ktgf_options(const Scene& s) {
  KtgfOptions k;
  parse_closure_set(s.tfm.closures, &k.closures);
  parse_radial_distribution(s.tfm.radial_distribution, &k.radial);
  parse_friction_model(s.tfm.friction, &k.friction);
  k.restitution = s.tfm.restitution == -1.0 ? s.particles.restitution : s.tfm.restitution;
  k.packing_limit = s.tfm.packing_limit;
  k.friction_min_solids = s.tfm.friction_min_solids;
  k.friction_angle_deg = s.tfm.friction_angle_deg;
  k.friction_delta = s.tfm.friction_delta;
  k.friction_max_viscosity_pa_s = s.tfm.friction_max_viscosity_pa_s;
  return k;
}
}  // namespace internal

namespace {

/// The [dbm] table: required by solver = "dbm", refused by the others; the DBM in turn refuses the
/// tables of the jet-driven models and a particle inventory (its emulsion fills the column).
bool dbm_is_valid(const Scene& s, std::string* error) {
  const bool dbm = s.solver == "dbm";
  if (!dbm) {
    if (s.dbm.present)
      return fail(error, "[dbm] is read only with solver = \"dbm\" (this scene's solver is \"" +
                             s.solver + "\"): remove the table or change the solver");
    if (s.grid.cells_z != 1)
      return fail(error, "[grid] cells_z = " + std::to_string(s.grid.cells_z) +
                             ": the pseudo-2D models have one cell across the depth (cells_z = 1); "
                             "only the DBM's emulsion grid is 3-D");
    return true;
  }
  if (!s.dbm.present)
    return fail(error,
                "[dbm] table is missing: solver = \"dbm\" needs it (superficial_velocity_m_s, "
                "emulsion and bubble properties, nozzles; docs/scenes.md)");
  for (const char* table : {"jet", "distributor", "bubble", "dem", "tfm"}) {
    if (std::find(s.tables.begin(), s.tables.end(), table) != s.tables.end())
      return fail(error, std::string("[") + table +
                             "] is not read by solver = \"dbm\" (its bubbles come from the [dbm] "
                             "nozzles): remove the table");
  }
  if (s.particles.count != 0 || s.particles.bed_height_mf_m != 0.0)
    return fail(error,
                "[particles] count / bed_height_mf_m: the DBM's emulsion fills the column (its "
                "surface is [geometry] height_m); remove them");
  const SceneDbm& d = s.dbm;
  const double column = std::min(s.geometry.width_m, s.geometry.depth_m);
  if (!in_range(d.superficial_velocity_m_s, 0.0, 10.0, true, false,
                "[dbm] superficial_velocity_m_s", "m/s", error) ||
      !in_range(d.bubble_density_kg_m3, 0.0, 20000.0, true, false, "[dbm] bubble_density_kg_m3",
                "kg/m^3", error) ||
      !in_range(d.emulsion_density_kg_m3, d.bubble_density_kg_m3, 20000.0, true, false,
                "[dbm] emulsion_density_kg_m3", "kg/m^3 (above bubble_density_kg_m3)", error) ||
      !in_range(d.emulsion_viscosity_pa_s, 0.0, 1000.0, true, false,
                "[dbm] emulsion_viscosity_pa_s", "Pa s", error) ||
      !in_range(d.bubble_diameter_m, 0.0, column, false, true, "[dbm] bubble_diameter_m",
                "m (0: Davidson-Harrison; below the column's width and depth)", error) ||
      !in_range(d.nozzle_pitch_m, 0.0, column, true, false, "[dbm] nozzle_pitch_m", "m", error) ||
      !in_range(d.virtual_mass_coefficient, 0.0, 10.0, false, false,
                "[dbm] virtual_mass_coefficient", "", error) ||
      !in_range(d.lift_coefficient, -1.0, 1.0, false, false, "[dbm] lift_coefficient", "", error) ||
      !in_range(d.film_drainage_s, 0.0, 10.0, false, false, "[dbm] film_drainage_s", "s", error) ||
      !in_range(d.coupling_width_m, 0.0, column, false, false, "[dbm] coupling_width_m",
                "m (0: 5 bubble diameters; at most the column's width and depth)", error) ||
      !in_range(d.dt_s, 0.0, 1.0, true, false, "[dbm] dt_s", "s (and the stability limit)",
                error) ||
      !in_range(s.time.duration_s, 0.0, 1e5, true, false, "[time] duration_s", "s", error) ||
      !in_range(d.cfl, 0.0, 0.9, false, false, "[dbm] cfl", "(0: the fixed step dt_s)", error) ||
      !in_range(d.injection_ramp_s, 0.0, s.time.duration_s, false, true, "[dbm] injection_ramp_s",
                "s [0, duration_s)", error) ||
      !in_range(d.average_from_s, 0.0, s.time.duration_s, false, true, "[dbm] average_from_s",
                "s [0, duration_s)", error) ||
      !in_range(d.sample_interval_s, 0.0, s.time.duration_s, true, false, "[dbm] sample_interval_s",
                "s (0, duration_s]", error)) {
    return false;
  }
  if (d.walls != "no_slip" && d.walls != "free_slip")
    return fail(error, "[dbm] walls = '" + d.walls + "' is not one of no_slip, free_slip");
  const double span = (d.nozzles_per_side - 1) * d.nozzle_pitch_m;
  if (span + std::max(d.bubble_diameter_m, 0.0) >= column)
    return fail(error, "[dbm] nozzles_per_side = " + std::to_string(d.nozzles_per_side) +
                           " at nozzle_pitch_m = " + fmt(d.nozzle_pitch_m) + " span " + fmt(span) +
                           " m: with the bubbles they do not fit the " + fmt(column) + " m bottom");
  if (d.bubble_diameter_m > 0.0 && d.nozzles_per_side > 1 && d.nozzle_pitch_m < d.bubble_diameter_m)
    return fail(error, "[dbm] nozzle_pitch_m = " + fmt(d.nozzle_pitch_m) +
                           " m is below bubble_diameter_m = " + fmt(d.bubble_diameter_m) +
                           " m: the bubbles of neighbouring nozzles would overlap");
  if (d.size_heights_m.empty())
    return fail(error, "[dbm] size_heights_m is empty (give the heights of the size report)");
  for (double h : d.size_heights_m) {
    if (!in_range(h, 0.0, s.geometry.height_m, true, true, "[dbm] size_heights_m",
                  "m (inside the bed)", error))
      return false;
  }
  if (s.time.duration_s / d.dt_s > 1e9)
    return fail(error, "[dbm] dt_s = " + fmt(d.dt_s) + " s would take more than 1e9 steps");
  if (s.grid.cells_x < 2 || s.grid.cells_y < 2)
    return fail(error, "[grid] cells_x and cells_y must be >= 2 for the DBM's emulsion");
  // The emulsion is a continuum of particles: its cells are at least one particle wide along
  // the depth too (x and y are checked with every model).
  const double dz = s.geometry.depth_m / s.grid.cells_z;
  if (dz < s.particles.diameter_m)
    return fail(error, "[grid] cells_z = " + std::to_string(s.grid.cells_z) + " makes cells " +
                           fmt(dz) + " m deep, less than one particle ([particles] diameter_m = " +
                           fmt(s.particles.diameter_m) + " m): at most " +
                           std::to_string(static_cast<long long>(s.geometry.depth_m /
                                                                 s.particles.diameter_m)) +
                           " cells_z");
  return true;
}

/// The [tfm] table: required by solver = "tfm", refused by the others; ranges via ktgf.h.
bool tfm_is_valid(const Scene& s, std::string* error) {
  const bool tfm = s.solver == "tfm";
  if (tfm && !s.tfm.present) {
    return fail(error,
                "[tfm] table is missing: solver = \"tfm\" needs it (closures, packing_limit, "
                "friction, ...; docs/scenes.md)");
  }
  if (!tfm) {
    if (s.tfm.present) {
      return fail(error, "[tfm] is read only with solver = \"tfm\" (this scene's solver is \"" +
                             s.solver + "\"): remove the table or change the solver");
    }
    return true;
  }
  KtgfOptions k;
  if (!parse_closure_set(s.tfm.closures, &k.closures)) {
    return fail(error,
                "[tfm] closures = '" + s.tfm.closures + "' is not one of nieuwland, gidaspow");
  }
  if (!parse_radial_distribution(s.tfm.radial_distribution, &k.radial)) {
    return fail(error, "[tfm] radial_distribution = '" + s.tfm.radial_distribution +
                           "' is not one of ma_ahmadi, carnahan_starling, sinclair_jackson, "
                           "lun_savage");
  }
  if (!parse_friction_model(s.tfm.friction, &k.friction)) {
    return fail(error, "[tfm] friction = '" + s.tfm.friction +
                           "' is not one of none, johnson_jackson_schaeffer, "
                           "johnson_jackson_openfoam");
  }
  // A key whose value names one of two choices.
  auto either = [error](const std::string& value, const char* field, const char* a, const char* b) {
    if (value == a || value == b) return true;
    return fail(error,
                std::string("[tfm] ") + field + " = '" + value + "' is not one of " + a + ", " + b);
  };
  if (!either(s.tfm.solids_walls, "solids_walls", "free_slip", "no_slip") ||
      !either(s.tfm.fraction_scheme, "fraction_scheme", "upwind", "van_leer") ||
      !either(s.tfm.solids_viscosity, "solids_viscosity", "explicit", "point_implicit") ||
      !either(s.tfm.solids_pressure, "solids_pressure", "explicit", "implicit") ||
      !either(s.tfm.granular_temperature, "granular_temperature", "transport", "algebraic")) {
    return false;
  }
  if (s.tfm.restitution != -1.0 &&
      !in_range(s.tfm.restitution, 0.0, 1.0, true, false, "[tfm] restitution", "", error)) {
    return false;
  }
  k = internal::scene_ktgf_options(s);
  if (!(s.tfm.packing_limit > 1.0 - s.eps_mf)) {
    return fail(error, "[tfm] packing_limit = " + fmt(s.tfm.packing_limit) +
                           " must exceed the bed's solids fraction at minimum fluidization 1 - "
                           "[drag] eps_mf = " +
                           fmt(1.0 - s.eps_mf));
  }
  if (!k.IsValid(error)) return false;
  if (!in_range(s.tfm.theta_initial_m2_s2, 0.0, 100.0, false, false, "[tfm] theta_initial_m2_s2",
                "m^2/s^2 (a granular temperature is >= 0)", error) ||
      !in_range(s.tfm.residual_solids, 0.0, 1e-2, true, false, "[tfm] residual_solids", "",
                error) ||
      !in_range(s.tfm.cfl, 0.0, 0.5, true, false, "[tfm] cfl", "", error) ||
      !in_range(s.tfm.dt_max_s, 0.0, 0.1, true, false, "[tfm] dt_max_s", "s", error)) {
    return false;
  }
  return true;
}

}  // namespace

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

Scene parse_scene(const std::string& toml_text, const std::string& origin) {
  namespace ts = core::toml_schema;
  const toml::table root = ts::parse(toml_text, origin);
  static const ts::Schema names = [] {
    ts::Schema out;
    for (const auto& [section, keys] : sections()) {
      out.push_back({section, {}});
      for (const Key& k : keys) out.back().second.push_back(k.name);
    }
    return out;
  }();
  Scene s;
  s.origin = origin;
  s.source_text = toml_text;
  const auto on_section = [&](const std::string& section, const toml::table& table,
                              const std::string& at) {
    if (section == "tfm") s.tfm.present = true;
    if (section == "dbm") s.dbm.present = true;
    s.tables.push_back(section);
    if (section == "dem") {
      s.dem_table = true;
      for (const auto& key : kDemKeys) {
        const toml::table* old = root[key[1]].as_table();
        if (table.contains(key[0]) && old && old->contains(key[0])) {
          bad(at + ": " + key[0] + " is given in [dem] and in [" + key[1] +
              "]: keep it in [dem] only");
        }
      }
    }
  };
  ts::visit(root, origin, names, on_section, [&](const ts::Entry& e) {
    for (const auto& [section, keys] : sections()) {
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
  std::string error;
  if (!s.IsValid(&error)) bad(origin + ": " + error);
  return s;
}

Scene load_scene(const std::string& path) {
  return parse_scene(core::read_text_input(path, "scene file"), path);
}

bool Scene::IsValid(std::string* error) const {
  // Where the DEM's keys stand in this file (messages name the section the user wrote).
  auto dem_at = [this](const char* old_section) {
    return std::string(dem_table ? "[dem]" : old_section);
  };
  if (name.empty()) return fail(error, "[scene] name is missing or empty");
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) {
      return fail(error,
                  "[scene] name '" + name + "' may contain only letters, digits, '_', '-' and '.'");
    }
  }
  {
    const std::vector<std::string> models = bed_model_keys();
    if (std::find(models.begin(), models.end(), solver) == models.end()) {
      std::string known;
      for (const std::string& k : models) known += (known.empty() ? "" : ", ") + k;
      return fail(
          error, "[scene] solver = '" + solver + "' is not a registered bed model (" + known + ")");
    }
  }
  // Geometry: a laboratory pseudo-2D bed, millimetres to metres.
  if (!in_range(geometry.width_m, 0.0, 10.0, true, false, "[geometry] width_m", "m", error) ||
      !in_range(geometry.height_m, 0.0, 10.0, true, false, "[geometry] height_m", "m", error) ||
      !in_range(geometry.depth_m, 0.0, 10.0, true, false, "[geometry] depth_m", "m", error)) {
    return false;
  }
  const double d = particles.diameter_m;
  // From fine powders (Geldart C, tens of microns) to coarse beads; below a micron the drag laws'
  // minimum fluidization has no root the solvers can find.
  if (!in_range(d, 1e-6, 0.1, false, false, "[particles] diameter_m", "m", error)) return false;
  if (!in_range(particles.density_kg_m3, 0.0, 30000.0, true, false, "[particles] density_kg_m3",
                "kg/m^3", error) ||
      !in_range(particles.restitution, 0.0, 1.0, true, false,
                dem_at("[particles]") + " restitution", "", error) ||
      !in_range(particles.friction, 0.0, 1.0, false, false, dem_at("[particles]") + " friction", "",
                error) ||
      !in_range(particles.spring_stiffness_n_m, 0.0, 1e9, true, false,
                dem_at("[particles]") + " spring_stiffness_n_m", "N/m", error)) {
    return false;
  }
  const double min_box = std::min({geometry.width_m, geometry.height_m, geometry.depth_m});
  if (d > min_box) {
    return fail(error, "[particles] diameter_m = " + fmt(d) +
                           " does not fit the box: it must be <= the smallest box size " +
                           fmt(min_box) + " m");
  }
  if (!in_range(gas.density_kg_m3, 0.0, 1000.0, true, false, "[gas] density_kg_m3", "kg/m^3",
                error) ||
      !in_range(gas.viscosity_pa_s, 0.0, 1.0, true, false, "[gas] viscosity_pa_s", "Pa s", error) ||
      !in_range(gas.gravity_m_s2, 0.0, 100.0, true, false, "[gas] gravity_m_s2", "m/s^2", error)) {
    return false;
  }
  if (!(particles.density_kg_m3 > gas.density_kg_m3)) {
    return fail(error, "[particles] density_kg_m3 = " + fmt(particles.density_kg_m3) +
                           " must exceed [gas] density_kg_m3 = " + fmt(gas.density_kg_m3) +
                           " (the bed would not settle)");
  }
  if (!in_range(eps_mf, 0.26, 0.9, false, true, "[drag] eps_mf", "(random packings: 0.36-0.5)",
                error)) {
    return false;
  }
  if (!dbm_is_valid(*this, error)) return false;
  if (solver != "dbm") {
    const bool has_count = particles.count > 0;
    const bool has_height = particles.bed_height_mf_m != 0.0;
    if (has_count == has_height) {
      // A 0 typed in the file reads as "not given": say so with the ranges.
      return fail(
          error,
          "[particles] give exactly one of count, in [1, 10000000], and bed_height_mf_m, "
          "in (0, " +
              fmt(geometry.height_m) + "] m (the box height)" +
              (has_count ? std::string(": both are given")
                         : std::string(": neither has a usable value (count = " +
                                       std::to_string(particles.count) + ", bed_height_mf_m = " +
                                       fmt(particles.bed_height_mf_m) + ")")));
    }
    if (has_height && !in_range(particles.bed_height_mf_m, 0.0, geometry.height_m, true, false,
                                "[particles] bed_height_mf_m", "m (the box height)", error)) {
      return false;
    }
    if (has_count && particles.count > 10000000) {
      return fail(error, "[particles] count = " + std::to_string(particles.count) +
                             " is outside [1, 10000000]");
    }
    if (solver == "dpm" && has_height) {
      // The particle solver holds every particle: the count a bed height makes obeys the cap
      // of [particles] count (checked in double: a tiny diameter overflows any integer).
      const double n = (1.0 - eps_mf) * geometry.width_m * geometry.depth_m *
                       particles.bed_height_mf_m /
                       (std::acos(-1.0) / 6.0 * particles.diameter_m * particles.diameter_m *
                        particles.diameter_m);
      if (!(n <= 10000000.0)) {
        return fail(error, "[particles] bed_height_mf_m = " + fmt(particles.bed_height_mf_m) +
                               " m of diameter_m = " + fmt(particles.diameter_m) + " m makes " +
                               fmt(n) +
                               " particles, more than the 10000000 the DPM holds (a lower bed, "
                               "larger particles or a narrower box)");
      }
    }
    const double h_mf = bed_height_mf_m();
    if (h_mf > geometry.height_m) {
      return fail(error, "[particles] count = " + std::to_string(particles.count) +
                             " makes a bed " + fmt(h_mf) + " m high at eps_mf = " + fmt(eps_mf) +
                             ": it does not fit the box ([geometry] height_m = " +
                             fmt(geometry.height_m) + " m)");
    }
    if (h_mf < d) {
      return fail(error, "[particles] the bed at eps_mf is " + fmt(h_mf) +
                             " m high, less than one particle diameter (give more particles)");
    }
    // Distributor.
    if (distributor.mode != BackgroundMode::kFixed) {
      if (!in_range(distributor.umf_factor, 0.0, 10.0, false, false, "[distributor] umf_factor", "",
                    error)) {
        return false;
      }
    } else if (!in_range(distributor.velocity_m_s, 0.0, 100.0, true, false,
                         "[distributor] velocity_m_s", "m/s (background = \"fixed\")", error)) {
      return false;
    }
    // Jet.
    if (!in_range(jet.slot_width_m, 0.0, geometry.width_m, true, false, "[jet] slot_width_m",
                  "m (0 < slot <= the bed width)", error) ||
        !in_range(jet.velocity_m_s, 0.0, 300.0, false, false, "[jet] velocity_m_s",
                  "m/s (incompressible gas: Mach < 0.9)", error) ||
        !in_range(jet.start_s, 0.0, 1e4, false, false, "[jet] start_s", "s", error) ||
        !in_range(jet.duration_s, 0.0, 1e4, false, false, "[jet] duration_s", "s", error) ||
        !in_range(jet.ramp_s, 0.0, 1.0, false, false, "[jet] ramp_s", "s", error)) {
      return false;
    }
    if (jet.center_m != -1.0) {  // -1: the default, the bed's centre line
      const double half = 0.5 * jet.slot_width_m;
      if (!in_range(jet.center_m, half, geometry.width_m - half, false, false, "[jet] center_m",
                    "m (the slot must lie inside the bottom)", error)) {
        return false;
      }
    }
    // Times.
    if (!in_range(time.duration_s, 0.0, 1e4, true, false, "[time] duration_s", "s", error) ||
        !in_range(time.t_ref_s, 0.0, 1e4, false, false, "[time] t_ref_s", "s", error) ||
        !in_range(time.settle_s, 0.0, 1e4, false, false, dem_at("[time]") + " settle_s", "s",
                  error) ||
        !in_range(time.dem_dt_s, 0.0, 1.0, false, false, dem_at("[time]") + " dem_dt_s",
                  "s (0 = auto)", error) ||
        !in_range(time.gas_dt_s, 0.0, 1.0, false, false, "[time] gas_dt_s", "s (0 = auto)",
                  error)) {
      return false;
    }
    if (time.contact_steps < 20 || time.contact_steps > 1000) {
      return fail(error, dem_at("[time]") + " contact_steps = " +
                             std::to_string(time.contact_steps) + " is outside [20, 1000]");
    }
    if (jet.start_s + time.t_ref_s > time.duration_s * (1.0 + 1e-12)) {
      return fail(error, "[time] t_ref_s = " + fmt(time.t_ref_s) + " after the jet start " +
                             fmt(jet.start_s) + " s is beyond [time] duration_s = " +
                             fmt(time.duration_s) + " s (t_ref_s <= duration_s - jet.start_s)");
    }
    // A positive step so small that the run could never finish is a typo, not a choice.
    constexpr double kMaxSteps = 1e9;
    if (time.gas_dt_s > 0.0 && time.duration_s / time.gas_dt_s > kMaxSteps) {
      return fail(error, "[time] gas_dt_s = " + fmt(time.gas_dt_s) + " s would take " +
                             fmt(time.duration_s / time.gas_dt_s) +
                             " gas steps for duration_s (more than 1e9): use 0 = auto, or a step "
                             ">= duration_s / 1e9 = " +
                             fmt(time.duration_s / kMaxSteps) + " s");
    }
    if (time.dem_dt_s > 0.0 && (time.settle_s + time.duration_s) / time.dem_dt_s > kMaxSteps) {
      return fail(error, dem_at("[time]") + " dem_dt_s = " + fmt(time.dem_dt_s) + " s would take " +
                             fmt((time.settle_s + time.duration_s) / time.dem_dt_s) +
                             " DEM steps for settle_s + duration_s (more than 1e9): use 0 = auto, "
                             "or a step >= (settle_s + duration_s) / 1e9 = " +
                             fmt((time.settle_s + time.duration_s) / kMaxSteps) + " s");
    }
    if (time.dem_dt_s > 0.0) {
      const double limit = contact_time_s(particles) / 20.0;
      if (time.dem_dt_s > limit) {
        return fail(error, dem_at("[time]") + " dem_dt_s = " + fmt(time.dem_dt_s) +
                               " s is above the stability limit t_c/20 = " + fmt(limit) +
                               " s of the contact model (use 0 = auto, or a smaller step)");
      }
    }
  }
  // Grid: the void fraction needs cells at least one particle wide.
  if (grid.cells_x < 2 || grid.cells_y < 2) {
    return fail(error, "[grid] cells_x and cells_y must be >= 2 (got " +
                           std::to_string(grid.cells_x) + ", " + std::to_string(grid.cells_y) +
                           ")");
  }
  const double dx = geometry.width_m / grid.cells_x, dy = geometry.height_m / grid.cells_y;
  if (dx < d || dy < d) {
    return fail(
        error,
        "[grid] cells of " + fmt(dx) + " x " + fmt(dy) + " m are smaller than a particle (" +
            fmt(d) +
            " m): use at most width/d = " + std::to_string(static_cast<int>(geometry.width_m / d)) +
            " cells_x and height/d = " + std::to_string(static_cast<int>(geometry.height_m / d)) +
            " cells_y");
  }
  if ((solver != "dbm" && !in_range(bubble.eps_threshold, eps_mf, 1.0, true, true,
                                    "[bubble] eps_threshold", "(eps_mf, 1)", error)) ||
      (solver != "dbm" && !in_range(bubble.sample_interval_s, 0.0, time.duration_s, true, false,
                                    "[bubble] sample_interval_s", "s (0, duration_s]", error)) ||
      !in_range(outputs.interval_s, 0.0, time.duration_s, false, false, "[outputs] interval_s",
                "s [0, duration_s]", error)) {
    return false;
  }
  if (laws.empty()) return fail(error, "[drag] laws is missing or empty (e.g. [\"ergun@1\"])");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < laws.size(); ++i) {
    if (laws[i].empty() || laws[i].find_first_of(" \t,") != std::string::npos) {
      return fail(error, "[drag] laws[" + std::to_string(i) + "] = '" + laws[i] +
                             "' is not a law reference (name@version, e.g. ergun@1)");
    }
    if (!seen.insert(laws[i]).second) {
      return fail(error, "[drag] laws lists '" + laws[i] + "' twice");
    }
  }
  if (!tfm_is_valid(*this, error)) return false;
  if (dem_table && solver != "dpm") {
    return fail(error, "[dem] is read only with solver = \"dpm\" (this scene's solver is \"" +
                           solver + "\"): remove the table or change the solver");
  }
  if (range_policy != "clamp" && range_policy != "extrapolate" && range_policy != "error") {
    return fail(error, "[drag] range_policy = '" + range_policy +
                           "' is not one of clamp, extrapolate, error");
  }
  return true;
}

void Scene::Validate() const {
  std::string error;
  if (!IsValid(&error)) bad((origin.empty() ? "" : origin + ": ") + error);
}

double Scene::particle_volume_m3() const {
  const double d = particles.diameter_m;
  return kPi * d * d * d / 6.0;
}

double Scene::particle_mass_kg() const { return particles.density_kg_m3 * particle_volume_m3(); }

std::int64_t Scene::particle_count() const {
  if (particles.count > 0) return particles.count;
  const double solids = (1.0 - eps_mf) * geometry.width_m * geometry.depth_m * bed_height_mf_m();
  return static_cast<std::int64_t>(std::llround(solids / particle_volume_m3()));
}

double Scene::bed_height_mf_m() const {
  if (solver == "dbm") return geometry.height_m;
  if (particles.count <= 0) return particles.bed_height_mf_m;
  return static_cast<double>(particles.count) * particle_volume_m3() /
         ((1.0 - eps_mf) * geometry.width_m * geometry.depth_m);
}

double Scene::jet_center_m() const {
  return jet.center_m == -1.0 ? 0.5 * geometry.width_m : jet.center_m;
}

std::string Scene::hash() const { return sha256_hex(source_text); }

double contact_time_s(const SceneParticles& p) {
  const double d = p.diameter_m;
  const double m_eff = 0.5 * p.density_kg_m3 * kPi * d * d * d / 6.0;
  const double k = p.spring_stiffness_n_m;
  const double log_e = std::log(p.restitution);
  const double eta =
      2.0 * std::sqrt(k * m_eff) * std::fabs(log_e) / std::sqrt(kPi * kPi + log_e * log_e);
  return kPi / std::sqrt(k / m_eff - eta * eta / (4.0 * m_eff * m_eff));
}

}  // namespace consumers
}  // namespace draglab
