// Regression checks of consumer predictions against stored baselines (regress.h).
#include "draglab/workflows/regress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "draglab/consumers/bed_model.h"
#include "draglab/core/text.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"

namespace draglab {
namespace workflows {
using consumers::BedProgress;
using consumers::consumer_result;
using consumers::find_bed_model;
using consumers::load_scene;
using consumers::parse_scene;
using consumers::run_bed_model;
namespace {

/// A value for a message, with `digits` significant digits.
std::string fmt(double x, int digits = 6) { return core::format_number(x, digits); }

/// IsValid() helper: stores `message` in *error (if given) and returns false.
bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The newest stored result of this scene and law version with the same content (a draft that
// changed since has another content hash, so its old results are not reused).
std::optional<ConsumerResult> stored_result(const Database& db, const std::string& scene_hash,
                                            const LawRecord& record) {
  ConsumerResultFilter filter;
  filter.scene_hash = scene_hash;
  filter.law_name = record.name;
  filter.law_version = record.version;
  filter.law_content_hash = record.content_hash;
  std::vector<ConsumerResult> found = list_consumer_results(db, filter);
  if (found.empty()) return std::nullopt;
  return found.back();
}

// One run of `scene` with `record` by the scene's bed model, as a result ready to store. Throws
// draglab::Error when the run fails (the caller reports it and stores nothing).
ConsumerResult run_scene(const Database& db, const Scene& scene, const LawRecord& record,
                         const BedRunOptions& options, std::vector<std::string>* warnings,
                         const BedProgress& progress) {
  std::string warning;
  std::shared_ptr<const Law> law =
      db.load(record.reference(), range_policy_from_string(scene.range_policy), &warning);
  if (!warning.empty() && warnings) warnings->push_back(warning);
  return consumer_result(scene, *law, run_bed_model(scene, law, options, progress));
}

bool version_is_checked(const LawRecord& record, bool include_drafts) {
  return record.status == LawStatus::kPublished ||
         (include_drafts && record.status == LawStatus::kDraft);
}

// A (scene, law version) to check, before it runs.
struct Planned {
  const ConsumerScene* stored_scene = nullptr;
  std::shared_ptr<const Scene> scene;  // null when the stored text no longer parses
  std::string scene_error;
  LawRecord record;
  std::optional<ConsumerBaseline> baseline;
  std::optional<ConsumerResult> stored;
  bool needs_run() const { return scene && !stored; }
};

std::string cell(double x) { return std::isfinite(x) ? fmt(x, 4) : std::string("-"); }

std::string pad(const std::string& s, std::size_t width) {
  return s.size() >= width ? s + " " : s + std::string(width - s.size(), ' ');
}

}  // namespace

RegressionTolerances default_regression_tolerances(const Scene& scene) {
  return find_bed_model(scene.solver).default_tolerances(scene);
}

// Headline numbers (the DBM's hold-up and circulation; its bubble sizes use the diameter
// tolerances): kHeadlineRelativeTolerance = 10 %. Both are time averages over the run after
// average_from_s, bitwise reproducible for one law content (measured on dbm_tiny: the same
// numbers at 1 and 2 OpenMP threads, with and without coalescence); what a law
// version changes is U_mf, and through it the bubble gas flow (u0 - U_mf) A of two-phase theory,
// to which the hold-up is about proportional: a change of U_mf by the 1 % U_mf tolerance moves
// the hold-up by (U_mf / (u0 - U_mf)) % (7 % on dbm_tiny, U_mf 0.037 of u0 0.042 m/s), so the
// hold-up shows law changes that U_mf alone passes, amplified where u0 is close to U_mf. The
// 10 % lies far above the scatter of the injection phases, which the tolerance must absorb
// because regress runs one seed: measured on dbm_tiny (12 s, gidaspow@1, seeds 1-4), the sample
// standard deviation over the seeds is 0.04 % of the hold-up and 0.003 % of the upflow without
// coalescence, 0.01 % of the hold-up with it (film_drainage_s 0; the mean sizes agree to
// round-off); a larger, more chaotic bed scatters more, and 10 % is also the smallest
// change of a hold-up or circulation a reactor model is used to resolve (two-phase theory and
// the bubble-size correlations differ by more).
double headline_tolerance(const std::string& name, double baseline,
                          const RegressionTolerances& tolerances) {
  if (name.rfind("mean_diameter", 0) == 0)
    return tolerances.diameter_abs_m + tolerances.diameter_rel * std::abs(baseline);
  return kHeadlineRelativeTolerance * std::abs(baseline);
}

std::vector<std::pair<std::string, double>> headline_of_result_json(const std::string& json) {
  std::vector<std::pair<std::string, double>> out;
  const nlohmann::json j = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return out;
  const auto head = j.find("headline");
  if (head == j.end() || !head->is_object()) return out;
  for (const auto& [name, value] : head->items()) {
    out.emplace_back(
        name, value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

std::vector<MetricComparison> compare_headline(const std::string& baseline_result_json,
                                               const std::string& value_result_json,
                                               const RegressionTolerances& tolerances) {
  std::vector<MetricComparison> out;
  const auto value = headline_of_result_json(value_result_json);
  for (const auto& [name, b] : headline_of_result_json(baseline_result_json)) {
    MetricComparison c;
    c.metric = name;
    c.baseline = b;
    c.value = std::numeric_limits<double>::quiet_NaN();  // absent in the new result: moved
    for (const auto& [n, v] : value)
      if (n == name) c.value = v;
    c.delta = c.value - b;
    c.tolerance = headline_tolerance(name, b, tolerances);
    c.moved = !(std::abs(c.delta) <= c.tolerance);  // a NaN moves
    out.push_back(c);
  }
  return out;
}

std::vector<MetricComparison> compare_metrics(const ConsumerMetrics& baseline,
                                              const ConsumerMetrics& value,
                                              const RegressionTolerances& tolerances) {
  std::vector<MetricComparison> out;
  auto add = [&](const char* metric, double b, double v, double tolerance) {
    MetricComparison c;
    c.metric = metric;
    c.baseline = b;
    c.value = v;
    c.delta = v - b;
    c.tolerance = tolerance;
    c.moved = !(std::abs(c.delta) <= tolerance);  // a NaN moves
    out.push_back(c);
  };
  add("umf_m_s", baseline.umf_m_s, value.umf_m_s, tolerances.umf_rel * std::abs(baseline.umf_m_s));
  add("bubble_present", baseline.bubble_present ? 1.0 : 0.0, value.bubble_present ? 1.0 : 0.0, 0.0);
  if (baseline.bubble_present && value.bubble_present) {
    add("bubble_diameter_m", baseline.bubble_diameter_m, value.bubble_diameter_m,
        tolerances.diameter_abs_m + tolerances.diameter_rel * std::abs(baseline.bubble_diameter_m));
  }
  return out;
}

const char* to_string(RegressOutcome outcome) {
  switch (outcome) {
    case RegressOutcome::kOk:
      return "ok";
    case RegressOutcome::kMoved:
      return "moved";
    case RegressOutcome::kFailed:
      return "failed";
    case RegressOutcome::kOutsideValidity:
      return "outside_validity";
    case RegressOutcome::kBaselineRegistered:
      return "baseline_registered";
    case RegressOutcome::kNoBaseline:
      return "no_baseline";
  }
  return "?";
}

int RegressSummary::count(RegressOutcome outcome) const {
  return static_cast<int>(std::count_if(
      entries.begin(), entries.end(), [&](const RegressEntry& e) { return e.outcome == outcome; }));
}

std::string RegressSummary::BriefReport() const {
  std::ostringstream s;
  s << "regress: " << entries.size() << " check" << (entries.size() == 1 ? "" : "s") << " (" << runs
    << " run" << (runs == 1 ? "" : "s") << " now, " << fmt(wall_s, 3)
    << " s): " << count(RegressOutcome::kMoved) << " moved, " << count(RegressOutcome::kOk)
    << " ok, " << count(RegressOutcome::kFailed) << " failed, "
    << count(RegressOutcome::kBaselineRegistered) << " baseline(s) registered";
  if (count(RegressOutcome::kOutsideValidity) > 0) {
    s << ", " << count(RegressOutcome::kOutsideValidity) << " outside the law's validity box";
  }
  if (count(RegressOutcome::kNoBaseline) > 0) {
    s << ", " << count(RegressOutcome::kNoBaseline) << " without baseline";
  }
  return s.str();
}

std::string RegressSummary::FullReport() const {
  std::ostringstream s;
  if (entries.empty()) {
    s << "Nothing to check: no registered scene has a baseline with a newer law version "
         "(register one: draglab regress register SCENE.toml --law NAME@V).\n";
    s << BriefReport() << "\n";
    return s.str();
  }
  const std::size_t w_scene = 20, w_law = 18, w_metric = 24, w_num = 11;
  s << pad("scene", w_scene) << pad("law", w_law) << pad("baseline", w_law)
    << pad("metric", w_metric) << pad("baseline", w_num) << pad("new", w_num) << pad("delta", w_num)
    << pad("tolerance", w_num) << "status\n";
  for (const RegressEntry& e : entries) {
    const std::string head = pad(e.scene_name, w_scene) + pad(e.law, w_law) +
                             pad(e.baseline_law.empty() ? "-" : e.baseline_law, w_law);
    switch (e.outcome) {
      case RegressOutcome::kFailed:
        s << head << "FAILED (not compared, nothing stored): " << e.error << "\n";
        continue;
      case RegressOutcome::kOutsideValidity:
        s << head << "NOT APPLICABLE, the scene leaves the law's validity box (not compared, "
          << "nothing stored): " << e.error << "\n";
        continue;
      case RegressOutcome::kBaselineRegistered:
        s << head << "baseline registered (result #" << e.result_id << ": U_mf "
          << cell(e.metrics.umf_m_s) << " m/s, "
          << (e.headline.empty() ? "bubble D at t_ref " : "mean bubble D ")
          << (e.metrics.bubble_present ? cell(e.metrics.bubble_diameter_m) + " m" : "none")
          << "; tolerances D " << cell(e.tolerances.diameter_abs_m) << " m + "
          << cell(100 * e.tolerances.diameter_rel) << " %, U_mf "
          << cell(100 * e.tolerances.umf_rel) << " %";
        if (!e.headline.empty()) {
          s << "; headline";
          for (const auto& [name, value] : e.headline) s << " " << name << " " << cell(value);
        }
        s << ")\n";
        continue;
      case RegressOutcome::kNoBaseline:
        s << head << "no baseline (result #" << e.result_id
          << " stored; drafts and retracted versions are not registered as baselines)\n";
        continue;
      default:
        break;
    }
    for (const MetricComparison& c : e.comparisons) {
      const bool flag = c.metric == "bubble_present";
      s << head << pad(c.metric, w_metric)
        << pad(flag ? (c.baseline > 0 ? "yes" : "no") : cell(c.baseline), w_num)
        << pad(flag ? (c.value > 0 ? "yes" : "no") : cell(c.value), w_num)
        << pad(flag ? "-" : cell(c.delta), w_num) << pad(flag ? "-" : cell(c.tolerance), w_num)
        << (c.moved ? "MOVED" : "ok") << "\n";
    }
  }
  for (const RegressEntry& e : entries) {
    for (const std::string& w : e.warnings) s << "warning: " << e.law << ": " << w << "\n";
  }
  s << BriefReport() << "\n";
  return s.str();
}

bool RegressOptions::IsValid(std::string* error) const {
  for (const auto& [field, value] :
       {std::pair<const char*, double>{"tol_diameter_abs_m", tol_diameter_abs_m},
        {"tol_diameter_rel", tol_diameter_rel},
        {"tol_umf_rel", tol_umf_rel}}) {
    if (std::isnan(value) || std::isinf(value)) {
      return fail(error, std::string(field) + " = " + fmt(value) +
                             " is out of range (allowed: finite; negative for the default)");
    }
  }
  if (tol_diameter_rel > 10.0) {
    return fail(error, "tol_diameter_rel = " + fmt(tol_diameter_rel) +
                           " is out of range (allowed: [0, 10], a fraction of the diameter)");
  }
  if (tol_umf_rel > 10.0) {
    return fail(error, "tol_umf_rel = " + fmt(tol_umf_rel) +
                           " is out of range (allowed: [0, 10], a fraction of U_mf)");
  }
  for (const std::string& hash : scene_hashes) {
    if (hash.size() != 64 || hash.find_first_not_of("0123456789abcdef") != std::string::npos) {
      return fail(error, "scene_hashes: '" + hash + "' is not a scene hash (64 hex digits)");
    }
  }
  return run.IsValid(error);
}

RegressionTolerances baseline_tolerances(const Scene& scene, const RegressOptions& options) {
  RegressionTolerances t = default_regression_tolerances(scene);
  if (options.tol_diameter_abs_m >= 0.0) t.diameter_abs_m = options.tol_diameter_abs_m;
  if (options.tol_diameter_rel >= 0.0) t.diameter_rel = options.tol_diameter_rel;
  if (options.tol_umf_rel >= 0.0) t.umf_rel = options.tol_umf_rel;
  return t;
}

RegressSummary run_regression(Database& db, const RegressOptions& options,
                              const RegressProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, "regress: " + why);

  // Single-law mode: resolve first (an unknown law is the caller's mistake, before any run).
  std::optional<LawRecord> single;
  if (!options.law.empty()) {
    single = db.resolve(options.law);
    if (single->status == LawStatus::kDraft && !options.include_drafts) {
      throw Error(ErrorCode::kInvalidArgument,
                  "law " + single->reference() +
                      " is a draft: pass include_drafts (--include-drafts) to check it, or "
                      "publish it first");
    }
  }

  // The registered scenes to check.
  const std::vector<ConsumerScene> all_scenes = list_consumer_scenes(db);
  std::vector<const ConsumerScene*> scenes;
  for (const ConsumerScene& s : all_scenes) {
    if (options.scene_hashes.empty() ||
        std::find(options.scene_hashes.begin(), options.scene_hashes.end(), s.hash) !=
            options.scene_hashes.end()) {
      scenes.push_back(&s);
    }
  }
  for (const std::string& hash : options.scene_hashes) {
    if (std::none_of(all_scenes.begin(), all_scenes.end(),
                     [&](const ConsumerScene& s) { return s.hash == hash; })) {
      throw Error(ErrorCode::kNotFound, "scene " + hash.substr(0, 12) + " is not registered in '" +
                                            db.path() + "' (see `draglab regress list`)");
    }
  }

  // Plan: what is compared with what, and which runs are needed.
  const std::vector<ConsumerBaseline> baselines = list_consumer_baselines(db);
  std::vector<Planned> plan;
  for (const ConsumerScene* stored : scenes) {
    Planned base;
    base.stored_scene = stored;
    try {
      base.scene = std::make_shared<const Scene>(parse_scene(
          stored->toml,
          "registered scene " + stored->name + " (" + stored->hash.substr(0, 12) + ")"));
    } catch (const Error& e) {
      base.scene_error = e.what();
    }
    if (single) {
      Planned p = base;
      p.record = *single;
      p.baseline = active_consumer_baseline(db, stored->hash, single->name);
      p.stored = stored_result(db, stored->hash, *single);
      plan.push_back(p);
      continue;
    }
    for (const ConsumerBaseline& b : baselines) {
      if (b.scene_hash != stored->hash) continue;
      for (const LawRecord& record : db.list(b.law_name, true)) {
        if (record.version <= b.result.law_version) continue;
        if (!version_is_checked(record, options.include_drafts)) continue;
        Planned p = base;
        p.record = record;
        p.baseline = b;
        p.stored = stored_result(db, stored->hash, record);
        plan.push_back(p);
      }
    }
  }
  const int runs = static_cast<int>(
      std::count_if(plan.begin(), plan.end(), [](const Planned& p) { return p.needs_run(); }));

  RegressSummary summary;
  int run_index = 0;
  for (const Planned& p : plan) {
    RegressEntry e;
    e.scene_name = p.stored_scene->name;
    e.scene_hash = p.stored_scene->hash;
    e.law = p.record.reference();
    if (p.baseline) {
      e.baseline_law = p.baseline->result.law_reference();
      e.baseline_result_id = p.baseline->result_id;
      e.tolerances = p.baseline->tolerances;
    }
    std::optional<ConsumerResult> result = p.stored;
    if (!p.scene) {
      e.outcome = RegressOutcome::kFailed;
      e.error = "the registered scene text no longer parses: " + p.scene_error;
      summary.entries.push_back(e);
      continue;
    }
    if (!result) {
      const int this_run = run_index++;
      const auto run_start = std::chrono::steady_clock::now();
      BedProgress on_progress;
      if (progress) {
        on_progress = [&](double fraction, const std::string& stage) {
          progress(this_run, runs, fraction, e.scene_name + " " + e.law + ": " + stage);
        };
      }
      try {
        result = run_scene(db, *p.scene, p.record, options.run, &e.warnings, on_progress);
      } catch (const Error& error) {
        e.outcome = error.code() == ErrorCode::kOutOfValidity ? RegressOutcome::kOutsideValidity
                                                              : RegressOutcome::kFailed;
        e.error = error.what();
        e.wall_s = seconds_since(run_start);
        ++summary.runs;
        summary.entries.push_back(e);
        continue;
      }
      e.ran = true;
      e.wall_s = seconds_since(run_start);
      ++summary.runs;
    }
    e.metrics = result->metrics;
    e.headline = headline_of_result_json(result->result_json);
    if (!p.baseline) {
      if (p.record.status == LawStatus::kPublished) {
        // The result (if new) and the baseline are stored together.
        e.tolerances = baseline_tolerances(*p.scene, options);
        const ConsumerBaseline b = store_consumer_baseline_run(
            db, p.stored_scene->name, p.stored_scene->toml, *result, e.tolerances, false);
        e.result_id = b.result_id;
        e.outcome = RegressOutcome::kBaselineRegistered;
      } else {
        e.result_id = result->id > 0 ? result->id : store_consumer_result(db, *result).id;
        e.outcome = RegressOutcome::kNoBaseline;
      }
      summary.entries.push_back(e);
      continue;
    }
    e.result_id = result->id > 0 ? result->id : store_consumer_result(db, *result).id;
    e.comparisons = compare_metrics(p.baseline->result.metrics, e.metrics, e.tolerances);
    for (MetricComparison& c :
         compare_headline(p.baseline->result.result_json, result->result_json, e.tolerances))
      e.comparisons.push_back(std::move(c));
    const bool moved = std::any_of(e.comparisons.begin(), e.comparisons.end(),
                                   [](const MetricComparison& c) { return c.moved; });
    e.outcome = moved ? RegressOutcome::kMoved : RegressOutcome::kOk;
    summary.entries.push_back(e);
  }
  summary.wall_s = seconds_since(start);
  return summary;
}

RegressSummary register_regression_baseline(Database& db, const Scene& scene,
                                            const RegressOptions& options,
                                            const RegressProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, "regress: " + why);
  if (options.law.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "regress register: give the law (NAME@V) to run");
  }
  if (scene.source_text.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                "regress register: scene '" + scene.name +
                    "' has no source text (parse it with parse_scene / load_scene)");
  }
  scene.Validate();
  const RegressionTolerances tolerances = baseline_tolerances(scene, options);
  if (!tolerances.IsValid(&why)) throw Error(ErrorCode::kInvalidArgument, "regress: " + why);
  const LawRecord record = db.resolve(options.law);
  if (record.status != LawStatus::kPublished) {
    throw Error(ErrorCode::kInvalidArgument,
                "law " + record.reference() + " is " + draglab::to_string(record.status) +
                    ": a baseline is a published version (publish it, or name another)");
  }
  const std::string hash = scene.hash();
  const std::optional<ConsumerBaseline> active = active_consumer_baseline(db, hash, record.name);
  if (active && !options.replace_baseline) {
    throw Error(ErrorCode::kInvalidArgument,
                "scene '" + scene.name + "' has a baseline for law " + record.name + " already (" +
                    active->result.law_reference() + ", registered " + active->registered_at +
                    "); pass --replace to replace it (the old one is kept as superseded)");
  }

  RegressSummary summary;
  RegressEntry e;
  e.scene_name = scene.name;
  e.scene_hash = hash;
  e.law = record.reference();
  if (active) {
    e.baseline_law = active->result.law_reference();
    e.baseline_result_id = active->result_id;
  }
  e.tolerances = tolerances;
  std::optional<ConsumerResult> result = stored_result(db, hash, record);
  if (!result) {
    BedProgress on_progress;
    if (progress) {
      on_progress = [&](double fraction, const std::string& stage) {
        progress(0, 1, fraction, scene.name + " " + e.law + ": " + stage);
      };
    }
    const auto run_start = std::chrono::steady_clock::now();
    result = run_scene(db, scene, record, options.run, &e.warnings, on_progress);  // throws
    e.ran = true;
    e.wall_s = seconds_since(run_start);
    summary.runs = 1;
  }
  const ConsumerBaseline b = store_consumer_baseline_run(db, scene.name, scene.source_text, *result,
                                                         tolerances, options.replace_baseline);
  e.result_id = b.result_id;
  e.metrics = result->metrics;
  e.headline = headline_of_result_json(result->result_json);
  e.outcome = RegressOutcome::kBaselineRegistered;
  summary.entries.push_back(e);
  summary.wall_s = seconds_since(start);
  return summary;
}

}  // namespace workflows
}  // namespace draglab
