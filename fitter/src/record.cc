// FitResult reports and the draft law record of a fit.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "drag_db_version.h"
#include "draglab/fitter/fit.h"

namespace draglab {
namespace fitter {

std::string FitResult::BriefReport() const {
  return fmt::format(
      "{}: {} free of {} parameters, {} points, chi2/dof = {:.4g}, rms/max relative error = "
      "{:.3g}/{:.3g}{}{}{}",
      form, num_free, names.size(), num_points, chi2_per_dof, rms_rel_err, max_rel_err,
      cv_rms_rel_err >= 0.0 ? fmt::format(", CV rms = {:.3g}", cv_rms_rel_err) : "",
      global_checked ? (global_agrees ? ", global check agrees" : ", global check DISAGREES") : "",
      constraints_checked
          ? (constraints_satisfied ? ", constraints hold" : ", constraints VIOLATED")
          : "");
}

std::string FitResult::FullReport() const {
  std::vector<double> printed(names.size(), std::nan(""));
  try {
    printed = find_law_form(form).default_parameters();
  } catch (const std::exception&) {
  }
  std::string out = fmt::format("Fit of form {} to {} points ({} free parameters, dof {})\n", form,
                                num_points, num_free, dof);
  out += fmt::format("{:<6} {:>12} {:>14} {:>28} {:>12}  {}\n", "param", "printed", "fitted",
                     "95 % interval", "bootstrap sd", "");
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string interval =
        is_free[k] ? fmt::format("[{:.6g}, {:.6g}]", ci95_low[k], ci95_high[k]) : "";
    const std::string boot =
        bootstrap_stddev.empty() || !is_free[k] ? "" : fmt::format("{:.4g}", bootstrap_stddev[k]);
    out += fmt::format("{:<6} {:>12.6g} {:>14.7g} {:>28} {:>12}  {}\n", names[k], printed[k],
                       values[k], interval, boot, is_free[k] ? "free" : "fixed");
  }
  out += fmt::format("chi2 = {:.6g}, chi2/dof = {:.4g}; relative error rms {:.4g}, max {:.4g}",
                     chi2, chi2_per_dof, rms_rel_err, max_rel_err);
  if (cv_rms_rel_err >= 0.0) out += fmt::format("; cross-validation rms {:.4g}", cv_rms_rel_err);
  out += "\n";
  if (global_checked) {
    out +=
        fmt::format("NLopt global check: best cost {:.10g}: {}{}\n", global_best_cost,
                    global_agrees ? "Ceres found the global optimum" : "Ceres did NOT",
                    global_restarted ? " (after a restart from the global search's optimum)" : "");
  }
  if (constraints_checked) {
    out += "Constraints F > 0, dF/dRe >= 0 over the validity grid: " +
           (constraints_satisfied ? std::string("satisfied") : "VIOLATED: " + constraint_report) +
           "\n";
  }
  out += "Ceres: " + ceres_report + "\n";
  if (selection.performed) {
    auto join = [](const std::vector<std::string>& items) {
      std::string text;
      for (std::size_t i = 0; i < items.size(); ++i) text += (i ? "," : "") + items[i];
      return text;
    };
    out += fmt::format(
        "Subset selection: fitting all of {} leaves {} with 95 % intervals wider than their "
        "values (least separable: {}); the largest determined subset is fitted (ties: lowest "
        "AICc). Candidates ({} fitted):\n",
        join(selection.requested),
        selection.undetermined.empty() ? std::string("a flat direction")
                                       : join(selection.undetermined),
        selection.inseparable, selection.candidates.size());
    out += fmt::format("  {:<28} {:>3} {:>12} {:>12} {:>9}  {}\n", "free", "k", "chi2", "AICc",
                       "rms", "determined");
    const std::size_t shown = std::min<std::size_t>(selection.candidates.size(), 12);
    for (std::size_t i = 0; i < shown; ++i) {
      const SubsetCandidate& c = selection.candidates[i];
      const bool chosen = c.free == selection.chosen;
      if (!c.fitted) {
        out += fmt::format("  {:<28} {:>3} {:>12} {:>12} {:>9}  fit failed\n", join(c.free),
                           c.free.size(), "-", "-", "-");
        continue;
      }
      out += fmt::format("  {:<28} {:>3} {:>12.6g} {:>12.6g} {:>8.3f}%  {}{}\n", join(c.free),
                         c.free.size(), c.chi2, c.aicc, 100 * c.rms_rel_err,
                         c.determined ? "yes" : "no (" + join(c.undetermined) + ")",
                         chosen ? "  <- chosen" : "");
    }
    if (shown < selection.candidates.size()) {
      out += fmt::format("  ({} more, all smaller or undetermined)\n",
                         selection.candidates.size() - shown);
    }
  }
  for (const std::string& note : notes) out += "note: " + note + "\n";
  return out;
}

LawRecord fitted_record(const FitResult& result, const FitOptions& options, const std::string& name,
                        const std::string& dataset_id, const std::string& dataset_hash,
                        const std::vector<FitPoint>& points) {
  const LawForm& form = find_law_form(result.form);
  LawRecord record;
  record.name = name;
  record.form = result.form;
  for (std::size_t k = 0; k < result.names.size(); ++k) {
    record.parameters.push_back(
        {result.names[k], result.values[k], form.description.parameters[k].unit});
  }
  record.covariance = result.covariance;
  record.convention = form.convention;
  record.validity = form.description.validity;
  if (!points.empty()) {
    auto [phi_lo, phi_hi] =
        std::minmax_element(points.begin(), points.end(),
                            [](const FitPoint& a, const FitPoint& b) { return a.phi < b.phi; });
    auto [re_lo, re_hi] =
        std::minmax_element(points.begin(), points.end(),
                            [](const FitPoint& a, const FitPoint& b) { return a.re < b.re; });
    record.validity.phi = {phi_lo->phi, phi_hi->phi};
    record.validity.re = {re_lo->re, re_hi->re};
    // A polydisperse form's extra inputs: the range the data cover.
    for (std::size_t k = 0; k < record.validity.extra.size(); ++k) {
      double lo = std::numeric_limits<double>::max(), hi = -lo;
      for (const FitPoint& p : points) {
        if (k >= p.extra.size()) continue;
        lo = std::min(lo, p.extra[k]);
        hi = std::max(hi, p.extra[k]);
      }
      if (lo <= hi) record.validity.extra[k].range = {lo, hi};
    }
  }
  record.provenance.kind = "fitted";
  record.provenance.citation = "draglab fit of " + form.description.title;
  record.provenance.dataset_id = dataset_id;
  record.provenance.data_hash = dataset_hash;
  nlohmann::json settings;
  settings["options"] = nlohmann::json::parse(options.to_json());
  nlohmann::json free = nlohmann::json::array();
  for (std::size_t k = 0; k < result.names.size(); ++k) {
    if (result.is_free[k]) free.push_back(result.names[k]);
  }
  settings["free_parameters"] = free;
  if (result.selection.performed) {
    settings["selection"] = {{"requested", result.selection.requested},
                             {"undetermined", result.selection.undetermined},
                             {"least_separable", result.selection.inseparable},
                             {"chosen", result.selection.chosen}};
  }
  // The fit's own 95 % intervals (Student t with the fit's dof), so that reports show exactly
  // what the fitter reported rather than re-deriving them from the covariance.
  nlohmann::json ci95 = nlohmann::json::object();
  for (std::size_t k = 0; k < result.names.size(); ++k) {
    if (result.is_free[k]) ci95[result.names[k]] = {result.ci95_low[k], result.ci95_high[k]};
  }
  settings["ci95"] = ci95;
  settings["statistics"] = {{"num_points", result.num_points},
                            {"dof", result.dof},
                            {"chi2", result.chi2},
                            {"chi2_per_dof", result.chi2_per_dof},
                            {"rms_rel_err", result.rms_rel_err},
                            {"max_rel_err", result.max_rel_err},
                            {"cv_rms_rel_err", result.cv_rms_rel_err},
                            {"global_checked", result.global_checked},
                            {"global_agrees", result.global_agrees},
                            {"constraints_checked", result.constraints_checked},
                            {"constraints_satisfied", result.constraints_satisfied}};
  settings["ceres"] = result.ceres_report;
  record.provenance.fitter_settings = settings.dump();
  record.provenance.code_version = kDragDbVersion;
  record.status = LawStatus::kDraft;
  record.notes = fmt::format("{} fit of {}: rms relative error {:.3g}, max {:.3g} over {} points",
                             to_string(options.objective), result.form, result.rms_rel_err,
                             result.max_rel_err, result.num_points);
  return record;
}

}  // namespace fitter
}  // namespace draglab
