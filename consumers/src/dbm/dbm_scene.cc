// The discrete bubble model's [dbm] table (dbm_scene.h).
#include "dbm/dbm_scene.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "draglab/error.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fail;
using scene_util::fmt;
using scene_util::in_range;

constexpr const char* kTable = "dbm";

SceneDbm& Dbm(SceneSection& s) { return static_cast<SceneDbm&>(s); }

/// The [dbm] table: required by solver = "dbm", refused by the others; the DBM in turn refuses the
/// tables of the jet-driven models and a particle inventory (its emulsion fills the column).
bool dbm_is_valid(const Scene& s, std::string* error) {
  const SceneDbm& t = dbm_section(s);
  const bool dbm = s.solver == "dbm";
  if (!dbm) {
    if (t.present)
      return fail(error, "[dbm] is read only with solver = \"dbm\" (this scene's solver is \"" +
                             s.solver + "\"): remove the table or change the solver");
    if (s.grid.cells_z != 1)
      return fail(error, "[grid] cells_z = " + std::to_string(s.grid.cells_z) +
                             ": the pseudo-2D models have one cell across the depth (cells_z = 1); "
                             "only the DBM's emulsion grid is 3-D");
    return true;
  }
  if (!t.present)
    return fail(error,
                "[dbm] table is missing: solver = \"dbm\" needs it (superficial_velocity_m_s, "
                "emulsion and bubble properties, nozzles; docs/scenes.md)");
  // The shared tables of a jet-driven particle bed (another model's own table is refused by
  // that model's checks).
  for (const char* table : {"jet", "distributor", "bubble"}) {
    if (std::find(s.tables.begin(), s.tables.end(), table) != s.tables.end())
      return fail(error, std::string("[") + table +
                             "] is not read by solver = \"dbm\" (its bubbles come from the [dbm] "
                             "nozzles): remove the table");
  }
  if (s.particles.count != 0 || s.particles.bed_height_mf_m != 0.0)
    return fail(error,
                "[particles] count / bed_height_mf_m: the DBM's emulsion fills the column (its "
                "surface is [geometry] height_m); remove them");
  const SceneDbm& d = t;
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

}  // namespace

const SceneDbm& dbm_section(const Scene& scene) { return scene.sections.As<SceneDbm>(kTable); }

SceneDbm& dbm_section(Scene& scene) { return scene.sections.As<SceneDbm>(kTable); }

const SceneTable& dbm_scene_table() {
  static const SceneTable table = [] {
    SceneTable t;
    t.name = kTable;
    t.make = [] { return std::make_unique<SceneDbm>(); };
    t.keys = {scene_key("superficial_velocity_m_s", &SceneDbm::superficial_velocity_m_s),
              scene_key("emulsion_density_kg_m3", &SceneDbm::emulsion_density_kg_m3),
              scene_key("emulsion_viscosity_pa_s", &SceneDbm::emulsion_viscosity_pa_s),
              scene_key("bubble_density_kg_m3", &SceneDbm::bubble_density_kg_m3),
              scene_key("bubble_diameter_m", &SceneDbm::bubble_diameter_m),
              scene_key("nozzles_per_side", &SceneDbm::nozzles_per_side, 1, 100),
              scene_key("nozzle_pitch_m", &SceneDbm::nozzle_pitch_m),
              scene_key("virtual_mass_coefficient", &SceneDbm::virtual_mass_coefficient),
              scene_key("lift", &SceneDbm::lift),
              scene_key("lift_coefficient", &SceneDbm::lift_coefficient),
              scene_key("coupling_width_m", &SceneDbm::coupling_width_m),
              scene_key("coalescence", &SceneDbm::coalescence),
              scene_key("film_drainage_s", &SceneDbm::film_drainage_s),
              scene_key("collisions", &SceneDbm::collisions),
              scene_key("dt_s", &SceneDbm::dt_s),
              scene_key("injection_ramp_s", &SceneDbm::injection_ramp_s),
              scene_key("cfl", &SceneDbm::cfl),
              scene_key("walls", &SceneDbm::walls),
              scene_key("average_from_s", &SceneDbm::average_from_s),
              scene_key("sample_interval_s", &SceneDbm::sample_interval_s),
              {"size_heights_m", [](SceneSection& s, const SceneValue& v) {
                 Dbm(s).size_heights_m = v.numbers("heights in m");
               }}};
    t.is_valid = dbm_is_valid;
    return t;
  }();
  return table;
}

}  // namespace consumers
}  // namespace draglab
