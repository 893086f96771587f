// The discrete bubble model's table of scene files, [dbm] (docs/scenes.md, docs/dbm.md): its
// keys, defaults and checks. Registered through the DBM's BedModel::scene_table; nothing
// outside consumers/src/dbm and its bed model reads it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"

namespace draglab {
namespace consumers {

/// [dbm]: the discrete bubble model (read only with solver = "dbm", which requires the table;
/// dbm.h, docs/dbm.md). The emulsion fills the column; its top is the bed surface.
struct SceneDbm : SceneSection {
  double superficial_velocity_m_s = 0.1;  ///< u0, (0, 10]; bubbles carry (u0 - U_mf) A.
  double emulsion_density_kg_m3 = 400.0;  ///< (bubble density, 20000].
  double emulsion_viscosity_pa_s = 1.0;   ///< Apparent viscosity, (0, 1000].
  double bubble_density_kg_m3 = 25.0;     ///< (0, emulsion density).
  /// Injected size [m], (0, column); 0: Davidson-Harrison from each nozzle's flow.
  double bubble_diameter_m = 0.04;
  int nozzles_per_side = 7;     ///< A square of n x n nozzles centred on the bottom, [1, 100].
  double nozzle_pitch_m = 0.1;  ///< Their spacing, > 0; the square must fit the bottom.
  double virtual_mass_coefficient = 0.5;  ///< [0, 10].
  bool lift = false;
  double lift_coefficient = 0.5;  ///< [-1, 1], with lift = true.
  /// Width of the kernel mapping bubbles to cells [m], [0, column]; 0: 5 injected diameters.
  double coupling_width_m = 0.0;
  bool coalescence = false;
  double film_drainage_s = 0.0;    ///< [0, 10].
  bool collisions = true;          ///< Without coalescence: overlapping bubbles pushed apart.
  double dt_s = 2e-3;              ///< Fixed step, (0, the stability limit].
  double cfl = 0.0;                ///< > 0: the step is cut to this emulsion CFL, (0, 0.9].
  double injection_ramp_s = 0.0;   ///< Start-up ramp of the bubble flow, [0, duration_s).
  std::string walls = "no_slip";   ///< Or "free_slip": the emulsion at the side walls.
  double average_from_s = 10.0;    ///< Time averages from here, [0, duration_s).
  double sample_interval_s = 0.1;  ///< Bubble samples, (0, duration_s].
  std::vector<double> size_heights_m = {1.0, 2.0};  ///< Where mean sizes are reported.

  std::unique_ptr<SceneSection> Clone() const override { return std::make_unique<SceneDbm>(*this); }
};

/// The scene's [dbm] table (the defaults when it has none).
const SceneDbm& dbm_section(const Scene& scene);
/// The same, to change (a study's variant of a scene).
SceneDbm& dbm_section(Scene& scene);

/// [dbm]'s keys and checks.
const SceneTable& dbm_scene_table();

}  // namespace consumers
}  // namespace draglab
