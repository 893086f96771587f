// `draglab regress`: consumer predictions of changed law versions against stored baselines
// (workflows/regress.h, docs/scenes.md "Regression checks").
//   draglab regress [--law NAME@V] [--include-drafts] [--json]
//   draglab regress register SCENE.toml --law NAME@V [--tol-diameter-rel X]
//                   [--tol-diameter-abs M] [--tol-umf-rel X] [--replace]
//   draglab regress list [--all]
// Exit codes: 1 when a prediction moved beyond its baseline's tolerance, 0 otherwise (failed runs
// are reported, with a warning, and not counted as moved), 2 on bad input. Every bed model's
// scenes work alike; a model with headline numbers (the DBM) has them compared too.
#include <cmath>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "cli/regress_report.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/error.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/regress.h"

namespace draglab {
namespace cli {
namespace {

struct RegressArgs {
  std::string law;
  bool include_drafts = false;
  // register
  std::string scene_path;
  double tol_diameter_rel = -1.0;
  double tol_diameter_abs_m = -1.0;
  double tol_umf_rel = -1.0;
  bool replace = false;
  // list
  bool all = false;
};

void print_summary(const CliContext& ctx, const workflows::RegressSummary& summary) {
  if (ctx.json) {
    ctx.print_json(workflows::regress_json(summary));
  } else {
    std::cout << summary.FullReport();
  }
}

void run_check(const CliContext& ctx, const RegressArgs& args) {
  workflows::RegressOptions options;
  options.law = args.law;
  options.include_drafts = args.include_drafts;
  auto db = ctx.open_database();
  ProgressLine line(!ctx.quiet);
  const workflows::RegressSummary summary =
      workflows::run_regression(*db, options, regress_progress(line));
  line.finish();
  db.reset();
  print_summary(ctx, summary);
  finish_regress(ctx, summary);
}

void run_register(const CliContext& ctx, const RegressArgs& args) {
  const consumers::Scene scene = consumers::load_scene(args.scene_path);  // kNotFound: exit 2
  workflows::RegressOptions options;
  options.law = args.law;
  options.tol_diameter_abs_m = args.tol_diameter_abs_m;
  options.tol_diameter_rel = args.tol_diameter_rel;
  options.tol_umf_rel = args.tol_umf_rel;
  options.replace_baseline = args.replace;
  auto db = ctx.open_database();
  ProgressLine line(!ctx.quiet);
  const workflows::RegressSummary summary =
      workflows::register_regression_baseline(*db, scene, options, regress_progress(line));
  line.finish();
  print_summary(ctx, summary);
}

void run_list(const CliContext& ctx, const RegressArgs& args) {
  auto db = ctx.open_database();  // created and seeded on first use, as every command
  const std::vector<ConsumerScene> scenes = list_consumer_scenes(*db);
  const std::vector<ConsumerBaseline> baselines = list_consumer_baselines(*db, args.all);
  auto scene_name = [&](const std::string& hash) {
    for (const ConsumerScene& s : scenes) {
      if (s.hash == hash) return s.name;
    }
    return std::string("?");
  };
  if (ctx.json) {
    nlohmann::json s = nlohmann::json::array(), b = nlohmann::json::array();
    for (const ConsumerScene& scene : scenes) {
      s.push_back({{"name", scene.name},
                   {"hash", scene.hash},
                   {"registered_at", scene.registered_at},
                   {"code_version", scene.code_version}});
    }
    for (const ConsumerBaseline& baseline : baselines) {
      b.push_back({{"id", baseline.id},
                   {"scene", scene_name(baseline.scene_hash)},
                   {"scene_hash", baseline.scene_hash},
                   {"law_name", baseline.law_name},
                   {"law", baseline.result.law_reference()},
                   {"result_id", baseline.result_id},
                   {"tolerances", workflows::tolerances_json(baseline.tolerances)},
                   {"metrics", workflows::metrics_json(baseline.result.metrics)},
                   {"registered_at", baseline.registered_at},
                   {"active", baseline.active()},
                   {"superseded_at", baseline.active() ? nlohmann::json(nullptr)
                                                       : nlohmann::json(baseline.superseded_at)},
                   {"supersedes", baseline.supersedes > 0 ? nlohmann::json(baseline.supersedes)
                                                          : nlohmann::json(nullptr)}});
    }
    ctx.print_json({{"scenes", s}, {"baselines", b}});
    return;
  }
  std::cout << fmt::format("{} registered scene(s) in {}\n", scenes.size(), db->path());
  for (const ConsumerScene& scene : scenes) {
    std::cout << fmt::format("  {:<24} {}  registered {}\n", scene.name, scene.hash.substr(0, 12),
                             scene.registered_at);
  }
  std::cout << fmt::format("{} baseline(s){}\n", baselines.size(), args.all ? "" : " (active)");
  if (baselines.empty()) {
    std::cout << "  none: draglab regress register SCENE.toml --law NAME@V\n";
    return;
  }
  std::cout << fmt::format("  {:<24} {:<20} {:>9} {:>10} {:>12} {:>22}  {}\n", "scene", "law",
                           "U_mf m/s", "D m", "tol D", "registered", "status");
  for (const ConsumerBaseline& b : baselines) {
    const ConsumerMetrics& m = b.result.metrics;
    std::cout << fmt::format(
        "  {:<24} {:<20} {:>9.4f} {:>10} {:>12} {:>22}  {}\n", scene_name(b.scene_hash),
        b.result.law_reference(), m.umf_m_s,
        m.bubble_present ? format_number(m.bubble_diameter_m, 4) : std::string("none"),
        fmt::format("{}m+{}%", format_number(b.tolerances.diameter_abs_m, 3),
                    format_number(100 * b.tolerances.diameter_rel, 3)),
        b.registered_at, b.active() ? "active" : "superseded " + b.superseded_at);
  }
}

}  // namespace

workflows::RegressProgress regress_progress(ProgressLine& line) {
  return [&line](int run, int runs, double fraction, const std::string& stage) {
    line.update(fraction, fmt::format("run {}/{} {}", run + 1, runs, stage));
  };
}

void finish_regress(const CliContext& ctx, const workflows::RegressSummary& summary) {
  using workflows::RegressOutcome;
  const int failed = summary.count(RegressOutcome::kFailed);
  if (failed > 0) {
    ctx.warn(fmt::format(
        "{} run(s) failed and were not compared (nothing stored for them); see the report",
        failed));
  }
  const int outside = summary.count(RegressOutcome::kOutsideValidity);
  if (outside > 0) {
    ctx.warn(fmt::format(
        "{} check(s) not applicable: the scene leaves the law's validity box (the law cannot be "
        "used there; not compared, nothing stored); see the report",
        outside));
  }
  if (!summary.any_moved()) return;
  std::string moved;
  for (const workflows::RegressEntry& e : summary.entries) {
    if (e.outcome != RegressOutcome::kMoved) continue;
    std::string metrics;
    for (const workflows::MetricComparison& c : e.comparisons) {
      if (c.moved) metrics += (metrics.empty() ? "" : ", ") + c.metric;
    }
    moved += fmt::format("{}{} on {} vs {} ({})", moved.empty() ? "" : "; ", e.law, e.scene_name,
                         e.baseline_law, metrics);
  }
  throw std::runtime_error(
      fmt::format("regression: {} prediction(s) moved beyond the baseline tolerance: {}",
                  summary.count(RegressOutcome::kMoved), moved));
}

void add_regress_commands(CLI::App& app, CliContext& ctx) {
  auto args = std::make_shared<RegressArgs>();
  auto* regress = app.add_subcommand(
      "regress",
      "Re-run the registered scenes for every law version newer than its baseline and report "
      "the predictions (U_mf, bubble at t_ref; DBM scenes: also hold-up, bubble sizes, "
      "circulation) that moved beyond the baseline's tolerance (exit 1 when one did)");
  regress->require_subcommand(0, 1);
  regress->add_option("--law", args->law,
                      "Check this version only (NAME@V) on every registered scene; where its "
                      "name has no baseline yet, its result becomes the baseline");
  regress->add_flag("--include-drafts", args->include_drafts,
                    "Also check draft versions (default: published only)");
  regress->footer(
      "Examples:\n"
      "  draglab regress register data/scenes/dpm_bubble_quick.toml --law ergun@1\n"
      "  draglab regress\n"
      "  draglab regress --law ergun@2 --json\n"
      "  draglab regress list\n"
      "Exit codes: 0 nothing moved (failed runs and scenes outside a law's validity box are "
      "reported, not counted as moved), 1 a "
      "prediction moved, 2 bad input.");

  auto* reg = regress->add_subcommand(
      "register",
      "Register a scene, run it with a published law version and store the result as the "
      "baseline of (scene, law name) with its tolerances");
  reg->add_option("SCENE", args->scene_path, "Scene file (TOML, docs/scenes.md)")->required();
  reg->add_option("--law", args->law, "Published law version NAME@V")->required();
  reg->add_option("--tol-diameter-rel", args->tol_diameter_rel,
                  "Bubble diameter tolerance, fraction of the baseline diameter, [0, 10] "
                  "(default 0.1)")
      ->check(CLI::Range(0.0, 10.0));
  reg->add_option("--tol-diameter-abs", args->tol_diameter_abs_m,
                  "Bubble diameter tolerance added to the relative one [m], [0, 10] (default: 2 "
                  "gas cells; DBM scenes: 0)")
      ->check(CLI::Range(0.0, 10.0));
  reg->add_option("--tol-umf-rel", args->tol_umf_rel,
                  "U_mf tolerance, fraction of the baseline U_mf, [0, 10] (default 0.01)")
      ->check(CLI::Range(0.0, 10.0));
  reg->add_flag("--replace", args->replace,
                "Replace an existing baseline of this scene and law name (kept as superseded)");
  reg->footer(
      "Example:\n"
      "  draglab regress register data/scenes/dpm_bubble_quick.toml --law ergun@1 "
      "--tol-diameter-rel 0.15");
  reg->callback([&ctx, args] { ctx.action = [&ctx, args] { run_register(ctx, *args); }; });

  auto* list = regress->add_subcommand("list", "Registered scenes and their baselines");
  list->add_flag("--all", args->all, "Also the superseded baselines");
  list->footer("Example:\n  draglab regress list --json");
  list->callback([&ctx, args] { ctx.action = [&ctx, args] { run_list(ctx, *args); }; });

  regress->callback([&ctx, args, regress] {
    if (!regress->get_subcommands().empty()) return;  // register / list set the action
    ctx.action = [&ctx, args] { run_check(ctx, *args); };
  });
}

}  // namespace cli
}  // namespace draglab
