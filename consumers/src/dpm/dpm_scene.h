// The particle model's table of scene files, [dem] (docs/scenes.md): the DEM's contact model and
// steps, their defaults and checks. Registered through the DPM's BedModel::scene_table; nothing
// outside consumers/src/dpm and its bed model reads it.
#pragma once

#include <string>
#include <vector>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"

namespace draglab {
namespace consumers {

/// [dem]: the DEM's linear spring-dashpot contacts (pairs and walls alike) and its steps (dem.h,
/// docs/dem.md). Read only with solver = "dpm". Older scene files give the keys in [particles]
/// (restitution, friction, spring_stiffness_n_m) and [time] (settle_s, dem_dt_s,
/// contact_steps): they are read from there too, and a key may stand in one place only.
struct SceneDem : SceneSection {
  double restitution = 0.97;             ///< Normal restitution, (0, 1].
  double friction = 0.1;                 ///< Coulomb friction, [0, 1].
  double spring_stiffness_n_m = 7000.0;  ///< Normal spring k_n [N/m] (consumers.md §3.5).
  double settle_s = 0.3;                 ///< Settling under gravity (no gas flow) before t = 0.
  double dem_dt_s = 0.0;                 ///< DEM step, or 0: t_c / contact_steps.
  int contact_steps = 20;                ///< DEM steps per contact time, [20, 1000].

  std::unique_ptr<SceneSection> Clone() const override { return std::make_unique<SceneDem>(*this); }
};

/// The scene's [dem] keys (the defaults where it gives none).
const SceneDem& dem_section(const Scene& scene);
/// The same, to change (a study's variant of a scene).
SceneDem& dem_section(Scene& scene);

/// [dem]'s keys, their older places and checks.
const SceneTable& dem_scene_table();

struct Particles;

namespace internal {

/// The n particles' diameters of a bed of size classes: whole particles per class from the
/// number fractions (largest remainders), the largest class first (the insertion order; positions
/// are drawn over the whole column, so the bed starts mixed).
std::vector<double> class_diameters(const Scene& scene, int n);

/// (mean centre height of the smallest size - that of the largest) / mean height of all, heights
/// above floor_y; 0 for one size (bubble.h, BedSample::segregation_index).
double segregation_index(const Particles& particles, double floor_y);

}  // namespace internal

}  // namespace consumers
}  // namespace draglab
