// The particle model's [dem] table (dpm_scene.h).
#include "dpm/dpm_scene.h"

#include <cmath>
#include <string>

#include "draglab/consumers/dpm.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fail;
using scene_util::fmt;
using scene_util::in_range;

constexpr const char* kTable = "dem";

/// A positive step so small that the run could never finish is a typo, not a choice.
constexpr double kMaxSteps = 1e9;
/// The DPM holds every particle: the cap of [particles] count, also for the count a bed height
/// makes.
constexpr double kMaxParticles = 1e7;

/// Where a key stands in the scene's file: messages name the table the user wrote.
std::string at(const SceneDem& d, const char* older_table) {
  return d.present ? std::string("[dem]") : std::string(older_table);
}

/// The contact model: ranges of its coefficients.
bool contacts_are_valid(const SceneDem& d, std::string* error) {
  return in_range(d.restitution, 0.0, 1.0, true, false, at(d, "[particles]") + " restitution", "",
                  error) &&
         in_range(d.friction, 0.0, 1.0, false, false, at(d, "[particles]") + " friction", "",
                  error) &&
         in_range(d.spring_stiffness_n_m, 0.0, 1e9, true, false,
                  at(d, "[particles]") + " spring_stiffness_n_m", "N/m", error);
}

/// The DEM's times and steps: ranges, a step count that can finish, and the stability limit of
/// the contact model.
bool steps_are_valid(const Scene& s, const SceneDem& d, std::string* error) {
  if (!in_range(d.settle_s, 0.0, 1e4, false, false, at(d, "[time]") + " settle_s", "s", error) ||
      !in_range(d.dem_dt_s, 0.0, 1.0, false, false, at(d, "[time]") + " dem_dt_s", "s (0 = auto)",
                error)) {
    return false;
  }
  if (d.contact_steps < 20 || d.contact_steps > 1000) {
    return fail(error, at(d, "[time]") + " contact_steps = " + std::to_string(d.contact_steps) +
                           " is outside [20, 1000]");
  }
  if (d.dem_dt_s == 0.0) return true;
  const double span = d.settle_s + s.time.duration_s;
  if (span / d.dem_dt_s > kMaxSteps) {
    return fail(error, at(d, "[time]") + " dem_dt_s = " + fmt(d.dem_dt_s) + " s would take " +
                           fmt(span / d.dem_dt_s) +
                           " DEM steps for settle_s + duration_s (more than 1e9): use 0 = auto, "
                           "or a step >= (settle_s + duration_s) / 1e9 = " +
                           fmt(span / kMaxSteps) + " s");
  }
  const double limit = contact_time_s(s) / 20.0;
  if (d.dem_dt_s > limit) {
    return fail(error, at(d, "[time]") + " dem_dt_s = " + fmt(d.dem_dt_s) +
                           " s is above the stability limit t_c/20 = " + fmt(limit) +
                           " s of the contact model (use 0 = auto, or a smaller step)");
  }
  return true;
}

/// The count a bed height makes obeys the cap of [particles] count (checked in double: a tiny
/// diameter overflows any integer).
bool particle_count_fits(const Scene& s, std::string* error) {
  if (s.particles.count > 0 || s.particles.bed_height_mf_m <= 0.0) return true;
  const double n = (1.0 - s.eps_mf) * s.geometry.width_m * s.geometry.depth_m *
                   s.particles.bed_height_mf_m / s.particle_volume_m3();
  if (n <= kMaxParticles) return true;
  return fail(error, "[particles] bed_height_mf_m = " + fmt(s.particles.bed_height_mf_m) +
                         " m of diameter_m = " + fmt(s.particles.diameter_m) + " m makes " +
                         fmt(n) +
                         " particles, more than the 10000000 the DPM holds (a lower bed, "
                         "larger particles or a narrower box)");
}

/// [dem] is the DPM's: refused with another solver. The keys in their older places are checked
/// in every particle-bed scene, as they always were.
bool dem_is_valid(const Scene& s, std::string* error) {
  const SceneDem& d = dem_section(s);
  if (d.present && s.solver != "dpm") {
    return fail(error, "[dem] is read only with solver = \"dpm\" (this scene's solver is \"" +
                           s.solver + "\"): remove the table or change the solver");
  }
  if (!contacts_are_valid(d, error)) return false;
  if (!find_bed_model(s.solver).particle_bed()) return true;
  if (!steps_are_valid(s, d, error)) return false;
  return s.solver != "dpm" || particle_count_fits(s, error);
}

}  // namespace

const SceneDem& dem_section(const Scene& scene) { return scene.sections.As<SceneDem>(kTable); }

SceneDem& dem_section(Scene& scene) { return scene.sections.As<SceneDem>(kTable); }

const SceneTable& dem_scene_table() {
  static const SceneTable table = [] {
    SceneTable t;
    t.name = kTable;
    t.make = [] { return std::make_unique<SceneDem>(); };
    t.keys = {scene_key("restitution", &SceneDem::restitution),
              scene_key("friction", &SceneDem::friction),
              scene_key("spring_stiffness_n_m", &SceneDem::spring_stiffness_n_m),
              scene_key("settle_s", &SceneDem::settle_s),
              scene_key("dem_dt_s", &SceneDem::dem_dt_s),
              scene_key("contact_steps", &SceneDem::contact_steps, 20, 1000,
                        "DEM steps per contact time")};
    t.older_places = {{"restitution", "particles"},
                      {"friction", "particles"},
                      {"spring_stiffness_n_m", "particles"},
                      {"settle_s", "time"},
                      {"dem_dt_s", "time"},
                      {"contact_steps", "time"}};
    t.is_valid = dem_is_valid;
    return t;
  }();
  return table;
}

double contact_time_s(const Scene& scene) {
  const SceneDem& d = dem_section(scene);
  // The lightest pair has the shortest contact (a bed of several sizes: two of the smallest).
  const double m_eff = 0.5 * scene.smallest_particle_mass_kg();
  const double k = d.spring_stiffness_n_m;
  const double log_e = std::log(d.restitution);
  const double eta = 2.0 * std::sqrt(k * m_eff) * std::fabs(log_e) /
                     std::sqrt(scene_util::kPi * scene_util::kPi + log_e * log_e);
  return scene_util::kPi / std::sqrt(k / m_eff - eta * eta / (4.0 * m_eff * m_eff));
}

}  // namespace consumers
}  // namespace draglab
