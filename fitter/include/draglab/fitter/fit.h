// draglab/fitter/fit.h: fitting drag-law forms to drag data (Ceres, confirmed by NLopt).
//
// A form from the law library (drag_db/law_form.h) is fitted with the same templated formula the
// library evaluates, so Ceres gets automatic derivatives (ceres::Jet through
// LawForm::F_autodiff). Default form: the seed's Eq. 6 (vdh2004), freeing the C0 and C1
// coefficients k0, k1, c10, c11, c12 (the seed's a, b, c0, c1, c2; these aliases are accepted,
// as is n for n0). Objective, with F_i +- sigma_i the data and F(x) the model, both canonical
// drag-only F:
//   least squares: sum_i rho(((F(phi_i, Re_i; x) - F_i) / sigma_i)^2)  (sigma absolute; for data
//     spanning orders of magnitude this is the relative residual over the relative uncertainty),
//     rho = identity or a robust loss (Huber, Cauchy) with scale `loss_scale` sigmas;
//   minimax: max_i |F(x)/F_i - 1| (NLopt, epigraph form).
// Uncertainty: Ceres covariance of the free parameters (scaled by chi2/dof when chi2/dof > 1),
// 95 % intervals from the Student t quantile with dof = points - free; optional bootstrap over the
// points; k-fold cross-validation RMS relative error. NLopt: a global search (multi-start around
// the optimum) confirms that Ceres found the global optimum, and the physical constraints (F > 0,
// dF/dRe >= 0 on a grid over the validity box) are checked for the least-squares optimum and
// imposed in the minimax fit.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "draglab/drag_db/law.h"

namespace draglab {
namespace fitter {

/// One data point (input of fit_law): canonical F at (phi, Re superficial) with its absolute
/// 1-sigma uncertainty.
struct FitPoint {
  double phi = 0.0;
  double re = 0.0;
  double F = 0.0;
  double sigma = 0.0;
  /// The form's extra inputs, one value each (polydisperse forms: y = d_i/<d>); empty otherwise.
  std::vector<double> extra;
  const double* extra_data() const { return extra.empty() ? nullptr : extra.data(); }
};

enum class Objective { kLeastSquares, kMinimax };
const char* to_string(Objective o);
Objective objective_from_string(const std::string& s);  ///< "lsq", "minimax"

enum class RobustLoss { kNone, kHuber, kCauchy };
const char* to_string(RobustLoss l);
RobustLoss robust_loss_from_string(const std::string& s);  ///< "none", "huber", "cauchy"

/// What fit_law does when the data do not determine every requested free parameter (a 95 %
/// interval wider than the value, or a flat direction of the cost).
enum class Selection {
  kOff,  ///< Fit the requested set as it is (a flat direction is an error).
  /// Fit the largest subset of the requested set whose every 95 % interval is narrower than its
  /// value, ties broken by the lowest AICc; the others stay at their starting values. Every
  /// subset is tried (up to 10 requested parameters; beyond, backward elimination).
  kLargestDetermined,
};
const char* to_string(Selection s);
Selection selection_from_string(const std::string& s);  ///< "off", "auto"

/// How to fit: form, free/fixed parameters, objective, robust loss, and which checks to run.
struct FitOptions {
  std::string form = "vdh2004";  ///< Law-form key.
  /// Parameters to fit (names or aliases); empty = the form's default set (vdh2004: k0, k1, c10,
  /// c11, c12; other forms: all parameters).
  std::vector<std::string> free;
  /// Starting values (free parameters) and fixed values (the others) by name or alias; any
  /// parameter not named starts at / stays fixed at the form's published default.
  std::vector<std::pair<std::string, double>> initial;
  Objective objective = Objective::kLeastSquares;
  RobustLoss loss = RobustLoss::kNone;
  double loss_scale = 2.0;        ///< Robust loss scale in units of sigma, > 0.
  bool global_check = true;       ///< NLopt multi-start global search around the optimum.
  bool check_constraints = true;  ///< F > 0 and dF/dRe >= 0 over the validity grid.
  int cv_folds = 5;               ///< k-fold cross-validation (0 = off; needs points >= 2 folds).
  int bootstrap = 0;              ///< Bootstrap resamples for a covariance check (0 = off).
  unsigned seed = 1;              ///< Seeds the folds, the bootstrap and the global search.
  Selection selection = Selection::kLargestDetermined;
  bool IsValid(std::string* error) const;
  std::string to_json() const;  ///< Canonical JSON text (stored as the law's fitter settings).
};

/// One subset of the requested free parameters, fitted by the selection (least squares only).
struct SubsetCandidate {
  std::vector<std::string> free;  ///< Canonical names, in the form's order.
  bool fitted = false;            ///< false: the fit failed (flat direction, too few points).
  bool determined = false;        ///< Fitted and every 95 % interval narrower than the value.
  double chi2 = 0.0;
  /// Akaike's criterion with the small-sample correction, chi2 + 2k + 2k(k+1)/(N-k-1): lower is
  /// better; differences below 2 are not significant.
  double aicc = 0.0;
  double rms_rel_err = 0.0;
  std::vector<std::string> undetermined;  ///< Free parameters with intervals wider than values.
  std::string why;                        ///< Why the fit failed, if it did.
};

/// What the subset selection found and chose (FitOptions::selection).
struct SelectionReport {
  /// true when the requested set was not determined and a subset was fitted instead.
  bool performed = false;
  std::vector<std::string> requested;     ///< The requested free set (canonical names).
  std::vector<std::string> undetermined;  ///< Of the requested set, in its own fit.
  /// The pair the data separate least in the requested fit, e.g. "k0 and c10 (correlation
  /// -0.998)"; or the flat direction's parameters when that fit had none.
  std::string inseparable;
  std::vector<std::string> chosen;
  /// Every subset tried: determined ones first, then by size (largest first), then AICc.
  std::vector<SubsetCandidate> candidates;
};

/// Outcome of fit_law. Parameters are dimensionless (as in the form); errors are relative
/// (0.05 = 5 %); chi2 is in units of the points' sigmas. Covariance and intervals describe the
/// least-squares optimum (for a minimax fit, the least-squares covariance around the minimax
/// values).
struct FitResult {
  std::string form;
  std::vector<std::string> names;  ///< All parameters of the form, in the form's order.
  std::vector<double> values;
  std::vector<bool> is_free;
  std::vector<double> covariance;           ///< Full n x n row-major, zeros for fixed ones.
  std::vector<double> ci95_low, ci95_high;  ///< 95 % intervals (= value for fixed ones).
  int num_points = 0, num_free = 0, dof = 0;
  double chi2 = 0.0, chi2_per_dof = 0.0;
  double rms_rel_err = 0.0, max_rel_err = 0.0;  ///< Of the fit against the data.
  double cv_rms_rel_err = -1.0;                 ///< -1 if not computed.
  std::vector<double> bootstrap_stddev;         ///< Per parameter, empty if not computed.
  // NLopt confirmation.
  bool global_checked = false;
  double global_best_cost = 0.0;  ///< Best least-squares cost the global search found.
  bool global_agrees = true;      ///< Ceres' cost within 1e-6 relative of the global best.
  /// The global search found a clearly better optimum and Ceres was restarted from it (the
  /// reported fit is the restarted one).
  bool global_restarted = false;
  bool constraints_checked = false;
  bool constraints_satisfied = true;
  std::string constraint_report;  ///< Where a constraint is violated, if anywhere.
  std::string ceres_report;       ///< ceres::Solver::Summary::BriefReport().
  bool converged = false;
  /// What the fitter decided along the way (covariance scaled by chi2/dof, Ceres restarted from
  /// the global optimum, CV skipped, minimax outcome), one sentence each.
  std::vector<std::string> notes;
  SelectionReport selection;
  /// Free parameters whose 95 % interval is wider than their value (half-width > |value|).
  std::vector<std::string> undetermined() const;
  /// The largest |correlation| between two free parameters (0 with fewer than two), and the pair.
  double strongest_correlation(std::string* pair) const;
  std::string BriefReport() const;
  std::string FullReport() const;
};

/// Fits `points` as the options say. Throws Error(kInvalidArgument) for invalid options, an
/// unknown form or parameter (listing the valid names), no free parameter, non-positive F or
/// sigma, fewer points than free parameters + 1, or (selection on) no determined subset;
/// Error(kOutOfValidity) if the optimizer does not converge.
FitResult fit_law(const std::vector<FitPoint>& points, const FitOptions& options);

/// The number of parameters `options` fits (its form's default set when `free` is empty): a fit
/// needs at least one point more. Throws as fit_law does for an unknown form or parameter.
int num_free_parameters(const FitOptions& options);

/// Index of parameter `name_or_alias` of `form`; throws Error(kInvalidArgument) listing names.
int parameter_index(const LawForm& form, const std::string& name_or_alias);

/// Relative errors F(phi_i, Re_i)/F_i - 1 of a law against the points (for comparisons). Uses the
/// law's range policy: load it with RangePolicy::kExtrapolate to compare outside its box.
std::vector<double> relative_errors(const Law& law, const std::vector<FitPoint>& points);

/// One row of compare_forms: a form refitted to the points (with the subset selection), or a
/// stored law evaluated as published. Errors are relative (0.05 = 5 %).
struct FormComparisonRow {
  std::string label;  ///< e.g. "Eq. 6 (vdh2004) refit, n = 3" or "bvk2007@1 as published"
  std::string form;
  bool refitted = false;
  std::vector<std::string> free;  ///< The fitted (selected) free parameters; empty as published.
  double rms_rel_err = 0.0, max_rel_err = 0.0;
  /// k-fold cross-validation rms of a refit; for a law as published nothing was fitted to these
  /// points, so its prediction error is its rms error itself.
  double cv_rms_rel_err = -1.0;
  double aicc = 0.0;  ///< Refits only (0 as published).
  std::string error;  ///< Why a refit failed (then the numbers are not meaningful).
};

/// The comparison of part of the seed's Section 3 on one dataset: Eq. 6 refitted with n = 3 and
/// with n free, bvk2007 and tang2015 refitted (each with FitOptions' defaults and the subset
/// selection), then each law of `published` as published (evaluated outside its box too: load
/// them with RangePolicy::kExtrapolate). A refit that fails is a row with `error` set.
std::vector<FormComparisonRow> compare_forms(const std::vector<FitPoint>& points,
                                             const std::vector<const Law*>& published, int cv_folds,
                                             unsigned seed);
/// The rows as a Markdown table (law, fitted parameters, rms, max, CV rms, AICc).
std::string form_comparison_markdown(const std::vector<FormComparisonRow>& rows);
/// The rows as JSON text: an array of {label, form, refitted, free, rms_rel_err, max_rel_err,
/// cv_rms_rel_err (null if none), aicc (null as published), error}.
std::string form_comparison_json_text(const std::vector<FormComparisonRow>& rows);

/// A draft record of the fitted law: form, fitted values, covariance, the form's convention and
/// validity box narrowed to the data's (phi, Re) range, provenance kind "fitted" with the given
/// dataset id/hash, fitter settings JSON (options + residual statistics) and code version.
LawRecord fitted_record(const FitResult& result, const FitOptions& options, const std::string& name,
                        const std::string& dataset_id, const std::string& dataset_hash,
                        const std::vector<FitPoint>& points);

}  // namespace fitter
}  // namespace draglab
