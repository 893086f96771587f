// `draglab campaign run|status|export` and `draglab dataset build|list|show|export|import`:
// LBM drag campaigns (docs/campaigns.md) and the datasets built from them.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "cli/stop_signal.h"
#include "drag_db_version.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/files.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "draglab/mpi/world.h"

namespace draglab {
namespace cli {
namespace {

struct RunCommand {
  std::string spec;
  bool resume = false;
  int jobs = 0;
  int threads_per_unit = 0;
  double worker_timeout_s = 30.0;
  double checkpoint_interval = 600.0;
};

struct ExportCommand {
  std::string id;
  bool csv = false;
  bool species = false;
  bool provenance = false;
  std::vector<std::string> notes;
  std::string out;
};

/// A spec path, or a preset name ("quick", "standard", "paper") from data/campaigns.
std::string resolve_spec_path(const std::string& spec) {
  if (core::file_exists(spec) || spec.find('/') != std::string::npos ||
      spec.find(".toml") != std::string::npos) {
    return spec;
  }
  for (const std::string& dir :
       {std::string(DRAGLAB_SOURCE_DATA_DIR) + "/campaigns",
        std::string("/usr/local/") + DRAGLAB_INSTALL_SHARE_DIR + "/campaigns",
        std::string("/usr/") + DRAGLAB_INSTALL_SHARE_DIR + "/campaigns"}) {
    if (core::file_exists(dir + "/" + spec + ".toml")) return dir + "/" + spec + ".toml";
  }
  return spec;
}

/// A finite number, or null (JSON has no nan).
nlohmann::json finite_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nullptr; }

nlohmann::json in_progress_json(const std::vector<campaign::UnitInProgress>& units) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& u : units) {
    nlohmann::json j = {{"unit", u.unit_id},
                        {"phi", u.phi},
                        {"re_target", u.re_target},
                        {"resolution", u.resolution},
                        {"realization", u.realization},
                        {"status", u.status},
                        {"checkpoint_age_s", u.checkpoint_age_s}};
    if (!u.unreadable.empty()) {
      j["unreadable"] = u.unreadable;
    } else {
      const lbm::CheckpointProgress& p = u.progress;
      j["code"] = p.code;
      j["step"] = p.step;
      j["checks"] = p.checks;
      j["F"] = finite_or_null(p.F);
      j["re"] = finite_or_null(p.re);
      j["relative_change"] = finite_or_null(p.relative_change);
      j["recent_F"] = {finite_or_null(p.recent_F_min), finite_or_null(p.recent_F_max)};
      j["recent_re"] = {finite_or_null(p.recent_re_min), finite_or_null(p.recent_re_max)};
      j["force_adjustments"] = p.force_adjustments;
      j["averaging"] = p.averaging;
      j["averaging_start"] = p.averaging_start;
      j["averaged_samples"] = p.averaged_samples;
      j["F_average"] = finite_or_null(p.F_average);
      j["F_average_standard_error"] = finite_or_null(p.F_average_standard_error);
    }
    a.push_back(std::move(j));
  }
  return a;
}

nlohmann::json status_json(const campaign::CampaignStatus& s) {
  return {{"id", s.id},
          {"name", s.name},
          {"spec_hash", s.spec_hash},
          {"created_at", s.created_at},
          {"units_total", s.units_total},
          {"units_done", s.units_done},
          {"units_failed", s.units_failed},
          {"units_pending", s.units_pending},
          {"units_running", s.units_running},
          {"wall_s", s.wall_s},
          {"in_progress", in_progress_json(s.in_progress)}};
}

nlohmann::json point_json(const DatasetPoint& p) {
  return {{"phi", p.phi},
          {"re_target", p.re_target},
          {"re", p.re},
          {"F", p.F},
          {"F_standard_error", p.F_standard_error},
          {"F_discretisation_error", p.F_discretisation_error},
          {"F_uncertainty", p.F_uncertainty},
          {"realizations", p.realizations},
          {"resolutions", p.resolutions},
          {"F_at_resolution", p.F_at_resolution},
          {"order", p.order},
          {"extrapolation", p.extrapolation},
          {"wall_s", p.wall_s}};
}

nlohmann::json dataset_json(const Dataset& d, bool with_points) {
  nlohmann::json j = {{"id", d.id},
                      {"hash", d.hash},
                      {"campaign_id", d.campaign_id},
                      {"name", d.name},
                      {"created_at", d.created_at},
                      {"code_version", d.code_version},
                      {"points", d.points.size()}};
  const auto method = nlohmann::json::parse(d.method, nullptr, false);
  j["method"] = method.is_discarded() ? nlohmann::json(d.method) : method;
  if (with_points) {
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : d.points) points.push_back(point_json(p));
    j["points"] = points;
  }
  return j;
}

void print_dataset_table(const Dataset& d) {
  std::cout << fmt::format("dataset {} ({} points) from {}, built {}\n", d.id, d.points.size(),
                           d.name, d.created_at);
  std::cout << fmt::format("{:>7} {:>8} {:>9} {:>11} {:>9} {:>9} {:>9} {:>5} {:>11}\n", "phi",
                           "Re_tgt", "Re", "F", "se", "disc", "total", "real", "extrap");
  for (const auto& p : d.points) {
    std::cout << fmt::format(
        "{:>7.4g} {:>8.4g} {:>9.4g} {:>11.6g} {:>9.2e} {:>9.2e} {:>9.2e} {:>5} {:>11}\n", p.phi,
        p.re_target, p.re, p.F, p.F_standard_error, p.F_discretisation_error, p.F_uncertainty,
        p.realizations, p.extrapolation + (p.order > 0 ? fmt::format("({:.2g})", p.order) : ""));
  }
}

/// Builds the dataset of a campaign, printing what was left out; returns it.
Dataset build_and_report(const CliContext& ctx, Database& db,
                         const std::vector<std::int64_t>& campaign_ids,
                         const campaign::BuildDatasetOptions& options = {}) {
  std::vector<std::string> skipped;
  const Dataset d = campaign::build_dataset(db, campaign_ids, options, &skipped);
  for (const auto& s : skipped) ctx.warn("dataset: left out " + s);
  const auto method = nlohmann::json::parse(d.method, nullptr, false);
  if (method.is_object() && method.contains("notes")) {
    for (const auto& n : method["notes"]) ctx.info("dataset: " + n.get<std::string>());
  }
  return d;
}

struct PlanCommand {
  std::string spec;
  int jobs = 0;
  double node_update_ns = 0.0;
};

/// `campaign plan`: units, memory and predicted time; a spec that cannot fit is bad input.
void run_plan_command(const CliContext& ctx, const PlanCommand& c) {
  const campaign::CampaignSpec spec = campaign::parse_campaign_spec(resolve_spec_path(c.spec));
  if (c.jobs < 0 || c.jobs > 1024) throw UsageError("--jobs must be in [0, 1024] (0 = all cores)");
  if (!std::isfinite(c.node_update_ns) || c.node_update_ns < 0.0 || c.node_update_ns > 1e6) {
    throw UsageError(fmt::format(
        "--node-update-ns = {} is outside [0, 1e+06] ns per fluid-node update (0 = measure on "
        "this machine)",
        format_number(c.node_update_ns)));
  }
  const int jobs =
      c.jobs > 0 ? c.jobs : std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
  if (c.node_update_ns == 0.0) {
    ctx.info("campaign plan: timing the engine on this machine (~2 s: TRT and rr)");
  }
  const campaign::CampaignPlan plan = campaign::plan_campaign(spec, jobs, c.node_update_ns * 1e-9);
  if (ctx.json) {
    nlohmann::json points = nlohmann::json::array();
    for (const campaign::PlannedPoint& p : plan.points) {
      points.push_back({{"phi", p.phi},
                        {"re", p.re},
                        {"resolution", p.resolution},
                        {"units", p.units},
                        {"collision", p.collision},
                        {"fluid_nodes", p.fluid_nodes},
                        {"steps", p.steps},
                        {"unit_seconds", p.unit_seconds},
                        {"memory_bytes", p.memory_bytes},
                        {"d_needed", p.d_needed},
                        {"resolution_verdict", p.resolution_verdict},
                        {"unsteady", p.unsteady},
                        {"resolution_detail", p.resolution_detail}});
    }
    ctx.print_json({{"campaign", spec.name},
                    {"units", plan.units},
                    {"jobs", plan.jobs},
                    {"node_update_seconds", plan.node_update_seconds},
                    {"rr_node_update_seconds", plan.rr_node_update_seconds},
                    {"core_seconds", plan.core_seconds},
                    {"wall_seconds", plan.wall_seconds},
                    {"largest_unit_memory_bytes", plan.largest_unit_memory_bytes},
                    {"machine_memory_bytes", plan.machine_memory_bytes},
                    {"fits_in_memory", plan.fits_in_memory},
                    {"refused_units", plan.refused_units},
                    {"under_resolved_units", plan.under_resolved_units},
                    {"unstable_units", plan.unstable_units},
                    {"unpackable_units", plan.unpackable_units},
                    {"packing_failures", plan.packing_failures},
                    {"packings_checked", plan.packings_checked},
                    {"points", points}});
  } else {
    std::cout << fmt::format("campaign {}\n", spec.name) << plan.FullReport();
  }
  if (!plan.fits_in_memory) {
    throw UsageError(fmt::format(
        "[lbm] resolutions: the largest unit needs about {:.1f} GiB, {:.1f} GiB for {} workers: "
        "more than 80 % of this machine's {:.1f} GiB; lower the resolution, the spheres per "
        "box, or --jobs",
        plan.largest_unit_memory_bytes / 1073741824.0,
        plan.largest_unit_memory_bytes * plan.jobs / 1073741824.0, plan.jobs,
        plan.machine_memory_bytes / 1073741824.0));
  }
}

void run_campaign_command(const CliContext& ctx, const RunCommand& c) {
  if (c.jobs < 0 || c.jobs > 1024) throw UsageError("--jobs must be in [0, 1024] (0 = all cores)");
  if (!(c.worker_timeout_s >= 1.0 && c.worker_timeout_s <= 86400.0)) {
    throw UsageError("--worker-timeout must be in [1, 86400] seconds");
  }
  campaign::RunCampaignOptions options;
  options.jobs = c.jobs;
  options.resume = c.resume;
  options.threads_per_unit = c.threads_per_unit;
  options.worker_timeout_s = c.worker_timeout_s;
  if (!(c.checkpoint_interval >= 0.0 && c.checkpoint_interval <= 1e6)) {
    throw UsageError("--checkpoint-interval must be in [0, 1e6] seconds");
  }
  options.checkpoint_interval = c.checkpoint_interval;
  const bool distributed = mpi::size() > 1;
  if (distributed && mpi::rank() != 0) {
    // A worker: the spec comes from rank 0 (no copy of the file needed here), no output.
    campaign::run_campaign(ctx.resolved_db_path(), campaign::CampaignSpec{}, options);
    return;
  }
  // The whole spec is checked before the database is opened: bad input writes nothing.
  campaign::CampaignSpec spec;
  try {
    spec = campaign::parse_campaign_spec(resolve_spec_path(c.spec));
  } catch (const Error& e) {
    campaign::cancel_distributed_run(e.is_bad_input() ? 2 : 1);
    throw;
  }
  if (!distributed && mpi::started_by_launcher()) {
    ctx.info(
        "note: started by an MPI launcher with one rank: running as the single-process "
        "runner (--jobs workers); start 2 or more ranks to distribute the units");
  }
  auto printer = std::make_shared<CampaignProgressPrinter>(!ctx.quiet);
  options.progress = [printer](std::int64_t finished, std::int64_t total, const std::string& line) {
    (*printer)(finished, total, line);
  };
  const std::string db_path = ctx.resolved_db_path();
  ctx.info(fmt::format(
      "campaign {}: {} phi x {} Re x {} realizations x {} = {} units (database {})", spec.name,
      spec.phi.size(), spec.re.size(), spec.realizations,
      spec.resolution_rule ? fmt::format("each point's resolutions (the rule, d {} to {})",
                                         spec.min_resolution, spec.max_resolution)
                           : fmt::format("{} resolutions", spec.resolutions.size()),
      spec.unit_count(), db_path));
  if (distributed) {
    ctx.info(fmt::format("MPI: {} ranks; rank 0 ({}) holds the database, ranks 1..{} run the units",
                         mpi::size(), mpi::host_name(), mpi::size() - 1));
  }
  const auto start = std::chrono::steady_clock::now();
  // One process keeps each unit's checkpoint: a SIGTERM or SIGINT then stops the units at their
  // next check with their checkpoints saved (an MPI campaign keeps none: the default stands).
  std::optional<StopOnSignal> stop_on_signal;
  if (!distributed) stop_on_signal.emplace();
  const campaign::CampaignStatus st = campaign::run_campaign(db_path, spec, options);
  printer->finish();
  if (lbm::stop_requested()) {
    // Not a failure of the campaign, but not its end either: exit 1, the queue as it stands.
    throw std::runtime_error(fmt::format(
        "stopped on request (SIGTERM or SIGINT): {} of {} units done, {} back in the queue, each "
        "unit that had started with its checkpoint; go on with: draglab campaign run {} --resume",
        st.units_done + st.units_failed, st.units_total, st.units_pending + st.units_running,
        c.spec));
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  nlohmann::json j = status_json(st);
  j["run_wall_s"] = wall;
  j["session"] = nlohmann::json::parse(st.session.ToJson());
  std::unique_ptr<Database> db = ctx.open_database();
  if (st.units_pending + st.units_running == 0 && st.units_done > 0) {
    const Dataset d = build_and_report(ctx, *db, {st.id});
    j["dataset_id"] = d.id;
    j["dataset_hash"] = d.hash;
    j["dataset_points"] = d.points.size();
  }
  if (st.units_failed > 0) {
    // Failed units are results too (recorded with their diagnosis): list them, exit 0.
    for (const auto& u : campaign::list_units(*db, st.id)) {
      if (u.status == "failed") {
        ctx.warn(fmt::format("unit phi = {}, Re = {}, d = {}, realization {} failed: {}", u.phi,
                             u.re_target, u.resolution, u.realization, u.diagnosis));
      }
    }
  }
  const bool nothing_converged = st.units_done == 0 && st.units_pending + st.units_running == 0;
  if (ctx.json) {
    ctx.print_json(j);
    if (nothing_converged) {
      throw std::runtime_error("no unit of campaign '" + st.name + "' converged: no dataset");
    }
    return;
  }
  std::cout << st.BriefReport() << "\n";
  std::cout << fmt::format("wall time        {:.1f} s this run, {:.1f} s of LBM units in all\n",
                           wall, st.wall_s);
  std::cout << st.session.FullReport();
  if (j.contains("dataset_id")) {
    std::cout << fmt::format("dataset          {} ({} points): draglab dataset show {}\n",
                             j["dataset_id"].get<std::string>(),
                             j["dataset_points"].get<std::size_t>(),
                             j["dataset_id"].get<std::string>());
  } else if (nothing_converged) {
    throw std::runtime_error("no unit of campaign '" + st.name + "' converged: no dataset");
  }
}

void run_status(const CliContext& ctx, const std::string& id) {
  std::unique_ptr<Database> db = ctx.open_database(true);
  if (!id.empty()) {
    const campaign::CampaignStatus st = campaign::campaign_status(*db, id);
    if (ctx.json) {
      ctx.print_json(status_json(st));
    } else {
      std::cout << st.FullReport();
    }
    return;
  }
  const auto all = campaign::list_campaigns(*db);
  if (ctx.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& s : all) j.push_back(status_json(s));
    ctx.print_json(j);
    return;
  }
  if (all.empty()) {
    std::cout << "no campaigns (start one with: draglab campaign run data/campaigns/quick.toml)\n";
    return;
  }
  std::cout << fmt::format("{:>4}  {:<20} {:>6} {:>6} {:>6} {:>6}  {:<20}\n", "id", "name", "total",
                           "done", "failed", "to run", "created");
  for (const auto& s : all) {
    std::cout << fmt::format("{:>4}  {:<20} {:>6} {:>6} {:>6} {:>6}  {:<20}\n", s.id, s.name,
                             s.units_total, s.units_done, s.units_failed,
                             s.units_pending + s.units_running, s.created_at);
  }
}

/// Every column of every unit, straight from the table.
void run_export(const CliContext& ctx, const ExportCommand& c) {
  if (c.provenance && !c.csv) throw UsageError("--provenance is for --csv (JSON has the status)");
  if (!c.notes.empty() && !c.provenance) throw UsageError("--note goes with --provenance");
  if (!c.out.empty()) core::check_output_file(c.out, "--out");
  std::unique_ptr<Database> db = ctx.open_database(true);
  const campaign::CampaignStatus st = campaign::campaign_status(*db, c.id);
  if (c.species) {
    std::size_t rows = 0;
    const std::string text = campaign::export_species_csv(*db, st.id, &rows);
    if (c.out.empty()) {
      std::cout << text;
    } else {
      core::write_file_atomically(c.out, text, "--out");
    }
    ctx.info(fmt::format("{} size-class rows of campaign {}{}{}", rows, st.name,
                         c.out.empty() ? "" : " to ", c.out));
    return;
  }
  const campaign::UnitsExport units = campaign::export_units(*db, st.id);
  const std::string text =
      c.csv ? (c.provenance ? campaign::units_provenance(*db, st.id, c.notes) : std::string()) +
                  units.csv
            : nlohmann::json(
                  {{"campaign", status_json(st)}, {"units", nlohmann::json::parse(units.json)}})
                      .dump(2) +
                  "\n";
  if (c.out.empty()) {
    std::cout << text;
    return;
  }
  core::write_file_atomically(c.out, text, "--out");
  ctx.info(fmt::format("wrote {} units of campaign {} to {}", units.count, st.name, c.out));
}

struct ImportCommand {
  std::string spec, units;
};

void run_import(const CliContext& ctx, const ImportCommand& c) {
  const campaign::CampaignSpec spec = campaign::parse_campaign_spec(resolve_spec_path(c.spec));
  campaign::check_units_file(spec, c.units);  // before the database is opened, or created
  std::unique_ptr<Database> db = ctx.open_database();
  const campaign::ImportSummary summary = campaign::import_campaign(*db, spec, c.units);
  if (ctx.json) {
    ctx.print_json(nlohmann::json::parse(summary.ToJson()));
    return;
  }
  std::cout << summary.BriefReport() << "\n";
  if (summary.pending > 0) {
    std::cout << fmt::format(
        "the {} units not finished run with: draglab campaign run {} --resume\n", summary.pending,
        c.spec);
  }
}

struct DatasetBuildCommand {
  std::vector<std::string> campaigns;
  campaign::BuildDatasetOptions options;
};

void run_dataset_build(const CliContext& ctx, const DatasetBuildCommand& c) {
  if (c.campaigns.size() > 1 && c.options.name.empty()) {
    throw UsageError(
        "dataset build: several campaigns (the parts of one grid) make one dataset: name it with "
        "--name");
  }
  std::unique_ptr<Database> db = ctx.open_database();
  std::vector<std::int64_t> ids;
  for (const std::string& id : c.campaigns) {
    const campaign::CampaignStatus st = campaign::campaign_status(*db, id);
    if (st.units_pending + st.units_running > 0) {
      ctx.warn(fmt::format("campaign {} has {} units not run yet: the dataset uses the {} finished",
                           st.name, st.units_pending + st.units_running,
                           st.units_done + st.units_failed));
    }
    ids.push_back(st.id);
  }
  const Dataset d = build_and_report(ctx, *db, ids, c.options);
  if (ctx.json) {
    ctx.print_json(dataset_json(d, true));
  } else {
    print_dataset_table(d);
  }
}

void run_dataset_list(const CliContext& ctx) {
  std::unique_ptr<Database> db = ctx.open_database(true);
  const auto all = list_datasets(*db);
  if (ctx.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& d : all) j.push_back(dataset_json(d, false));
    ctx.print_json(j);
    return;
  }
  if (all.empty()) {
    std::cout << "no datasets (build one: draglab dataset build CAMPAIGN, or draglab dataset "
                 "import FILE.csv)\n";
    return;
  }
  std::cout << fmt::format("{:<12}  {:<20} {:>8}  {:<20}\n", "id", "name", "campaign", "created");
  for (const auto& d : all) {
    std::cout << fmt::format("{:<12}  {:<20} {:>8}  {:<20}\n", d.id, d.name,
                             d.campaign_id ? std::to_string(d.campaign_id) : "-", d.created_at);
  }
}

void run_dataset_show(const CliContext& ctx, const std::string& id) {
  std::unique_ptr<Database> db = ctx.open_database(true);
  const Dataset d = load_dataset(*db, id);
  if (ctx.json) {
    ctx.print_json(dataset_json(d, true));
  } else {
    print_dataset_table(d);
  }
}

void run_dataset_export(const CliContext& ctx, const std::string& id, const std::string& out) {
  if (!out.empty()) core::check_output_file(out, "--out");
  std::unique_ptr<Database> db = ctx.open_database(true);
  const Dataset d = load_dataset(*db, id);
  // Provenance travels with the file: how it was built, from which campaign spec, by which code.
  std::vector<std::string> provenance = {
      fmt::format("built {} by draglab {}; method {}", d.created_at, d.code_version, d.method),
      fmt::format("exported by draglab {}: draglab dataset export {}", kDragDbVersion, d.id)};
  if (d.campaign_id != 0) {
    try {
      const campaign::CampaignStatus c =
          campaign::campaign_status(*db, std::to_string(d.campaign_id));
      provenance.push_back(fmt::format(
          "campaign {} (id {}), spec hash {}, created {}: {} of {} units done, {} failed, {:.0f} "
          "core-seconds of LBM",
          c.name, c.id, c.spec_hash, c.created_at, c.units_done, c.units_total, c.units_failed,
          c.wall_s));
    } catch (const Error& e) {
      provenance.push_back(
          fmt::format("campaign {}: not in this database ({})", d.campaign_id, e.what()));
    }
  }
  if (out.empty()) {
    std::cout << dataset_csv_text(d, provenance);
    return;
  }
  core::write_file_atomically(out, dataset_csv_text(d, provenance), "--out");
  ctx.info(fmt::format("wrote dataset {} ({} points) to {}", d.id, d.points.size(), out));
}

void run_dataset_import(const CliContext& ctx, const std::string& file) {
  const Dataset parsed = read_dataset_csv(file);  // checked before the database is touched
  std::unique_ptr<Database> db = ctx.open_database();
  const Dataset d = store_dataset(*db, parsed);
  if (ctx.json) {
    ctx.print_json(dataset_json(d, false));
  } else {
    std::cout << fmt::format("dataset {} ({} points) imported from {}\n", d.id, d.points.size(),
                             file);
  }
}

}  // namespace

void add_campaign_commands(CLI::App& app, CliContext& ctx) {
  CLI::App* campaign = app.add_subcommand(
      "campaign", "LBM drag campaigns: a TOML spec -> units (phi, Re, realization, resolution)");
  campaign->require_subcommand(1);
  campaign->footer(
      "Examples:\n  draglab campaign run data/campaigns/quick.toml --jobs 2\n"
      "  draglab campaign run quick --resume\n  draglab campaign status\n"
      "  draglab campaign status quick --json\n  draglab campaign export 1 --csv --out units.csv\n"
      "Spec format: docs/campaigns.md.");
  {
    auto* cmd = campaign->add_subcommand(
        "run",
        "Run a campaign (each finished unit is committed at once; --resume continues a "
        "killed or extended one)");
    auto o = std::make_shared<RunCommand>();
    cmd->add_option("spec", o->spec, "Spec file (TOML) or preset name: quick, standard, paper")
        ->required();
    cmd->add_flag("--resume", o->resume,
                  "Continue the campaign of the same name (finished units are kept; units in "
                  "flight when it stopped run again)");
    cmd->add_option("--jobs", o->jobs, "Units run in parallel (0 = all cores; one process)")
        ->capture_default_str();
    cmd->add_option("--threads-per-unit", o->threads_per_unit,
                    "OpenMP threads of each unit's LBM run (0 = the node's cores shared among its "
                    "workers); runs that must give the same dataset id use the same value")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    cmd->add_option("--worker-timeout", o->worker_timeout_s,
                    "MPI: seconds of silence after which a worker rank is presumed dead and its "
                    "unit handed to another, [1, 86400]")
        ->check(CLI::Range(1.0, 86400.0))
        ->capture_default_str();
    cmd->add_option("--checkpoint-interval", o->checkpoint_interval,
                    "One process: seconds between the checkpoints of each unit's LBM run (kept "
                    "beside the database; a unit taken over after a kill goes on from its "
                    "checkpoint), [0, 1e6]")
        ->capture_default_str();
    cmd->footer(
        "Examples:\n  draglab campaign run data/campaigns/quick.toml --db q.db --jobs 2\n"
        "  draglab campaign run data/campaigns/quick.toml --db q.db --resume\n"
        "  mpirun -np 9 draglab campaign run paper --db paper.db   (rank 0 + 8 workers)\n"
        "One process at a time runs a campaign (a lock file next to the database guards it).\n"
        "Under MPI (mpirun, srun) rank 0 alone opens the database and ranks 1..N-1 run the\n"
        "units; `mpirun --enable-recovery` (srun --no-kill) lets the job go on past a dead rank.\n"
        "When every unit has finished, the dataset is built and its id printed.");
    cmd->callback([&ctx, o] {
      ctx.runs_on_ranks = true;
      ctx.action = [&ctx, o] { run_campaign_command(ctx, *o); };
    });
  }
  {
    auto* cmd = campaign->add_subcommand(
        "plan", "Units, memory and predicted run time of a spec, before any work");
    auto o = std::make_shared<PlanCommand>();
    cmd->add_option("spec", o->spec, "Spec file (TOML) or preset name: quick, standard, paper")
        ->required();
    cmd->add_option("--jobs", o->jobs, "Workers the prediction assumes (0 = all cores)")
        ->capture_default_str();
    cmd->add_option("--node-update-ns", o->node_update_ns,
                    "Time per fluid-node update on one core, ns, for every operator (0 = measure "
                    "TRT's and rr's here, ~2 s)")
        ->capture_default_str();
    cmd->footer(
        "Prediction: fluid nodes x the engine's step model (lbm::predicted_steps) x the\n"
        "measured time per node update, units scheduled longest first on --jobs workers.\n"
        "Exit 2 if the largest unit does not fit in memory for --jobs workers.\n"
        "Examples:\n  draglab campaign plan quick\n  draglab campaign plan paper --jobs 64 --json");
    cmd->callback([&ctx, o] { ctx.action = [&ctx, o] { run_plan_command(ctx, *o); }; });
  }
  {
    auto* cmd = campaign->add_subcommand("status",
                                         "Units total/done/failed of one campaign, or "
                                         "the list of campaigns");
    auto id = std::make_shared<std::string>();
    cmd->add_option("campaign", *id, "Campaign id or name (default: list all)");
    cmd->footer("Examples:\n  draglab campaign status\n  draglab campaign status quick --json");
    cmd->callback([&ctx, id] { ctx.action = [&ctx, id] { run_status(ctx, *id); }; });
  }
  {
    auto* cmd = campaign->add_subcommand("export", "Every field of every unit (JSON, or CSV)");
    auto o = std::make_shared<ExportCommand>();
    cmd->add_option("campaign", o->id, "Campaign id or name")->required();
    cmd->add_flag("--csv", o->csv, "CSV instead of JSON");
    cmd->add_flag("--species", o->species,
                  "CSV of the drag of each size class of each finished unit (polydisperse "
                  "packings): y, x, F_i with its own diameter, the mixture's F");
    cmd->add_flag("--provenance", o->provenance,
                  "With --csv: '#' lines above the table: spec hash, code versions and hosts of "
                  "the finished units, their core-seconds, unit counts, this machine (for a "
                  "shipped part; campaign import checks the spec hash)");
    cmd->add_option("--note", o->notes,
                    "With --provenance: one more '#' line (the command, a predicted cost); "
                    "repeatable");
    cmd->add_option("--out", o->out, "Output file (default: stdout)");
    cmd->footer(
        "Examples:\n  draglab campaign export 1 > units.json\n"
        "  draglab campaign export standard_re100 --csv --provenance --note 'Command: ...' "
        "--out part.csv\n"
        "  draglab campaign export quick --csv --out units.csv\n"
        "  draglab campaign export bidisperse --species --out species.csv");
    cmd->callback([&ctx, o] { ctx.action = [&ctx, o] { run_export(ctx, *o); }; });
  }

  {
    auto* cmd = campaign->add_subcommand(
        "import",
        "Restore a campaign from its spec and the CSV of its units (campaign export --csv): "
        "finished units as they were, the others pending for --resume");
    auto o = std::make_shared<ImportCommand>();
    cmd->add_option("spec", o->spec, "The spec file (TOML) the units were run from")->required();
    cmd->add_option("units", o->units, "The units CSV (campaign export --csv)")->required();
    cmd->footer(
        "A dataset computed in parts keeps each part's units in the repository; on another\n"
        "machine, import them, resume the parts not finished, and build the dataset:\n"
        "  draglab --db s.db campaign import data/campaigns/standard/standard_re100.toml \\\n"
        "      data/datasets/standard/standard_re100.csv\n"
        "  draglab --db s.db campaign run data/campaigns/standard/standard_re100.toml --resume\n"
        "Refused with exit 2, nothing stored: a header without the export's columns, a cell\n"
        "that is not a finite number, a unit twice or missing, a row that is not a unit of the\n"
        "spec (phi, Re, d or seed differ), a campaign of that name already in the database.");
    cmd->callback([&ctx, o] { ctx.action = [&ctx, o] { run_import(ctx, *o); }; });
  }

  CLI::App* dataset = app.add_subcommand(
      "dataset", "Drag datasets (per (phi, Re): mean F, resolution-extrapolated, uncertainty)");
  dataset->require_subcommand(1);
  dataset->footer(
      "Examples:\n  draglab dataset build quick\n  draglab dataset list\n"
      "  draglab dataset show 3f2a9c --json\n  draglab dataset export 3f2a9c --out quick.csv\n"
      "  draglab dataset import my_dns.csv");
  {
    auto* cmd = dataset->add_subcommand(
        "build",
        "Build (and store) a dataset from the finished units of a campaign, or of several "
        "campaigns that are parts of one grid");
    auto o = std::make_shared<DatasetBuildCommand>();
    cmd->add_option("campaign", o->campaigns, "Campaign ids or names (one, or the parts)")
        ->required();
    cmd->add_option("--name", o->options.name,
                    "Name of the dataset (required for several campaigns)");
    cmd->add_flag("--allow-mixed-code", o->options.allow_mixed_code,
                  "Accept units computed by several code versions (the dataset records them)");
    cmd->callback([&ctx, o] { ctx.action = [&ctx, o] { run_dataset_build(ctx, *o); }; });
  }
  {
    auto* cmd = dataset->add_subcommand("list", "List datasets, newest first");
    cmd->callback([&ctx] { ctx.action = [&ctx] { run_dataset_list(ctx); }; });
  }
  {
    auto* cmd = dataset->add_subcommand("show", "Show a dataset's points");
    auto id = std::make_shared<std::string>();
    cmd->add_option("dataset", *id, "Dataset id or hash prefix (>= 4 hex digits)")->required();
    cmd->callback([&ctx, id] { ctx.action = [&ctx, id] { run_dataset_show(ctx, *id); }; });
  }
  {
    auto* cmd = dataset->add_subcommand("export", "Write a dataset as CSV");
    auto id = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    cmd->add_option("dataset", *id, "Dataset id or hash prefix")->required();
    cmd->add_option("--out", *out, "Output file (default: stdout)");
    cmd->callback(
        [&ctx, id, out] { ctx.action = [&ctx, id, out] { run_dataset_export(ctx, *id, *out); }; });
  }
  {
    auto* cmd = dataset->add_subcommand(
        "import", "Import a CSV dataset (columns phi,re,F,F_uncertainty required)");
    auto file = std::make_shared<std::string>();
    cmd->add_option("file", *file, "CSV file")->required();
    cmd->callback([&ctx, file] { ctx.action = [&ctx, file] { run_dataset_import(ctx, *file); }; });
  }
}

}  // namespace cli
}  // namespace draglab
