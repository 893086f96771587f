// gas/mac_pressure.h: the pressure equation of a projection on the staggered (MAC)
// grid of the bed models, shared by the gas phase of the DPM (gas_phase.h), the two-fluid model
// (tfm.h) and the emulsion of the discrete bubble model (dbm.h). The grid is 3-D (x across the
// width, y across the depth, z up); the pseudo-2D models use its 2-D mode, one cell across the
// depth (ny = 1) with unit depth, through the ArrayXXd overload.
//
// Each model predicts face velocities without the new pressure gradient and knows how a face's
// volume flux answers the pressure gradient, flux_f = flux_hat_f - C_f A_f dp/dn. The caller
// passes those face coefficients C (x-faces (nx+1) x nz, z-faces nx x (nz+1); the wall faces are
// ignored) and, per cell, the residual of its continuity equation with the predicted fluxes
// (net outflow of the predicted volume flux plus the storage term, per unit depth [m^2/s]).
// MacPressureSolver then solves
//     sum_f C_f A_f (p_cell - p_neighbour) / h_f [+ C_top A_top (p_cell - p_out) / (dz / 2)]
//         = -residual_cell,
// i.e. -div(C grad p) = -div(flux_hat) - storage, with a Dirichlet outlet half a cell above the
// top row (VerticalBoundary::kInflowOutlet) or periodic in z with p(0, 0) pinned. The matrix is
// symmetric positive (semi-)definite; it is refactorised only when C changes (the sparsity
// pattern is analysed once). Units: SI; C in m^3 s / kg (velocity per pressure gradient).
//
// 3-D layout (flat vectors, x fastest, then z, then y): cell (i, j, k) at i + nx (j + nz k), j
// the height index, k the depth index; x-faces (nx+1) x nz x ny at i + (nx+1)(j + nz k); z-faces
// nx x (nz+1) x ny at i + nx (j + (nz+1) k); y-faces nx x nz x (ny+1) at i + nx (j + nz k). The
// side walls (x and y) are closed. With ny = 1 the layout is the 2-D one of the ArrayXXd arrays.
#pragma once

#include <Eigen/Core>

#include <memory>

#include "draglab/consumers/gas_phase.h"

namespace draglab {
namespace consumers {

/// Grid, boundaries and linear solver of the pressure equation.
struct MacPressureOptions {
  int nx = 2;
  int nz = 2;
  int ny = 1;  ///< Cells across the depth; 1 with dy = 1: the 2-D mode (per unit depth).
  double dx = 1.0;
  double dz = 1.0;
  double dy = 1.0;
  VerticalBoundary vertical = VerticalBoundary::kInflowOutlet;
  PoissonSolver solver = PoissonSolver::kDirectLDLT;
  double cg_tolerance = 1e-10;   ///< Relative residual of the CG solve, in (0, 1e-3].
  int cg_max_iterations = 5000;  ///< >= 1.
};

/// Residual and iterations of the last solve.
struct MacPressureDiagnostics {
  double relative_residual = 0.0;  ///< |A p - b| / |b| of the full (unpinned) system.
  int iterations = 0;              ///< CG iterations (0 for the direct solver).
};

/// Assembles and solves the pressure equation above.
class MacPressureSolver {
 public:
  explicit MacPressureSolver(const MacPressureOptions& options);
  ~MacPressureSolver();
  MacPressureSolver(MacPressureSolver&&) noexcept;
  MacPressureSolver& operator=(MacPressureSolver&&) noexcept;
  MacPressureSolver(const MacPressureSolver&) = delete;
  MacPressureSolver& operator=(const MacPressureSolver&) = delete;

  /// Solves for the cell pressures (nx x nz) given the face coefficients c_u ((nx+1) x nz) and
  /// c_w (nx x (nz+1); column nz is the outlet face, column 0 the periodic face), the continuity
  /// residual per cell (nx x nz) and the outlet pressure. `guess` (nx x nz) starts CG.
  /// Throws Error(kInvalidArgument) naming cg_max_iterations when CG does not converge and
  /// Error(kInternal) when the LDLT factorisation fails.
  Eigen::ArrayXXd Solve(const Eigen::ArrayXXd& c_u, const Eigen::ArrayXXd& c_w,
                        const Eigen::ArrayXXd& continuity_residual, double outlet_pressure_pa,
                        const Eigen::ArrayXXd& guess);

  /// The 3-D form (layout in the file comment): face coefficients c_x, c_y, c_z, the continuity
  /// residual per cell [m^3/s] and a CG start, all flat. The 2-D overload is this with ny = 1.
  Eigen::VectorXd Solve(const Eigen::VectorXd& c_x, const Eigen::VectorXd& c_y,
                        const Eigen::VectorXd& c_z, const Eigen::VectorXd& continuity_residual,
                        double outlet_pressure_pa, const Eigen::VectorXd& guess);

  const MacPressureDiagnostics& diagnostics() const { return diag_; }
  const MacPressureOptions& options() const { return opt_; }

 private:
  MacPressureOptions opt_;
  MacPressureDiagnostics diag_;
  struct Cache;
  std::unique_ptr<Cache> cache_;
};

}  // namespace consumers
}  // namespace draglab
