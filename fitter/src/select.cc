// fit_law's subset selection (the largest free set the data determine) and the comparison of
// forms on one dataset (compare_forms).
//
// Why a selection: a campaign over a limited (phi, Re) range often cannot separate all five of
// Eq. 6's C0/C1 coefficients (b, c1, c2 trade off against each other when Re spans one decade).
// Publishing such a fit would publish intervals wider than the values; fixing the weakest at
// their published values and fitting the rest is what a closure modeller does by hand, and the
// criterion (every interval narrower than its value, then AICc) is printed so it can be checked.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "draglab/error.h"
#include "draglab/fitter/fit.h"
#include "fit_internal.h"

namespace draglab {
namespace fitter {

std::vector<std::string> FitResult::undetermined() const {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (!is_free[k]) continue;
    const double half = 0.5 * (ci95_high[k] - ci95_low[k]);
    if (!(half < std::fabs(values[k]))) out.push_back(names[k]);
  }
  return out;
}

double FitResult::strongest_correlation(std::string* pair) const {
  const std::size_t n = names.size();
  double worst = 0.0;
  if (covariance.size() != n * n) return worst;
  for (std::size_t i = 0; i < n; ++i) {
    if (!is_free[i]) continue;
    for (std::size_t j = i + 1; j < n; ++j) {
      if (!is_free[j]) continue;
      const double cii = covariance[i * n + i], cjj = covariance[j * n + j];
      if (!(cii > 0.0 && cjj > 0.0)) continue;
      const double r = covariance[i * n + j] / std::sqrt(cii * cjj);
      if (std::fabs(r) > std::fabs(worst)) {
        worst = r;
        if (pair) *pair = names[i] + " and " + names[j];
      }
    }
  }
  return worst;
}

namespace {

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i];
  return out;
}

double aicc_of(double chi2, int k, int n) {
  const double correction =
      n - k - 1 > 0 ? 2.0 * k * (k + 1) / (n - k - 1) : std::numeric_limits<double>::infinity();
  return chi2 + 2.0 * k + correction;
}

/// A least-squares fit of one subset: what the selection needs, nothing more (no global check,
/// no cross-validation, no bootstrap, no constraint grid).
SubsetCandidate fit_subset(const std::vector<FitPoint>& points, FitOptions options,
                           const std::vector<std::string>& free, bool rethrow = false) {
  SubsetCandidate c;
  c.free = free;
  options.free = free;
  options.selection = Selection::kOff;
  options.objective = Objective::kLeastSquares;
  options.global_check = false;
  options.check_constraints = false;
  options.cv_folds = 0;
  options.bootstrap = 0;
  try {
    const FitResult r = internal::fit_requested(points, options);
    c.fitted = true;
    c.chi2 = r.chi2;
    c.aicc = aicc_of(r.chi2, r.num_free, r.num_points);
    c.rms_rel_err = r.rms_rel_err;
    c.undetermined = r.undetermined();
    c.determined = c.undetermined.empty();
  } catch (const Error& e) {
    if (rethrow) throw;
    c.why = e.what();
  }
  return c;
}

bool better(const SubsetCandidate& a, const SubsetCandidate& b) {
  if (a.determined != b.determined) return a.determined;
  if (a.free.size() != b.free.size()) return a.free.size() > b.free.size();
  if (a.fitted != b.fitted) return a.fitted;
  return a.aicc < b.aicc;
}

}  // namespace

FitResult fit_law(const std::vector<FitPoint>& points, const FitOptions& options) {
  if (options.selection == Selection::kOff) return internal::fit_requested(points, options);
  std::string why;
  if (!options.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, "fit options: " + why);
  const LawForm& form = internal::checked_form(options.form);
  const std::vector<bool> is_free = internal::requested_free(form, options);
  SelectionReport report;
  for (int k = 0; k < form.num_parameters; ++k) {
    if (is_free[k]) report.requested.push_back(form.description.parameters[k].name);
  }

  // The requested set first: when the data determine it, the fit is the plain fit.
  FitOptions requested_options = options;
  requested_options.free = report.requested;
  requested_options.selection = Selection::kOff;
  SubsetCandidate requested;
  try {
    requested = fit_subset(points, options, report.requested, true);
  } catch (const Error& e) {
    // Bad input (too few points, a bad value) is not a matter of selection; a flat direction
    // or an optimizer lost along one is.
    const bool flat = e.code() == ErrorCode::kOutOfValidity ||
                      std::string(e.what()).find("not determined") != std::string::npos;
    if (!flat) throw;
    requested.free = report.requested;
    requested.why = e.what();
  }
  if (requested.determined) {
    FitResult result = internal::fit_requested(points, requested_options);
    report.chosen = report.requested;
    result.selection = report;
    return result;
  }
  report.performed = true;
  report.undetermined = requested.undetermined;
  if (requested.fitted) {
    FitOptions probe = requested_options;
    probe.global_check = false;
    probe.cv_folds = 0;
    probe.bootstrap = 0;
    probe.check_constraints = false;
    const FitResult r = internal::fit_requested(points, probe);
    std::string pair;
    const double corr = r.strongest_correlation(&pair);
    if (!pair.empty()) report.inseparable = fmt::format("{} (correlation {:.4f})", pair, corr);
  } else {
    report.inseparable = requested.why;
  }

  // Every proper subset (2^n - 2 fits of a few points each) up to 10 parameters; beyond that,
  // backward elimination of the least determined parameter.
  const std::size_t n = report.requested.size();
  report.candidates.push_back(requested);
  if (n <= 10) {
    for (unsigned mask = 1; mask + 1 < (1u << n); ++mask) {
      std::vector<std::string> subset;
      for (std::size_t j = 0; j < n; ++j) {
        if (mask & (1u << j)) subset.push_back(report.requested[j]);
      }
      report.candidates.push_back(fit_subset(points, options, subset));
    }
  } else {
    std::vector<std::string> current = report.requested;
    SubsetCandidate last = requested;
    while (current.size() > 1 && !last.determined) {
      const std::string drop =
          !last.undetermined.empty() ? last.undetermined.back() : current.back();
      current.erase(std::find(current.begin(), current.end(), drop));
      last = fit_subset(points, options, current);
      report.candidates.push_back(last);
    }
  }
  std::stable_sort(report.candidates.begin(), report.candidates.end(), better);
  const SubsetCandidate& best = report.candidates.front();
  if (!best.determined) {
    // Nothing smaller helps: the requested set is fitted as asked (if it can be), and the
    // report says which intervals are wider than their values.
    if (!requested.fitted) {
      throw Error(ErrorCode::kInvalidArgument,
                  fmt::format("no subset of the free parameters {} of form {} is determined by "
                              "these {} points, and the full set cannot be fitted ({}): add data "
                              "over a wider phi and Re range or fix parameters with --set",
                              join(report.requested), form.key(), points.size(), requested.why));
    }
    FitResult result = internal::fit_requested(points, requested_options);
    report.chosen = report.requested;
    result.notes.push_back(fmt::format(
        "Subset selection: no subset of {} is determined by these data (every one leaves a 95 % "
        "interval wider than its value); the requested set is fitted as given, and {} remain "
        "undetermined.",
        join(report.requested), join(report.undetermined)));
    result.selection = report;
    return result;
  }
  report.chosen = best.free;

  FitOptions chosen_options = options;
  chosen_options.free = report.chosen;
  chosen_options.selection = Selection::kOff;
  FitResult result = internal::fit_requested(points, chosen_options);
  std::vector<std::string> fixed;
  for (const std::string& name : report.requested) {
    if (std::find(report.chosen.begin(), report.chosen.end(), name) == report.chosen.end())
      fixed.push_back(name);
  }
  result.notes.push_back(fmt::format(
      "Subset selection: fitting all of {} leaves {} with 95 % intervals wider than their "
      "values (least separable: {}); fitted the largest determined subset {} (AICc {:.4g}, "
      "lowest of its size), with {} fixed at their starting values.",
      join(report.requested),
      report.undetermined.empty() ? std::string("a flat direction") : join(report.undetermined),
      report.inseparable.empty() ? "-" : report.inseparable, join(report.chosen), best.aicc,
      join(fixed)));
  result.selection = report;
  return result;
}

std::vector<FormComparisonRow> compare_forms(const std::vector<FitPoint>& points,
                                             const std::vector<const Law*>& published, int cv_folds,
                                             unsigned seed) {
  struct Refit {
    std::string label, form;
    std::vector<std::string> free;  // empty = the form's default set
  };
  const std::vector<Refit> refits = {
      {"Eq. 6 (vdh2004) refit, n = 3", "vdh2004", {}},
      {"Eq. 6 (vdh2004) refit, n free", "vdh2004", {"n0", "k0", "k1", "c10", "c11", "c12"}},
      {"bvk2007 refit", "bvk2007", {}},
      {"tang2015 refit", "tang2015", {}},
  };
  std::vector<FormComparisonRow> rows;
  for (const Refit& refit : refits) {
    FormComparisonRow row;
    row.label = refit.label;
    row.form = refit.form;
    row.refitted = true;
    FitOptions options;
    options.form = refit.form;
    options.free = refit.free;
    options.seed = seed;
    options.global_check = false;
    options.check_constraints = false;
    const int smallest_train = static_cast<int>(points.size()) -
                               (static_cast<int>(points.size()) + cv_folds - 1) / cv_folds;
    options.cv_folds = cv_folds > 0 && smallest_train > 6 ? cv_folds : 0;
    try {
      const FitResult r = fit_law(points, options);
      for (std::size_t k = 0; k < r.names.size(); ++k) {
        if (r.is_free[k]) row.free.push_back(r.names[k]);
      }
      row.rms_rel_err = r.rms_rel_err;
      row.max_rel_err = r.max_rel_err;
      row.cv_rms_rel_err = r.cv_rms_rel_err;
      row.aicc = aicc_of(r.chi2, r.num_free, r.num_points);
    } catch (const Error& e) {
      row.error = e.what();
    }
    rows.push_back(row);
  }
  for (const Law* law : published) {
    FormComparisonRow row;
    row.label = law->reference() + " as published";
    row.form = law->record().form;
    double sum2 = 0.0, worst = 0.0;
    for (double e : relative_errors(*law, points)) {
      sum2 += e * e;
      worst = std::max(worst, std::fabs(e));
    }
    row.rms_rel_err = points.empty() ? 0.0 : std::sqrt(sum2 / points.size());
    row.max_rel_err = worst;
    row.cv_rms_rel_err = row.rms_rel_err;
    rows.push_back(row);
  }
  return rows;
}

std::string form_comparison_markdown(const std::vector<FormComparisonRow>& rows) {
  std::string out =
      "| law | fitted parameters | rms error | max error | CV rms error | AICc |\n"
      "|---|---|---:|---:|---:|---:|\n";
  for (const FormComparisonRow& r : rows) {
    if (!r.error.empty()) {
      out += fmt::format("| {} | refit failed: {} | | | | |\n", r.label, r.error);
      continue;
    }
    out += fmt::format(
        "| {} | {} | {:.2f} % | {:.2f} % | {} | {} |\n", r.label,
        r.refitted ? join(r.free) : "none (as published)", 100 * r.rms_rel_err, 100 * r.max_rel_err,
        r.cv_rms_rel_err >= 0 ? fmt::format("{:.2f} %", 100 * r.cv_rms_rel_err) : "-",
        r.refitted ? fmt::format("{:.4g}", r.aicc) : "-");
  }
  return out;
}

std::string form_comparison_json_text(const std::vector<FormComparisonRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const FormComparisonRow& r : rows) {
    out.push_back({{"label", r.label},
                   {"form", r.form},
                   {"refitted", r.refitted},
                   {"free", r.free},
                   {"rms_rel_err", r.rms_rel_err},
                   {"max_rel_err", r.max_rel_err},
                   {"cv_rms_rel_err", r.cv_rms_rel_err >= 0 ? nlohmann::json(r.cv_rms_rel_err)
                                                            : nlohmann::json(nullptr)},
                   {"aicc", r.refitted ? nlohmann::json(r.aicc) : nlohmann::json(nullptr)},
                   {"error", r.error}});
  }
  return out.dump();
}

}  // namespace fitter
}  // namespace draglab
