// `draglab pack ...`: random and ordered sphere packings, ensembles, statistics, voxelization.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "draglab/arrays/packing.h"
#include "draglab/arrays/packing_io.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/core/files.h"
#include "draglab/error.h"

namespace draglab {
namespace cli {
namespace {

struct PackOptions {
  // random
  double phi = std::nan("");
  bool phi_given = false;
  bool n_given = false;
  int n = 0;
  std::string dist = "mono";
  double size_ratio = 2.0;
  double large_fraction = 0.5;
  double sigma = 0.2;
  std::uint64_t seed = 1;
  double min_gap = 0.0;
  int sweeps = 1000;
  std::vector<double> aspect{1.0, 1.0, 1.0};
  // ordered
  std::string ordered;
  int cells = 1;
  // output
  std::string out;
  // ensemble
  int realizations = 1;
  std::string out_dir;
};

/// The library names its fields (size_ratio = 9 is outside ...); the user typed options.
std::string with_option_names(const std::string& message) {
  static const std::pair<const char*, const char*> kOptions[] = {
      {"large_volume_fraction", "--large-fraction"},
      {"size_ratio", "--size-ratio"},
      {"lognormal_sigma", "--sigma"},
      {"min_gap", "--min-gap"},
      {"equilibration_sweeps", "--sweeps"},
      {"aspect", "--aspect"},
      {"phi", "--phi"},
      {"n ", "--n"},
      {"cells", "--cells"}};
  for (const auto& [field, option] : kOptions) {
    if (message.rfind(field, 0) == 0) return std::string(option) + ": " + message;
  }
  return message;
}

arrays::RandomPackingOptions random_options(const PackOptions& o) {
  arrays::RandomPackingOptions r;
  r.phi = o.phi;
  r.n = o.n;
  r.distribution = arrays::size_distribution_from_string(o.dist);
  r.size_ratio = o.size_ratio;
  r.large_volume_fraction = o.large_fraction;
  r.lognormal_sigma = o.sigma;
  r.seed = o.seed;
  r.min_gap = o.min_gap;
  r.equilibration_sweeps = o.sweeps;
  if (o.aspect.size() != 3) throw UsageError("--aspect takes three values, e.g. 1,1,2");
  r.aspect = {o.aspect[0], o.aspect[1], o.aspect[2]};
  std::string error;
  if (!r.IsValid(&error)) throw UsageError(with_option_names(error));
  return r;
}

nlohmann::json statistics_json(const arrays::Packing& p, const arrays::PackingStatistics& s) {
  return {{"phi", s.phi},
          {"n", s.n},
          {"box_length", p.box_length},
          {"min_gap", s.min_gap},
          {"overlapping_pairs", s.overlapping_pairs},
          {"q6", s.q6},
          {"crystalline_fraction", s.crystalline_fraction},
          {"mean_neighbours", s.mean_neighbours},
          {"g_contact", s.g_contact},
          {"sauter_diameter", p.sauter_diameter()},
          {"seed", p.seed},
          {"generator", p.generator}};
}

void print_statistics(const arrays::Packing& p, const arrays::PackingStatistics& s) {
  std::cout << fmt::format("spheres          {}\n", s.n);
  std::cout << fmt::format("box              {} x {} x {} d_ref\n", format_number(p.box_length[0]),
                           format_number(p.box_length[1]), format_number(p.box_length[2]));
  std::cout << fmt::format("phi              {:.12f} (exact)\n", s.phi);
  std::cout << fmt::format(
      "min surface gap  {} d_ref{}\n", format_number(s.min_gap),
      s.overlapping_pairs ? fmt::format("  ({} OVERLAPPING pairs)", s.overlapping_pairs) : "");
  std::cout << fmt::format("g(contact)       {}\n", format_number(s.g_contact, 4));
  std::cout << fmt::format("Q6               {} (random ~0, FCC 0.575)\n", format_number(s.q6, 4));
  std::cout << fmt::format("crystal-like     {:.2f} % of spheres, {:.2f} neighbours per sphere\n",
                           100.0 * s.crystalline_fraction, s.mean_neighbours);
}

void check_phi_given(const PackOptions& o) {
  if (!o.phi_given) throw UsageError("--phi is required");
  if (!std::isfinite(o.phi)) {
    throw UsageError("--phi: '" + std::to_string(o.phi) + "' is not a finite number");
  }
}

arrays::Packing generate(const PackOptions& o, const CliContext& ctx,
                         arrays::GenerationSummary* summary) {
  if (!o.ordered.empty()) {
    arrays::OrderedPackingOptions oo;
    oo.lattice = arrays::lattice_from_string(o.ordered);
    oo.phi = o.phi;
    oo.cells = o.cells;
    std::string error;
    if (!oo.IsValid(&error)) throw UsageError(with_option_names(error));
    return arrays::generate_ordered_packing(oo);
  }
  if (!o.n_given) throw UsageError("--n is required for random packings (or use --ordered)");
  const arrays::RandomPackingOptions r = random_options(o);
  ProgressLine progress(!ctx.quiet);
  arrays::Packing p = arrays::generate_random_packing(
      r, summary, [&progress](double f, const std::string& stage) { progress.update(f, stage); });
  progress.finish();
  return p;
}

void run_pack(const CliContext& ctx, const PackOptions& o) {
  check_phi_given(o);
  if (o.out.empty()) throw UsageError("--out FILE.h5 is required");
  core::check_output_file(o.out, "--out");
  arrays::GenerationSummary summary;
  const auto start = std::chrono::steady_clock::now();
  const arrays::Packing p = generate(o, ctx, &summary);
  const arrays::PackingStatistics s = arrays::compute_statistics(p);
  if (s.overlapping_pairs > 0) {
    throw Error(ErrorCode::kInternal, "generated packing has overlapping spheres; not written");
  }
  arrays::write_packing_hdf5(o.out, p, &s);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (ctx.json) {
    nlohmann::json j = statistics_json(p, s);
    j["out"] = o.out;
    j["wall_s"] = wall;
    if (o.ordered.empty()) {
      j["attempts"] = summary.attempts;
      j["mc_sweeps"] = summary.mc_sweeps;
      j["mc_acceptance"] = summary.mc_acceptance;
    }
    ctx.print_json(j);
    return;
  }
  if (o.ordered.empty()) ctx.info(summary.BriefReport());
  print_statistics(p, s);
  std::cout << fmt::format("wrote            {} ({:.2f} s)\n", o.out, wall);
}

void run_ensemble(const CliContext& ctx, const PackOptions& o) {
  check_phi_given(o);
  if (o.realizations < 1 || o.realizations > 10000) {
    throw UsageError("--realizations must lie in [1, 10000]");
  }
  if (o.out_dir.empty()) throw UsageError("--out-dir DIR is required");
  core::check_output_directory(o.out_dir, "--out-dir");
  core::make_directories(o.out_dir, "--out-dir");
  nlohmann::json out = nlohmann::json::array();
  double sum_g = 0, sum_g2 = 0;
  for (int r = 0; r < o.realizations; ++r) {
    PackOptions one = o;
    // Independent realizations: consecutive seeds feed a 64-bit mixer inside the generator.
    one.seed = o.seed + static_cast<std::uint64_t>(r);
    one.out = fmt::format("{}/realization_{:04d}.h5", o.out_dir, r);
    arrays::GenerationSummary summary;
    const arrays::Packing p = generate(one, ctx, &summary);
    const arrays::PackingStatistics s = arrays::compute_statistics(p);
    arrays::write_packing_hdf5(one.out, p, &s);
    nlohmann::json j = statistics_json(p, s);
    j["out"] = one.out;
    out.push_back(j);
    sum_g += s.g_contact;
    sum_g2 += s.g_contact * s.g_contact;
    ctx.info(fmt::format("realization {}/{}: {} (Q6 {:.3f}, g(contact) {:.3f})", r + 1,
                         o.realizations, one.out, s.q6, s.g_contact));
  }
  if (ctx.json) {
    ctx.print_json(out);
    return;
  }
  const double n = o.realizations;
  const double mean = sum_g / n;
  const double sd = n > 1 ? std::sqrt(std::max(0.0, (sum_g2 - n * mean * mean) / (n - 1))) : 0.0;
  std::cout << fmt::format("{} realizations in {}; g(contact) = {:.4f} +- {:.4f} (standard error)",
                           o.realizations, o.out_dir, mean, sd / std::sqrt(n));
  if (o.dist == "mono" && o.ordered.empty() && o.phi < 0.494) {
    std::cout << fmt::format("; Carnahan-Starling {:.4f}",
                             arrays::carnahan_starling_contact(o.phi));
  }
  std::cout << '\n';
}

void run_stats(const CliContext& ctx, const std::string& file) {
  const arrays::Packing p = arrays::read_packing_hdf5(file);
  const arrays::PackingStatistics s = arrays::compute_statistics(p);
  if (ctx.json) {
    nlohmann::json j = statistics_json(p, s);
    j["file"] = file;
    ctx.print_json(j);
    return;
  }
  std::cout << fmt::format("{}\n", file);
  print_statistics(p, s);
}

void run_voxelize(const CliContext& ctx, const std::string& file, double resolution,
                  const std::string& raw) {
  const arrays::Packing p = arrays::read_packing_hdf5(file);
  arrays::VoxelizationOptions vo;
  vo.resolution = resolution;
  std::string error;
  if (!vo.IsValid(&error)) throw UsageError(error);
  if (!raw.empty()) core::check_output_file(raw, "--raw");
  ProgressLine progress(!ctx.quiet);
  const auto start = std::chrono::steady_clock::now();
  const arrays::VoxelGrid g = arrays::voxelize(
      p, vo, [&progress](double f, const std::string& stage) { progress.update(f, stage); });
  progress.finish();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double gap = arrays::min_gap_lattice_units(p, g.resolution());
  // The solid flags as they are stored (1 solid, 0 fluid, x fastest): another code's input.
  if (!raw.empty()) core::write_file_atomically(raw, g.solid.data(), g.solid.size(), "--raw");
  if (ctx.json) {
    ctx.print_json({{"file", file},
                    {"dims", g.dims},
                    {"resolution", g.resolution()},
                    {"phi", p.phi()},
                    {"phi_lattice", g.phi_lattice()},
                    {"links", g.num_links()},
                    {"memory_bytes", g.memory_bytes()},
                    {"min_gap_lattice", gap},
                    {"raw", raw.empty() ? nlohmann::json() : nlohmann::json(raw)},
                    {"wall_s", wall}});
    return;
  }
  std::cout << fmt::format("lattice          {} x {} x {} nodes, d_ref/dx = {}\n", g.dims[0],
                           g.dims[1], g.dims[2], format_number(g.resolution()));
  std::cout << fmt::format("phi              {:.6f} exact, {:.6f} on the lattice ({:+.3f} %)\n",
                           p.phi(), g.phi_lattice(), 100.0 * (g.phi_lattice() / p.phi() - 1.0));
  std::cout << fmt::format("boundary links   {} ({:.1f} MiB with the flags)\n", g.num_links(),
                           g.memory_bytes() / 1048576.0);
  std::cout << fmt::format("smallest gap     {} lattice units\n", format_number(gap, 3));
  if (!raw.empty()) {
    std::cout << fmt::format("solid flags      {} ({} bytes: 1 solid, 0 fluid, x fastest)\n", raw,
                             g.solid.size());
  }
  std::cout << fmt::format("time             {:.2f} s\n", wall);
}

}  // namespace

void add_pack_commands(CLI::App& app, CliContext& ctx) {
  auto o = std::make_shared<PackOptions>();
  CLI::App* pack = app.add_subcommand(
      "pack", "Generate periodic sphere packings (random or ordered), show their statistics");
  pack->require_subcommand(0, 1);
  auto add_generation_options = [o](CLI::App* cmd) {
    cmd->add_option("--phi", o->phi,
                    "Solids fraction: random (0, 0.64], ordered up to close "
                    "packing")
        ->each([o](const std::string&) { o->phi_given = true; });
    cmd->add_option("--n", o->n, "Number of spheres (random), >= 1")->each([o](const std::string&) {
      o->n_given = true;
    });
    cmd->add_option("--dist", o->dist, "Size distribution: mono, bi or lognormal")
        ->capture_default_str()
        ->check(CLI::IsMember({"mono", "bi", "lognormal"}));
    cmd->add_option("--size-ratio", o->size_ratio, "Bidisperse d_large/d_small, (1, 4]")
        ->capture_default_str();
    cmd->add_option("--large-fraction", o->large_fraction,
                    "Bidisperse volume share of the large spheres, [0, 1]")
        ->capture_default_str();
    cmd->add_option("--sigma", o->sigma, "Lognormal standard deviation of ln d, (0, 0.5]")
        ->capture_default_str();
    cmd->add_option("--seed", o->seed, "Random seed, an integer in [0, 2^64 - 1]")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
              // CLI11 would wrap -1 and 2^64 silently; a seed is a plain unsigned decimal.
              errno = 0;
              char* end = nullptr;
              if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
                  (std::strtoull(text.c_str(), &end, 10), errno == ERANGE)) {
                return "'" + text + "' must be an integer in [0, 18446744073709551615]";
              }
              return std::string();
            },
            "UINT64"))
        ->capture_default_str();
    cmd->add_option("--min-gap", o->min_gap, "Minimum surface gap in d_ref, [0, 0.5]")
        ->capture_default_str();
    cmd->add_option("--sweeps", o->sweeps, "Hard-sphere Monte-Carlo equilibration sweeps")
        ->capture_default_str();
    cmd->add_option("--aspect", o->aspect, "Box edge ratios (cuboid), e.g. 1,1,2")
        ->delimiter(',')
        ->expected(3);
    cmd->add_option("--ordered", o->ordered, "Ordered lattice instead: sc, bcc or fcc")
        ->check(CLI::IsMember({"sc", "bcc", "fcc"}));
    cmd->add_option("--cells", o->cells, "Ordered: unit cells per box edge")->capture_default_str();
  };
  add_generation_options(pack);
  pack->add_option("--out", o->out, "Output HDF5 file (group /packing)");
  pack->footer(
      "Examples:\n"
      "  draglab pack --phi 0.4 --n 1000 --seed 7 --out p.h5\n"
      "  draglab pack --phi 0.3 --n 500 --dist bi --size-ratio 2 --large-fraction 0.5 --out b.h5\n"
      "  draglab pack --phi 0.2 --n 400 --dist lognormal --sigma 0.3 --out l.h5 --json\n"
      "  draglab pack --ordered fcc --phi 0.5 --cells 2 --out fcc.h5\n"
      "  draglab pack stats p.h5 --json\n"
      "  draglab pack ensemble --phi 0.3 --n 500 --realizations 8 --out-dir runs/phi03\n"
      "  draglab pack voxelize p.h5 --resolution 24");

  auto* ensemble = pack->add_subcommand("ensemble", "R independent realizations (seeds S..S+R-1)");
  add_generation_options(ensemble);
  ensemble->add_option("-R,--realizations", o->realizations, "Number of realizations")
      ->capture_default_str();
  ensemble->add_option("--out-dir", o->out_dir, "Output directory (realization_NNNN.h5)");
  ensemble->footer("Example:\n  draglab pack ensemble --phi 0.3 --n 500 -R 8 --out-dir runs/phi03");
  ensemble->callback([&ctx, o] { ctx.action = [&ctx, o] { run_ensemble(ctx, *o); }; });

  auto stats_file = std::make_shared<std::string>();
  auto* stats = pack->add_subcommand("stats", "phi, minimum gap, g(r) contact value, Q6 of a file");
  stats->add_option("file", *stats_file, "Packing HDF5 file")->required();
  stats->footer("Example:\n  draglab pack stats p.h5 --json");
  stats->callback(
      [&ctx, stats_file] { ctx.action = [&ctx, stats_file] { run_stats(ctx, *stats_file); }; });

  auto vox_file = std::make_shared<std::string>();
  auto resolution = std::make_shared<double>(16.0);
  auto* vox = pack->add_subcommand(
      "voxelize", "Lattice solid fraction, boundary links and memory at a resolution");
  vox->add_option("file", *vox_file, "Packing HDF5 file")->required();
  vox->add_option("--resolution", *resolution, "Lattice units per reference diameter")
      ->capture_default_str();
  auto raw = std::make_shared<std::string>();
  vox->add_option("--raw", *raw,
                  "Also write the solid flags to this file: one byte per node (1 solid, 0 fluid), "
                  "x fastest, then y, then z (the lattice `lbm run` uses at this d_ref/dx, for "
                  "another code)");
  vox->footer(
      "Examples:\n  draglab pack voxelize p.h5 --resolution 24 --json\n"
      "  draglab pack voxelize p.h5 --resolution 16 --raw p_d16.raw   # e.g. for a peer LBM code");
  vox->callback([&ctx, vox_file, resolution, raw] {
    ctx.action = [&ctx, vox_file, resolution, raw] {
      run_voxelize(ctx, *vox_file, *resolution, *raw);
    };
  });

  pack->callback([&ctx, o, pack] {
    if (!pack->get_subcommands().empty()) return;  // a nested command set the action
    ctx.action = [&ctx, o] { run_pack(ctx, *o); };
  });
}

}  // namespace cli
}  // namespace draglab
