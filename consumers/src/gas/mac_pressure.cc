// The pressure equation of the MAC-grid projections (consumers/src/gas/mac_pressure.h).
#include "gas/mac_pressure.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cstdio>
#include <string>
#include <vector>

#include "draglab/error.h"

namespace draglab {
namespace consumers {

struct MacPressureSolver::Cache {
  std::vector<double> coefficients;    // C_f of every face: the matrix is reused when unchanged
  Eigen::SparseMatrix<double> matrix;  // the full operator (for the residual)
  Eigen::SparseMatrix<double> solver_matrix;  // pinned copy; CG keeps a reference to it
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  // LDLT ordering and symbolic analysis done: the pattern never changes, only the values.
  bool ordered = false;
};

MacPressureSolver::MacPressureSolver(const MacPressureOptions& options)
    : opt_(options), cache_(std::make_unique<Cache>()) {
  if (opt_.nx < 1 || opt_.ny < 1 || opt_.nz < 1 || !(opt_.dx > 0.0) || !(opt_.dy > 0.0) ||
      !(opt_.dz > 0.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "pressure equation: the grid needs nx, ny, nz >= 1 and dx, dy, dz > 0");
  }
}

MacPressureSolver::~MacPressureSolver() = default;
MacPressureSolver::MacPressureSolver(MacPressureSolver&&) noexcept = default;
MacPressureSolver& MacPressureSolver::operator=(MacPressureSolver&&) noexcept = default;

Eigen::ArrayXXd MacPressureSolver::Solve(const Eigen::ArrayXXd& c_u, const Eigen::ArrayXXd& c_w,
                                         const Eigen::ArrayXXd& continuity_residual,
                                         double outlet_pressure_pa, const Eigen::ArrayXXd& guess) {
  const int nx = opt_.nx, nz = opt_.nz;
  auto shape = [](const Eigen::ArrayXXd& a, int rows, int cols, const char* name) {
    if (a.rows() != rows || a.cols() != cols)
      throw Error(ErrorCode::kInvalidArgument,
                  std::string("pressure equation: ") + name + " has " + std::to_string(a.rows()) +
                      " x " + std::to_string(a.cols()) + " entries, expected " +
                      std::to_string(rows) + " x " + std::to_string(cols));
  };
  if (opt_.ny != 1)
    throw Error(ErrorCode::kInvalidArgument,
                "pressure equation: the 2-D arrays need ny = 1 (use the 3-D overload)");
  shape(c_u, nx + 1, nz, "c_u");
  shape(c_w, nx, nz + 1, "c_w");
  shape(continuity_residual, nx, nz, "continuity_residual");
  shape(guess, nx, nz, "guess");
  auto flat = [](const Eigen::ArrayXXd& a) {
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(a.data(), a.size()));
  };
  const Eigen::VectorXd p = Solve(flat(c_u), Eigen::VectorXd::Zero(2 * nx * nz), flat(c_w),
                                  flat(continuity_residual), outlet_pressure_pa, flat(guess));
  return Eigen::Map<const Eigen::ArrayXXd>(p.data(), nx, nz);
}

Eigen::VectorXd MacPressureSolver::Solve(const Eigen::VectorXd& c_x, const Eigen::VectorXd& c_y,
                                         const Eigen::VectorXd& c_z,
                                         const Eigen::VectorXd& continuity_residual,
                                         double outlet_pressure_pa, const Eigen::VectorXd& guess) {
  const int nx = opt_.nx, ny = opt_.ny, nz = opt_.nz;
  const double dx = opt_.dx, dy = opt_.dy, dz = opt_.dz;
  const bool periodic = opt_.vertical == VerticalBoundary::kPeriodic;
  const int n = nx * ny * nz;
  auto size = [](const Eigen::VectorXd& a, long expected, const char* name) {
    if (a.size() != expected)
      throw Error(ErrorCode::kInvalidArgument,
                  std::string("pressure equation: ") + name + " has " + std::to_string(a.size()) +
                      " entries, expected " + std::to_string(expected));
  };
  size(c_x, static_cast<long>(nx + 1) * nz * ny, "c_x");
  size(c_y, static_cast<long>(nx) * nz * (ny + 1), "c_y");
  size(c_z, static_cast<long>(nx) * (nz + 1) * ny, "c_z");
  size(continuity_residual, n, "continuity_residual");
  size(guess, n, "guess");
  auto id = [nx, nz](int i, int j, int k) { return i + nx * (j + nz * k); };
  auto xf = [nx, nz](int i, int j, int k) { return i + (nx + 1) * (j + nz * k); };
  auto yf = [nx, nz](int i, int j, int k) { return i + nx * (j + nz * k); };
  auto zf = [nx, nz](int i, int j, int k) { return i + nx * (j + (nz + 1) * k); };
  const double ax = dy * dz, ay = dx * dz, az = dx * dy;  // face areas
  std::vector<double> coefficients;
  coefficients.reserve(static_cast<size_t>(c_x.size() + c_y.size() + c_z.size()));
  coefficients.assign(c_x.data(), c_x.data() + c_x.size());
  if (ny > 1) coefficients.insert(coefficients.end(), c_y.data(), c_y.data() + c_y.size());
  coefficients.insert(coefficients.end(), c_z.data(), c_z.data() + c_z.size());

  Cache& cache = *cache_;
  const bool pinned = periodic;  // no Dirichlet boundary: remove the constant null space
  if (coefficients != cache.coefficients || cache.matrix.rows() != n) {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<size_t>(7 * n));
    auto couple = [&](int a, int b, double g) {  // g = C A / h between cells a and b
      triplets.emplace_back(a, a, g);
      triplets.emplace_back(b, b, g);
      triplets.emplace_back(a, b, -g);
      triplets.emplace_back(b, a, -g);
    };
    for (int k = 0; k < ny; ++k) {
      for (int j = 0; j < nz; ++j) {
        for (int i = 1; i < nx; ++i)
          couple(id(i - 1, j, k), id(i, j, k), c_x(xf(i, j, k)) * ax / dx);
      }
      for (int i = 0; i < nx; ++i) {
        for (int j = 1; j < nz; ++j)
          couple(id(i, j - 1, k), id(i, j, k), c_z(zf(i, j, k)) * az / dz);
        if (periodic) {
          couple(id(i, nz - 1, k), id(i, 0, k), c_z(zf(i, 0, k)) * az / dz);
        } else {
          // Outlet: p = outlet_pressure at the top face, half a cell above the centre.
          const int c = id(i, nz - 1, k);
          triplets.emplace_back(c, c, c_z(zf(i, nz, k)) * az / (0.5 * dz));
        }
      }
      if (k > 0) {
        for (int j = 0; j < nz; ++j) {
          for (int i = 0; i < nx; ++i)
            couple(id(i, j, k - 1), id(i, j, k), c_y(yf(i, j, k)) * ay / dy);
        }
      }
    }
    cache.matrix.resize(n, n);
    cache.matrix.setFromTriplets(triplets.begin(), triplets.end());
    cache.solver_matrix = cache.matrix;
    Eigen::SparseMatrix<double>& matrix = cache.solver_matrix;
    if (pinned) {
      // Keep the matrix symmetric: zero row and column 0, unit diagonal, rhs 0 there.
      for (int c = 0; c < matrix.outerSize(); ++c) {
        for (Eigen::SparseMatrix<double>::InnerIterator it(matrix, c); it; ++it) {
          if (it.row() == 0 || it.col() == 0) it.valueRef() = (it.row() == it.col()) ? 1.0 : 0.0;
        }
      }
    }
    if (opt_.solver == PoissonSolver::kDirectLDLT) {
      // The sparsity pattern depends only on the grid and the boundaries, not on C: order
      // (AMD) and analyse it once, then only the numeric factorisation when C changes.
      if (!cache.ordered) {
        cache.ldlt.analyzePattern(matrix);
        cache.ordered = true;
      }
      cache.ldlt.factorize(matrix);
      if (cache.ldlt.info() != Eigen::Success) {
        throw Error(ErrorCode::kInternal, "pressure equation: LDLT factorisation failed");
      }
    } else {
      cache.cg.setTolerance(opt_.cg_tolerance);
      cache.cg.setMaxIterations(opt_.cg_max_iterations);
      cache.cg.compute(matrix);
    }
    cache.coefficients = std::move(coefficients);
  }

  Eigen::VectorXd rhs = -continuity_residual;
  if (!periodic) {
    for (int k = 0; k < ny; ++k) {
      for (int i = 0; i < nx; ++i)
        rhs(id(i, nz - 1, k)) += c_z(zf(i, nz, k)) * az / (0.5 * dz) * outlet_pressure_pa;
    }
  }
  Eigen::VectorXd full_rhs = rhs;
  if (pinned) rhs(0) = 0.0;
  Eigen::VectorXd pressure;
  int iterations = 0;
  if (opt_.solver == PoissonSolver::kDirectLDLT) {
    pressure = cache.ldlt.solve(rhs);
  } else {
    Eigen::VectorXd start = guess;
    if (pinned) start.array() -= start(0);
    pressure = cache.cg.solveWithGuess(rhs, start);
    iterations = static_cast<int>(cache.cg.iterations());
    if (cache.cg.info() != Eigen::Success) {
      char buffer[320];
      std::snprintf(buffer, sizeof buffer,
                    "pressure equation: conjugate gradient did not reach cg_tolerance %g in "
                    "cg_max_iterations %d (estimated error %.3g); remedy: raise "
                    "cg_max_iterations or use the direct LDLT solver",
                    opt_.cg_tolerance, opt_.cg_max_iterations, cache.cg.error());
      throw Error(ErrorCode::kInvalidArgument, buffer);
    }
  }
  // Residual of the full (unpinned) system: also checks that a closed box got a compatible
  // right-hand side (d/dt int eps = net inflow).
  const double b_norm = full_rhs.norm();
  const double residual = (cache.matrix * pressure - full_rhs).norm();
  diag_.relative_residual = b_norm > 0.0 ? residual / b_norm : residual;
  diag_.iterations = iterations;
  return pressure;
}

}  // namespace consumers
}  // namespace draglab
