// What every bed model samples the same way: the bubble criterion of a scene and a cell field
// on the scene's grid as bubble.h's GridField2D (x across, y = the model's z up).
#pragma once

#include <Eigen/Core>

#include "draglab/consumers/bubble.h"
#include "draglab/consumers/scene.h"

namespace draglab {
namespace consumers {
namespace internal {

/// The scene's [bubble] criterion around its jet (a column at least one cell wide), with the
/// bed's initial height for the expansion ratio.
BubbleOptions scene_bubble_options(const Scene& scene, double initial_bed_height_m);

/// A cell field (nx x nz, Eigen index (i, j)) on the scene's grid as a GridField2D.
GridField2D scene_grid_field(const Scene& scene, const Eigen::ArrayXXd& values);

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
