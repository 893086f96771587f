// workflows/src/report.cc: see draglab/workflows/report.h.
#include "draglab/workflows/report.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "drag_db_version.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/fitter/fit.h"
#include "draglab/workflows/scripts.h"

namespace draglab {
namespace workflows {

namespace {

constexpr double kNormalQuantile975 = 1.959963984540054;
constexpr int kReCurvePoints = 60;      // per phi; smooth on a log axis spanning ~3 decades
constexpr int kStokesCurvePoints = 81;  // F(phi, 0) over the data's phi range
const char* const kFigures[] = {"fig3_seed.png", "parity.png", "residuals.png",
                                "work_precision.png"};

/// A law of the report: fitted (--law) or a comparison (--compare / the default list).
struct ReportLaw {
  std::shared_ptr<Law> law;
  std::string role;  ///< "fit" or "reference"
  std::string label;
};

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string law_label(const LawRecord& r, const std::string& role) {
  if (role == "fit") return r.reference() + " (fit)";
  if (r.name == "vdh2004") return r.reference() + " (Eq. 6 as printed)";
  if (r.name == "ergun") return r.reference() + " (Ergun)";
  if (r.name == "hill_koch_ladd") return r.reference() + " (Hill-Koch-Ladd)";
  if (r.name == "bvk2007") return r.reference() + " (Beetstra et al. 2007)";
  return r.reference();
}

/// F at (phi, re) with the extrapolate policy; NaN when the formula gives no finite value there.
double evaluate_or_nan(const Law& law, double phi, double re, bool* outside) {
  try {
    const LawEvaluation e = law.evaluate(phi, re);
    *outside = e.out_of_validity;
    return std::isfinite(e.F) ? e.F : std::numeric_limits<double>::quiet_NaN();
  } catch (const Error&) {
    *outside = true;
    return std::numeric_limits<double>::quiet_NaN();
  }
}

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

std::vector<double> log_grid(double lo, double hi, int n) {
  std::vector<double> g(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    g[static_cast<std::size_t>(i)] =
        lo * std::pow(hi / lo, static_cast<double>(i) / static_cast<double>(n - 1));
  }
  return g;
}

/// Everything the figures need for one law: smooth curves, the Stokes curve, values at the data
/// points and the relative differences from the data.
nlohmann::json dataset_json(const Dataset& ds, const std::string& source) {
  nlohmann::json points = nlohmann::json::array();
  for (const DatasetPoint& p : ds.points) {
    points.push_back({{"phi", p.phi},
                      {"re", p.re},
                      {"re_target", p.re_target},
                      {"F", p.F},
                      {"F_uncertainty", p.F_uncertainty},
                      {"F_standard_error", p.F_standard_error},
                      {"F_discretisation_error", p.F_discretisation_error},
                      {"realizations", p.realizations},
                      {"resolutions", p.resolutions},
                      {"extrapolation", p.extrapolation},
                      {"wall_s", p.wall_s}});
  }
  return {{"id", ds.id},
          {"hash", ds.hash},
          {"name", ds.name},
          {"source", source},
          {"campaign_id", ds.campaign_id},
          {"points", points}};
}

nlohmann::json units_json(const std::vector<campaign::UnitRecord>& units) {
  nlohmann::json out = nlohmann::json::array();
  for (const campaign::UnitRecord& u : units) {
    out.push_back({{"id", u.id},
                   {"phi", u.phi},
                   {"re_target", u.re_target},
                   {"realization", u.realization},
                   {"resolution", u.resolution},
                   {"status", u.status},
                   {"F", u.F},
                   {"re", u.re},
                   {"error_estimate", u.error_estimate},
                   {"wall_s", u.wall_s},
                   {"steps", u.steps},
                   {"diagnosis", u.diagnosis}});
  }
  return out;
}

/// The dataset's checks the figures rely on (a stored dataset passed them already; a CSV too, but
/// an empty one would give empty axes).
void check_dataset(const Dataset& ds, const std::string& field) {
  if (ds.points.empty())
    throw Error(ErrorCode::kInvalidArgument, field + ": the dataset has no points");
  for (const DatasetPoint& p : ds.points) {
    if (!(p.F > 0.0) || !std::isfinite(p.F) || !(p.phi > 0.0 && p.phi < 1.0) || !(p.re >= 0.0)) {
      throw Error(
          ErrorCode::kInvalidArgument,
          fmt::format(
              "{}: point phi = {}, Re = {}, F = {}: every point needs phi in (0, 1), Re >= 0 and a "
              "finite F > 0",
              field, p.phi, p.re, p.F));
    }
  }
}

struct ReportInputs {
  Dataset dataset;
  std::string source;
  std::vector<ReportLaw> laws;
  nlohmann::json missing = nlohmann::json::array();
  std::int64_t campaign_id = 0;
  std::vector<campaign::UnitRecord> units;
};

/// Loads the dataset, the laws and the units; throws (exit 2) on bad input before anything is
/// written.
ReportInputs load_inputs(const Database& db, const ReportOptions& c, const Messages& messages) {
  ReportInputs in;
  if (!c.data_csv.empty()) {
    if (!core::file_exists(c.data_csv)) {
      throw Error(ErrorCode::kInvalidArgument,
                  fmt::format("--data: no such file '{}'", c.data_csv));
    }
    in.dataset = read_dataset_csv(c.data_csv);  // Error(kInvalidArgument) names line and column
    in.source = "csv:" + c.data_csv;
    check_dataset(in.dataset, "--data");
  } else {
    in.dataset = load_dataset(db, c.dataset_id);  // Error(kNotFound): exit 2
    in.source = "database";
    check_dataset(in.dataset, "--dataset");
  }

  auto add_law = [&](const std::string& ref, const std::string& role, bool required) {
    std::string warning;
    std::shared_ptr<Law> law;
    try {
      law = db.load(ref, RangePolicy::kExtrapolate, &warning);
    } catch (const Error& e) {
      if (required || e.code() != ErrorCode::kNotFound) {
        throw Error(e.code(),
                    fmt::format("{} {}: {}", role == "fit" ? "--law" : "--compare", ref, e.what()));
      }
      messages.warn(fmt::format("comparison law {} skipped: {}", ref, e.what()));
      in.missing.push_back({{"reference", ref}, {"reason", e.what()}});
      return;
    }
    if (law->num_extra_inputs() != 0) {
      const std::string why = fmt::format(
          "{} needs {} extra (polydisperse) input(s) per point, which a dataset does not carry",
          law->reference(), law->num_extra_inputs());
      if (required) throw Error(ErrorCode::kInvalidArgument, why);
      messages.warn("comparison law skipped: " + why);
      in.missing.push_back({{"reference", ref}, {"reason", why}});
      return;
    }
    for (const ReportLaw& have : in.laws) {
      if (have.law->reference() == law->reference()) return;  // listed twice: draw it once
    }
    // A fitted draft is the normal case (before `law publish`); a retraction always warns.
    if (!warning.empty() && (role != "fit" || law->record().status == LawStatus::kRetracted)) {
      messages.warn(warning);
    }
    in.laws.push_back({law, role, law_label(law->record(), role)});
  };
  for (const std::string& ref : c.laws) add_law(ref, "fit", true);
  const std::vector<std::string> compare =
      core::split_list(c.compare_given ? c.compare : ReportOptions::kDefaultComparisons,
                       "--compare", "vdh2004@1,ergun@1");
  for (const std::string& ref : compare) add_law(ref, "reference", c.compare_given);
  if (in.laws.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                "no law to compare with: give --law NAME@V or --compare REF,...");
  }

  if (!c.campaign.empty()) {
    in.campaign_id = campaign::campaign_status(db, c.campaign).id;  // kNotFound: exit 2
  } else {
    in.campaign_id = in.dataset.campaign_id;
  }
  if (in.campaign_id != 0) {
    try {
      in.units = campaign::list_units(db, in.campaign_id);
    } catch (const Error& e) {
      if (!c.campaign.empty()) throw;
      // The dataset names a campaign this database does not hold (copied dataset): no units.
      messages.warn(
          fmt::format("campaign {} of the dataset: {}; the work-precision figure stays empty",
                      in.campaign_id, e.what()));
    }
  }
  return in;
}

nlohmann::json conventions_json() {
  return {
      {"F", "canonical drag-only force F = F_d / (3 pi mu d eps u), mean-pressure part excluded"},
      {"Re", "superficial, diameter based: Re = rho eps d u / mu (u interstitial slip)"},
      {"beta", "beta d^2/mu = 18 phi eps F; K = F/(1 - phi) is the total force"},
      {"fig3_axes",
       "y = (beta d^2/mu) eps/((1 - eps) Re) = 18 eps^2 F / Re, x = Re/(1 - eps) = Re/phi"},
      {"relative_difference", "|F_law/F_data - 1| at the data points"},
      {"range_policy",
       "laws are evaluated with the 'extrapolate' policy; outside_validity marks the points "
       "outside a law's validity box"},
      {"uncertainty", "F_uncertainty is 1 sigma (realizations and resolution extrapolation)"},
      {"ci95", "parameter value +- 1.959964 sqrt(covariance diagonal) (normal quantile)"}};
}

}  // namespace

nlohmann::json report_law_json(const Law& law, const std::string& role, const std::string& label,
                               const Dataset& ds, ReportLawStatistics* stats_out) {
  const LawRecord& r = law.record();
  nlohmann::json j = {{"reference", r.reference()},
                      {"name", r.name},
                      {"version", r.version},
                      {"label", label},
                      {"role", role},
                      {"form", r.form},
                      {"status", to_string(r.status)},
                      {"hash", r.content_hash},
                      {"provenance", r.provenance.kind},
                      {"validity",
                       {{"phi", {r.validity.phi.min, r.validity.phi.max}},
                        {"re", {r.validity.re.min, r.validity.re.max}}}}};
  if (!r.provenance.dataset_id.empty()) j["dataset_id"] = r.provenance.dataset_id;
  nlohmann::json params = nlohmann::json::array();
  for (const LawParameter& p : r.parameters) {
    params.push_back({{"name", p.name}, {"value", p.value}, {"unit", p.unit}});
  }
  j["parameters"] = params;
  if (!r.provenance.fitter_settings.empty()) {
    // The fitter's record of which parameters were free and its statistics (fitter/record.cc);
    // shown in report.md when present, ignored if it is not the JSON the fitter writes.
    const nlohmann::json settings =
        nlohmann::json::parse(r.provenance.fitter_settings, nullptr, /*allow_exceptions=*/false);
    if (settings.is_object()) {
      nlohmann::json fitter = nlohmann::json::object();
      for (const char* key : {"free_parameters", "statistics", "ci95"}) {
        if (settings.contains(key)) fitter[key] = settings[key];
      }
      if (!fitter.empty()) j["fitter"] = fitter;
    }
  }
  const std::size_t n = r.parameters.size();
  if (r.covariance.size() == n * n && n > 0) {
    j["covariance"] = r.covariance;
    nlohmann::json ci = nlohmann::json::array();
    for (std::size_t i = 0; i < n; ++i) {
      const double var = r.covariance[i * n + i];
      const double half = std::sqrt(std::max(var, 0.0)) * kNormalQuantile975;
      ci.push_back({r.parameters[i].value - half, r.parameters[i].value + half});
    }
    j["ci95"] = ci;
    j["ci95_method"] = "normal";
    // Prefer the fitter's own (Student t) intervals where its record has them.
    if (j.contains("fitter") && j["fitter"].contains("ci95") && j["fitter"]["ci95"].is_object()) {
      for (std::size_t i = 0; i < n; ++i) {
        const auto& fitted = j["fitter"]["ci95"];
        if (fitted.contains(r.parameters[i].name)) {
          j["ci95"][i] = fitted[r.parameters[i].name];
          j["ci95_method"] = "student_t";
        }
      }
    }
  }

  // Curves for the seed figure: per phi of the data, Re on a log grid over the data's Re > 0.
  std::set<double> phis;
  double re_min = std::numeric_limits<double>::infinity(), re_max = 0.0;
  double phi_min = 1.0, phi_max = 0.0;
  for (const DatasetPoint& p : ds.points) {
    phis.insert(p.phi);
    phi_min = std::min(phi_min, p.phi);
    phi_max = std::max(phi_max, p.phi);
    if (p.re > 0.0) {
      re_min = std::min(re_min, p.re);
      re_max = std::max(re_max, p.re);
    }
  }
  nlohmann::json curves = nlohmann::json::array();
  if (re_max > 0.0) {
    const std::vector<double> res = log_grid(re_min / 1.5, re_max * 1.5, kReCurvePoints);
    for (double phi : phis) {
      nlohmann::json F = nlohmann::json::array(), outside = nlohmann::json::array();
      for (double re : res) {
        bool out = false;
        F.push_back(number_or_null(evaluate_or_nan(law, phi, re, &out)));
        outside.push_back(out);
      }
      curves.push_back({{"phi", phi}, {"re", res}, {"F", F}, {"outside_validity", outside}});
    }
  }
  j["curves"] = curves;
  {
    // Stokes limit over the data's phi range, widened a little so the data sit inside the line.
    const double lo = std::max(0.01, phi_min - 0.05), hi = std::min(0.65, phi_max + 0.05);
    nlohmann::json phi_grid = nlohmann::json::array(), F = nlohmann::json::array(),
                   outside = nlohmann::json::array();
    for (int i = 0; i < kStokesCurvePoints; ++i) {
      const double phi = lo + (hi - lo) * i / (kStokesCurvePoints - 1);
      bool out = false;
      phi_grid.push_back(phi);
      F.push_back(number_or_null(evaluate_or_nan(law, phi, 0.0, &out)));
      outside.push_back(out);
    }
    j["stokes_curve"] = {{"phi", phi_grid}, {"F", F}, {"outside_validity", outside}};
  }

  ReportLawStatistics s;
  s.label = label;
  s.reference = r.reference();
  s.role = role;
  double sum_sq = 0.0;
  nlohmann::json F = nlohmann::json::array(), outside = nlohmann::json::array();
  for (const DatasetPoint& p : ds.points) {
    bool out = false;
    const double f = evaluate_or_nan(law, p.phi, p.re, &out);
    F.push_back(number_or_null(f));
    outside.push_back(out);
    if (out) ++s.n_outside_validity;
    if (!std::isfinite(f)) continue;
    const double rel = std::fabs(f / p.F - 1.0);
    s.max_rel_diff = std::max(s.max_rel_diff, rel);
    sum_sq += rel * rel;
    ++s.n_evaluated;
  }
  s.rms_rel_diff = s.n_evaluated ? std::sqrt(sum_sq / s.n_evaluated) : std::nan("");
  if (!s.n_evaluated) s.max_rel_diff = std::nan("");
  j["at_points"] = {{"F", F}, {"outside_validity", outside}};
  j["stats"] = {{"max_rel_diff", number_or_null(s.max_rel_diff)},
                {"rms_rel_diff", number_or_null(s.rms_rel_diff)},
                {"n_evaluated", s.n_evaluated},
                {"n_outside_validity", s.n_outside_validity}};
  if (stats_out) *stats_out = s;
  return j;
}

std::string ReportOptions::Invalid() const {
  if (dataset_id.empty() && data_csv.empty())
    return "one of --dataset ID or --data FILE.csv is required";
  if (!dataset_id.empty() && !data_csv.empty())
    return "--dataset and --data exclude each other: give one";
  std::string dir = out_dir;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  if (dir.empty()) return "--out DIR is required";
  if (core::file_exists(dir)) return fmt::format("--out: '{}' is a file, not a directory", dir);
  return "";
}

nlohmann::json ReportSummary::ToJson() const {
  return {
      {"out_dir", out_dir}, {"report", report_path}, {"figures", figures}, {"bundle", bundle_path}};
}

std::string ReportSummary::BriefReport() const {
  double worst = -1.0;
  std::string worst_label;
  for (const ReportLawStatistics& s : laws) {
    if (std::isfinite(s.rms_rel_diff) && s.rms_rel_diff > worst) {
      worst = s.rms_rel_diff;
      worst_label = s.label;
    }
  }
  return fmt::format(
      "report: {} law(s) against the data{}; {}", laws.size(),
      worst >= 0.0 ? fmt::format(", largest RMS difference {:.2f} % ({})", 100 * worst, worst_label)
                   : std::string(),
      report_path.empty() ? bundle_path : report_path);
}

std::string ReportSummary::FullReport() const {
  std::string out = fmt::format("{:<44} {:>14} {:>14} {:>9}\n", "law", "max |rel diff|",
                                "RMS rel diff", "outside");
  const auto percent = [](double x) {
    return std::isfinite(x) ? fmt::format("{:.2f} %", 100 * x) : std::string("-");
  };
  for (const ReportLawStatistics& s : laws) {
    out += fmt::format("{:<44} {:>14} {:>14} {:>9}\n", s.label, percent(s.max_rel_diff),
                       percent(s.rms_rel_diff), s.n_outside_validity);
  }
  if (!report_path.empty()) out += "report   " + report_path + '\n';
  for (const std::string& f : figures) out += "figure   " + f + '\n';
  if (!has_units && !report_path.empty())
    out += "(no campaign units: work_precision.png says so and is empty)\n";
  out += "bundle   " + bundle_path + '\n';
  return out;
}

ReportSummary write_report(const Database& db, const ReportOptions& options,
                           const Messages& messages) {
  const std::string invalid = options.Invalid();
  if (!invalid.empty()) throw Error(ErrorCode::kInvalidArgument, invalid);
  ReportOptions c = options;
  while (c.out_dir.size() > 1 && c.out_dir.back() == '/') c.out_dir.pop_back();
  ReportInputs in = load_inputs(db, c, messages);

  ReportSummary summary;
  nlohmann::json laws = nlohmann::json::array();
  for (const ReportLaw& rl : in.laws) {
    ReportLawStatistics s;
    laws.push_back(report_law_json(*rl.law, rl.role, rl.label, in.dataset, &s));
    summary.laws.push_back(s);
    if (s.n_outside_validity > 0) {
      messages.info(
          fmt::format("{}: {} of {} data point(s) outside its validity box (extrapolated)",
                      rl.law->reference(), s.n_outside_validity, in.dataset.points.size()));
    }
  }
  // Forms refitted and laws as published on the same points (the seed's comparison of forms).
  std::vector<fitter::FitPoint> fit_points;
  for (const DatasetPoint& p : in.dataset.points)
    fit_points.push_back({p.phi, p.re, p.F, p.F_uncertainty, {}});
  std::vector<const Law*> published;
  for (const ReportLaw& rl : in.laws) {
    if (rl.role == "reference") published.push_back(rl.law.get());
  }
  const nlohmann::json form_comparison = nlohmann::json::parse(
      fitter::form_comparison_json_text(fitter::compare_forms(fit_points, published, 5, 1)));
  summary.bundle = {{"format", "draglab_report_bundle"},
                    {"format_version", 1},
                    {"generated_at", utc_now()},
                    {"code_version", kDragDbVersion},
                    {"database", db.path()},
                    {"conventions", conventions_json()},
                    {"dataset", dataset_json(in.dataset, in.source)},
                    {"laws", laws},
                    {"form_comparison", form_comparison},
                    {"missing_laws", in.missing},
                    {"campaign_id", in.campaign_id},
                    {"units", units_json(in.units)}};
  summary.has_units = !in.units.empty();

  core::make_directories(c.out_dir, "--out");
  summary.out_dir = c.out_dir;
  summary.bundle_path = c.out_dir + "/report_bundle.json";
  const std::string report_path = c.out_dir + "/report.md";
  // Outputs of an earlier report in the same directory must not pass for this one's.
  for (const char* name : kFigures) std::remove((c.out_dir + "/" + name).c_str());
  std::remove(report_path.c_str());
  core::write_file_atomically(summary.bundle_path, summary.bundle.dump(1) + "\n", "report bundle");
  messages.info("report: bundle written to " + summary.bundle_path);
  if (!c.render_figures) return summary;

  std::vector<std::string> args = {summary.bundle_path, c.out_dir};
  if (c.quiet) args.push_back("--quiet");
  run_figure_script("draglab_report.py", args, summary.bundle_path, report_path);
  summary.report_path = report_path;
  for (const char* name : kFigures) {
    const std::string path = c.out_dir + "/" + name;
    if (core::file_exists(path)) summary.figures.push_back(path);
  }
  return summary;
}

}  // namespace workflows
}  // namespace draglab
