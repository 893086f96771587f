// What every bed model takes from a scene the same way: the gas grid, gas and inflow (the
// scene -> GasOptions mapping), the bubble criterion, and a cell field on the scene's grid as
// bubble.h's GridField2D (x across, y = the model's z up).
#pragma once

#include <Eigen/Core>

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

/// A cell field (nx x nz, Eigen index (i, j)) on the scene's grid as a GridField2D.
GridField2D scene_grid_field(const Scene& scene, const Eigen::ArrayXXd& values);

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
