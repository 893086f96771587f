// The particle <-> cell kernel shared by the bed models that carry Lagrangian objects on the
// gas grid (the DPM's particles, later the DBM's bubbles): a bilinear tent on the cell centres.
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

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
