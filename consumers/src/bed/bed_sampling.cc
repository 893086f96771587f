// Shared sampling of the bed models (bed/bed_sampling.h).
#include "bed/bed_sampling.h"

#include <algorithm>
#include <cstddef>

namespace draglab {
namespace consumers {
namespace internal {

BubbleOptions scene_bubble_options(const Scene& s, double initial_bed_height_m) {
  BubbleOptions bo;
  bo.eps_threshold = s.bubble.eps_threshold;
  const double dx = s.geometry.width_m / s.grid.cells_x;
  const double half = std::max(0.5 * s.jet.slot_width_m, 0.5 * dx);
  bo.jet_x_min_m = s.jet_center_m() - half;
  bo.jet_x_max_m = s.jet_center_m() + half;
  bo.bed_height_initial_m = initial_bed_height_m;
  return bo;
}

GridField2D scene_grid_field(const Scene& scene, const Eigen::ArrayXXd& values) {
  GridField2D f;
  f.nx = scene.grid.cells_x;
  f.ny = scene.grid.cells_y;
  f.width_m = scene.geometry.width_m;
  f.height_m = scene.geometry.height_m;
  f.values.resize(static_cast<std::size_t>(f.nx) * f.ny);
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) f.values[static_cast<std::size_t>(j) * f.nx + i] = values(i, j);
  return f;
}

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
