// `draglab scene ...`: scene files (docs/scenes.md) -> minimum fluidization per law and the
// numbers a scene implies.
//   draglab scene umf data/scenes/dpm_bubble.toml [--law ergun@1,bvk2007@1] [--json]
//   draglab scene check data/scenes/dpm_bubble.toml [--json]
//   draglab scene run data/scenes/dpm_bubble_quick.toml [--law ergun@1] [--duration S] [--json]
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/core/text.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/error.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/regress.h"

namespace draglab {
namespace cli {
namespace {

using consumers::Scene;

struct SceneArgs {
  std::string scene_path;
  std::string laws;       // --law a,b,c
  double duration_s = 0;  // scene run --duration (not given: the scene's)
  bool duration_given = false;
  bool laws_given = false;  // scene run --law (given empty: refused, not the scene's)
  bool no_store = false;    // scene run --no-store
};

/// The laws to evaluate: --law, else the scene's plus the five reference laws' version 1 that
/// exist in the database.
std::vector<std::string> laws_for(const Scene& scene, const SceneArgs& args, const Database& db) {
  if (!args.laws.empty()) return core::split_list(args.laws, "--law", "gidaspow@1,ergun@1");
  std::vector<std::string> laws = scene.laws;
  for (const char* name : {"gidaspow", "ergun", "hill_koch_ladd", "vdh2004", "bvk2007"}) {
    const std::string ref = std::string(name) + "@1";
    bool listed = false;
    for (const auto& l : laws) listed = listed || l == ref;
    if (listed) continue;
    try {
      db.resolve(ref);
      laws.push_back(ref);
    } catch (const Error& e) {
      if (e.code() != ErrorCode::kNotFound) throw;
    }
  }
  return laws;
}

nlohmann::json umf_json(const consumers::MinFluidizationResult& r) {
  return {{"law", r.law},
          {"umf_m_s", r.umf_m_s},
          {"re_mf", r.re_mf},
          {"eps_mf", r.eps_mf},
          {"archimedes", r.archimedes},
          {"F_mf", r.F_mf},
          {"beta_mf", r.beta_mf},
          {"iterations", r.iterations},
          {"extrapolation",
           r.extrapolation.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.extrapolation)}};
}

void run_umf(const CliContext& ctx, const SceneArgs& args) {
  const Scene scene = consumers::load_scene(args.scene_path);
  auto db = ctx.open_database();  // created and seeded on first use, as every command
  consumers::MinFluidizationOptions options;
  options.eps_mf = scene.eps_mf;
  nlohmann::json rows = nlohmann::json::array();
  std::vector<consumers::MinFluidizationResult> results;
  for (const auto& ref : laws_for(scene, args, *db)) {
    std::string warning;
    auto law = db->load(ref, range_policy_from_string(scene.range_policy), &warning);
    if (!warning.empty()) ctx.warn(warning);
    results.push_back(consumers::minimum_fluidization(*law, scene.particles, scene.gas, options));
    rows.push_back(umf_json(results.back()));
  }
  if (ctx.json) {
    ctx.print_json({{"scene", scene.name}, {"scene_hash", scene.hash()}, {"laws", rows}});
    return;
  }
  std::cout << fmt::format(
      "Minimum fluidization, scene {} (d = {} m, rho_p = {} kg/m^3, "
      "eps_mf = {}, Ar = {}):\n",
      scene.name, format_number(scene.particles.diameter_m),
      format_number(scene.particles.density_kg_m3), scene.eps_mf,
      format_number(results.front().archimedes, 4));
  std::cout << fmt::format("{:<24} {:>10} {:>9} {:>10} {:>12}\n", "law", "U_mf m/s", "Re_mf",
                           "F_mf", "beta kg/m3/s");
  for (const auto& r : results) {
    std::cout << fmt::format("{:<24} {:>10.4f} {:>9.2f} {:>10.4g} {:>12.4g}\n", r.law, r.umf_m_s,
                             r.re_mf, r.F_mf, r.beta_mf);
  }
  for (const auto& r : results) {
    if (!r.extrapolation.empty())
      std::cout << r.law << " EXTRAPOLATED: " << r.extrapolation << "\n";
  }
}

void run_check(const CliContext& ctx, const SceneArgs& args) {
  const Scene scene = consumers::load_scene(args.scene_path);
  auto db = ctx.open_database();  // created and seeded on first use, as every command
  nlohmann::json per_law = nlohmann::json::array();
  std::vector<consumers::SceneDerived> derived;
  for (const auto& ref : args.laws.empty()
                             ? scene.laws
                             : core::split_list(args.laws, "--law", "gidaspow@1,ergun@1")) {
    std::string warning;
    auto law = db->load(ref, RangePolicy::kError, &warning);
    if (!warning.empty()) ctx.warn(warning);
    derived.push_back(consumers::derive_scene(scene, *law));
    const auto& r = derived.back();
    per_law.push_back({{"law", r.umf.law},
                       {"umf_m_s", r.umf.umf_m_s},
                       {"re_mf", r.umf.re_mf},
                       {"eps_mf", r.umf.eps_mf},
                       {"background_m_s", r.background_m_s},
                       {"stokes_number", r.stokes_number},
                       {"gas_drag_relaxation_s", r.gas_drag_relaxation_s},
                       {"solids_drag_relaxation_s", r.solids_drag_relaxation_s},
                       {"recommended_gas_dt_s", r.recommended_gas_dt_s},
                       {"leakage_bubble_diameter_m", r.leakage_bubble_diameter_m}});
  }
  const auto& first = derived.front();
  const consumers::BedModelSettings model_settings =
      consumers::find_bed_model(scene.solver).Settings(scene);
  if (ctx.json) {
    nlohmann::json out = {{"scene", scene.name},
                          {"scene_hash", scene.hash()},
                          {"valid", true},
                          {"solver", scene.solver},
                          {"particle_count", first.particle_count},
                          {"bed_height_mf_m", first.bed_height_mf_m},
                          {"archimedes", first.archimedes},
                          {"particle_response_s", first.particle_response_s},
                          {"jet_area_rate_m2_s", first.jet_area_rate_m2_s},
                          {"background", consumers::to_string(scene.distributor.mode)},
                          {"laws", per_law}};
    for (const auto& [key, value] : model_settings.numbers) out[key] = value;
    ctx.print_json(out);
    return;
  }
  std::cout << fmt::format("scene {} ({}): valid, solver {} ({})\n", scene.name, scene.origin,
                           scene.solver, consumers::find_bed_model(scene.solver).description());
  std::string sizes = "d = " + format_number(scene.particles.diameter_m) + " m";
  if (scene.polydisperse()) {
    sizes = "Sauter mean d = " + format_number(scene.particles.diameter_m) + " m of";
    for (std::size_t i = 0; i < scene.particles.diameters_m.size(); ++i) {
      sizes += (i ? ", " : " ") + format_number(scene.particles.diameters_m[i]) + " m (volume " +
               format_number(scene.particles.volume_fractions[i]) + ")";
    }
  }
  std::cout << fmt::format(
      "  particles: {} of {} (H_mf = {} m at eps_mf = {}); Ar = {}; Stokes response {} s\n",
      first.particle_count, sizes, format_number(first.bed_height_mf_m, 4), scene.eps_mf,
      format_number(first.archimedes, 4), format_number(first.particle_response_s, 3));
  std::cout << "  " << model_settings.line << "\n";
  // Scenes without a jet (the DBM's nozzles are in its settings line) have no jet line.
  if (scene.jet.slot_width_m > 0.0) {
    std::cout << fmt::format(
        "  jet q = {} m^2/s through {} m at {} m/s; background: {}\n",
        format_number(first.jet_area_rate_m2_s, 3), format_number(scene.jet.slot_width_m),
        format_number(scene.jet.velocity_m_s), consumers::to_string(scene.distributor.mode));
  }
  std::cout << fmt::format("{:<20} {:>8} {:>7} {:>10} {:>6} {:>10} {:>10} {:>10} {:>8}\n", "law",
                           "U_mf m/s", "Re_mf", "backgr m/s", "St", "tau_gas s", "tau_sol s",
                           "gas dt s", "D* m");
  for (const auto& r : derived) {
    std::cout << fmt::format(
        "{:<20} {:>8.4f} {:>7.1f} {:>10.4f} {:>6.0f} {:>10.3g} {:>10.3g} {:>10.3g} {:>8.4f}\n",
        r.umf.law, r.umf.umf_m_s, r.umf.re_mf, r.background_m_s, r.stokes_number,
        r.gas_drag_relaxation_s, r.solids_drag_relaxation_s, r.recommended_gas_dt_s,
        r.leakage_bubble_diameter_m);
  }
  std::cout << "  tau_gas = eps rho_g/beta at U_mf: the gas solver couples drag implicitly, so its "
               "step is not limited by it; D* = q/(pi U_mf) (Davidson-Harrison with leakage).\n";
}

void run_run(const CliContext& ctx, const SceneArgs& args) {
  if (args.duration_given && !(args.duration_s > 0.0 && std::isfinite(args.duration_s)))
    throw UsageError(
        fmt::format("--duration = {} must be a time > 0 s (leave it out for the "
                    "scene's [time] duration_s)",
                    format_number(args.duration_s)));
  if (args.laws_given && args.laws.empty())
    throw UsageError("--law: empty (give NAME@V, or leave --law out for the scene's first law)");
  const Scene scene = consumers::load_scene(args.scene_path);
  const std::string ref = args.laws.empty() ? scene.laws.front() : args.laws;
  if (ref.find(',') != std::string::npos)
    throw UsageError("--law: `scene run` takes one NAME@V (use `draglab sensitivity` for several)");
  auto db = ctx.open_database();
  std::string warning;
  std::shared_ptr<const Law> law =
      db->load(ref, range_policy_from_string(scene.range_policy), &warning);
  if (!warning.empty()) ctx.warn(warning);
  consumers::BedRunOptions options;
  options.duration_s = args.duration_given ? args.duration_s : 0.0;  // 0: the scene's
  ProgressLine progress(!ctx.quiet);
  const consumers::BedResult r = consumers::run_bed_model(
      scene, law, options, [&](double f, const std::string& stage) { progress.update(f, stage); });
  progress.finish();
  // Consumer results are provenance like laws and datasets: scene text, law content, code
  // version and metrics, stored (immutable) unless asked not to.
  std::int64_t result_id = 0;
  if (!args.no_store) {
    register_consumer_scene(*db, scene.name, scene.source_text);
    result_id = store_consumer_result(*db, consumers::consumer_result(scene, *law, r)).id;
  }
  if (r.void_fraction_clamps > 0)
    ctx.warn(fmt::format("{} cell void fractions were raised to the minimum (dense packing)",
                         r.void_fraction_clamps));
  if (ctx.json) {
    ctx.print_json(workflows::scene_run_json(scene, r, result_id));
    return;
  }
  std::cout << r.brief << "\n";
  if (!r.headline.empty()) {
    // A model with headline numbers (the DBM) has no jet bubble to follow: its series is in the
    // JSON result; the headline numbers are what its studies compare.
    for (const auto& [name, value] : r.headline)
      std::cout << fmt::format("  {:<28} {}\n", name, format_number(value, 4));
  } else {
    std::cout << fmt::format("{:>9} {:>10} {:>11} {:>10} {:>10}\n", "t-jet s", "D m", "centroid m",
                             "bed m", "dp Pa");
    for (const auto& smp : r.series) {
      std::cout << fmt::format("{:>9.3f} {:>10.4f} {:>11.4f} {:>10.4f} {:>10.1f}\n", smp.t_s,
                               smp.bubble_diameter_m, smp.bubble_centroid_m, smp.bed_height_m,
                               smp.pressure_drop_pa);
    }
  }
  if (r.headline_uncertainty >= 0.0)
    std::cout << "  numerical uncertainty: " << format_number(r.headline_uncertainty, 2) << " ("
              << r.headline_uncertainty_method << ")\n";
  else
    std::cout << "  numerical uncertainty: not estimated (one grid, one packing; see draglab "
                 "sensitivity)\n";
  for (const auto& file : r.output_files) std::cout << "  wrote " << file << "\n";
  if (result_id > 0) std::cout << "  stored as consumer result " << result_id << "\n";
}

}  // namespace

void add_scene_commands(CLI::App& app, CliContext& ctx) {
  auto* scene = app.add_subcommand(
      "scene", "Fluidized-bed scenes (TOML, docs/scenes.md): minimum fluidization, checks");
  scene->require_subcommand(1);
  scene->footer(
      "Examples:\n"
      "  draglab scene check data/scenes/dpm_bubble_quick.toml\n"
      "  draglab scene umf data/scenes/dpm_bubble_quick.toml\n"
      "  draglab scene run data/scenes/dpm_bubble_quick.toml --law gidaspow@1\n"
      "Scene format: docs/scenes.md.");

  auto umf_args = std::make_shared<SceneArgs>();
  auto* umf = scene->add_subcommand(
      "umf",
      "Minimum fluidization velocity per law for the scene's particles, gas and eps_mf: solves "
      "18 Re F(1 - eps_mf, Re) = eps_mf Ar (drag on the bed = its buoyant weight)");
  umf->add_option("SCENE", umf_args->scene_path, "Scene file (TOML)")->required();
  umf->add_option("--law", umf_args->laws,
                  "Laws NAME@V,... (default: the scene's plus gidaspow, ergun, hill_koch_ladd, "
                  "vdh2004, bvk2007 @1 where present)");
  umf->footer(
      "Examples:\n  draglab scene umf data/scenes/dpm_bubble.toml\n"
      "  draglab scene umf data/scenes/dpm_bubble.toml --law ergun@1,bvk2007@1 --json");
  umf->callback([&ctx, umf_args] { ctx.action = [&ctx, umf_args] { run_umf(ctx, *umf_args); }; });

  auto check_args = std::make_shared<SceneArgs>();
  auto* check = scene->add_subcommand(
      "check",
      "Validate a scene file and print its derived numbers (particle count, Archimedes and Stokes "
      "numbers, drag relaxation times at U_mf, recommended DEM and gas time steps)");
  check->add_option("SCENE", check_args->scene_path, "Scene file (TOML)")->required();
  check->add_option("--law", check_args->laws, "Laws NAME@V,... (default: the scene's)");
  check->footer("Example:\n  draglab scene check data/scenes/dpm_bubble_quick.toml --json");
  check->callback(
      [&ctx, check_args] { ctx.action = [&ctx, check_args] { run_check(ctx, *check_args); }; });

  auto run_args = std::make_shared<SceneArgs>();
  auto* run = scene->add_subcommand(
      "run",
      "Run a scene with its bed model and one law (dpm: CFD-DEM, docs/dpm.md, settles the "
      "packing first; tfm: two-fluid with KTGF, docs/tfm.md): fluidize, inject the jet's "
      "bubble; prints U_mf, the background velocity used, the bubble diameter at t_ref and the "
      "time series (progress with ETA on stderr)");
  run->add_option("SCENE", run_args->scene_path, "Scene file (TOML)")->required();
  run->add_option("--law", run_args->laws, "One law NAME@V (default: the scene's first)")
      ->each([run_args](const std::string&) { run_args->laws_given = true; });
  run->add_option("--duration", run_args->duration_s,
                  "Simulated time after the flow starts [s] (default: the scene's)")
      ->each([run_args](const std::string&) { run_args->duration_given = true; });
  run->add_flag("--no-store", run_args->no_store,
                "Do not store the result in the database (stored by default: scene text, law "
                "content hash, code version, metrics)");
  run->footer(
      "Example:\n  draglab scene run data/scenes/dpm_bubble_quick.toml --law ergun@1 --json");
  run->callback([&ctx, run_args] { ctx.action = [&ctx, run_args] { run_run(ctx, *run_args); }; });
}

}  // namespace cli
}  // namespace draglab
