// cell_list.h (private): a periodic cell list that enumerates every periodic image of every
// sphere near a point, whatever the box size.
//
// The box is cut into n_a cells of edge h_a = L_a / n_a >= the requested minimum per axis. A
// query walks the unwrapped cell indices u covering [p - reach, p + reach]; cell u holds the
// spheres of cell (u mod n_a), seen through the image shift floor(u / n_a) * L_a. Each
// (sphere, image) pair therefore appears exactly once, also when the reach exceeds half the box
// (small N, where a sphere may touch several images of a neighbour or its own images). The caller
// tests the actual distance; the list only limits the candidates.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "draglab/arrays/packing.h"

namespace draglab {
namespace arrays {
namespace internal {

class PeriodicCellList {
 public:
  /// box: edge lengths (> 0). min_cell_edge: smallest allowed cell edge (> 0). expected_count:
  /// number of spheres; the cell count is capped near 2 * expected_count + 27 so that dilute
  /// packings do not allocate huge empty grids.
  PeriodicCellList(const Vec3& box, double min_cell_edge, std::size_t expected_count) : box_(box) {
    const double volume = box[0] * box[1] * box[2];
    const double cap_edge = std::cbrt(volume / (2.0 * static_cast<double>(expected_count) + 27.0));
    const double edge = std::max(min_cell_edge, cap_edge);
    for (int a = 0; a < 3; ++a) {
      counts_[a] = std::max(1, static_cast<int>(std::floor(box[a] / edge)));
      cell_edge_[a] = box[a] / counts_[a];
    }
    cells_.resize(static_cast<std::size_t>(counts_[0]) * counts_[1] * counts_[2]);
  }

  /// Rebuilds the list; spheres within a cell are kept in index order (deterministic queries).
  void Build(const std::vector<Vec3>& centers) {
    for (auto& cell : cells_) cell.clear();
    cell_of_.resize(centers.size());
    for (std::size_t i = 0; i < centers.size(); ++i) {
      const std::size_t c = CellOf(centers[i]);
      cell_of_[i] = c;
      cells_[c].push_back(static_cast<int>(i));
    }
  }

  /// Moves sphere i to `position` (which must already be wrapped into the box).
  void Move(int i, const Vec3& position) {
    const std::size_t c = CellOf(position);
    const std::size_t old = cell_of_[static_cast<std::size_t>(i)];
    if (c == old) return;
    auto& members = cells_[old];
    members.erase(std::find(members.begin(), members.end(), i));
    cells_[c].push_back(i);
    cell_of_[static_cast<std::size_t>(i)] = c;
  }

  /// Calls fn(j, shift) for every sphere j and image shift (a multiple of the box edges per axis)
  /// such that the image c_j + shift may lie within `reach` of p (a superset: the caller checks).
  /// p must lie in the box (rounding at the upper edge is tolerated).
  template <class Fn>
  void ForEachNear(const Vec3& p, double reach, Fn&& fn) const {
    AnyNear(p, reach, [&fn](int j, const Vec3& shift) {
      fn(j, shift);
      return false;
    });
  }

  /// True as soon as pred(j, shift) is true for a candidate of ForEachNear(p, reach, ...);
  /// stops the walk there.
  template <class Pred>
  bool AnyNear(const Vec3& p, double reach, Pred&& pred) const {
    int lo[3], hi[3];
    // The slack covers rounding in p / h; it only adds candidates, never removes one.
    const double slack = 1e-9;
    for (int a = 0; a < 3; ++a) {
      lo[a] = static_cast<int>(std::floor((p[a] - reach) / cell_edge_[a] - slack));
      hi[a] = static_cast<int>(std::floor((p[a] + reach) / cell_edge_[a] + slack));
    }
    for (int uz = lo[2]; uz <= hi[2]; ++uz) {
      const int wz = Wrap(uz, counts_[2]);
      const double sz = static_cast<double>(FloorDiv(uz, counts_[2])) * box_[2];
      for (int uy = lo[1]; uy <= hi[1]; ++uy) {
        const int wy = Wrap(uy, counts_[1]);
        const double sy = static_cast<double>(FloorDiv(uy, counts_[1])) * box_[1];
        const std::size_t row = static_cast<std::size_t>(counts_[0]) * (wy + counts_[1] * wz);
        for (int ux = lo[0]; ux <= hi[0]; ++ux) {
          const int wx = Wrap(ux, counts_[0]);
          const double sx = static_cast<double>(FloorDiv(ux, counts_[0])) * box_[0];
          const Vec3 shift{sx, sy, sz};
          for (int j : cells_[row + static_cast<std::size_t>(wx)]) {
            if (pred(j, shift)) return true;
          }
        }
      }
    }
    return false;
  }

  const std::array<int, 3>& counts() const { return counts_; }

 private:
  static int FloorDiv(int u, int n) { return u >= 0 ? u / n : -((-u + n - 1) / n); }
  static int Wrap(int u, int n) { return u - FloorDiv(u, n) * n; }

  std::size_t CellOf(const Vec3& p) const {
    std::size_t index = 0;
    for (int a = 2; a >= 0; --a) {
      int c = static_cast<int>(std::floor(p[a] / cell_edge_[a]));
      c = std::min(std::max(c, 0), counts_[a] - 1);
      index = index * static_cast<std::size_t>(counts_[a]) + static_cast<std::size_t>(c);
    }
    return index;
  }

  Vec3 box_;
  std::array<int, 3> counts_{1, 1, 1};
  Vec3 cell_edge_{1.0, 1.0, 1.0};
  std::vector<std::vector<int>> cells_;
  std::vector<std::size_t> cell_of_;
};

/// Wraps x into [0, length): the result is never equal to length (rounding of x + length).
inline double wrap_into_box(double x, double length) {
  x -= length * std::floor(x / length);
  if (x >= length || x < 0.0) x = 0.0;
  return x;
}

}  // namespace internal
}  // namespace arrays
}  // namespace draglab
