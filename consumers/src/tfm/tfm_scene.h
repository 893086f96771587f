// The two-fluid model's table of scene files, [tfm] (docs/scenes.md): its keys, defaults and
// checks, and the kinetic-theory options it declares. Registered through the TFM's
// BedModel::scene_table; nothing outside consumers/src/tfm and its bed model reads it.
#pragma once

#include <memory>
#include <string>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "tfm/ktgf.h"

namespace draglab {
namespace consumers {

/// [tfm]: closures and numerics of the two-fluid model (read only with solver = "tfm", which
/// requires the table; tfm.h, ktgf.h, docs/tfm.md). Names as ktgf.h's to_string.
struct SceneTfm : SceneSection {
  std::string closures = "nieuwland";  ///< "nieuwland" or "gidaspow".
  std::string radial_distribution = "ma_ahmadi";
  double restitution = -1.0;    ///< Particle-particle e, (0, 1]; -1: [particles] restitution.
  double packing_limit = 0.64;  ///< phi_max, (1 - eps_mf, 0.74].
  std::string friction = "johnson_jackson_schaeffer";  ///< Or "johnson_jackson_openfoam", "none".
  double friction_min_solids = 0.5;           ///< Johnson-Jackson phi_min, (0, packing_limit).
  double friction_angle_deg = 28.5;           ///< (0, 90).
  double friction_delta = 0.02;               ///< Johnson-Jackson delta (the gap clip), (0, 0.1].
  double friction_max_viscosity_pa_s = 10.0;  ///< Cap of the Schaeffer viscosity, (0, 1e4].
  double theta_initial_m2_s2 = 1e-4;          ///< Initial granular temperature of the bed, >= 0.
  double residual_solids = 1e-4;              ///< (0, 1e-2].
  double cfl = 0.3;                           ///< (0, 0.5].
  double dt_max_s = 5e-4;                     ///< (0, 0.1].
  std::string solids_walls = "free_slip";     ///< Or "no_slip": the solids' wall condition.
  std::string fraction_scheme = "upwind";     ///< Or "van_leer": face solids fractions.
  std::string solids_viscosity = "explicit";  ///< Or "point_implicit" (tfm.h).
  std::string solids_pressure = "explicit";   ///< Or "implicit" (tfm.h).
  std::string granular_temperature = "transport";  ///< Or "algebraic" (local equilibrium).

  std::unique_ptr<SceneSection> Clone() const override { return std::make_unique<SceneTfm>(*this); }
};

/// The scene's [tfm] table (the defaults when it has none).
const SceneTfm& tfm_section(const Scene& scene);
/// The same, to change (a study's variant of a scene).
SceneTfm& tfm_section(Scene& scene);

/// [tfm]'s keys and checks.
const SceneTable& tfm_scene_table();

namespace internal {
/// The closure set, g0, restitution (the [particles] one unless [tfm] gives it), packing limit
/// and friction of `scene`'s [tfm] table. A name that does not parse leaves the default
/// (Scene::IsValid reports it); ranges are KtgfOptions::IsValid's.
KtgfOptions scene_ktgf_options(const Scene& scene);
}  // namespace internal

}  // namespace consumers
}  // namespace draglab
