// `draglab sensitivity`: a bed scene (any model) per drag law, the bubble diameter at t_ref with
// its numerical uncertainty, the seed's Fig. 4 (and with --beside Fig. 5) as a PNG; and
// --work-precision (bubble diameter against grid size and the model's time step, with run
// times). A model with headline numbers (the DBM: hold-up, bubble sizes at the report heights,
// circulation) reports those instead of the bubble at t_ref, and draws no figure (its own figure
// comes from `scene run` with [outputs] fields = true). docs/scenes.md, "Sensitivity and
// work-precision".
//   draglab sensitivity data/scenes/dpm_bubble_quick.toml --laws gidaspow@1,vdh2004@1
//   draglab sensitivity SCENE --uncertainty grids --out out/quick --json
//   draglab sensitivity data/scenes/dbm_reactor.toml --laws gidaspow@1,bvk2007@1 --uncertainty
//   both
//   draglab sensitivity data/scenes/dbm_tiny.toml --work-precision --law gidaspow@1 --grids
//   4x10x4,6x15x6 --dt 5e-3,2.5e-3
//   draglab sensitivity SCENE --work-precision --law ergun@1 --grids 8x24,12x36 --contact-steps
//   20,40
//   draglab sensitivity data/scenes/tfm_bubble.toml --work-precision --law gidaspow@1 --cfl
//   0.3,0.15
//
// The C++ side runs everything and writes DIR/sensitivity.json (or DIR/work_precision.json) with
// every number and the snapshots; scripts/draglab_fig4.py (Debian's /usr/bin/python3 +
// matplotlib) only draws from it, so a figure can be redrawn without rerunning.
#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/sensitivity.h"
#include "draglab/workflows/studies.h"

namespace draglab {
namespace cli {
namespace {

using consumers::Scene;

struct SensitivityArgs {
  std::string scene_path;
  std::string laws;  // --laws a@1,b@1
  std::string uncertainty = "realizations";
  int realizations = 2;
  double duration_s = 0.0;  // --duration (not given: the scene's)
  bool duration_given = false;
  double t_ref_s = -1.0;  // --t-ref: the snapshot time after injection (not given: the scene's)
  bool t_ref_given = false;
  std::string out_dir;
  bool resume = false;  // --resume: keep the finished runs in DIR/state, go on from them
  double checkpoint_interval_s = 600.0;  // --checkpoint-interval, with --resume
  bool checkpoint_interval_given = false;
  bool no_figure = false;
  std::string beside;  // --beside OTHER/sensitivity.json: fig5.png, OTHER's panels above these
  bool work_precision = false;
  std::string law;    // --work-precision --law
  std::string grids;  // --grids 8x24,12x36
  /// The registered models' time-step options (BedModel::time_resolution), by flag: a list of
  /// values each (--contact-steps 20,40 for the DPM).
  std::map<std::string, std::string> time_steps;
};

/// The time-step options of the registered models: each flag with the models that take it.
std::map<std::string, std::vector<std::string>> time_step_flags() {
  std::map<std::string, std::vector<std::string>> flags;
  for (const std::string& key : consumers::bed_model_keys()) {
    flags[consumers::time_resolution_flag(consumers::find_bed_model(key).time_resolution())]
        .push_back(key);
  }
  return flags;
}

std::string joined(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

std::string cm(double metres) { return fmt::format("{:.2f}", 100.0 * metres); }

/// The law table of a model with headline numbers: per law, one line per number with its value
/// +- total uncertainty and the runs' values.
void print_headline_table(const workflows::SensitivitySummary& s) {
  std::size_t name_width = 6, per_run_width = 12;
  std::vector<std::vector<std::string>> per_run(s.laws.size());
  for (std::size_t i = 0; i < s.laws.size(); ++i) {
    const auto& lr = s.laws[i];
    for (std::size_t n = 0; n < lr.headline.size(); ++n) {
      name_width = std::max(name_width, lr.headline[n].name.size());
      std::string runs;
      for (const auto& r : lr.runs)
        runs += (runs.empty() ? "" : " ") +
                (n < r.headline.size() ? format_number(r.headline[n].second, 4) : "-");
      per_run_width = std::max(per_run_width, runs.size());
      per_run[i].push_back(runs);
    }
  }
  std::cout << fmt::format("Headline numbers per law, scene {} ({} uncertainty)\n", s.scene,
                           workflows::to_string(s.method));
  std::cout << fmt::format("{:<22} {:>8} {:<{}} {:>22}  {:<{}} {:>8}\n", "law", "U_mf m/s",
                           "number", name_width, "value +- u", "per run", per_run_width, "wall s");
  for (std::size_t i = 0; i < s.laws.size(); ++i) {
    const auto& lr = s.laws[i];
    for (std::size_t n = 0; n < lr.headline.size(); ++n) {
      const auto& h = lr.headline[n];
      const bool first = n == 0;
      std::cout << fmt::format(
          "{:<22} {:>8} {:<{}} {:>22}  {:<{}} {:>8}\n", first ? lr.law : std::string(),
          first ? fmt::format("{:.4f}", lr.umf_m_s) : std::string(), h.name, name_width,
          format_number(h.estimate, 4) + " +- " + format_number(h.total, 2), per_run[i][n],
          per_run_width, first ? fmt::format("{:.1f}", lr.wall_s) : std::string());
    }
  }
  std::cout << "  value +- u: " << s.method_description << "\n";
  std::string runs;
  for (const auto& r : s.laws.front().runs)
    runs += fmt::format("{}{} {}", runs.empty() ? "" : ", ",
                        s.realization_kind.empty() ? "run" : "seed " + std::to_string(r.seed),
                        workflows::to_string(workflows::GridSize{r.cells_x, r.cells_y, r.cells_z}));
  std::cout << "  per run: " << runs << "\n";
}

void print_sensitivity_table(const workflows::SensitivitySummary& s) {
  if (s.has_headline()) {
    print_headline_table(s);
    return;
  }
  std::vector<std::string> per_run;
  std::size_t per_run_width = 12;
  for (const auto& lr : s.laws) {
    std::string runs;
    for (const auto& r : lr.runs)
      runs += (runs.empty() ? "" : " ") + (r.bubble_found ? cm(r.bubble_diameter_m) : "-");
    per_run_width = std::max(per_run_width, runs.size());
    per_run.push_back(runs);
  }
  std::cout << fmt::format("Bubble diameter D at t_ref = {} s after injection, scene {}\n",
                           format_number(s.t_ref_s, 4), s.scene);
  std::cout << fmt::format("{:<22} {:>8} {:>16} {:>14}  {:<{}} {:>8}\n", "law", "U_mf m/s",
                           "background m/s", "D cm", "D per run cm", per_run_width, "wall s");
  for (std::size_t i = 0; i < s.laws.size(); ++i) {
    const auto& lr = s.laws[i];
    std::cout << fmt::format("{:<22} {:>8.3f} {:>16} {:>14}  {:<{}} {:>8.1f}\n", lr.law, lr.umf_m_s,
                             fmt::format("{:.3f} ({})", lr.background_m_s, lr.background_mode),
                             cm(lr.diameter.estimate_m) + " +- " + cm(lr.diameter.total_m),
                             per_run[i], per_run_width, lr.wall_s);
  }
  std::cout << "  D +- u: " << s.method_description << "; '-': no bubble at t_ref (D = 0)\n";
  for (const auto& p : s.packings) {
    if (p.particles == 0) continue;
    std::cout << fmt::format(
        "  packing seed {}: {} particles, settled bed {} cm, settling {:.1f} s{}\n", p.seed,
        p.particles, cm(p.settled_bed_height_m), p.settle_wall_s,
        p.reused ? " (kept from an earlier part of the study)" : "");
  }
  int kept = 0, runs = 0;
  for (const auto& lr : s.laws) {
    for (const auto& r : lr.runs) {
      ++runs;
      kept += r.reused ? 1 : 0;
    }
  }
  if (kept > 0) {
    std::cout << fmt::format(
        "  {} of {} runs kept from an earlier part of the study (--resume); their wall times are "
        "those of that part\n",
        kept, runs);
  }
}

/// Work-precision of a model with headline numbers: each number and its difference to the
/// reference (the finest configuration) against the wall time.
void print_headline_work_precision_table(const workflows::WorkPrecisionResult& w) {
  std::cout << w.BriefReport();
  std::string head = fmt::format("{:>10} {:>13}", "grid", w.time_resolution_name);
  for (const auto& [name, value] : w.reference_headline)
    head += fmt::format(" {:>24}", name + " (diff)");
  std::cout << head << fmt::format(" {:>9} {:>8}\n", "steps", "wall s");
  for (const auto& r : w.rows) {
    std::string line = fmt::format(
        "{:>10} {:>13}", workflows::to_string(workflows::GridSize{r.cells_x, r.cells_y, r.cells_z}),
        format_number(r.time_resolution, 4));
    for (std::size_t n = 0; n < r.headline.size(); ++n) {
      const double diff = n < r.headline_difference.size() ? r.headline_difference[n] : 0.0;
      line += fmt::format(
          " {:>24}", format_number(r.headline[n].second, 4) + " (" +
                         (std::isfinite(diff) ? format_number(diff, 2) : std::string("ref")) + ")");
    }
    std::cout << line << fmt::format(" {:>9} {:>8.2f}\n", r.gas_steps, r.wall_s);
  }
  std::cout << "  diff: value - the reference's (the finest configuration: most cells, then the "
               "finest step)\n";
}

void print_work_precision_table(const workflows::WorkPrecisionResult& w) {
  if (w.has_headline()) {
    print_headline_work_precision_table(w);
    return;
  }
  std::cout << w.BriefReport();
  std::cout << fmt::format("{:>9} {:>13} {:>7} {:>7} {:>11} {:>9} {:>10} {:>8}\n", "grid",
                           w.time_resolution_name, "h cm", "D cm", "error cm", "steps", "DEM steps",
                           "wall s");
  for (const auto& r : w.rows) {
    std::cout << fmt::format("{:>9} {:>13} {:>7} {:>7} {:>11} {:>9} {:>10} {:>8.1f}\n",
                             fmt::format("{}x{}", r.cells_x, r.cells_y),
                             format_number(r.time_resolution, 4), cm(r.cell_size_m),
                             r.bubble_found ? cm(r.bubble_diameter_m) : std::string("-"),
                             std::isfinite(r.error_m) ? cm(r.error_m) : std::string("(ref)"),
                             r.gas_steps, r.dem_steps, r.wall_s);
  }
  std::cout << "  error: |D - D_ref| against the reference above; h: the bubble-boundary bound "
               "(one cell) of each grid\n";
}

void run_sensitivity_command(const CliContext& ctx, const SensitivityArgs& args) {
  // Flags of the other mode are a usage error, not silently ignored.
  if (args.work_precision) {
    if (!args.laws.empty())
      throw UsageError("--laws is for the law table; with --work-precision give one --law NAME@V");
    if (args.uncertainty != "realizations" || args.realizations != 2)
      throw UsageError("--uncertainty/--realizations do not apply to --work-precision");
    if (args.law.empty()) throw UsageError("--work-precision needs --law NAME@V (one law)");
    if (args.law.find(',') != std::string::npos)
      throw UsageError("--law: --work-precision takes one NAME@V, got '" + args.law + "'");
    if (args.resume) throw UsageError("--resume applies to the law table, not --work-precision");
  } else {
    std::vector<std::string> given;
    if (!args.law.empty()) given.push_back("--law");
    if (!args.grids.empty()) given.push_back("--grids");
    for (const auto& [flag, list] : args.time_steps)
      if (!list.empty()) given.push_back(flag);
    if (!given.empty()) {
      throw UsageError(joined(given, ", ") +
                       ": these belong to --work-precision (the law table takes --laws a@1,b@1)");
    }
  }
  if (args.duration_given && !(args.duration_s > 0.0 && std::isfinite(args.duration_s)))
    throw UsageError(
        fmt::format("--duration = {} must be a time > 0 s (leave it out for the "
                    "scene's [time] duration_s)",
                    format_number(args.duration_s)));
  if (args.t_ref_given && !(args.t_ref_s >= 0.0 && std::isfinite(args.t_ref_s)))
    throw UsageError(
        fmt::format("--t-ref = {} must be a time >= 0 s after the jet start (leave "
                    "it out for the scene's [time] t_ref_s)",
                    format_number(args.t_ref_s)));

  Scene scene = consumers::load_scene(args.scene_path);
  if (args.t_ref_given) {
    // Another snapshot time of the same bed (the seed's Fig. 5 compares at 0.2 s, its Fig. 4 at
    // 0.3 s); the scene's checks apply (t_ref within the duration).
    scene.time.t_ref_s = args.t_ref_s;
    std::string why;
    if (!scene.IsValid(&why)) throw UsageError("--t-ref: " + why);
  }
  consumers::BedRunOptions run;
  run.duration_s = args.duration_given ? args.duration_s : 0.0;  // 0: the scene's

  workflows::SensitivityOptions sens;
  workflows::WorkPrecisionOptions wp;
  std::string why;
  if (args.work_precision) {
    wp.law = args.law;
    if (!args.grids.empty()) wp.grids = workflows::parse_grid_list(args.grids, "--grids");
    // Each model names the value that sets its time step; the option of another model is a
    // usage error rather than silently ignored.
    const consumers::TimeResolution step =
        consumers::find_bed_model(scene.solver).time_resolution();
    for (const auto& [flag, list] : args.time_steps) {
      if (list.empty()) continue;
      if (flag != consumers::time_resolution_flag(step))
        throw UsageError(fmt::format(
            "{}: this scene's model ({}) sets its time step by {} ({}): use {}", flag, scene.solver,
            step.name, step.description, consumers::time_resolution_flag(step)));
      for (double v : core::parse_number_list(list, flag)) {
        if (step.whole_number && v != std::floor(v))
          throw UsageError(fmt::format("{}: {} is not a whole number ({}, {})", flag,
                                       format_number(v), step.description, step.range));
        if (!(v > 0.0 && std::isfinite(v)))
          throw UsageError(fmt::format("{}: {} is not a positive number ({}, {})", flag,
                                       format_number(v), step.description, step.range));
        if (v >= 1e9)  // far beyond every model's range, and beyond an int on the way there
          throw UsageError(fmt::format("{}: {} is outside {} ({})", flag, format_number(v),
                                       step.range, step.description));
        wp.time_resolutions.push_back(v);
      }
    }
    wp.run = run;
    if (!wp.IsValid(&why)) throw UsageError(why);
  } else {
    if (!args.laws.empty()) sens.laws = core::split_list(args.laws, "--laws", "gidaspow@1,ergun@1");
    sens.uncertainty = workflows::uncertainty_method_from_string(args.uncertainty);
    if (args.realizations < 2 || args.realizations > 32)
      throw UsageError(fmt::format("--realizations must be in [2, 32], got {}", args.realizations));
    if (sens.uncertainty == workflows::UncertaintyMethod::kGrids && args.realizations != 2)
      throw UsageError("--realizations applies to --uncertainty realizations or both only");
    if (args.realizations != 2 &&
        consumers::find_bed_model(scene.solver).realization_kind().empty())
      throw UsageError(fmt::format(
          "--realizations: the {} model is deterministic (no realizations); its uncertainty "
          "comes from two grids",
          scene.solver));
    sens.realizations = args.realizations;
    sens.run = run;
    if (!sens.IsValid(&why)) throw UsageError(why);
  }

  workflows::StudyOutput output;
  output.out_dir = args.out_dir.empty() ? "out/" + scene.name + "_sensitivity" : args.out_dir;
  if (args.resume) sens.state_directory = output.out_dir + "/state";
  if (args.checkpoint_interval_given && !args.resume) {
    throw UsageError(
        "--checkpoint-interval applies with --resume (the checkpoints are kept in "
        "its state folder)");
  }
  sens.checkpoint_interval_s = args.checkpoint_interval_s;
  output.figure = !args.no_figure;
  output.beside = args.beside;
  output.quiet = ctx.quiet;
  // Read-write: a missing database is created and seeded with the literature library.
  auto db = ctx.open_database(/*read_only=*/false);
  // One progress line for the whole study (its ETA is the study's); each settling or run is
  // announced on its own line as it starts.
  ProgressLine progress(!ctx.quiet);
  std::string current;
  const auto on_progress = [&](double f, const std::string& stage) {
    if (stage != current) {
      current = stage;
      progress.finish();
      ctx.info(stage);
    }
    progress.update(f, args.work_precision ? "work-precision" : "sensitivity");
  };

  if (args.work_precision) {
    const workflows::WorkPrecisionStudy study =
        workflows::run_work_precision_study(*db, scene, wp, output, ctx.messages(), on_progress);
    progress.finish();
    if (ctx.json) {
      ctx.print_json(study.ToJson(output.out_dir));
      return;
    }
    print_work_precision_table(study.result);
    std::cout << "  data: " << study.bundle_path
              << (study.figure_path.empty() ? "" : "\n  figure: " + study.figure_path) << "\n";
    return;
  }
  const workflows::SensitivityStudy study =
      workflows::run_sensitivity_study(*db, scene, sens, output, ctx.messages(), on_progress);
  progress.finish();
  if (ctx.json) {
    ctx.print_json(study.ToJson(scene, output.out_dir));
    return;
  }
  print_sensitivity_table(study.summary);
  std::cout << "  data: " << study.bundle_path
            << (study.figure_path.empty() ? "" : "\n  figure: " + study.figure_path)
            << (study.beside_path.empty() ? "" : "\n  figure: " + study.beside_path) << "\n";
}

}  // namespace

void add_sensitivity_commands(CLI::App& app, CliContext& ctx) {
  auto args = std::make_shared<SensitivityArgs>();
  auto* cmd = app.add_subcommand(
      "sensitivity",
      "Run a scene per drag law with its bed model: bubble diameter at t_ref with its numerical "
      "uncertainty (DPM: two packing realizations, two grids or both; TFM: two grids), the "
      "seed's Fig. 4 (bubble snapshot per law: particles coloured by initial layer, or the TFM's "
      "solids fraction in grey) as DIR/fig4.png, D(t) as DIR/bubble_series.png, with --beside "
      "the seed's Fig. 5 (another study's panels above these) as DIR/fig5.png; for the DBM its "
      "headline numbers (hold-up, mean bubble diameter at the report heights, circulation) with "
      "their uncertainty (injection seeds, grids or both), no figure; or, with --work-precision, "
      "the bubble diameter (DBM: the headline numbers) against grid size and time step with run "
      "times");
  cmd->add_option("SCENE", args->scene_path, "Scene file (TOML, docs/scenes.md)")->required();
  cmd->add_option("--laws", args->laws, "Laws NAME@V,... (default: the scene's [drag] laws)");
  cmd->add_option("--uncertainty", args->uncertainty,
                  "realizations (default: seeds scene.seed and scene.seed+1, same grid), grids "
                  "(the scene's grid and a 1.5x finer one, same realization) or both (every seed "
                  "on both grids)");
  cmd->add_option("--realizations", args->realizations,
                  "Realizations (packings, injection seeds) for --uncertainty realizations or "
                  "both, [2, 32] (default 2)");
  cmd->add_option("--t-ref", args->t_ref_s,
                  "Snapshot time after the jet start [s] (default: the scene's [time] t_ref_s)")
      ->each([args](const std::string&) { args->t_ref_given = true; });
  cmd->add_option("--duration", args->duration_s,
                  "Simulated time after the flow starts [s] (default: the scene's)")
      ->each([args](const std::string&) { args->duration_given = true; });
  cmd->add_option("--out", args->out_dir,
                  "Output folder for the JSON data and the PNG (default out/<scene>_sensitivity)");
  cmd->add_flag("--resume", args->resume,
                "Keep each finished run and settled packing in DIR/state as the study goes, and "
                "take from there what the same study already finished: a long study stopped "
                "part-way (killed, or a session's end) goes on where it was when run again with "
                "the same command, with the results of an uninterrupted one");
  cmd->add_option("--checkpoint-interval", args->checkpoint_interval_s,
                  "With --resume: wall seconds between the checkpoints of a packing still "
                  "settling, so that a settling longer than a sitting goes on from where it "
                  "stopped, [0, 1e6]")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str()
      ->each([args](const std::string&) { args->checkpoint_interval_given = true; });
  cmd->add_flag("--no-figure", args->no_figure,
                "Write the JSON data only (draw later with /usr/bin/python3 "
                "scripts/draglab_fig4.py DATA.json DIR)");
  cmd->add_option("--beside", args->beside,
                  "Another study's sensitivity.json (e.g. the DPM's): also draw DIR/fig5.png, its "
                  "panels above this study's, per shared law");
  const std::map<std::string, std::vector<std::string>> step_flags = time_step_flags();
  std::vector<std::string> per_model;
  for (const auto& [flag, models] : step_flags)
    per_model.push_back(flag + " for " + joined(models, ", ") + " scenes");
  cmd->add_flag("--work-precision", args->work_precision,
                "Work-precision study of one law (--law) over --grids x the model's time step (" +
                    joined(per_model, "; ") + ")");
  cmd->add_option("--law", args->law, "--work-precision: the law NAME@V");
  cmd->add_option("--grids", args->grids,
                  "--work-precision: grids CXxCY or CXxCYxCZ (CZ: depth cells, 3-D scenes),... "
                  "(default: the scene's), e.g. 8x24,12x36 or 4x10x4,6x15x6");
  for (const auto& [flag, models] : step_flags) {
    const consumers::TimeResolution t = consumers::find_bed_model(models.front()).time_resolution();
    cmd->add_option(flag, args->time_steps[flag],
                    "--work-precision, " + joined(models, ", ") + " scenes: " + t.description +
                        ", " + t.range + (t.example.empty() ? "" : ", e.g. " + t.example) +
                        " (default: the scene's " + t.name + ")");
  }
  cmd->footer(
      "Examples:\n"
      "  draglab sensitivity data/scenes/dpm_bubble_quick.toml --laws gidaspow@1,vdh2004@1\n"
      "  draglab sensitivity data/scenes/dpm_bubble_quick.toml --uncertainty grids --json\n"
      "  draglab sensitivity data/scenes/tfm_bubble.toml --laws gidaspow@1,hill_koch_ladd@1 "
      "--beside out/dpm_bubble_sensitivity/sensitivity.json\n"
      "  draglab sensitivity data/scenes/dpm_binary_seed.toml --laws bvk2007@1 --out out/binary "
      "--resume   (run again after a stop to go on)\n"
      "  draglab sensitivity data/scenes/dpm_bubble_quick.toml --work-precision --law ergun@1 "
      "--grids 8x24,12x36 --contact-steps 20,40\n"
      "  draglab sensitivity data/scenes/tfm_bubble.toml --work-precision --law gidaspow@1 "
      "--grids 12x40,18x60 --cfl 0.3,0.15\n"
      "  draglab sensitivity data/scenes/dbm_reactor.toml --laws gidaspow@1,bvk2007@1 "
      "--uncertainty both\n"
      "  draglab sensitivity data/scenes/dbm_tiny.toml --work-precision --law gidaspow@1 "
      "--grids 4x10x4,6x15x6 --dt 5e-3,2.5e-3 --duration 6\n"
      "Writes DIR/sensitivity.json + DIR/fig4.png, or DIR/work_precision.json + "
      "DIR/work_precision.png.");
  cmd->callback(
      [&ctx, args] { ctx.action = [&ctx, args] { run_sensitivity_command(ctx, *args); }; });
}

}  // namespace cli
}  // namespace draglab
