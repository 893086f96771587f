// The shared staggered-grid operators (consumers/src/gas/mac_operators.h) and the particle <->
// cell kernel (particle_kernel.h) against closed forms.
//
// (1) Consistency: second differences are exact for quadratics and one-sided (upwind)
//     differences for linear fields, so on a uniform-eps grid the viscous term of
//     u = a + b x^2 + c z^2 is mu (2 b + 2 c) and the advection of linear fields is
//     u du/dx + w du/dz, both to round-off at interior faces.
// (2) Flux form: div(eps mu grad u) of a linear u with a linear eps is mu (du/dx)(d eps/dx).
// (3) Boundaries: a uniform tangential velocity U next to a no-slip wall feels the wall stress
//     mu U / (h/2) over its cell, -2 mu U / h^2; next to a free-slip wall, none; with periodic
//     z the row below the first is the last.
// (4) Kernel: a deposit conserves the amount wherever the point lies (walls included), the
//     interpolation of a linear field is exact between the first and last cell centres, and
//     interpolation is the transpose of deposition (the action-reaction balance of the DPM).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "gas/mac_operators.h"
#include "gas/particle_kernel.h"

namespace draglab {
namespace consumers {
namespace {

using internal::FaceMomentumTerms;
using internal::MacGasOperators;

constexpr int kNx = 6, kNz = 8;
constexpr double kDx = 0.01, kDz = 0.02, kMu = 2.0;

double XFaceX(int i) { return i * kDx; }
double CellZ(int j) { return (j + 0.5) * kDz; }
double CellX(int i) { return (i + 0.5) * kDx; }
double ZFaceZ(int j) { return j * kDz; }

TEST(MacOperators, ViscousTermIsExactForQuadratics) {
  Eigen::ArrayXXd u(kNx + 1, kNz), w = Eigen::ArrayXXd::Zero(kNx, kNz + 1);
  const Eigen::ArrayXXd eps = Eigen::ArrayXXd::Ones(kNx, kNz);
  const double b = 3.0, c = -1.5;
  for (int j = 0; j < kNz; ++j)
    for (int i = 0; i <= kNx; ++i)
      u(i, j) = 0.7 + b * XFaceX(i) * XFaceX(i) + c * CellZ(j) * CellZ(j);
  const MacGasOperators ops(u, w, eps, kDx, kDz, kMu, true, false);
  for (int j = 1; j < kNz - 1; ++j)
    for (int i = 1; i < kNx; ++i)
      EXPECT_NEAR(ops.XFace(i, j).viscous, kMu * (2.0 * b + 2.0 * c), 1e-9) << i << " " << j;
  // The same for w on the z-faces (the outlet face j = nz has its own zero-gradient ghost).
  Eigen::ArrayXXd u0 = Eigen::ArrayXXd::Zero(kNx + 1, kNz), wq(kNx, kNz + 1);
  for (int j = 0; j <= kNz; ++j)
    for (int i = 0; i < kNx; ++i)
      wq(i, j) = -0.2 + b * CellX(i) * CellX(i) + c * ZFaceZ(j) * ZFaceZ(j);
  const MacGasOperators opz(u0, wq, eps, kDx, kDz, kMu, true, false);
  for (int j = 1; j < kNz; ++j)
    for (int i = 1; i < kNx - 1; ++i)
      EXPECT_NEAR(opz.ZFace(i, j).viscous, kMu * (2.0 * b + 2.0 * c), 1e-9) << i << " " << j;
}

TEST(MacOperators, UpwindAdvectionIsExactForLinearFields) {
  Eigen::ArrayXXd u(kNx + 1, kNz), w(kNx, kNz + 1);
  const Eigen::ArrayXXd eps = Eigen::ArrayXXd::Ones(kNx, kNz);
  // u = 1 + 3 x + 0.5 z, w = 0.2 - 4 x + 2 z: both signs of both components occur.
  for (int j = 0; j < kNz; ++j)
    for (int i = 0; i <= kNx; ++i) u(i, j) = 1.0 - 30.0 * XFaceX(i) + 0.5 * CellZ(j);
  for (int j = 0; j <= kNz; ++j)
    for (int i = 0; i < kNx; ++i) w(i, j) = 0.2 - 4.0 * CellX(i) + 2.0 * ZFaceZ(j);
  const MacGasOperators ops(u, w, eps, kDx, kDz, kMu, true, false);
  for (int j = 1; j < kNz - 1; ++j)
    for (int i = 1; i < kNx; ++i) {
      const double x = XFaceX(i), z = CellZ(j);
      const double uu = 1.0 - 30.0 * x + 0.5 * z, ww = 0.2 - 4.0 * x + 2.0 * z;
      EXPECT_NEAR(ops.XFace(i, j).advection, uu * -30.0 + ww * 0.5, 1e-9) << i << " " << j;
    }
  for (int j = 1; j < kNz; ++j)
    for (int i = 1; i < kNx - 1; ++i) {
      const double x = CellX(i), z = ZFaceZ(j);
      const double uu = 1.0 - 30.0 * x + 0.5 * z, ww = 0.2 - 4.0 * x + 2.0 * z;
      EXPECT_NEAR(ops.ZFace(i, j).advection, uu * -4.0 + ww * 2.0, 1e-9) << i << " " << j;
    }
}

TEST(MacOperators, ViscousTermWeightsTheFluxesWithEps) {
  Eigen::ArrayXXd u(kNx + 1, kNz), w = Eigen::ArrayXXd::Zero(kNx, kNz + 1), eps(kNx, kNz);
  for (int j = 0; j < kNz; ++j) {
    for (int i = 0; i <= kNx; ++i) u(i, j) = 2.0 * XFaceX(i);
    for (int i = 0; i < kNx; ++i) eps(i, j) = 0.4 + 5.0 * CellX(i);
  }
  const MacGasOperators ops(u, w, eps, kDx, kDz, kMu, true, false);
  for (int j = 1; j < kNz - 1; ++j)
    for (int i = 1; i < kNx; ++i) EXPECT_NEAR(ops.XFace(i, j).viscous, kMu * 2.0 * 5.0, 1e-9);
}

TEST(MacOperators, WallsGhostsAndPeriodicity) {
  const double U = 0.3;
  const Eigen::ArrayXXd eps = Eigen::ArrayXXd::Ones(kNx, kNz);
  const Eigen::ArrayXXd u = Eigen::ArrayXXd::Constant(kNx + 1, kNz, U);
  const Eigen::ArrayXXd w0 = Eigen::ArrayXXd::Zero(kNx, kNz + 1);
  // Bottom plate (no slip for the tangential u): the wall stress over the first row.
  const MacGasOperators bottom(u, w0, eps, kDx, kDz, kMu, true, false);
  EXPECT_NEAR(bottom.XFace(2, 0).viscous, -2.0 * kMu * U / (kDz * kDz), 1e-9);
  EXPECT_NEAR(bottom.XFace(2, 3).viscous, 0.0, 1e-9);
  EXPECT_NEAR(bottom.XFace(2, kNz - 1).viscous, 0.0, 1e-9) << "outlet: zero gradient";
  // Periodic in z: no wall at all.
  const MacGasOperators periodic(u, w0, eps, kDx, kDz, kMu, true, true);
  EXPECT_NEAR(periodic.XFace(2, 0).viscous, 0.0, 1e-9);
  // Side walls for the tangential w: no slip or free slip.
  const Eigen::ArrayXXd u0 = Eigen::ArrayXXd::Zero(kNx + 1, kNz);
  const Eigen::ArrayXXd w = Eigen::ArrayXXd::Constant(kNx, kNz + 1, U);
  const MacGasOperators noslip(u0, w, eps, kDx, kDz, kMu, true, false);
  const MacGasOperators freeslip(u0, w, eps, kDx, kDz, kMu, false, false);
  EXPECT_NEAR(noslip.ZFace(0, 3).viscous, -2.0 * kMu * U / (kDx * kDx), 1e-9);
  EXPECT_NEAR(noslip.ZFace(kNx - 1, 3).viscous, -2.0 * kMu * U / (kDx * kDx), 1e-9);
  EXPECT_NEAR(noslip.ZFace(2, 3).viscous, 0.0, 1e-9);
  EXPECT_NEAR(freeslip.ZFace(0, 3).viscous, 0.0, 1e-9);
}

TEST(ParticleKernel, DepositConservesInterpolationIsExactAndTransposed) {
  using internal::Deposit;
  using internal::Interpolate;
  using internal::TentAt;
  const double points[][2] = {{0.001, 0.002}, {0.031, 0.077}, {0.0599, 0.159}, {0.025, 0.05}};
  for (const auto& pt : points) {
    Eigen::ArrayXXd field = Eigen::ArrayXXd::Zero(kNx, kNz);
    Deposit(field, TentAt(pt[0], pt[1], kDx, kDz, kNx, kNz), 2.5);
    EXPECT_NEAR(field.sum(), 2.5, 1e-14) << pt[0] << " " << pt[1];
    EXPECT_GE(field.minCoeff(), 0.0);
  }
  Eigen::ArrayXXd linear(kNx, kNz), f(kNx, kNz);
  for (int j = 0; j < kNz; ++j)
    for (int i = 0; i < kNx; ++i) {
      linear(i, j) = 1.0 + 7.0 * CellX(i) - 3.0 * CellZ(j);
      f(i, j) = std::sin(1.0 + i) * std::cos(0.3 * j);
    }
  const double x = 0.031, z = 0.077;
  const internal::Tent t = TentAt(x, z, kDx, kDz, kNx, kNz);
  EXPECT_NEAR(Interpolate(linear, t), 1.0 + 7.0 * x - 3.0 * z, 1e-12);
  Eigen::ArrayXXd delta = Eigen::ArrayXXd::Zero(kNx, kNz);
  Deposit(delta, t, 1.0);
  EXPECT_NEAR((f * delta).sum(), Interpolate(f, t), 1e-14);
}

// The DBM's smooth kernel (particle_kernel.h Smooth3): the separable cosine bell of radius R,
// (1 + cos(pi s)) / 2 / R per axis, integrated over the cells, mirrored at the walls.
// References: the weights sum to one (the bell's integral) to round-off, anywhere in the grid,
// however wide the bell against the grid; deposition and interpolation are transposes; and, the
// property the DBM needs, the mapped density converges to the continuous bell at second order
// in h as the grid is refined under a fixed R (cell averages of a smooth function).
double Bell(double s) { return std::abs(s) < 1.0 ? 0.5 * (1.0 + std::cos(M_PI * s)) : 0.0; }

TEST(SmoothKernel, ConservesEverywhereAndIsTheTransposeOfInterpolation) {
  const int nx = 10, ny = 3, nz = 20;
  const double h = 0.05;
  const double points[][3] = {{0.25, 0.07, 0.5}, {0.004, 0.001, 0.02}, {0.499, 0.149, 0.999}};
  for (double r : {0.01, 0.1, 0.4}) {  // below a cell (floored to one), 2 cells, past the depth
    for (const auto& p : points) {
      Eigen::VectorXd field = Eigen::VectorXd::Zero(nx * ny * nz);
      const internal::Smooth3 s = internal::SmoothAt3(p[0], p[1], p[2], r, h, h, h, nx, ny, nz);
      internal::Deposit3(field, s, 2.5, nx, nz);
      EXPECT_NEAR(field.sum(), 2.5, 1e-13) << "r " << r << " at " << p[0] << " " << p[2];
      EXPECT_GE(field.minCoeff(), 0.0);
      Eigen::VectorXd f(field.size());
      for (int c = 0; c < f.size(); ++c) f(c) = std::sin(1.0 + c) * std::cos(0.3 * c);
      EXPECT_NEAR(f.dot(field) / 2.5, internal::Interpolate3(f, s, nx, nz), 1e-13);
    }
  }
  // Continuous as the point moves: a shift of 1e-6 cells moves no weight by more than ~1e-6.
  const internal::Smooth3 a = internal::SmoothAt3(0.25, 0.07, 0.5, 0.1, h, h, h, nx, ny, nz);
  const internal::Smooth3 b =
      internal::SmoothAt3(0.25 + 1e-6 * h, 0.07, 0.5, 0.1, h, h, h, nx, ny, nz);
  auto by_cell = [&](const internal::Smooth3& s) {
    std::vector<double> w(nx, 0.0);
    for (int i = 0; i < s.count[0]; ++i) w[s.index[0][i]] += s.weight[0][i];
    return w;
  };
  const std::vector<double> wa = by_cell(a), wb = by_cell(b);
  for (int i = 0; i < nx; ++i) EXPECT_NEAR(wa[i], wb[i], 1e-5) << i;
}

TEST(SmoothKernel, MappedDensityConvergesUnderAFixedWidth) {
  // A unit amount at (0.31, 0.43, 0.57) m in a 1 m cube, R = 0.2 m; the density in each cell
  // against the continuous bell product at the cell centre, on 10, 20, 40 cells per side.
  const double x = 0.31, y = 0.43, z = 0.57, r = 0.2;
  std::vector<double> errors;
  for (int n : {10, 20, 40}) {
    const double h = 1.0 / n;
    Eigen::VectorXd field = Eigen::VectorXd::Zero(n * n * n);
    internal::Deposit3(field, internal::SmoothAt3(x, y, z, r, h, h, h, n, n, n), 1.0, n, n);
    double error = 0.0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double exact = Bell(((i + 0.5) * h - x) / r) * Bell(((k + 0.5) * h - y) / r) *
                               Bell(((j + 0.5) * h - z) / r) / (r * r * r);
          error = std::max(error, std::abs(field(i + n * (j + n * k)) / (h * h * h) - exact));
        }
    errors.push_back(error);
  }
  // Second order: each halving divides the error by about four (3 allows for the bell's
  // weaker smoothness at its edge, where its second derivative jumps).
  EXPECT_GT(errors[0] / errors[1], 3.0) << errors[0] << " " << errors[1];
  EXPECT_GT(errors[1] / errors[2], 3.0) << errors[1] << " " << errors[2];
  EXPECT_LT(errors[2], 0.02 / (r * r * r)) << "2 % of the peak density on 40 cells";
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
