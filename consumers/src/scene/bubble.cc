// Bubble metrics from a gas-fraction field (bubble.h): 4-connected flood fill inside the bed.
#include "draglab/consumers/bubble.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/error.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fail;
using scene_util::fmt;
using scene_util::kPi;

}  // namespace

bool GridField2D::IsValid(std::string* error) const {
  if (nx < 1 || ny < 1) {
    return fail(error, "field nx, ny = " + std::to_string(nx) + ", " + std::to_string(ny) +
                           " must be >= 1");
  }
  if (!(std::isfinite(width_m) && width_m > 0.0 && std::isfinite(height_m) && height_m > 0.0)) {
    return fail(
        error, "field width_m, height_m = " + fmt(width_m) + ", " + fmt(height_m) + " must be > 0");
  }
  if (values.size() != static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny)) {
    return fail(error, "field values has " + std::to_string(values.size()) + " entries, nx*ny = " +
                           std::to_string(static_cast<long long>(nx) * ny) + " expected");
  }
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k]) || values[k] < 0.0 || values[k] > 1.0 + 1e-9) {
      return fail(error, "field values[" + std::to_string(k) + "] = " + fmt(values[k]) +
                             " is not a gas fraction in [0, 1]");
    }
  }
  return true;
}

bool BubbleOptions::IsValid(std::string* error) const {
  if (!(eps_threshold > 0.0 && eps_threshold < 1.0)) {
    return fail(error, "eps_threshold = " + fmt(eps_threshold) + " is outside (0, 1)");
  }
  if (!(bed_eps > 0.0 && bed_eps < 1.0)) {
    return fail(error, "bed_eps = " + fmt(bed_eps) + " is outside (0, 1)");
  }
  if (!(std::isfinite(seed_x_m) && std::isfinite(seed_y_m) && std::isfinite(jet_x_min_m) &&
        std::isfinite(jet_x_max_m))) {
    return fail(error, "seed_x_m, seed_y_m, jet_x_min_m, jet_x_max_m must be finite");
  }
  if (seed_y_m < 0.0 && !(jet_x_max_m >= jet_x_min_m)) {
    return fail(error, "jet_x_max_m = " + fmt(jet_x_max_m) + " must be >= jet_x_min_m = " +
                           fmt(jet_x_min_m) + " (no seed point given)");
  }
  if (!(bed_height_initial_m >= 0.0 && std::isfinite(bed_height_initial_m))) {
    return fail(error,
                "bed_height_initial_m = " + fmt(bed_height_initial_m) + " is outside [0, inf)");
  }
  return true;
}

std::string BubbleMetrics::BriefReport() const {
  std::ostringstream s;
  s.precision(4);
  if (!found) {
    s << "no bubble (" << regions_above_threshold << " regions above the threshold), bed height "
      << bed_height_m << " m";
    return s.str();
  }
  s << "bubble D = " << diameter_m << " m (A = " << area_m2 << " m^2, " << cells
    << " cells), centroid (" << centroid_x_m << ", " << centroid_y_m << ") m, spans " << bottom_m
    << "-" << top_m << " m" << (touches_surface ? " (erupting)" : "") << "; bed height "
    << bed_height_m << " m";
  if (bed_expansion > 0.0) s << " (expansion " << bed_expansion << ")";
  return s.str();
}

BubbleMetrics measure_bubble(const GridField2D& field, const BubbleOptions& options) {
  std::string error;
  if (!field.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  const int nx = field.nx, ny = field.ny;
  const double dx = field.dx(), dy = field.dy();
  BubbleMetrics m;

  // Bed surface: the top face of the highest row whose width-averaged eps <= bed_eps. Bubbles
  // are searched below it only, so the freeboard (eps = 1) is never taken for a bubble.
  int bed_rows = 0;
  for (int j = 0; j < ny; ++j) {
    double sum = 0.0;
    for (int i = 0; i < nx; ++i) sum += field.at(i, j);
    if (sum / nx <= options.bed_eps) bed_rows = j + 1;
  }
  m.bed_height_m = bed_rows * dy;
  if (options.bed_height_initial_m > 0.0)
    m.bed_expansion = m.bed_height_m / options.bed_height_initial_m;

  // Label the 4-connected regions with eps > threshold inside the bed.
  std::vector<int> label(static_cast<std::size_t>(nx) * ny, -1);
  std::vector<int> region_cells;
  std::vector<int> stack;
  auto index = [nx](int i, int j) { return static_cast<std::size_t>(j) * nx + i; };
  for (int j = 0; j < bed_rows; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (label[index(i, j)] >= 0 || !(field.at(i, j) > options.eps_threshold)) continue;
      const int id = static_cast<int>(region_cells.size());
      region_cells.push_back(0);
      stack.assign(1, static_cast<int>(index(i, j)));
      label[index(i, j)] = id;
      while (!stack.empty()) {
        const int k = stack.back();
        stack.pop_back();
        ++region_cells[id];
        const int ci = k % nx, cj = k / nx;
        const int ni[4] = {ci - 1, ci + 1, ci, ci};
        const int nj[4] = {cj, cj, cj - 1, cj + 1};
        for (int q = 0; q < 4; ++q) {
          if (ni[q] < 0 || ni[q] >= nx || nj[q] < 0 || nj[q] >= bed_rows) continue;
          const std::size_t n = index(ni[q], nj[q]);
          if (label[n] >= 0 || !(field.values[n] > options.eps_threshold)) continue;
          label[n] = id;
          stack.push_back(static_cast<int>(n));
        }
      }
    }
  }
  m.regions_above_threshold = static_cast<int>(region_cells.size());

  int chosen = -1;
  if (options.seed_y_m >= 0.0) {
    const int i = static_cast<int>(std::floor(options.seed_x_m / dx));
    const int j = static_cast<int>(std::floor(options.seed_y_m / dy));
    if (i >= 0 && i < nx && j >= 0 && j < ny) chosen = label[index(i, j)];
  } else {
    for (int j = 0; j < bed_rows; ++j) {
      for (int i = 0; i < nx; ++i) {
        const double xc = (i + 0.5) * dx;
        if (xc < options.jet_x_min_m || xc > options.jet_x_max_m) continue;
        const int id = label[index(i, j)];
        if (id >= 0 && (chosen < 0 || region_cells[id] > region_cells[chosen])) chosen = id;
      }
    }
  }
  if (chosen < 0) return m;

  m.found = true;
  double sx = 0.0, sy = 0.0;
  int top = -1, bottom = ny;
  for (int j = 0; j < bed_rows; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (label[index(i, j)] != chosen) continue;
      ++m.cells;
      sx += (i + 0.5) * dx;
      sy += (j + 0.5) * dy;
      top = std::max(top, j);
      bottom = std::min(bottom, j);
    }
  }
  m.area_m2 = m.cells * dx * dy;
  m.diameter_m = std::sqrt(4.0 * m.area_m2 / kPi);
  m.centroid_x_m = sx / m.cells;
  m.centroid_y_m = sy / m.cells;
  m.top_m = (top + 1) * dy;
  m.bottom_m = bottom * dy;
  m.touches_surface = top == bed_rows - 1;
  return m;
}

}  // namespace consumers
}  // namespace draglab
