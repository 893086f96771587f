// The particle <-> cell kernels shared by the bed models that carry Lagrangian objects on the
// gas grid: a bilinear (2-D) or trilinear (3-D, the layout of mac_pressure.h) tent on the cell
// centres (the DPM's particles), and a smooth kernel of a fixed physical width (the DBM's
// bubbles), whose mapped fields converge as the grid is refined under it.
// Weight that would fall outside the grid is folded into the boundary cell, so a deposited
// quantity is conserved exactly (the mapped solids volume is the particles' volume) and the
// field stays continuous as an object crosses cell faces. Interpolation is the transpose of the
// deposition, so the force an object feels and the reaction the cells receive balance.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace draglab {
namespace consumers {
namespace internal {

/// The two cells per axis around a point and their weights (wx[0] + wx[1] = 1, same for z).
struct Tent {
  int i[2], j[2];
  double wx[2], wz[2];
};

/// The tent of the point (x, z) [m] on an nx x nz grid of cells dx x dz whose origin is the
/// grid's lower-left corner.
inline Tent TentAt(double x, double z, double dx, double dz, int nx, int nz) {
  Tent t;
  const double sx = x / dx - 0.5, sz = z / dz - 0.5;
  const double fx = std::floor(sx), fz = std::floor(sz);
  const int i0 = static_cast<int>(fx), j0 = static_cast<int>(fz);
  t.wx[1] = sx - fx;
  t.wx[0] = 1.0 - t.wx[1];
  t.wz[1] = sz - fz;
  t.wz[0] = 1.0 - t.wz[1];
  t.i[0] = std::clamp(i0, 0, nx - 1);
  t.i[1] = std::clamp(i0 + 1, 0, nx - 1);
  t.j[0] = std::clamp(j0, 0, nz - 1);
  t.j[1] = std::clamp(j0 + 1, 0, nz - 1);
  return t;
}

/// Adds `amount` to the cells of the tent, by weight.
inline void Deposit(Eigen::ArrayXXd& field, const Tent& t, double amount) {
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) field(t.i[a], t.j[b]) += amount * t.wx[a] * t.wz[b];
}

/// The field at the tent's point (the transpose of Deposit).
inline double Interpolate(const Eigen::ArrayXXd& field, const Tent& t) {
  double v = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) v += field(t.i[a], t.j[b]) * t.wx[a] * t.wz[b];
  return v;
}

/// The 3-D tent: two cells per axis around a point (x across the width, y across the depth, z
/// up) and their weights; the cell (i, j, k) is i + nx (j + nz k), j up, k across the depth.
struct Tent3 {
  int i[2], j[2], k[2];
  double wx[2], wz[2], wy[2];
  int Cell(int a, int b, int c, int nx, int nz) const { return i[a] + nx * (j[b] + nz * k[c]); }
  double Weight(int a, int b, int c) const { return wx[a] * wz[b] * wy[c]; }
};

/// The tent of the point (x, y, z) on an nx x ny x nz grid of cells dx x dy x dz.
inline Tent3 TentAt3(double x, double y, double z, double dx, double dy, double dz, int nx, int ny,
                     int nz) {
  const Tent a = TentAt(x, z, dx, dz, nx, nz);
  Tent3 t;
  for (int s = 0; s < 2; ++s) {
    t.i[s] = a.i[s];
    t.j[s] = a.j[s];
    t.wx[s] = a.wx[s];
    t.wz[s] = a.wz[s];
  }
  const double sy = y / dy - 0.5, fy = std::floor(sy);
  const int k0 = static_cast<int>(fy);
  t.wy[1] = sy - fy;
  t.wy[0] = 1.0 - t.wy[1];
  t.k[0] = std::clamp(k0, 0, ny - 1);
  t.k[1] = std::clamp(k0 + 1, 0, ny - 1);
  return t;
}

/// Adds `amount` to the cells of the 3-D tent (a flat field in the layout above), by weight.
inline void Deposit3(Eigen::VectorXd& field, const Tent3& t, double amount, int nx, int nz) {
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) field(t.Cell(a, b, c, nx, nz)) += amount * t.Weight(a, b, c);
}

/// The field at the 3-D tent's point (the transpose of Deposit3).
inline double Interpolate3(const Eigen::VectorXd& field, const Tent3& t, int nx, int nz) {
  double v = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) v += field(t.Cell(a, b, c, nx, nz)) * t.Weight(a, b, c);
  return v;
}

/// The smooth kernel: separable, each axis the cosine bell (1 + cos(pi s)) / 2, s = (x' - x) / R,
/// of radius R, integrated over each cell so the weights sum to one (to round-off) and vary
/// continuously as the point moves. Weight beyond a wall is mirrored back into the grid (no flux
/// through the wall), so a deposited quantity is conserved. The radius is at least one cell on
/// each axis: a kernel narrower than the grid cannot be represented, and at that floor it is as
/// smooth as the tent. Interpolation is the transpose of deposition.
struct Smooth3 {
  static constexpr int kMaxCells = 128;  ///< Per axis; wider radii are cut to fit.
  int count[3] = {0, 0, 0};              ///< Cells per axis (x, z, y).
  int index[3][kMaxCells];
  double weight[3][kMaxCells];
};

/// Cumulative weight of the cosine bell of unit radius up to s.
inline double CosineBellCdf(double s) {
  if (s <= -1.0) return 0.0;
  if (s >= 1.0) return 1.0;
  constexpr double kPi = 3.14159265358979323846;
  return 0.5 * (1.0 + s + std::sin(kPi * s) / kPi);
}

/// One axis of Smooth3: the cells of n cells of size h that the bell of radius r at x covers.
inline void SmoothAxis(double x, double r, double h, int n, int* index, double* weight,
                       int* count) {
  r = std::clamp(r, h, 0.5 * (Smooth3::kMaxCells - 2) * h);
  const int first = static_cast<int>(std::floor((x - r) / h));
  const int last = static_cast<int>(std::floor((x + r) / h));
  *count = 0;
  for (int c = first; c <= last; ++c) {
    // (Never below zero: at the bell's flat ends round-off could make it -1e-17.)
    const double w =
        std::max(CosineBellCdf(((c + 1) * h - x) / r) - CosineBellCdf((c * h - x) / r), 0.0);
    int m = c;
    while (m < 0 || m >= n) m = m < 0 ? -1 - m : 2 * n - 1 - m;  // mirror at the walls
    int slot = 0;
    while (slot < *count && index[slot] != m) ++slot;
    if (slot == *count) {
      index[slot] = m;
      weight[slot] = 0.0;
      ++*count;
    }
    weight[slot] += w;
  }
}

/// The smooth kernel of radius r [m] at (x, y, z) on an nx x ny x nz grid of cells dx x dy x dz.
inline Smooth3 SmoothAt3(double x, double y, double z, double r, double dx, double dy, double dz,
                         int nx, int ny, int nz) {
  Smooth3 s;
  SmoothAxis(x, r, dx, nx, s.index[0], s.weight[0], &s.count[0]);
  SmoothAxis(z, r, dz, nz, s.index[1], s.weight[1], &s.count[1]);
  SmoothAxis(y, r, dy, ny, s.index[2], s.weight[2], &s.count[2]);
  return s;
}

/// Adds `amount` to the cells of the smooth kernel (the flat layout of Tent3), by weight.
inline void Deposit3(Eigen::VectorXd& field, const Smooth3& s, double amount, int nx, int nz) {
  for (int c = 0; c < s.count[2]; ++c)
    for (int b = 0; b < s.count[1]; ++b) {
      const double w = amount * s.weight[2][c] * s.weight[1][b];
      const int base = nx * (s.index[1][b] + nz * s.index[2][c]);
      for (int a = 0; a < s.count[0]; ++a) field(base + s.index[0][a]) += w * s.weight[0][a];
    }
}

/// The field at the smooth kernel's point (the transpose of Deposit3).
inline double Interpolate3(const Eigen::VectorXd& field, const Smooth3& s, int nx, int nz) {
  double v = 0.0;
  for (int c = 0; c < s.count[2]; ++c)
    for (int b = 0; b < s.count[1]; ++b) {
      const int base = nx * (s.index[1][b] + nz * s.index[2][c]);
      double row = 0.0;
      for (int a = 0; a < s.count[0]; ++a) row += field(base + s.index[0][a]) * s.weight[0][a];
      v += row * s.weight[2][c] * s.weight[1][b];
    }
  return v;
}

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
