// Private pieces of the fitter shared by fit.cc, global.cc and the tests: the model (a form with
// its fixed and free parameters), Jet-based gradients, the least-squares cost, the physical
// constraint grid, the NLopt global search and the minimax fit.
//
// Free parameters are optimised as scaled variables z_j = x_j / scale_j (scale_j = |start value|,
// or 1 for a zero start) so that coefficients of very different size (tang2015: c2 = 0.00456,
// vdh2004: A = 180) give a well-conditioned Jacobian for Ceres, its covariance and NLopt.
#pragma once

#include <string>
#include <vector>

#include "draglab/drag_db/law_form.h"
#include "draglab/fitter/fit.h"

namespace draglab {
namespace fitter {
namespace internal {

/// A form with every parameter value; the free ones are moved by the optimizers through z.
struct Model {
  const LawForm* form = nullptr;
  std::vector<double> params;   ///< All parameters (fixed ones at their fixed values).
  std::vector<int> free_index;  ///< Indices into params of the free parameters.
  std::vector<double> scale;    ///< x = scale * z for each free parameter, > 0.

  int num_free() const { return static_cast<int>(free_index.size()); }
  std::vector<double> z_of_params() const;               ///< Current free values, scaled.
  std::vector<double> params_at(const double* z) const;  ///< All parameters with free = scale*z.
};

/// F(phi, Re) of the model at free variables z; `extra` holds the form's extra inputs (null if
/// it has none).
double model_F(const Model& m, const double* z, double phi, double re, const double* extra);
/// F and dF/dz_j (num_free values) by automatic differentiation (Jets in chunks of 4).
double model_F_gradient(const Model& m, const double* z, double phi, double re, const double* extra,
                        double* grad);
/// dF/dRe at (phi, re) for the full parameter vector (automatic differentiation).
double dF_dRe(const LawForm& form, const double* params, double phi, double re,
              const double* extra);

/// Ceres' robust loss rho(s) of the squared residual s (rho = s without loss); *drho = rho'(s).
double robust_rho(RobustLoss loss, double scale, double s, double* drho);
/// Ceres' cost 0.5 sum rho(r_i^2), r_i = (F_i(z) - F_i)/sigma_i; gradient in z if grad != null.
double lsq_cost(const Model& m, const std::vector<FitPoint>& points, RobustLoss loss,
                double loss_scale, const double* z, double* grad);

/// The (phi, Re) grid on which F > 0 and dF/dRe >= 0 are required: 12 x 12 over the form's
/// validity box intersected with the data range extended by 10 % on each side (Re: 0 if the data
/// has it, then log-spaced).
struct ConstraintGrid {
  std::vector<double> phi;
  std::vector<double> re;
  /// Values of the form's extra inputs at which the grid is checked: the data's smallest and
  /// largest of each (one empty set for a form without extra inputs).
  std::vector<std::vector<double>> extra_sets{{}};
  std::size_t nodes() const { return phi.size() * re.size() * extra_sets.size(); }
};
ConstraintGrid constraint_grid(const LawForm& form, const std::vector<FitPoint>& points);
/// "" if F > 0 and dF/dRe >= 0 hold at every grid node, else where they do not.
std::string check_constraints(const LawForm& form, const double* params,
                              const ConstraintGrid& grid);

/// Multi-start NLopt search (L-BFGS from quasi-random starts in center +- halfwidth, in z).
struct GlobalSearchResult {
  double best_cost = 0.0;
  std::vector<double> best_z;
  int starts = 0;
  int successful_starts = 0;
};
GlobalSearchResult global_search(const Model& m, const std::vector<FitPoint>& points,
                                 RobustLoss loss, double loss_scale,
                                 const std::vector<double>& z_center,
                                 const std::vector<double>& z_halfwidth, unsigned seed, int starts);

/// Minimax fit in epigraph form with NLopt SLSQP: minimise t subject to |F_i(z)/F_i - 1| <= t and,
/// if `grid` is non-null, F > 0 and dF/dRe >= 0 on it. Starts at z_start; returns false (with
/// *message) if no feasible improvement was found, else sets *z_out and *max_rel_err.
bool minimax_fit(const Model& m, const std::vector<FitPoint>& points, const ConstraintGrid* grid,
                 const std::vector<double>& z_start, std::vector<double>* z_out,
                 double* max_rel_err, std::string* message);

/// The requested free parameters of `form` (FitOptions::free, or the form's default set); throws
/// Error(kInvalidArgument) for an unknown or repeated name, or when none is free.
std::vector<bool> requested_free(const LawForm& form, const FitOptions& options);
/// The form to fit by key; throws Error(kInvalidArgument) for an unknown or polydisperse form.
const LawForm& checked_form(const std::string& key);
/// fit_law with the requested free set as it is (no subset selection).
FitResult fit_requested(const std::vector<FitPoint>& points, const FitOptions& options);

}  // namespace internal
}  // namespace fitter
}  // namespace draglab
