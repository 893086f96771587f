// workflows/src/pipeline.cc: see draglab/workflows/pipeline.h.
#include "draglab/workflows/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include <fmt/core.h>

#include "draglab/consumers/scene.h"
#include "draglab/core/files.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/report.h"
#include "draglab/workflows/scripts.h"

namespace draglab {
namespace workflows {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::vector<fitter::FitPoint> fit_points(const Dataset& dataset) {
  std::vector<fitter::FitPoint> points;
  for (const DatasetPoint& p : dataset.points)
    points.push_back({p.phi, p.re, p.F, p.F_uncertainty, {}});
  return points;
}

/// RMS and max of |r| over the relative differences r.
std::pair<double, double> rms_and_max(const std::vector<double>& relative) {
  double sum = 0.0, max = 0.0;
  for (double r : relative) {
    sum += r * r;
    max = std::max(max, std::abs(r));
  }
  return {relative.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(relative.size())), max};
}

/// Stores the fit as a new published version of its name, unless the latest published version
/// already has the same content and dataset (re-running the pipeline on the same data).
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

std::vector<PipelineComparison> compare_over_grid(const Database& db, const Law& fitted,
                                                  const std::string& fitted_label,
                                                  const Dataset& dataset,
                                                  const Messages& messages) {
  const std::vector<fitter::FitPoint> points = fit_points(dataset);
  std::shared_ptr<Law> bvk;
  try {
    bvk = db.load("bvk2007@1", RangePolicy::kExtrapolate);
  } catch (const Error&) {
    messages.warn("bvk2007@1 is not in the database: no comparison with it");
  }
  std::vector<PipelineComparison> rows;
  const auto add_row = [&](const std::string& label, const Law& law) {
    PipelineComparison row;
    row.law = label;
    std::tie(row.rms_vs_data, row.max_vs_data) = rms_and_max(fitter::relative_errors(law, points));
    if (bvk) {
      std::vector<double> relative;
      for (const DatasetPoint& p : dataset.points)
        relative.push_back(law.F(p.phi, p.re) / bvk->F(p.phi, p.re) - 1.0);
      std::tie(row.rms_vs_bvk2007, row.max_vs_bvk2007) = rms_and_max(relative);
    }
    rows.push_back(row);
  };
  add_row(fitted_label, fitted);
  for (const char* ref : {"vdh2004@1", "bvk2007@1", "ergun@1"}) {
    try {
      const auto law = db.load(ref, RangePolicy::kExtrapolate);
      add_row(std::string(ref) + (std::string(ref) == "vdh2004@1" ? " (Eq. 6 as printed)" : ""),
              *law);
    } catch (const Error& e) {
      messages.warn(std::string(ref) + ": " + e.what());
    }
  }
  return rows;
}

/// The regression check of the published law. `scene` (may be null) is the --regress-scene
/// file, read before the campaign; without it the registered scenes, registering the shipped
/// quick scene if there is none. Returns false (with a warning) if there is nothing to run on.
bool run_check(const std::string& db_path, const LawRecord& record, const consumers::Scene* scene,
               const Messages& messages, const PipelineProgress& progress,
               workflows::RegressSummary* summary) {
  Database db(db_path);
  workflows::RegressOptions options;
  options.law = record.reference();
  if (scene) {
    register_consumer_scene(db, scene->name, scene->source_text);
    options.scene_hashes = {scene->hash()};
  } else if (list_consumer_scenes(db).empty()) {
    const std::string path = find_shipped_file("scenes/dpm_bubble_quick.toml");
    if (path.empty()) {
      messages.warn(
          "regression check skipped: no scene is registered and the quick scene "
          "scenes/dpm_bubble_quick.toml was not found (pass --regress-scene FILE)");
      return false;
    }
    const consumers::Scene quick = consumers::load_scene(path);
    register_consumer_scene(db, quick.name, quick.source_text);
    messages.info("pipeline: registered the scene " + path + " for regression checks");
  }
  messages.info("pipeline: regression check of " + record.reference() +
                " on the registered scenes");
  *summary = workflows::run_regression(db, options, progress.regression);
  if (progress.stage_done) progress.stage_done();
  return true;
}

/// The spec's extension dataset, read and checked before the campaign (bad input, exit 2): its
/// file, its pinned id, and at least one point outside the grid's box.
std::unique_ptr<Dataset> read_extension(const campaign::CampaignSpec& spec,
                                        const std::string& spec_path, const DatasetBox& box) {
  if (spec.extend_with.empty()) return nullptr;
  const std::string field = spec_path + ": [dataset] extend_with = " + spec.extend_with;
  auto extension = std::make_unique<Dataset>();
  try {
    *extension = read_dataset_csv(spec.extend_with);
  } catch (const Error& e) {
    throw Error(ErrorCode::kInvalidArgument, field + ": " + e.what());
  }
  if (!spec.extend_with_id.empty() && extension->id != spec.extend_with_id) {
    throw Error(ErrorCode::kInvalidArgument,
                field + ": the file holds dataset " + extension->id + ", the spec expects " +
                    spec.extend_with_id +
                    " (extend_with_id): restore the file, or check it and set the new id");
  }
  const auto outside = std::count_if(extension->points.begin(), extension->points.end(),
                                     [&](const DatasetPoint& p) { return !box.contains(p); });
  if (outside == 0) {
    throw Error(
        ErrorCode::kInvalidArgument,
        fmt::format("{}: none of its {} points lies outside the grid's box phi [{:g}, "
                    "{:g}] x Re [{:g}, {:g}], so it adds nothing",
                    field, extension->points.size(), box.phi_lo, box.phi_hi, box.re_lo, box.re_hi));
  }
  return extension;
}

DatasetBox grid_box(const campaign::CampaignSpec& spec) {
  const auto [phi_lo, phi_hi] = std::minmax_element(spec.phi.begin(), spec.phi.end());
  const auto [re_lo, re_hi] = std::minmax_element(spec.re.begin(), spec.re.end());
  return {*phi_lo, *phi_hi, *re_lo, *re_hi};
}

std::string join(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

}  // namespace

std::string preset_spec_path(const std::string& preset) {
  const std::string file = "campaigns/" + preset + ".toml";
  const std::string path = find_shipped_file(file);
  if (path.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                "preset '" + preset + "': no spec file " + file +
                    " in the source tree's data/ or the installed share/draglab");
  }
  return path;
}

PipelineSummary run_pipeline(const PipelineOptions& options, const Messages& messages,
                             const PipelineProgress& progress) {
  const auto start = Clock::now();
  const campaign::CampaignSpec spec = campaign::parse_campaign_spec(options.spec_path);
  PipelineSummary out;
  out.spec_name = spec.name;
  out.db_path = options.db_path;
  const std::string law_name = options.law_name.empty() ? "eq6_" + spec.name : options.law_name;
  out.out_dir = options.out_dir.empty() ? "out/" + spec.name : options.out_dir;
  // The law name and the check's scene are checked before hours of LBM (the database would
  // refuse a bad name only at the end).
  try {
    check_law_name(law_name);
  } catch (const Error& e) {
    throw Error(e.code(), std::string("--law-name: ") + e.what());
  }
  // The report folder, and enough grid points for the fit: known now, found late otherwise (the
  // law would be published before the report failed).
  const std::size_t grid_points = spec.phi.size() * spec.re.size();
  const int free_parameters = fitter::num_free_parameters(fitter::FitOptions());
  if (grid_points < static_cast<std::size_t>(free_parameters) + 1) {
    throw Error(ErrorCode::kInvalidArgument,
                options.spec_path + ": [grid] phi x re gives " + std::to_string(grid_points) +
                    " points, too few to fit Eq. 6's " + std::to_string(free_parameters) +
                    " free parameters (need at least " + std::to_string(free_parameters + 1) +
                    "): add phi or re values");
  }
  if (options.report) core::check_output_directory(out.out_dir, "--out");
  out.grid_box = grid_box(spec);
  const std::unique_ptr<Dataset> extension = read_extension(spec, options.spec_path, out.grid_box);
  std::unique_ptr<consumers::Scene> regress_scene;
  if (!options.regress_scene.empty()) {
    if (!options.regress)
      throw Error(ErrorCode::kInvalidArgument,
                  "--regress-scene and --no-regress exclude each other");
    regress_scene =
        std::make_unique<consumers::Scene>(consumers::load_scene(options.regress_scene));
  }
  // 1. Campaign (resumed if one of the same name exists). The database is created, migrated and
  // seeded here, before the workers open it.
  campaign::RunCampaignOptions run_options;
  run_options.jobs = options.jobs;
  {
    Database db(options.db_path);
    for (const campaign::CampaignStatus& c : campaign::list_campaigns(db))
      if (c.name == spec.name) run_options.resume = true;
  }
  messages.info("pipeline: campaign '" + spec.name + "' from " + options.spec_path + " -> " +
                options.db_path);
  run_options.progress = progress.campaign;
  const auto campaign_start = Clock::now();
  out.campaign = campaign::run_campaign(options.db_path, spec, run_options);
  if (progress.stage_done) progress.stage_done();
  out.campaign_s = seconds_since(campaign_start);
  messages.info(out.campaign.BriefReport());

  // 2. Dataset; 3. fit of Eq. 6 (the C0 and C1 coefficients), confirmed by NLopt, published.
  {
    Database db(options.db_path);
    std::vector<std::string> skipped;
    out.dataset = campaign::build_dataset(db, out.campaign.id, &skipped);
    for (const std::string& s : skipped) messages.warn("dataset: left out " + s);
    if (extension) {
      out.campaign_dataset_id = out.dataset.id;
      out.extension_id = extension->id;
      out.extension_source = spec.extend_with;
      const std::size_t own = out.dataset.points.size();
      out.dataset = store_dataset(
          db, extend_dataset(out.dataset, out.grid_box, *extension, spec.extend_with));
      out.extension_points = out.dataset.points.size() - own;
      messages.info(fmt::format(
          "pipeline: dataset {} = the campaign's {} ({} points) and {} points of dataset {} "
          "outside its grid ({})",
          out.dataset.id, out.campaign_dataset_id, own, out.extension_points, out.extension_id,
          spec.extend_with));
    }
    fitter::FitOptions fit_options;  // vdh2004, free k0, k1, c10, c11, c12
    fit_options.cv_folds = out.dataset.points.size() >= 10 ? 5 : 0;
    out.cv_folds = fit_options.cv_folds;
    const std::vector<fitter::FitPoint> points = fit_points(out.dataset);
    out.fit = fitter::fit_law(points, fit_options);
    out.law = publish_fit(db, fitter::fitted_record(out.fit, fit_options, law_name, out.dataset.id,
                                                    out.dataset.hash, points));
    // 4. Comparison over the dataset's points.
    const auto fitted = db.load(out.law.reference(), RangePolicy::kExtrapolate);
    out.comparison =
        compare_over_grid(db, *fitted, out.law.reference() + " (fit)", out.dataset, messages);
  }

  // 5. Report: a failure leaves the stored law and dataset, and says how to redo it.
  if (options.report) {
    ReportOptions request;
    request.dataset_id = out.dataset.id;
    request.laws = {out.law.reference()};
    if (out.campaign.id > 0) request.campaign = std::to_string(out.campaign.id);
    request.out_dir = out.out_dir;
    request.quiet = options.quiet;
    try {
      DatabaseOptions read_only;
      read_only.read_only = true;
      Database db(options.db_path, read_only);
      out.report_path = write_report(db, request, messages).report_path;
    } catch (const std::exception& e) {
      messages.warn(std::string("the report failed: ") + e.what() +
                    " (the dataset and the law are stored; rerun `draglab report --dataset " +
                    out.dataset.id + " --law " + out.law.reference() + " --out " + out.out_dir +
                    "`)");
    }
  }
  // 6. Regression check of the published law on the registered consumer scenes.
  out.regress_skipped = !options.regress;
  if (options.regress) {
    out.checked =
        run_check(options.db_path, out.law, regress_scene.get(), messages, progress, &out.check);
  }
  out.wall_s = seconds_since(start);
  return out;
}

nlohmann::json PipelineSummary::ToJson() const {
  nlohmann::json params = nlohmann::json::object(), ci95 = nlohmann::json::object();
  for (std::size_t i = 0; i < fit.names.size(); ++i) {
    params[fit.names[i]] = fit.values[i];
    if (fit.is_free[i]) ci95[fit.names[i]] = {fit.ci95_low[i], fit.ci95_high[i]};
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const PipelineComparison& r : comparison) {
    rows.push_back({{"law", r.law},
                    {"rms_rel_err", r.rms_vs_data},
                    {"max_rel_err", r.max_vs_data},
                    {"rms_rel_diff_bvk2007", r.rms_vs_bvk2007},
                    {"max_rel_diff_bvk2007", r.max_vs_bvk2007}});
  }
  return {{"campaign", campaign.name},
          {"campaign_id", campaign.id},
          {"units_total", campaign.units_total},
          {"units_done", campaign.units_done},
          {"units_failed", campaign.units_failed},
          {"dataset", dataset.id},
          {"points", dataset.points.size()},
          {"extended_with", extension_id.empty()
                                ? nlohmann::json(nullptr)
                                : nlohmann::json{{"campaign_dataset", campaign_dataset_id},
                                                 {"dataset", extension_id},
                                                 {"file", extension_source},
                                                 {"points", extension_points},
                                                 {"grid_box",
                                                  {{"phi", {grid_box.phi_lo, grid_box.phi_hi}},
                                                   {"re", {grid_box.re_lo, grid_box.re_hi}}}}}},
          {"law", law.name},
          {"version", law.version},
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
          {"comparison", rows},
          {"report", report_path},
          {"regress", checked ? regress_json(check) : nlohmann::json(nullptr)},
          {"campaign_s", campaign_s},
          {"wall_s", wall_s}};
}

std::string PipelineSummary::BriefReport() const {
  return fmt::format("pipeline '{}': {} of {} units done, {} points, published {} (RMS {:.2f} %)",
                     spec_name, campaign.units_done, campaign.units_total, dataset.points.size(),
                     law.reference(), 100 * fit.rms_rel_err);
}

std::string PipelineSummary::FullReport() const {
  std::ostringstream out;
  out << fmt::format("draglab pipeline '{}': {} of {} LBM units done, {} failed ({:.0f} s)\n",
                     spec_name, campaign.units_done, campaign.units_total, campaign.units_failed,
                     campaign_s);
  out << fmt::format(
      "dataset {}: {} (phi, Re) points, F with realization and resolution uncertainty\n",
      dataset.id, dataset.points.size());
  if (!extension_id.empty()) {
    out << fmt::format(
        "  {} measured by this campaign (dataset {}, phi {:g}-{:g}, Re {:g}-{:g}) and {} taken "
        "from dataset {} outside that box\n  ({})\n",
        dataset.points.size() - extension_points, campaign_dataset_id, grid_box.phi_lo,
        grid_box.phi_hi, grid_box.re_lo, grid_box.re_hi, extension_points, extension_id,
        extension_source);
  }
  out << "\n";
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
    out << fmt::format(", {}-fold CV {:.2f} %", cv_folds, 100 * fit.cv_rms_rel_err);
  }
  out << "\n";
  // Say plainly which coefficients these data do not pin down (95 % half-width above the value)
  // and what the fitter did about it.
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
  out << "  NLopt global search: "
      << (fit.global_checked ? (fit.global_agrees ? "agrees" : "found a different optimum")
                             : "not run")
      << "; constraints F > 0, dF/dRe >= 0: "
      << (fit.constraints_checked
              ? (fit.constraints_satisfied ? "satisfied" : "VIOLATED: " + fit.constraint_report)
              : "not checked")
      << "\n\n";
  out << "Over the dataset's points (relative differences):\n";
  out << fmt::format("  {:<34}{:>12}{:>12}{:>16}{:>16}\n", "law", "RMS vs data", "max vs data",
                     "RMS vs bvk2007", "max vs bvk2007");
  for (const PipelineComparison& r : comparison) {
    out << fmt::format("  {:<34}{:>11.2f}%{:>11.2f}%{:>15.2f}%{:>15.2f}%\n", r.law,
                       100 * r.rms_vs_data, 100 * r.max_vs_data, 100 * r.rms_vs_bvk2007,
                       100 * r.max_vs_bvk2007);
  }
  out << "\nStored: law " << law.reference() << " (published, immutable) in " << db_path
      << "; dataset " << dataset.id << "\n";
  if (!report_path.empty()) out << "Report: " << report_path << " (figures in " << out_dir << ")\n";
  out << fmt::format("Pipeline wall time {:.0f} s.\n", wall_s);
  out << "Next: draglab law show " << law.reference() << " | draglab law eval " << law.reference()
      << " --phi 0.3 --re 20 | draglab fit --dataset " << dataset.id << " --free a,n,b,c0,c1,c2\n";
  if (checked) {
    out << "\nRegression check of " << law.reference()
        << " (consumer predictions against the stored baselines):\n"
        << check.FullReport();
    if (check.any_moved()) {
      out << "PREDICTION MOVED: " << law.reference()
          << " changes a consumer prediction beyond the baseline's tolerance (the law is "
             "published; see `draglab regress list`)\n";
    }
  } else if (regress_skipped) {
    out << "\nRegression check skipped (--no-regress).\n";
  }
  return out.str();
}

}  // namespace workflows
}  // namespace draglab
