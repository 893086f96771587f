// fit_law: Ceres least squares with automatic derivatives through the law templates, covariance,
// Student-t intervals, cross-validation, bootstrap, and the NLopt checks (global.cc).
#include "draglab/fitter/fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <random>
#include <set>

#include <ceres/ceres.h>
#include <fmt/core.h>
#include <glog/logging.h>
#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "draglab/error.h"
#include "fit_internal.h"
#include "student_t.h"

namespace draglab {
namespace fitter {

using internal::Model;

// ---- names and options ----------------------------------------------------------------------
const char* to_string(Objective o) { return o == Objective::kMinimax ? "minimax" : "lsq"; }

Objective objective_from_string(const std::string& s) {
  if (s == "lsq") return Objective::kLeastSquares;
  if (s == "minimax") return Objective::kMinimax;
  throw Error(ErrorCode::kInvalidArgument,
              "objective '" + s + "' is unknown (allowed: lsq, minimax)");
}

const char* to_string(RobustLoss l) {
  switch (l) {
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
    case RobustLoss::kNone:
      break;
  }
  return "none";
}

RobustLoss robust_loss_from_string(const std::string& s) {
  if (s == "none") return RobustLoss::kNone;
  if (s == "huber") return RobustLoss::kHuber;
  if (s == "cauchy") return RobustLoss::kCauchy;
  throw Error(ErrorCode::kInvalidArgument,
              "loss '" + s + "' is unknown (allowed: none, huber, cauchy)");
}

const char* to_string(Selection s) { return s == Selection::kOff ? "off" : "auto"; }

Selection selection_from_string(const std::string& s) {
  if (s == "off") return Selection::kOff;
  if (s == "auto") return Selection::kLargestDetermined;
  throw Error(ErrorCode::kInvalidArgument, "selection '" + s + "' is unknown (allowed: auto, off)");
}

bool FitOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (form.empty()) return fail("form: empty (e.g. vdh2004, bvk2007, tang2015)");
  if (!std::isfinite(loss_scale) || loss_scale <= 0.0) {
    return fail(fmt::format("loss_scale = {} must be finite and > 0 (units of sigma)", loss_scale));
  }
  if (cv_folds != 0 && (cv_folds < 2 || cv_folds > 1000)) {
    return fail(fmt::format("cv_folds = {} must be 0 (off) or in [2, 1000]", cv_folds));
  }
  if (bootstrap < 0 || bootstrap > 100000) {
    return fail(fmt::format("bootstrap = {} must be in [0, 100000] (0 = off)", bootstrap));
  }
  std::set<std::string> seen;
  for (const std::string& name : free) {
    if (name.empty()) return fail("free: empty parameter name");
    if (!seen.insert(name).second) return fail("free: parameter '" + name + "' given twice");
  }
  for (const auto& [name, value] : initial) {
    if (!std::isfinite(value))
      return fail(fmt::format("initial value of '{}' = {} is not finite", name, value));
  }
  return true;
}

std::string FitOptions::to_json() const {
  nlohmann::json j;
  j["form"] = form;
  j["free"] = free;
  nlohmann::json init = nlohmann::json::object();
  for (const auto& [name, value] : initial) init[name] = value;
  j["initial"] = init;
  j["objective"] = to_string(objective);
  j["loss"] = to_string(loss);
  j["loss_scale"] = loss_scale;
  j["global_check"] = global_check;
  j["check_constraints"] = check_constraints;
  j["cv_folds"] = cv_folds;
  j["bootstrap"] = bootstrap;
  j["seed"] = seed;
  j["selection"] = to_string(selection);
  return j.dump();
}

namespace {

/// The seed's names for vdh2004 (Eq. 6 as printed: a, n, b, c0, c1, c2).
const std::vector<std::pair<std::string, std::string>>& vdh2004_aliases() {
  static const std::vector<std::pair<std::string, std::string>> aliases = {
      {"a", "k0"}, {"n", "n0"}, {"b", "k1"}, {"c0", "c10"}, {"c1", "c11"}, {"c2", "c12"}};
  return aliases;
}

const LawForm& fit_form(const std::string& key) {
  const LawForm* form = nullptr;
  try {
    form = &find_law_form(key);
  } catch (const Error&) {
    throw Error(ErrorCode::kInvalidArgument,
                "form '" + key + "' is unknown (known forms: " + law_form_keys() + ")");
  }
  return *form;
}

void validate_points(const std::vector<FitPoint>& points, const LawForm& form) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const FitPoint& p = points[i];
    if (static_cast<int>(p.extra.size()) != form.num_extra_inputs) {
      std::string names;
      for (const ExtraInputSpec& e : form.description.validity.extra) {
        names += (names.empty() ? "" : ", ") + e.name;
      }
      throw Error(ErrorCode::kInvalidArgument,
                  fmt::format("data point {} (phi = {}, Re = {}) has {} extra input(s); form {} "
                              "takes {}{}",
                              i + 1, p.phi, p.re, p.extra.size(), form.key(), form.num_extra_inputs,
                              names.empty() ? std::string() : " (" + names + ")"));
    }
    for (double e : p.extra) {
      if (!std::isfinite(e) || e <= 0.0) {
        throw Error(ErrorCode::kInvalidArgument,
                    fmt::format("data point {} (phi = {}, Re = {}): extra input {} must be finite "
                                "and > 0",
                                i + 1, p.phi, p.re, e));
      }
    }
    auto bad = [&](const char* field, double value, const char* range) {
      throw Error(ErrorCode::kInvalidArgument,
                  fmt::format("data point {} (phi = {}, Re = {}): {} = {} must be {}", i + 1, p.phi,
                              p.re, field, value, range));
    };
    if (!std::isfinite(p.phi) || p.phi <= 0.0 || p.phi >= 1.0) bad("phi", p.phi, "in (0, 1)");
    if (!std::isfinite(p.re) || p.re < 0.0) bad("Re", p.re, "finite and >= 0");
    if (!std::isfinite(p.F) || p.F <= 0.0) bad("F", p.F, "finite and > 0");
    if (!std::isfinite(p.sigma) || p.sigma <= 0.0) bad("sigma", p.sigma, "finite and > 0");
  }
}

double value_of(double x) { return x; }
double value_of(const AutoDiffScalar& x) { return x.a; }
double eval_F(const LawForm& f, double phi, double re, const std::vector<double>& extra,
              const double* p) {
  return f.F(phi, re, extra.empty() ? nullptr : extra.data(), p);
}
AutoDiffScalar eval_F(const LawForm& f, const AutoDiffScalar& phi, const AutoDiffScalar& re,
                      const std::vector<double>& extra, const AutoDiffScalar* p) {
  std::vector<AutoDiffScalar> jets(extra.begin(), extra.end());
  return f.F_autodiff(phi, re, jets.empty() ? nullptr : jets.data(), p);
}

/// r = (F(phi, Re; x) - F_i)/sigma_i over the scaled free variables z (one parameter block).
struct PointResidual {
  const Model* model;
  FitPoint point;
  template <typename T>
  bool operator()(T const* const* z, T* residual) const {
    std::vector<T> p(model->params.size());
    for (std::size_t k = 0; k < p.size(); ++k) p[k] = T(model->params[k]);
    for (int j = 0; j < model->num_free(); ++j) p[model->free_index[j]] = z[0][j] * model->scale[j];
    const T F = eval_F(*model->form, T(point.phi), T(point.re), point.extra, p.data());
    residual[0] = (F - point.F) / point.sigma;
    return std::isfinite(value_of(F));
  }
};

ceres::LossFunction* make_loss(RobustLoss loss, double scale) {
  switch (loss) {
    case RobustLoss::kHuber:
      return new ceres::HuberLoss(scale);
    case RobustLoss::kCauchy:
      return new ceres::CauchyLoss(scale);
    case RobustLoss::kNone:
      break;
  }
  return nullptr;
}

struct SolveOutcome {
  bool converged = false;
  double cost = 0.0;  ///< Ceres' final cost 0.5 sum rho(r^2).
  std::string brief;
  std::string message;
  bool covariance_ok = false;
  std::vector<double> covariance_z;  ///< num_free^2, row-major (if requested and ok).
};

/// Ceres reports a rank-deficient covariance through glog ("E... covariance_impl.cc] Error:
/// Covariance matrix is near rank deficient"), a line a user cannot act on: the fit reports the
/// parameters the data leave undetermined itself (undetermined_parameters). Only FATAL records
/// (Ceres' own check failures, which abort) are kept. Set once: glog's flag is a process global.
void silence_ceres_log() {
  static std::once_flag once;
  std::call_once(once, [] { FLAGS_minloglevel = google::GLOG_FATAL; });
}

/// Ceres Levenberg-Marquardt from z (updated in place); covariance of z if asked.
SolveOutcome solve_lsq(const Model& m, const std::vector<FitPoint>& points, RobustLoss loss,
                       double loss_scale, std::vector<double>& z, bool want_covariance) {
  ceres::Problem problem;
  const int n = m.num_free();
  for (const FitPoint& pt : points) {
    auto* cost =
        new ceres::DynamicAutoDiffCostFunction<PointResidual, 4>(new PointResidual{&m, pt});
    cost->AddParameterBlock(n);
    cost->SetNumResiduals(1);
    problem.AddResidualBlock(cost, make_loss(loss, loss_scale), z.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 500;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  SolveOutcome out;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.cost = summary.final_cost;
  out.brief = summary.BriefReport();
  out.message = summary.message;
  if (want_covariance && out.converged) {
    silence_ceres_log();
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    cov_options.num_threads = 1;
    ceres::Covariance covariance(cov_options);
    std::vector<std::pair<const double*, const double*>> blocks = {{z.data(), z.data()}};
    if (covariance.Compute(blocks, &problem)) {
      out.covariance_z.assign(static_cast<std::size_t>(n) * n, 0.0);
      out.covariance_ok =
          covariance.GetCovarianceBlock(z.data(), z.data(), out.covariance_z.data());
    }
  }
  return out;
}

/// Names of parameters the data do not determine: columns of the (column-normalised) Jacobian
/// that are zero or take part in its numerical null space (singular value below 1e-7 of the
/// largest, the same threshold Ceres' DENSE_SVD covariance applies to J'J: 1e-14).
std::vector<std::string> undetermined_parameters(const Model& m,
                                                 const std::vector<FitPoint>& points,
                                                 const std::vector<double>& z) {
  const int n = m.num_free();
  Eigen::MatrixXd J(points.size(), n);
  std::vector<double> g(n);
  for (std::size_t i = 0; i < points.size(); ++i) {
    internal::model_F_gradient(m, z.data(), points[i].phi, points[i].re, points[i].extra_data(),
                               g.data());
    for (int j = 0; j < n; ++j) J(i, j) = std::isfinite(g[j]) ? g[j] / points[i].sigma : 0.0;
  }
  std::vector<bool> flagged(n, false);
  for (int j = 0; j < n; ++j) {
    const double norm = J.col(j).norm();
    if (norm == 0.0) {
      flagged[j] = true;
    } else {
      J.col(j) /= norm;
    }
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  const double largest = s.size() > 0 ? s(0) : 0.0;
  for (int k = 0; k < s.size(); ++k) {
    if (s(k) > 1e-7 * largest) continue;
    for (int j = 0; j < n; ++j) {
      if (std::fabs(svd.matrixV()(j, k)) > 0.1) flagged[j] = true;
    }
  }
  std::vector<std::string> names;
  for (int j = 0; j < n; ++j) {
    if (flagged[j]) names.push_back(m.form->description.parameters[m.free_index[j]].name);
  }
  return names;
}

std::string join(const std::vector<std::string>& items, const std::string& sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

[[noreturn]] void throw_undetermined(const std::vector<std::string>& names, const LawForm& form,
                                     const std::vector<FitPoint>& points) {
  const bool stokes_only =
      std::all_of(points.begin(), points.end(), [](const FitPoint& p) { return p.re == 0.0; });
  throw Error(
      ErrorCode::kInvalidArgument,
      fmt::format("parameter(s) {} of form {} are not determined by the data ({} points{}): "
                  "fix them (leave them out of --free, set values with --set) or add data "
                  "at Re > 0 and more phi values",
                  names.empty() ? std::string("(a combination)") : join(names), form.key(),
                  points.size(), stokes_only ? ", all at Re = 0" : ""));
}

}  // namespace

int parameter_index(const LawForm& form, const std::string& name_or_alias) {
  const auto& params = form.description.parameters;
  for (std::size_t k = 0; k < params.size(); ++k) {
    if (params[k].name == name_or_alias) return static_cast<int>(k);
  }
  std::string alias_text;
  if (form.key() == "vdh2004") {
    for (const auto& [alias, name] : vdh2004_aliases()) {
      if (alias == name_or_alias) return parameter_index(form, name);
      alias_text += (alias_text.empty() ? "" : ", ") + alias + "=" + name;
    }
  }
  std::vector<std::string> names;
  for (const ParameterSpec& p : params) names.push_back(p.name);
  throw Error(
      ErrorCode::kInvalidArgument,
      fmt::format("parameter '{}' is unknown for form {} (parameters: {}{})", name_or_alias,
                  form.key(), join(names), alias_text.empty() ? "" : "; aliases: " + alias_text));
}

std::vector<double> relative_errors(const Law& law, const std::vector<FitPoint>& points) {
  std::vector<double> errors;
  errors.reserve(points.size());
  for (const FitPoint& p : points) {
    errors.push_back(law.F(p.phi, p.re, p.extra_data()) / p.F - 1.0);
  }
  return errors;
}

namespace internal {

std::vector<bool> requested_free(const LawForm& form, const FitOptions& options) {
  const int num_params = form.num_parameters;
  std::vector<bool> is_free(num_params, false);
  if (options.free.empty()) {
    if (form.key() == "vdh2004") {
      for (const char* name : {"k0", "k1", "c10", "c11", "c12"})
        is_free[parameter_index(form, name)] = true;
    } else {
      is_free.assign(num_params, true);
    }
  } else {
    for (const std::string& name : options.free) {
      const int k = parameter_index(form, name);
      if (is_free[k]) {
        throw Error(ErrorCode::kInvalidArgument, "free: parameter '" + name + "' given twice");
      }
      is_free[k] = true;
    }
  }
  if (std::none_of(is_free.begin(), is_free.end(), [](bool f) { return f; })) {
    throw Error(ErrorCode::kInvalidArgument,
                "form " + form.key() +
                    " has no free parameter to fit (it has no parameters, or --free names "
                    "none): choose a form with parameters or name them with --free");
  }
  return is_free;
}

const LawForm& checked_form(const std::string& key) { return fit_form(key); }

FitResult fit_requested(const std::vector<FitPoint>& points, const FitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, "fit options: " + why);
  const LawForm& form = fit_form(options.form);
  const int num_params = form.num_parameters;

  Model model;
  model.form = &form;
  model.params = form.default_parameters();
  for (const auto& [name, value] : options.initial)
    model.params[parameter_index(form, name)] = value;
  const std::vector<bool> is_free = requested_free(form, options);
  for (int k = 0; k < num_params; ++k) {
    if (!is_free[k]) continue;
    model.free_index.push_back(k);
    model.scale.push_back(model.params[k] != 0.0 ? std::fabs(model.params[k]) : 1.0);
  }
  const int num_free = model.num_free();

  validate_points(points, form);
  const int num_points = static_cast<int>(points.size());
  if (num_points < num_free + 1) {
    throw Error(ErrorCode::kInvalidArgument,
                fmt::format("{} data point(s) are too few to fit {} free parameter(s) of {}: need "
                            "at least {} (fix some parameters or add data)",
                            num_points, num_free, form.key(), num_free + 1));
  }

  FitResult result;
  result.form = form.key();
  for (const ParameterSpec& p : form.description.parameters) result.names.push_back(p.name);
  result.is_free = is_free;
  result.num_points = num_points;
  result.num_free = num_free;
  result.dof = num_points - num_free;

  // Parameters the data cannot determine (e.g. inertial ones from Stokes-only data): a clear
  // error before the optimizer wanders along a flat direction.
  std::vector<double> z = model.z_of_params();
  {
    const auto undetermined = undetermined_parameters(model, points, z);
    if (!undetermined.empty()) throw_undetermined(undetermined, form, points);
  }

  SolveOutcome solve = solve_lsq(model, points, options.loss, options.loss_scale, z, true);
  if (!solve.converged) {
    throw Error(ErrorCode::kOutOfValidity,
                fmt::format("Ceres did not converge fitting {} to {} points: {}", form.key(),
                            num_points, solve.message));
  }
  if (!solve.covariance_ok) {
    throw_undetermined(undetermined_parameters(model, points, z), form, points);
  }

  // NLopt global check: multi-start L-BFGS in the box of fit.h around the Ceres optimum.
  if (options.global_check && num_free > 0) {
    std::vector<double> halfwidth(num_free);
    for (int j = 0; j < num_free; ++j) {
      const double x = z[j] * model.scale[j];
      const double sd =
          std::sqrt(std::max(0.0, solve.covariance_z[j * num_free + j])) * model.scale[j];
      halfwidth[j] = std::max({5.0 * sd, 0.5 * std::fabs(x), 1.0}) / model.scale[j];
    }
    const internal::GlobalSearchResult global = internal::global_search(
        model, points, options.loss, options.loss_scale, z, halfwidth, options.seed, 16);
    result.global_checked = true;
    result.global_best_cost = global.best_cost;
    // Costs below 1e-12 (noise-free data) are equal for this purpose.
    const double tolerance = 1e-6 * std::max(global.best_cost, 1e-12);
    if (global.best_cost < solve.cost - tolerance) {
      std::vector<double> z_restart = global.best_z;
      SolveOutcome restarted =
          solve_lsq(model, points, options.loss, options.loss_scale, z_restart, true);
      if (restarted.converged && restarted.covariance_ok && restarted.cost < solve.cost) {
        result.notes.push_back(fmt::format(
            "The NLopt global search found a lower cost ({:.8g}) than Ceres ({:.8g}); Ceres was "
            "restarted from it and converged to {:.8g}.",
            global.best_cost, solve.cost, restarted.cost));
        solve = restarted;
        z = z_restart;
        result.global_restarted = true;
      }
    }
    result.global_agrees = solve.cost <= global.best_cost + tolerance;
    result.notes.push_back(fmt::format(
        "Global check: {} L-BFGS starts ({} finished) in +-max(5 sd, 50 %, 1) around the "
        "optimum; best cost {:.10g}, Ceres {:.10g}: {}.",
        global.starts, global.successful_starts, global.best_cost, solve.cost,
        result.global_agrees ? "agree" : "Ceres is NOT at the best optimum found"));
  }
  result.ceres_report = solve.brief;
  result.converged = true;

  // Statistics of the least-squares optimum.
  std::vector<double> covariance_z = solve.covariance_z;
  auto residual_stats = [&](const std::vector<double>& zz) {
    double chi2 = 0.0, sum_rel2 = 0.0, max_rel = 0.0;
    for (const FitPoint& p : points) {
      const double F = internal::model_F(model, zz.data(), p.phi, p.re, p.extra_data());
      chi2 += std::pow((F - p.F) / p.sigma, 2);
      const double rel = std::fabs(F / p.F - 1.0);
      sum_rel2 += rel * rel;
      max_rel = std::max(max_rel, rel);
    }
    result.chi2 = chi2;
    result.chi2_per_dof = chi2 / result.dof;
    result.rms_rel_err = std::sqrt(sum_rel2 / num_points);
    result.max_rel_err = max_rel;
  };
  residual_stats(z);

  const internal::ConstraintGrid grid = internal::constraint_grid(form, points);
  if (options.objective == Objective::kMinimax) {
    std::vector<double> z_minimax;
    double max_err = 0.0;
    std::string message;
    const bool ok =
        internal::minimax_fit(model, points, options.check_constraints ? &grid : nullptr, z,
                              &z_minimax, &max_err, &message);
    result.notes.push_back(message);
    if (ok && max_err <= result.max_rel_err) {
      z = z_minimax;
      residual_stats(z);
      result.notes.push_back(
          "Minimax parameters reported; their intervals use the least-squares covariance.");
    } else {
      result.notes.push_back(
          "Minimax did not improve on least squares; least-squares values kept.");
    }
  }

  result.values = model.params_at(z.data());
  if (options.check_constraints) {
    result.constraints_checked = true;
    result.constraint_report = internal::check_constraints(form, result.values.data(), grid);
    result.constraints_satisfied = result.constraint_report.empty();
  }

  // Covariance of x = scale * z, scaled by chi2/dof when the scatter exceeds the stated sigmas.
  const double variance_factor = std::max(1.0, result.chi2_per_dof);
  if (result.chi2_per_dof > 1.0) {
    result.notes.push_back(fmt::format(
        "chi2/dof = {:.3g} > 1: covariance scaled by it (the data scatter more than their "
        "uncertainties say).",
        result.chi2_per_dof));
  }
  result.covariance.assign(static_cast<std::size_t>(num_params) * num_params, 0.0);
  for (int a = 0; a < num_free; ++a) {
    for (int b = 0; b < num_free; ++b) {
      result.covariance[model.free_index[a] * num_params + model.free_index[b]] =
          variance_factor * covariance_z[a * num_free + b] * model.scale[a] * model.scale[b];
    }
  }
  const double t975 = student_t_quantile(0.975, result.dof);
  result.ci95_low = result.values;
  result.ci95_high = result.values;
  for (int k = 0; k < num_params; ++k) {
    if (!is_free[k]) continue;
    const double half = t975 * std::sqrt(std::max(0.0, result.covariance[k * num_params + k]));
    result.ci95_low[k] -= half;
    result.ci95_high[k] += half;
  }

  // Least-squares refits on subsets start from the optimum; each is a fresh Ceres problem.
  Model fit_model = model;
  fit_model.params = result.values;
  const std::vector<double> z_best = fit_model.z_of_params();
  std::mt19937 rng(options.seed);

  if (options.cv_folds > 0) {
    const int folds = options.cv_folds;
    const int smallest_train = num_points - (num_points + folds - 1) / folds;
    if (num_points < folds || smallest_train < num_free + 1) {
      result.notes.push_back(fmt::format(
          "{}-fold cross-validation skipped: {} points leave too few ({}) to fit {} parameters.",
          folds, num_points, smallest_train, num_free));
    } else {
      std::vector<int> order(num_points);
      std::iota(order.begin(), order.end(), 0);
      std::shuffle(order.begin(), order.end(), rng);
      double sum_rel2 = 0.0;
      int failed = 0;
      for (int f = 0; f < folds; ++f) {
        std::vector<FitPoint> train, test;
        for (int i = 0; i < num_points; ++i)
          (i % folds == f ? test : train).push_back(points[order[i]]);
        std::vector<double> zf = z_best;
        const SolveOutcome s =
            solve_lsq(fit_model, train, options.loss, options.loss_scale, zf, false);
        if (!s.converged) ++failed;
        for (const FitPoint& p : test) {
          sum_rel2 += std::pow(
              internal::model_F(fit_model, zf.data(), p.phi, p.re, p.extra_data()) / p.F - 1.0, 2);
        }
      }
      result.cv_rms_rel_err = std::sqrt(sum_rel2 / num_points);
      if (failed > 0) {
        result.notes.push_back(
            fmt::format("Cross-validation: {} of {} fold fits did not fully "
                        "converge (their last iterate was used).",
                        failed, folds));
      }
    }
  }

  if (options.bootstrap > 0) {
    std::vector<std::vector<double>> samples;
    std::uniform_int_distribution<int> pick(0, num_points - 1);
    std::vector<FitPoint> resample(num_points);
    for (int b = 0; b < options.bootstrap; ++b) {
      for (int i = 0; i < num_points; ++i) resample[i] = points[pick(rng)];
      std::vector<double> zb = z_best;
      const SolveOutcome s =
          solve_lsq(fit_model, resample, options.loss, options.loss_scale, zb, false);
      if (s.converged) samples.push_back(zb);
    }
    if (samples.size() >= 2) {
      result.bootstrap_stddev.assign(num_params, 0.0);
      for (int j = 0; j < num_free; ++j) {
        double mean = 0.0, m2 = 0.0;
        for (const auto& s : samples) mean += s[j];
        mean /= samples.size();
        for (const auto& s : samples) m2 += (s[j] - mean) * (s[j] - mean);
        result.bootstrap_stddev[model.free_index[j]] =
            std::sqrt(m2 / (samples.size() - 1.0)) * model.scale[j];
      }
      if (static_cast<int>(samples.size()) < options.bootstrap) {
        result.notes.push_back(fmt::format("Bootstrap: {} of {} refits converged.", samples.size(),
                                           options.bootstrap));
      }
    } else {
      result.notes.push_back("Bootstrap: fewer than 2 refits converged; no bootstrap spread.");
    }
  }
  return result;
}

}  // namespace internal

int num_free_parameters(const FitOptions& options) {
  const std::vector<bool> is_free =
      internal::requested_free(internal::checked_form(options.form), options);
  return static_cast<int>(std::count(is_free.begin(), is_free.end(), true));
}

}  // namespace fitter
}  // namespace draglab
