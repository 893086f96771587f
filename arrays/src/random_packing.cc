// Random packings: radii from the size distribution, box from the target phi (exact), random
// centres, FIRE minimisation of a harmonic overlap energy until no pair overlaps, then
// hard-sphere Monte-Carlo displacement moves; configurations that crystallised are regenerated.
//
// Relaxation. Energy E = (1/2) sum_pairs max(0, rho_i + rho_j - |r_ij|)^2 with padded radii
// rho_i = r_i (1 + kRelaxPadding) + min_gap / 2, minimised by FIRE (Bitzek et al., PRL 97,
// 170201, 2006; the semi-implicit Euler integration of FIRE 2.0, Guenole et al., Comput. Mater.
// Sci. 175, 109584, 2020). Below jamming the minimum is E = 0; the run stops once every padded
// overlap is below kRelaxPadding (r_i + r_j) / 2, which leaves a surface gap of at least
// min_gap + kRelaxPadding (r_i + r_j) / 2 between every pair: no overlap in the exact sense.
// Unit masses, unit stiffness; lengths in d_ref.
//
// Equilibration. Single-sphere displacement moves, uniform in a cube of half-edge `step`,
// accepted if no pair comes closer than r_i + r_j + min_gap (relative safety 1e-9 against
// round-off in later recomputations). The step is adapted towards 30 % acceptance during the first
// quarter of the sweeps only and then fixed, so the remaining sweeps satisfy detailed balance and
// sample the hard-sphere fluid (of diameters d + min_gap). Above freezing (phi = 0.494) the
// sampled state is the metastable fluid; crystallisation is detected with the ten Wolde-Frenkel
// criterion (see statistics.cc) and the configuration regenerated with a derived seed.
//
// Reproducibility: the only random source is std::mt19937_64 (exactly specified by the C++
// standard) turned into uniform and normal deviates here (the std distributions are
// implementation-defined). Parallel loops (large N only) compute per-sphere quantities in a fixed
// order and are reduced serially, so results do not depend on the thread count.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cell_list.h"
#include "draglab/arrays/packing.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;
/// Relative radius padding during relaxation (see the file comment).
constexpr double kRelaxPadding = 1e-3;
/// Relative safety on the hard-sphere contact distance in the MC moves.
constexpr double kMcSafety = 1e-9;
/// MC acceptance the step is adapted towards.
constexpr double kTargetAcceptance = 0.3;
/// Iteration cap of the relaxation; a jammed state is recognised much earlier (see relax()).
constexpr long long kMaxRelaxIterations = 100000;
/// Smallest N for which the relaxation loop runs in parallel. Below it an iteration takes less
/// than a few milliseconds, and on a busy machine (parallel test runs, builds) each OpenMP barrier
/// can cost a whole scheduler time slice, so threads would slow the run down.
constexpr std::size_t kMinParallelSpheres = 8192;
/// Minimum interval between two progress calls.
constexpr double kProgressInterval = 0.25;

using core::format_number;

/// Uniform and normal deviates from std::mt19937_64, identical on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Standard normal (Box-Muller; one deviate per call keeps the stream simple).
  double Normal() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  /// Uniform index in [0, n).
  std::size_t Index(std::size_t n) {
    return std::min(n - 1, static_cast<std::size_t>(Uniform() * static_cast<double>(n)));
  }

 private:
  std::mt19937_64 engine_;
};

/// Seed of attempt k > 0 (splitmix64 of the user seed and k): well separated streams.
std::uint64_t derive_seed(std::uint64_t seed, int attempt) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(attempt);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// Throttled progress reporting: stage boundaries always, otherwise at most every 0.25 s.
class Progress {
 public:
  explicit Progress(const ProgressCallback& callback) : callback_(callback) {}
  void Report(double fraction, const char* stage, bool force = false) {
    if (!callback_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && std::chrono::duration<double>(now - last_).count() < kProgressInterval) return;
    last_ = now;
    callback_(std::min(1.0, std::max(0.0, fraction)), stage);
  }

 private:
  const ProgressCallback& callback_;
  std::chrono::steady_clock::time_point last_{};
};

/// Diameters (before scaling to d_ref) and what was drawn.
std::vector<double> draw_diameters(const RandomPackingOptions& o, Random* rng,
                                   nlohmann::json* info) {
  const std::size_t n = static_cast<std::size_t>(o.n);
  std::vector<double> d(n, 1.0);
  switch (o.distribution) {
    case SizeDistribution::kBidisperse: {
      const BidisperseCounts counts = bidisperse_counts(o.n, o.size_ratio, o.large_volume_fraction);
      const std::size_t n_large = static_cast<std::size_t>(counts.large);
      for (std::size_t i = 0; i < n_large; ++i) d[i] = o.size_ratio;  // Large spheres first.
      (*info)["n_large"] = n_large;
      (*info)["n_small"] = n - n_large;
      (*info)["size_ratio"] = o.size_ratio;
      (*info)["large_volume_fraction_requested"] = o.large_volume_fraction;
      (*info)["large_volume_fraction_achieved"] = counts.large_volume_fraction;
      break;
    }
    case SizeDistribution::kLognormal: {
      double sum = 0.0, sum2 = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double ln_d = o.lognormal_sigma * rng->Normal();
        d[i] = std::exp(ln_d);
        sum += ln_d;
        sum2 += ln_d * ln_d;
      }
      const double mean = sum / static_cast<double>(n);
      (*info)["lognormal_sigma"] = o.lognormal_sigma;
      (*info)["sample_sigma_ln_d"] =
          n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * mean * mean) / static_cast<double>(n - 1)))
                : 0.0;
      break;
    }
    case SizeDistribution::kMonodisperse:
    default:
      break;
  }
  return d;
}

/// FIRE relaxation of the padded overlap energy. Returns false if the configuration jammed.
struct RelaxResult {
  bool converged = false;
  long long iterations = 0;
  double max_overlap = 0.0;  ///< Largest padded overlap at the end, in d_ref.
};

RelaxResult relax(const Vec3& box, const std::vector<double>& radii, double min_gap,
                  std::vector<Vec3>* centers_io, Progress* progress) {
  std::vector<Vec3>& x = *centers_io;
  const std::size_t n = radii.size();
  std::vector<double> rho(n), tol(n);
  for (std::size_t i = 0; i < n; ++i) {
    rho[i] = radii[i] * (1.0 + kRelaxPadding) + 0.5 * min_gap;
    tol[i] = 0.5 * kRelaxPadding * radii[i];  // Pair tolerance tol_i + tol_j.
  }
  const double rho_max = *std::max_element(rho.begin(), rho.end());
  const double rho_min = *std::min_element(rho.begin(), rho.end());
  const double r_min = *std::min_element(radii.begin(), radii.end());
  internal::PeriodicCellList cells(box, rho_min + rho_max, n);

  // FIRE parameters of Bitzek et al. 2006 (N_min, f_inc, f_dec, alpha_start, f_alpha); dt in
  // units of sqrt(m / k): the stiffest mode of a sphere with ~12 contacts has omega ~ 5, so
  // dt_max = 0.2 stays below the stability limit 2 / omega of the integration.
  const double dt_max = 0.2, f_inc = 1.1, f_dec = 0.5, alpha_start = 0.1, f_alpha = 0.99;
  const int n_min = 5;
  double dt = 0.02, alpha = alpha_start;
  int positive_steps = 0;

  std::vector<Vec3> v(n, Vec3{0.0, 0.0, 0.0}), f(n);
  double first_overlap = -1.0, best_fraction = 0.0;
  RelaxResult result;
  for (long long it = 0; it < kMaxRelaxIterations; ++it) {
    cells.Build(x);
    double max_force = 0.0, max_overlap = 0.0, max_excess = -1.0;
#pragma omp parallel for schedule(static) if (n >= kMinParallelSpheres) \
    reduction(max                                                       \
              : max_force, max_overlap, max_excess)
    for (long long ii = 0; ii < static_cast<long long>(n); ++ii) {
      const std::size_t i = static_cast<std::size_t>(ii);
      Vec3 fi{0.0, 0.0, 0.0};
      double excess_i = -1.0, overlap_i = 0.0;
      const Vec3 xi = x[i];
      cells.ForEachNear(xi, rho[i] + rho_max, [&](int j, const Vec3& s) {
        const std::size_t jj = static_cast<std::size_t>(j);
        if (jj == i) return;  // Self images never overlap: box edges >= 2 rho_max is checked.
        const double dx = xi[0] - x[jj][0] - s[0], dy = xi[1] - x[jj][1] - s[1],
                     dz = xi[2] - x[jj][2] - s[2];
        const double contact = rho[i] + rho[jj];
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 >= contact * contact) return;
        const double d = std::sqrt(d2);
        const double overlap = contact - d;
        if (d > 0.0) {
          const double scale = overlap / d;
          fi[0] += scale * dx;
          fi[1] += scale * dy;
          fi[2] += scale * dz;
        } else {
          fi[0] += overlap;  // Coincident centres: push apart along x (either way is fine).
        }
        overlap_i = std::max(overlap_i, overlap);
        excess_i = std::max(excess_i, overlap - tol[i] - tol[jj]);
      });
      f[i] = fi;
      max_force = std::max(max_force, std::sqrt(fi[0] * fi[0] + fi[1] * fi[1] + fi[2] * fi[2]));
      max_overlap = std::max(max_overlap, overlap_i);
      max_excess = std::max(max_excess, excess_i);
    }
    result.iterations = it;
    result.max_overlap = max_overlap;
    if (max_excess <= 0.0) {
      result.converged = true;
      return result;
    }
    // Jammed: the forces balance (no sphere can move) while overlaps remain.
    if (max_force < 1e-6 * max_overlap) return result;

    if (first_overlap < 0.0) first_overlap = max_overlap;
    const double target = kRelaxPadding * r_min;
    if (max_overlap > target && first_overlap > target) {
      best_fraction = std::max(
          best_fraction, std::log(first_overlap / max_overlap) / std::log(first_overlap / target));
    }
    progress->Report(best_fraction, "relax");

    // FIRE step: P = F.v decides whether to accelerate or to stop and restart.
    double power = 0.0, f_norm2 = 0.0, v_norm2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) {
        power += f[i][a] * v[i][a];
        f_norm2 += f[i][a] * f[i][a];
        v_norm2 += v[i][a] * v[i][a];
      }
    }
    if (power > 0.0) {
      if (++positive_steps > n_min) {
        dt = std::min(dt * f_inc, dt_max);
        alpha *= f_alpha;
      }
    } else {
      positive_steps = 0;
      dt *= f_dec;
      alpha = alpha_start;
      for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) {
          // Step back half a step (FIRE 2.0).
          x[i][a] = internal::wrap_into_box(x[i][a] - 0.5 * dt * v[i][a], box[a]);
          v[i][a] = 0.0;
        }
      }
    }
    // Semi-implicit Euler with the FIRE velocity mixing.
    v_norm2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) {
        v[i][a] += dt * f[i][a];
        v_norm2 += v[i][a] * v[i][a];
      }
    }
    const double mix = f_norm2 > 0.0 ? alpha * std::sqrt(v_norm2 / f_norm2) : 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      double v2 = 0.0;
      for (int a = 0; a < 3; ++a) {
        v[i][a] = (1.0 - alpha) * v[i][a] + mix * f[i][a];
        v2 += v[i][a] * v[i][a];
      }
      // A sphere moves at most a tenth of its radius per iteration: the deep overlaps of the
      // random start cannot fling it through its neighbours.
      const double max_step = 0.1 * radii[i];
      const double scale =
          v2 * dt * dt > max_step * max_step ? max_step / (std::sqrt(v2) * dt) : 1.0;
      for (int a = 0; a < 3; ++a) {
        x[i][a] = internal::wrap_into_box(x[i][a] + scale * dt * v[i][a], box[a]);
      }
    }
  }
  return result;
}

struct McResult {
  long long sweeps = 0;
  double acceptance = 0.0;  ///< Over the fixed-step sweeps.
  double step = 0.0;
};

McResult equilibrate(const Vec3& box, const std::vector<double>& radii, double min_gap, int sweeps,
                     Random* rng, std::vector<Vec3>* centers_io, Progress* progress) {
  std::vector<Vec3>& x = *centers_io;
  const std::size_t n = radii.size();
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const double r_min = *std::min_element(radii.begin(), radii.end());
  internal::PeriodicCellList cells(box, r_min + r_max + min_gap, n);
  cells.Build(x);
  const double max_step = 0.5 * std::min({box[0], box[1], box[2]});
  const int adapt_sweeps = sweeps / 4;
  McResult result;
  result.step = std::min(0.1, max_step);
  long long accepted_fixed = 0, trials_fixed = 0;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    long long accepted = 0;
    for (std::size_t t = 0; t < n; ++t) {
      const std::size_t i = rng->Index(n);
      Vec3 trial;
      for (int a = 0; a < 3; ++a) {
        trial[a] =
            internal::wrap_into_box(x[i][a] + result.step * (2.0 * rng->Uniform() - 1.0), box[a]);
      }
      const double ri = radii[i];
      const bool overlaps = cells.AnyNear(
          trial, (ri + r_max + min_gap) * (1.0 + kMcSafety), [&](int j, const Vec3& s) {
            const std::size_t jj = static_cast<std::size_t>(j);
            if (jj == i) return false;  // Self images: box edges >= 2 r_max + min_gap.
            const double dx = x[jj][0] + s[0] - trial[0], dy = x[jj][1] + s[1] - trial[1],
                         dz = x[jj][2] + s[2] - trial[2];
            const double contact = (ri + radii[jj] + min_gap) * (1.0 + kMcSafety);
            return dx * dx + dy * dy + dz * dz < contact * contact;
          });
      if (!overlaps) {
        x[i] = trial;
        cells.Move(static_cast<int>(i), trial);
        ++accepted;
      }
    }
    if (sweep < adapt_sweeps) {
      const double rate = static_cast<double>(accepted) / static_cast<double>(n);
      result.step *= std::min(1.5, std::max(0.67, rate / kTargetAcceptance));
      result.step = std::min(max_step, std::max(1e-6, result.step));
    } else {
      accepted_fixed += accepted;
      trials_fixed += static_cast<long long>(n);
    }
    ++result.sweeps;
    progress->Report(static_cast<double>(sweep + 1) / sweeps, "equilibrate");
  }
  if (trials_fixed > 0) {
    result.acceptance = static_cast<double>(accepted_fixed) / static_cast<double>(trials_fixed);
  }
  return result;
}

}  // namespace

Packing generate_random_packing(const RandomPackingOptions& options, GenerationSummary* summary,
                                const ProgressCallback& progress_callback) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  const auto start = std::chrono::steady_clock::now();
  Progress progress(progress_callback);
  GenerationSummary local;
  GenerationSummary& sum = summary != nullptr ? *summary : local;
  sum = GenerationSummary();
  std::string attempts_log;
  int jammed_attempts = 0;

  for (int attempt = 0; attempt < options.max_attempts; ++attempt) {
    const std::uint64_t sub_seed = attempt == 0 ? options.seed : derive_seed(options.seed, attempt);
    Random rng(sub_seed);
    nlohmann::json settings;
    settings["kind"] = "random";
    settings["distribution"] = to_string(options.distribution);
    settings["phi"] = options.phi;
    settings["n"] = options.n;
    settings["seed"] = options.seed;
    settings["attempt"] = attempt;
    settings["sub_seed"] = sub_seed;
    settings["min_gap"] = options.min_gap;
    settings["aspect"] = {options.aspect[0], options.aspect[1], options.aspect[2]};
    settings["max_crystalline_fraction"] = options.max_crystalline_fraction;
    settings["d_ref"] = options.distribution == SizeDistribution::kMonodisperse
                            ? "sphere diameter"
                            : "Sauter mean diameter";

    // Radii scaled so that the Sauter mean diameter is 1.
    std::vector<double> d = draw_diameters(options, &rng, &settings);
    long double s2 = 0.0L, s3 = 0.0L, volume = 0.0L;
    for (double di : d) {
      s2 += static_cast<long double>(di) * di;
      s3 += static_cast<long double>(di) * di * di;
    }
    const double sauter = static_cast<double>(s3 / s2);
    std::vector<double> radii(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) {
      radii[i] =
          options.distribution == SizeDistribution::kMonodisperse ? 0.5 : 0.5 * d[i] / sauter;
      volume += static_cast<long double>(radii[i]) * radii[i] * radii[i];
    }
    volume *= 4.0L / 3.0L * static_cast<long double>(kPi);

    // Box from the exact sphere volume.
    const double box_volume = static_cast<double>(volume) / options.phi;
    const double scale =
        std::cbrt(box_volume / (options.aspect[0] * options.aspect[1] * options.aspect[2]));
    const Vec3 box{options.aspect[0] * scale, options.aspect[1] * scale, options.aspect[2] * scale};
    const double r_max = *std::max_element(radii.begin(), radii.end());
    const double min_edge = std::min({box[0], box[1], box[2]});
    const double padded_r_max = r_max * (1.0 + kRelaxPadding) + 0.5 * options.min_gap;
    if (min_edge < 2.0 * padded_r_max) {
      throw Error(ErrorCode::kInvalidArgument,
                  "n = " + std::to_string(options.n) + " at phi = " + format_number(options.phi) +
                      " gives a box edge " + format_number(min_edge) +
                      " smaller than the largest sphere diameter plus min_gap (" +
                      format_number(2.0 * padded_r_max) +
                      "): a sphere would touch its own image; "
                      "increase n or lower phi");
    }
    long double padded_volume = 0.0L;
    for (double r : radii) {
      const long double rp = r + 0.5 * options.min_gap;
      padded_volume += rp * rp * rp;
    }
    const double padded_phi =
        static_cast<double>(padded_volume * 4.0L / 3.0L * static_cast<long double>(kPi)) /
        box_volume;
    if (padded_phi > kMaxRandomPhi) {
      throw Error(ErrorCode::kInvalidArgument,
                  "min_gap = " + format_number(options.min_gap) +
                      " at phi = " + format_number(options.phi) +
                      " pads the spheres to a solids fraction " + format_number(padded_phi) +
                      " above " + format_number(kMaxRandomPhi) + "; lower min_gap or phi");
    }

    std::vector<Vec3> centers(radii.size());
    for (Vec3& c : centers) {
      for (int a = 0; a < 3; ++a) c[a] = rng.Uniform() * box[a];
    }

    progress.Report(0.0, "relax", true);
    const RelaxResult relaxed = relax(box, radii, options.min_gap, &centers, &progress);
    sum.attempts = attempt + 1;
    sum.relaxation_iterations += relaxed.iterations;
    if (!relaxed.converged) {
      // A single jammed start can be bad luck (small N); two mean phi is beyond jamming.
      ++jammed_attempts;
      attempts_log += "\n  attempt " + std::to_string(attempt + 1) + " (seed " +
                      std::to_string(sub_seed) + "): jammed after " +
                      std::to_string(relaxed.iterations) + " FIRE iterations, overlaps up to " +
                      format_number(relaxed.max_overlap) + " d_ref";
      if (jammed_attempts < 2 && attempt + 1 < options.max_attempts) continue;
      sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      throw Error(
          ErrorCode::kInternal,
          "random packing: overlaps could not be removed at phi = " + format_number(options.phi) +
              (options.min_gap > 0.0 ? " with min_gap = " + format_number(options.min_gap) : "") +
              " (" + to_string(options.distribution) + ", n = " + std::to_string(options.n) +
              "): the FIRE relaxation jammed:" + attempts_log +
              "\nphi is too close to random close packing for this size distribution; "
              "lower phi or min_gap (monodisperse spheres jam near 0.64; up to 0.62 is "
              "safe)");
    }
    progress.Report(1.0, "relax", true);

    progress.Report(0.0, "equilibrate", true);
    const McResult mc = equilibrate(box, radii, options.min_gap, options.equilibration_sweeps, &rng,
                                    &centers, &progress);
    progress.Report(1.0, "equilibrate", true);
    sum.mc_sweeps += mc.sweeps;
    sum.mc_acceptance = mc.acceptance;
    sum.mc_step = mc.step;

    Packing packing;
    packing.box_length = box;
    packing.centers = std::move(centers);
    packing.radii = std::move(radii);
    packing.generator = "random: FIRE overlap removal + hard-sphere MC";
    packing.seed = options.seed;
    const PackingStatistics stats = compute_statistics(packing);
    sum.q6 = stats.q6;
    sum.crystalline_fraction = stats.crystalline_fraction;
    sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (stats.min_gap < options.min_gap) {
      throw Error(ErrorCode::kInternal, "random packing: internal check failed, smallest gap " +
                                            format_number(stats.min_gap) + " < min_gap " +
                                            format_number(options.min_gap) +
                                            " (please report: seed " +
                                            std::to_string(options.seed) + ")");
    }
    attempts_log += "\n  attempt " + std::to_string(attempt + 1) + " (seed " +
                    std::to_string(sub_seed) + "): crystalline fraction " +
                    format_number(stats.crystalline_fraction) + ", Q6 " + format_number(stats.q6);
    if (stats.crystalline_fraction <= options.max_crystalline_fraction) {
      settings["relaxation"] = {
          {"method", "FIRE"}, {"padding", kRelaxPadding}, {"iterations", relaxed.iterations}};
      settings["equilibration_sweeps"] = options.equilibration_sweeps;
      settings["mc"] = {{"sweeps", mc.sweeps},
                        {"adapted_sweeps", options.equilibration_sweeps / 4},
                        {"step", mc.step},
                        {"acceptance", mc.acceptance},
                        {"target_acceptance", kTargetAcceptance}};
      settings["q6"] = stats.q6;
      settings["crystalline_fraction"] = stats.crystalline_fraction;
      packing.settings_json = settings.dump();
      return packing;
    }
  }
  throw Error(ErrorCode::kInternal,
              "random packing: no attempt gave a disordered packing (crystalline fraction at "
              "most max_crystalline_fraction = " +
                  format_number(options.max_crystalline_fraction) +
                  ") at phi = " + format_number(options.phi) + " after " +
                  std::to_string(options.equilibration_sweeps) + " MC sweeps:" + attempts_log +
                  "\nThe hard-sphere fluid freezes above phi = 0.494; use fewer "
                  "equilibration_sweeps, a polydisperse size distribution, or more attempts");
}

}  // namespace arrays
}  // namespace draglab
