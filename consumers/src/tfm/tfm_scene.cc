// The two-fluid model's [tfm] table (tfm_scene.h).
#include "tfm/tfm_scene.h"

#include <string>

#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fail;
using scene_util::fmt;
using scene_util::in_range;

constexpr const char* kTable = "tfm";

SceneTfm& Tfm(SceneSection& s) { return static_cast<SceneTfm&>(s); }

/// The [tfm] table: required by solver = "tfm", refused by the others; ranges via ktgf.h.
bool tfm_is_valid(const Scene& s, std::string* error) {
  const SceneTfm& t = tfm_section(s);
  const bool tfm = s.solver == "tfm";
  if (tfm && !t.present) {
    return fail(error,
                "[tfm] table is missing: solver = \"tfm\" needs it (closures, packing_limit, "
                "friction, ...; docs/scenes.md)");
  }
  if (!tfm) {
    if (t.present) {
      return fail(error, "[tfm] is read only with solver = \"tfm\" (this scene's solver is \"" +
                             s.solver + "\"): remove the table or change the solver");
    }
    return true;
  }
  KtgfOptions k;
  if (!parse_closure_set(t.closures, &k.closures)) {
    return fail(error, "[tfm] closures = '" + t.closures + "' is not one of nieuwland, gidaspow");
  }
  if (!parse_radial_distribution(t.radial_distribution, &k.radial)) {
    return fail(error, "[tfm] radial_distribution = '" + t.radial_distribution +
                           "' is not one of ma_ahmadi, carnahan_starling, sinclair_jackson, "
                           "lun_savage");
  }
  if (!parse_friction_model(t.friction, &k.friction)) {
    return fail(error, "[tfm] friction = '" + t.friction +
                           "' is not one of none, johnson_jackson_schaeffer, "
                           "johnson_jackson_openfoam");
  }
  // A key whose value names one of two choices.
  auto either = [error](const std::string& value, const char* field, const char* a, const char* b) {
    if (value == a || value == b) return true;
    return fail(error,
                std::string("[tfm] ") + field + " = '" + value + "' is not one of " + a + ", " + b);
  };
  if (!either(t.solids_walls, "solids_walls", "free_slip", "no_slip") ||
      !either(t.fraction_scheme, "fraction_scheme", "upwind", "van_leer") ||
      !either(t.solids_viscosity, "solids_viscosity", "explicit", "point_implicit") ||
      !either(t.solids_pressure, "solids_pressure", "explicit", "implicit") ||
      !either(t.granular_temperature, "granular_temperature", "transport", "algebraic")) {
    return false;
  }
  if (t.restitution != -1.0 &&
      !in_range(t.restitution, 0.0, 1.0, true, false, "[tfm] restitution", "", error)) {
    return false;
  }
  k = internal::scene_ktgf_options(s);
  if (!(t.packing_limit > 1.0 - s.eps_mf)) {
    return fail(error, "[tfm] packing_limit = " + fmt(t.packing_limit) +
                           " must exceed the bed's solids fraction at minimum fluidization 1 - "
                           "[drag] eps_mf = " +
                           fmt(1.0 - s.eps_mf));
  }
  if (!k.IsValid(error)) return false;
  if (!in_range(t.theta_initial_m2_s2, 0.0, 100.0, false, false, "[tfm] theta_initial_m2_s2",
                "m^2/s^2 (a granular temperature is >= 0)", error) ||
      !in_range(t.residual_solids, 0.0, 1e-2, true, false, "[tfm] residual_solids", "", error) ||
      !in_range(t.cfl, 0.0, 0.5, true, false, "[tfm] cfl", "", error) ||
      !in_range(t.dt_max_s, 0.0, 0.1, true, false, "[tfm] dt_max_s", "s", error)) {
    return false;
  }
  return true;
}

}  // namespace

const SceneTfm& tfm_section(const Scene& scene) { return scene.sections.As<SceneTfm>(kTable); }

SceneTfm& tfm_section(Scene& scene) { return scene.sections.As<SceneTfm>(kTable); }

const SceneTable& tfm_scene_table() {
  static const SceneTable table = [] {
    SceneTable t;
    t.name = kTable;
    t.make = [] { return std::make_unique<SceneTfm>(); };
    t.keys = {
        scene_key("closures", &SceneTfm::closures),
        scene_key("radial_distribution", &SceneTfm::radial_distribution),
        {"restitution",
         [](SceneSection& s, const SceneValue& v) { Tfm(s).restitution = v.number_or_default(); }},
        scene_key("packing_limit", &SceneTfm::packing_limit),
        scene_key("friction", &SceneTfm::friction),
        scene_key("friction_min_solids", &SceneTfm::friction_min_solids),
        scene_key("friction_angle_deg", &SceneTfm::friction_angle_deg),
        scene_key("friction_delta", &SceneTfm::friction_delta),
        scene_key("friction_max_viscosity_pa_s", &SceneTfm::friction_max_viscosity_pa_s),
        scene_key("theta_initial_m2_s2", &SceneTfm::theta_initial_m2_s2),
        scene_key("residual_solids", &SceneTfm::residual_solids),
        scene_key("cfl", &SceneTfm::cfl),
        scene_key("dt_max_s", &SceneTfm::dt_max_s),
        scene_key("solids_walls", &SceneTfm::solids_walls),
        scene_key("fraction_scheme", &SceneTfm::fraction_scheme),
        scene_key("solids_viscosity", &SceneTfm::solids_viscosity),
        scene_key("solids_pressure", &SceneTfm::solids_pressure),
        scene_key("granular_temperature", &SceneTfm::granular_temperature)};
    t.is_valid = tfm_is_valid;
    return t;
  }();
  return table;
}

namespace internal {
KtgfOptions scene_ktgf_options(const Scene& s) {
  const SceneTfm& t = tfm_section(s);
  KtgfOptions k;
  parse_closure_set(t.closures, &k.closures);
  parse_radial_distribution(t.radial_distribution, &k.radial);
  parse_friction_model(t.friction, &k.friction);
  k.restitution = t.restitution == -1.0 ? s.particles.restitution : t.restitution;
  k.packing_limit = t.packing_limit;
  k.friction_min_solids = t.friction_min_solids;
  k.friction_angle_deg = t.friction_angle_deg;
  k.friction_delta = t.friction_delta;
  k.friction_max_viscosity_pa_s = t.friction_max_viscosity_pa_s;
  return k;
}
}  // namespace internal

}  // namespace consumers
}  // namespace draglab
