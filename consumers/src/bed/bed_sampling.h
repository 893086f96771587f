// What every bed model takes from a scene the same way: the gas grid, gas and inflow (the
// scene -> GasOptions mapping), the bubble criterion, and a cell field on the scene's grid as
// bubble.h's GridField2D (x across, y = the model's z up).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/bubble.h"
#include "draglab/consumers/gas_phase.h"
#include "draglab/consumers/scene.h"

namespace draglab {
namespace consumers {
namespace internal {

/// The gas phase of a scene: its grid, gas, gravity (down), no-slip side walls, the
/// distributor at `background_m_s` (superficial) and, when `with_jet`, the jet; both ramped by
/// the jet's ramp_s.
GasOptions scene_gas_options(const Scene& scene, double background_m_s, bool with_jet);

/// The scene's [bubble] criterion around its jet (a column at least one cell wide), with the
/// bed's initial height for the expansion ratio.
BubbleOptions scene_bubble_options(const Scene& scene, double initial_bed_height_m);

/// Where a run writes the files its scene asks for: `override` (BedRunOptions), else the
/// scene's [outputs] directory, else out/<scene name>.
std::string scene_output_directory(const Scene& scene, const std::string& override_directory);

/// A result with the header every model fills the same way: the model's key, the law
/// (name@version), the scene, its hash and eps_mf, and how the background flow is set.
BedResult result_header(const std::string& model, const Scene& scene,
                        const std::string& law_reference, const std::string& background_mode);

/// The sample times of a run of `duration_s` [s]: every `interval_s` [s] from the first
/// interval on (a time within 1e-9 of an interval past the end still counts; the last time is
/// cut to the duration).
std::vector<double> sample_times(double duration_s, double interval_s);

/// A cell field (nx x nz, Eigen index (i, j)) on the scene's grid as a GridField2D.
GridField2D scene_grid_field(const Scene& scene, const Eigen::ArrayXXd& values);

/// The "snapshot" entry of a model's result JSON: the bubble of the sample nearest t_ref.
nlohmann::json snapshot_json(double t_s, const BubbleMetrics& bubble);

/// The bubble sampling every bed model does: at each sample time, the bubble in the gas
/// fraction (the scene's criterion), the bed height and the pressure drop, and whether the
/// sample is the nearest to t_ref so far (the one the result reports; a sample counts only
/// within half a sample interval of t_ref).
class BedSampler {
 public:
  BedSampler(const Scene& scene, double initial_bed_height_m);

  struct Taken {
    BedSample sample;
    BubbleMetrics bubble;
    bool nearest_to_ref = false;
  };
  /// A sample at the model's time t_abs [s] (the jet starts at scene.jet.start_s) from its gas
  /// fraction (nx x nz) and width-averaged pressure drop.
  Taken Take(double t_abs, const Eigen::ArrayXXd& gas_fraction, double pressure_drop_pa);

 private:
  const Scene& scene_;
  BubbleOptions bubble_;
  double t_ref_abs_;
  double best_gap_;
};

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
