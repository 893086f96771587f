// `draglab pipeline`: the product's main job end to end, from nothing to a published law.
//
//   campaign spec -> LBM units (campaign/) -> dataset (drag_db/) -> Ceres fit of Eq. 6 with the
//   NLopt check (fitter/) -> new law version, published -> report (figures + summary).
//
// Sample runs:
//   draglab pipeline --preset quick                 # what ./run.sh runs (minutes on 2 cores)
//   draglab pipeline --preset standard --jobs 2     # about an hour, Richardson in d
//   draglab pipeline --spec my_campaign.toml --law-name eq6_mine --out out/mine
//
// Re-running is cheap and safe: the campaign resumes (finished units are kept), the dataset is
// identified by its content hash, and a fit that gives a law identical to the latest published
// version of the name (same content hash, same dataset) reuses it instead of adding a version.
//
// The pipeline ends with the regression check of the law it published (`draglab regress --law`,
// consumers/regress.h) on the registered scenes (the quick scene data/scenes/dpm_bubble_quick.toml
// is registered if none is; --regress-scene FILE checks that scene instead; --no-regress skips
// the check). A brand-new law name registers its baseline; a prediction that moved beyond the
// baseline's tolerance is printed and the pipeline exits 1 (the law stays published).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "cli/regress_report.h"
#include "draglab/campaign/campaign.h"
#include "draglab/consumers/regress.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/drag_db/error.h"
#include "draglab/fitter/fit.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/report.h"

namespace draglab {
namespace cli {
namespace {

namespace fs = std::filesystem;

std::string executable_path() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("draglab") : self.string();
}

// The preset's spec file: next to the sources in a build tree, under share/draglab when
// installed (relative to the executable, so installs are relocatable).
std::string preset_path(const std::string& preset) {
  const std::string file = "campaigns/" + preset + ".toml";
  const fs::path source = fs::path(DRAGLAB_SOURCE_DATA_DIR) / file;
  if (fs::exists(source)) return source.string();
  const fs::path installed =
      fs::path(executable_path()).parent_path() / ".." / DRAGLAB_INSTALL_SHARE_DIR / file;
  if (fs::exists(installed)) return installed.lexically_normal().string();
  throw UsageError("preset '" + preset + "': no spec file " + source.string() + " or " +
                   installed.lexically_normal().string());
}

// The scene the pipeline's regression check registers when no scene is registered yet: found
// like the presets (source tree, else the installed share directory); empty if neither exists.
std::string quick_scene_path() {
  const std::string file = "scenes/dpm_bubble_quick.toml";
  const fs::path source = fs::path(DRAGLAB_SOURCE_DATA_DIR) / file;
  if (fs::exists(source)) return source.string();
  const fs::path installed =
      fs::path(executable_path()).parent_path() / ".." / DRAGLAB_INSTALL_SHARE_DIR / file;
  if (fs::exists(installed)) return installed.lexically_normal().string();
  return "";
}

std::vector<fitter::FitPoint> fit_points(const Dataset& dataset) {
  std::vector<fitter::FitPoint> points;
  for (const DatasetPoint& p : dataset.points) {
    points.push_back({p.phi, p.re, p.F, p.F_uncertainty});
  }
  return points;
}

struct Deviation {
  double rms = 0.0, max = 0.0;
};
Deviation deviation_of(const std::vector<double>& relative) {
  Deviation d;
  for (double r : relative) {
    d.rms += r * r;
    d.max = std::max(d.max, std::abs(r));
  }
  d.rms = relative.empty() ? 0.0 : std::sqrt(d.rms / static_cast<double>(relative.size()));
  return d;
}

// Relative difference of `law` from `reference` at the dataset's (phi, Re) points.
Deviation law_difference(const Law& law, const Law& reference, const Dataset& dataset) {
  std::vector<double> relative;
  for (const DatasetPoint& p : dataset.points) {
    relative.push_back(law.F(p.phi, p.re) / reference.F(p.phi, p.re) - 1.0);
  }
  return deviation_of(relative);
}

// Stores the fit as a new published version of `name`, unless the latest published version
// already has the same content and dataset (re-running the pipeline on the same data).
LawRecord publish_fit(Database& db, const LawRecord& draft_record) {
  LawRecord probe = draft_record;
  probe.content_hash = content_hash_of(probe);
  for (const LawRecord& existing : db.list(draft_record.name, false)) {
    if (existing.status == LawStatus::kPublished && existing.content_hash == probe.content_hash &&
        existing.provenance.data_hash == draft_record.provenance.data_hash) {
      return existing;
    }
  }
  return db.add_published(draft_record);
}

struct PipelineArgs {
  std::string preset = "quick";
  std::string spec;
  std::string law_name;
  std::string out_dir;
  int jobs = 0;
  bool no_report = false;
  bool no_regress = false;
  std::string regress_scene;  // --regress-scene FILE (default: the registered scenes)
};

// 6. The regression check of the published law (consumers/regress.h). `scene` is the
// --regress-scene file, parsed before the campaign; null: the registered scenes, registering the
// quick scene if there is none. Returns false (with a warning) if there is nothing to run on.
bool run_pipeline_check(const CliContext& ctx, const LawRecord& record,
                        const consumers::Scene* scene, consumers::RegressSummary* summary) {
  auto db = ctx.open_database(false);
  consumers::RegressOptions options;
  options.law = record.reference();
  if (scene) {
    register_consumer_scene(*db, scene->name, scene->source_text);
    options.scene_hashes = {scene->hash()};
  } else if (list_consumer_scenes(*db).empty()) {
    const std::string path = quick_scene_path();
    if (path.empty()) {
      ctx.warn(
          "regression check skipped: no scene is registered and the quick scene "
          "scenes/dpm_bubble_quick.toml was not found (pass --regress-scene FILE)");
      return false;
    }
    const consumers::Scene quick = consumers::load_scene(path);
    register_consumer_scene(*db, quick.name, quick.source_text);
    ctx.info("pipeline: registered the scene " + path + " for regression checks");
  }
  ctx.info("pipeline: regression check of " + record.reference() + " on the registered scenes");
  ProgressLine line(!ctx.quiet);
  *summary = consumers::run_regression(*db, options, regress_progress(line));
  line.finish();
  return true;
}

void run_pipeline(const CliContext& ctx, const PipelineArgs& args) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const std::string spec_path = args.spec.empty() ? preset_path(args.preset) : args.spec;
  const campaign::CampaignSpec spec = campaign::parse_campaign_spec(spec_path);
  const std::string law_name = args.law_name.empty() ? "eq6_" + spec.name : args.law_name;
  const std::string out_dir = args.out_dir.empty() ? "out/" + spec.name : args.out_dir;
  {
    // The law name is checked before hours of LBM (the database would refuse it at the end).
    try {
      check_law_name(law_name);
    } catch (const Error& e) {
      throw UsageError(std::string("--law-name: ") + e.what());
    }
  }
  // The check's scene is read before hours of LBM too (a bad file exits 2 here).
  std::unique_ptr<consumers::Scene> regress_scene;
  if (!args.regress_scene.empty()) {
    if (args.no_regress) throw UsageError("--regress-scene and --no-regress exclude each other");
    regress_scene = std::make_unique<consumers::Scene>(consumers::load_scene(args.regress_scene));
  }
  const std::string db_path = ctx.resolved_db_path();
  ctx.open_database(false);  // create, migrate and seed the database before the workers open it

  // 1. Campaign (resumed if it exists with the same spec).
  ctx.info("pipeline: campaign '" + spec.name + "' from " + spec_path + " -> " + db_path);
  campaign::RunCampaignOptions run_options;
  run_options.jobs = args.jobs;
  run_options.resume = false;
  {
    auto db = ctx.open_database(true);
    for (const campaign::CampaignStatus& c : campaign::list_campaigns(*db)) {
      if (c.name == spec.name) run_options.resume = true;  // same name: continue it
    }
  }
  auto printer = std::make_shared<CampaignProgressPrinter>(!ctx.quiet);
  run_options.progress = [printer](std::int64_t finished, std::int64_t total,
                                   const std::string& line) { (*printer)(finished, total, line); };
  const auto campaign_start = Clock::now();
  const campaign::CampaignStatus status = campaign::run_campaign(db_path, spec, run_options);
  printer->finish();
  const double campaign_s = std::chrono::duration<double>(Clock::now() - campaign_start).count();
  ctx.info(status.BriefReport());

  // 2. Dataset.
  auto db = ctx.open_database(false);
  std::vector<std::string> skipped;
  const Dataset dataset = campaign::build_dataset(*db, status.id, &skipped);
  for (const std::string& s : skipped) ctx.warn("dataset: left out " + s);

  // 3. Fit of Eq. 6 (the C0 and C1 coefficients), confirmed by NLopt, then published.
  fitter::FitOptions fit_options;  // vdh2004, free k0, k1, c10, c11, c12
  fit_options.cv_folds = dataset.points.size() >= 10 ? 5 : 0;
  const std::vector<fitter::FitPoint> points = fit_points(dataset);
  const fitter::FitResult fit = fitter::fit_law(points, fit_options);
  const LawRecord record = publish_fit(
      *db, fitter::fitted_record(fit, fit_options, law_name, dataset.id, dataset.hash, points));
  const auto fitted = db->load(record.reference(), RangePolicy::kExtrapolate);

  // 4. Comparison over the campaign grid.
  struct Row {
    std::string law;
    Deviation from_data;
    Deviation from_bvk;
  };
  std::vector<Row> rows;
  std::shared_ptr<Law> bvk;
  try {
    bvk = db->load("bvk2007@1", RangePolicy::kExtrapolate);
  } catch (const Error&) {
    ctx.warn("bvk2007@1 is not in the database: no comparison with it");
  }
  auto add_row = [&](const std::string& label, const Law& law) {
    Row row;
    row.law = label;
    row.from_data = deviation_of(fitter::relative_errors(law, points));
    if (bvk) row.from_bvk = law_difference(law, *bvk, dataset);
    rows.push_back(row);
  };
  add_row(record.reference() + " (fit)", *fitted);
  for (const char* ref : {"vdh2004@1", "bvk2007@1", "ergun@1"}) {
    try {
      const auto law = db->load(ref, RangePolicy::kExtrapolate);
      add_row(std::string(ref) + (std::string(ref) == "vdh2004@1" ? " (Eq. 6 as printed)" : ""),
              *law);
    } catch (const Error& e) {
      ctx.warn(std::string(ref) + ": " + e.what());
    }
  }

  // 5. Report.
  std::string report_file;
  if (!args.no_report) {
    workflows::ReportOptions request;
    request.dataset_id = dataset.id;
    request.laws = {record.reference()};
    if (status.id > 0) request.campaign = std::to_string(status.id);
    request.out_dir = out_dir;
    request.quiet = ctx.quiet;
    try {
      auto report_db = ctx.open_database(/*read_only=*/true);
      report_file = workflows::write_report(*report_db, request, ctx.messages()).report_path;
    } catch (const std::exception& e) {
      ctx.warn(std::string("the report failed: ") + e.what() +
               " (the dataset and the law are stored; rerun `draglab report --dataset " +
               dataset.id + " --law " + record.reference() + " --out " + out_dir + "`)");
    }
  }
  // 6. Regression check of the published law on the registered consumer scenes.
  consumers::RegressSummary check;
  bool checked = false;
  if (!args.no_regress) {
    db.reset();  // the check opens its own connection
    checked = run_pipeline_check(ctx, record, regress_scene.get(), &check);
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();

  if (ctx.json) {
    nlohmann::json params = nlohmann::json::object(), ci95 = nlohmann::json::object();
    for (std::size_t i = 0; i < fit.names.size(); ++i) {
      params[fit.names[i]] = fit.values[i];
      if (fit.is_free[i]) ci95[fit.names[i]] = {fit.ci95_low[i], fit.ci95_high[i]};
    }
    nlohmann::json comparison = nlohmann::json::array();
    for (const Row& r : rows) {
      comparison.push_back({{"law", r.law},
                            {"rms_rel_err", r.from_data.rms},
                            {"max_rel_err", r.from_data.max},
                            {"rms_rel_diff_bvk2007", r.from_bvk.rms},
                            {"max_rel_diff_bvk2007", r.from_bvk.max}});
    }
    ctx.print_json({{"campaign", status.name},
                    {"campaign_id", status.id},
                    {"units_total", status.units_total},
                    {"units_done", status.units_done},
                    {"units_failed", status.units_failed},
                    {"dataset", dataset.id},
                    {"points", dataset.points.size()},
                    {"law", record.name},
                    {"version", record.version},
                    {"params", params},
                    {"ci95", ci95},
                    {"rms_rel_err", fit.rms_rel_err},
                    {"max_rel_err", fit.max_rel_err},
                    {"cv_rms_rel_err", fit.cv_rms_rel_err},
                    {"chi2_per_dof", fit.chi2_per_dof},
                    {"global_agrees", fit.global_agrees},
                    {"constraints_satisfied", fit.constraints_satisfied},
                    {"selection",
                     {{"performed", fit.selection.performed},
                      {"requested", fit.selection.requested},
                      {"undetermined", fit.selection.undetermined},
                      {"least_separable", fit.selection.inseparable},
                      {"chosen", fit.selection.chosen}}},
                    {"undetermined", fit.undetermined()},
                    {"comparison", comparison},
                    {"report", report_file},
                    {"regress", checked ? workflows::regress_json(check) : nlohmann::json(nullptr)},
                    {"campaign_s", campaign_s},
                    {"wall_s", wall_s}});
    if (checked) finish_regress(ctx, check);
    return;
  }

  std::ostringstream out;
  out << fmt::format("draglab pipeline '{}': {} of {} LBM units done, {} failed ({:.0f} s)\n",
                     spec.name, status.units_done, status.units_total, status.units_failed,
                     campaign_s);
  out << fmt::format(
      "dataset {}: {} (phi, Re) points, F with realization and resolution "
      "uncertainty\n\n",
      dataset.id, dataset.points.size());
  out << "Eq. 6 refitted (Ceres, weighted least squares on F; 95 % intervals):\n"
      << "  beta d^2/mu = [A + C0] phi^2/eps + [B + C1] (phi/eps) Re,\n"
      << "  C0 = a eps^n (1 + b sqrt(phi))/phi,  C1 = c0 + c1 phi + c2 phi^2\n";
  const LawForm& form = find_law_form(fit.form);
  const char* seed_names[] = {"A", "B", "a", "n", "b", "c0", "c1", "c2"};
  out << fmt::format("  {:<10}{:>10}{:>12}   {}\n", "parameter", "printed", "fitted",
                     "95 % interval");
  for (std::size_t i = 0; i < fit.names.size(); ++i) {
    const std::string label = fit.form == "vdh2004" && i < 8
                                  ? fmt::format("{} ({})", seed_names[i], fit.names[i])
                                  : fit.names[i];
    out << fmt::format("  {:<10}{:>10.4g}{:>12.5g}   {}\n", label,
                       form.description.parameters[i].value, fit.values[i],
                       fit.is_free[i]
                           ? fmt::format("[{:.5g}, {:.5g}]", fit.ci95_low[i], fit.ci95_high[i])
                           : std::string("fixed"));
  }
  out << fmt::format("  chi2/dof {:.3g} (dof {}), RMS rel. error {:.2f} %, max {:.2f} %",
                     fit.chi2_per_dof, fit.dof, 100 * fit.rms_rel_err, 100 * fit.max_rel_err);
  if (fit.cv_rms_rel_err >= 0) {
    out << fmt::format(", {}-fold CV {:.2f} %", fit_options.cv_folds, 100 * fit.cv_rms_rel_err);
  }
  out << "\n";
  {
    // Say plainly which coefficients these data do not pin down (95 % half-width above the
    // value) and what the fitter did about it.
    auto join = [](const std::vector<std::string>& items) {
      std::string text;
      for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
      return text;
    };
    const std::vector<std::string> weak = fit.undetermined();
    if (fit.selection.performed) {
      out << "  Subset selection: fitting all of " << join(fit.selection.requested) << " leaves "
          << join(fit.selection.undetermined)
          << " with 95 % intervals wider than their values\n  (least separable: "
          << fit.selection.inseparable << "); fitted the largest "
          << "determined subset " << join(fit.selection.chosen)
          << ", the others fixed at their printed values (draglab fit prints the candidates).\n";
    }
    if (!weak.empty()) {
      std::string pair;
      const double worst = fit.strongest_correlation(&pair);
      out << "  Not determined by these data (95 % interval wider than the value): " << join(weak)
          << fmt::format(
                 ";\n  strongest correlation {:.3f} ({}). Fix some (draglab fit --free) or add "
                 "data over a wider phi and Re range (--preset standard).\n",
                 worst, pair);
    }
  }
  out << "  NLopt global search: "
      << (fit.global_checked ? (fit.global_agrees ? "agrees" : "found a different optimum")
                             : "not run")
      << "; constraints F > 0, dF/dRe >= 0: "
      << (fit.constraints_checked
              ? (fit.constraints_satisfied ? "satisfied" : "VIOLATED: " + fit.constraint_report)
              : "not checked")
      << "\n\n";
  out << "Over the campaign grid (relative differences):\n";
  out << fmt::format("  {:<34}{:>12}{:>12}{:>16}{:>16}\n", "law", "RMS vs data", "max vs data",
                     "RMS vs bvk2007", "max vs bvk2007");
  for (const Row& r : rows) {
    out << fmt::format("  {:<34}{:>11.2f}%{:>11.2f}%{:>15.2f}%{:>15.2f}%\n", r.law,
                       100 * r.from_data.rms, 100 * r.from_data.max, 100 * r.from_bvk.rms,
                       100 * r.from_bvk.max);
  }
  out << "\nStored: law " << record.reference() << " (published, immutable) in " << db_path
      << "; dataset " << dataset.id << "\n";
  if (!report_file.empty()) out << "Report: " << report_file << " (figures in " << out_dir << ")\n";
  out << fmt::format("Pipeline wall time {:.0f} s.\n", wall_s);
  out << "Next: draglab law show " << record.reference() << " | draglab law eval "
      << record.reference() << " --phi 0.3 --re 20 | draglab fit --dataset " << dataset.id
      << " --free a,n,b,c0,c1,c2\n";
  if (checked) {
    out << "\nRegression check of " << record.reference()
        << " (consumer predictions against the stored baselines):\n"
        << check.FullReport();
    if (check.any_moved()) {
      out << "PREDICTION MOVED: " << record.reference()
          << " changes a consumer prediction beyond the baseline's tolerance (the law is "
             "published; see `draglab regress list`)\n";
    }
  } else if (args.no_regress) {
    out << "\nRegression check skipped (--no-regress).\n";
  }
  std::cout << out.str();
  if (checked) finish_regress(ctx, check);
}

}  // namespace

void add_pipeline_commands(CLI::App& app, CliContext& ctx) {
  auto args = std::make_shared<PipelineArgs>();
  auto* cmd = app.add_subcommand(
      "pipeline", "Campaign -> dataset -> fit of Eq. 6 -> published law -> report, in one command");
  cmd->add_option("--preset", args->preset, "Campaign preset: quick, standard or paper")
      ->check(CLI::IsMember({"quick", "standard", "paper"}))
      ->capture_default_str();
  cmd->add_option("--spec", args->spec, "Campaign spec file (TOML) instead of a preset")
      ->check(CLI::ExistingFile);
  cmd->add_option("--law-name", args->law_name,
                  "Name of the fitted law (default eq6_<campaign name>)");
  cmd->add_option("--out", args->out_dir, "Report directory (default out/<campaign name>)");
  cmd->add_option("--jobs", args->jobs, "Parallel LBM units (0 = number of cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--no-report", args->no_report, "Skip the figures");
  cmd->add_flag("--no-regress", args->no_regress,
                "Skip the final regression check of the published law");
  cmd->add_option("--regress-scene", args->regress_scene,
                  "Scene (TOML) of the final regression check, registered if new (default: the "
                  "registered scenes; the quick scene if none is)")
      ->check(CLI::ExistingFile);
  cmd->footer(
      "Examples:\n"
      "  draglab pipeline --preset quick\n"
      "  draglab pipeline --preset standard --jobs 2 --out out/standard\n"
      "  draglab pipeline --spec my.toml --law-name eq6_mine --json\n"
      "Re-running resumes the campaign and reuses an identical fitted version. The pipeline "
      "ends with `draglab regress --law` for the published version: exit 1 if a consumer "
      "prediction moved beyond its baseline's tolerance.");
  cmd->callback([&ctx, args] { ctx.action = [&ctx, args] { run_pipeline(ctx, *args); }; });
}

}  // namespace cli
}  // namespace draglab
