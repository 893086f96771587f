// Packing basics: names of distributions and lattices, Packing geometry, option checks and the
// generation summary.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "draglab/arrays/packing.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;

using core::format_number;

// Sets *error (if given) and returns false: the IsValid idiom.
bool fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

// True if lo <= x <= hi (false for NaN).
bool in_closed(double x, double lo, double hi) { return x >= lo && x <= hi; }

}  // namespace

const char* to_string(SizeDistribution d) {
  switch (d) {
    case SizeDistribution::kBidisperse:
      return "bi";
    case SizeDistribution::kLognormal:
      return "lognormal";
    case SizeDistribution::kMonodisperse:
    default:
      return "mono";
  }
}

SizeDistribution size_distribution_from_string(const std::string& s) {
  if (s == "mono" || s == "monodisperse") return SizeDistribution::kMonodisperse;
  if (s == "bi" || s == "bidisperse") return SizeDistribution::kBidisperse;
  if (s == "lognormal") return SizeDistribution::kLognormal;
  throw Error(ErrorCode::kInvalidArgument,
              "size distribution '" + s + "' is not one of: mono, bi, lognormal");
}

const char* to_string(Lattice l) {
  switch (l) {
    case Lattice::kBodyCentredCubic:
      return "bcc";
    case Lattice::kFaceCentredCubic:
      return "fcc";
    case Lattice::kSimpleCubic:
    default:
      return "sc";
  }
}

Lattice lattice_from_string(const std::string& s) {
  if (s == "sc") return Lattice::kSimpleCubic;
  if (s == "bcc") return Lattice::kBodyCentredCubic;
  if (s == "fcc") return Lattice::kFaceCentredCubic;
  throw Error(ErrorCode::kInvalidArgument, "lattice '" + s + "' is not one of: sc, bcc, fcc");
}

double close_packing_phi(Lattice l) {
  switch (l) {
    case Lattice::kBodyCentredCubic:
      return std::sqrt(3.0) * kPi / 8.0;
    case Lattice::kFaceCentredCubic:
      return std::sqrt(2.0) * kPi / 6.0;
    case Lattice::kSimpleCubic:
    default:
      return kPi / 6.0;
  }
}

double Packing::phi() const {
  // Long double accumulation keeps the sum exact to ~1e-16 relative for any N we allow.
  long double volume = 0.0L;
  for (double r : radii) volume += static_cast<long double>(r) * r * r;
  return static_cast<double>(volume * (4.0L / 3.0L) * static_cast<long double>(kPi) /
                             static_cast<long double>(box_volume()));
}

double Packing::sauter_diameter() const {
  long double s3 = 0.0L, s2 = 0.0L;
  for (double r : radii) {
    s2 += static_cast<long double>(r) * r;
    s3 += static_cast<long double>(r) * r * r;
  }
  return s2 > 0.0L ? static_cast<double>(2.0L * s3 / s2) : 0.0;
}

Vec3 Packing::separation(std::size_t i, std::size_t j) const {
  Vec3 d;
  for (int a = 0; a < 3; ++a) {
    d[a] = centers[j][a] - centers[i][a];
    d[a] -= box_length[a] * std::round(d[a] / box_length[a]);
  }
  return d;
}

BidisperseCounts bidisperse_counts(int n, double size_ratio, double large_volume_fraction) {
  const double r3 = size_ratio * size_ratio * size_ratio;
  const double s = large_volume_fraction;
  const double x = s / (r3 * (1.0 - s) + s);
  BidisperseCounts c;
  c.large = static_cast<int>(std::min<long long>(n, std::llround(x * n)));
  c.small = n - c.large;
  const double v_large = c.large * r3;
  c.large_volume_fraction = v_large > 0.0 ? v_large / (v_large + c.small) : 0.0;
  return c;
}

int bidisperse_min_spheres(double size_ratio, double large_volume_fraction) {
  for (int n = 2; n <= 10000000; ++n) {
    const BidisperseCounts c = bidisperse_counts(n, size_ratio, large_volume_fraction);
    if (c.large >= 1 && c.small >= 1 &&
        std::fabs(c.large_volume_fraction - large_volume_fraction) <= kBidisperseShareTolerance) {
      return n;
    }
  }
  return 0;
}

bool RandomPackingOptions::IsValid(std::string* error) const {
  if (!(phi > 0.0 && phi <= kMaxRandomPhi)) {
    return fail(error, "phi = " + format_number(phi) + " is outside (0, " +
                           format_number(kMaxRandomPhi) +
                           "] (random close packing limit of random packings)");
  }
  if (n < 1 || n > 10000000) {
    return fail(error, "n = " + std::to_string(n) + " is outside [1, 10000000]");
  }
  if (distribution == SizeDistribution::kBidisperse) {
    if (!(size_ratio > 1.0 && size_ratio <= 4.0)) {
      return fail(error, "size_ratio = " + format_number(size_ratio) +
                             " is outside (1, 4] (bidisperse d_large/d_small)");
    }
    if (!in_closed(large_volume_fraction, 0.0, 1.0)) {
      return fail(error, "large_volume_fraction = " + format_number(large_volume_fraction) +
                             " is outside [0, 1]");
    }
  }
  if (distribution == SizeDistribution::kBidisperse && large_volume_fraction > 0.0 &&
      large_volume_fraction < 1.0) {
    const BidisperseCounts c = bidisperse_counts(n, size_ratio, large_volume_fraction);
    if (c.large < 1 || c.small < 1 ||
        std::fabs(c.large_volume_fraction - large_volume_fraction) > kBidisperseShareTolerance) {
      const int need = bidisperse_min_spheres(size_ratio, large_volume_fraction);
      return fail(error, "n = " + std::to_string(n) + " spheres split into " +
                             std::to_string(c.large) + " large and " + std::to_string(c.small) +
                             " small ones at size_ratio " + format_number(size_ratio) +
                             ", a large volume share of " + format_number(c.large_volume_fraction) +
                             " for the " + format_number(large_volume_fraction) +
                             " asked (both sizes, within " +
                             format_number(kBidisperseShareTolerance) +
                             "): use n >= " + std::to_string(need));
    }
  }
  if (distribution == SizeDistribution::kLognormal &&
      !(lognormal_sigma > 0.0 && lognormal_sigma <= 0.5)) {
    return fail(error,
                "lognormal_sigma = " + format_number(lognormal_sigma) + " is outside (0, 0.5]");
  }
  if (!in_closed(min_gap, 0.0, 0.5)) {
    return fail(error, "min_gap = " + format_number(min_gap) + " is outside [0, 0.5] (in d_ref)");
  }
  // Spheres padded by min_gap / 2 must themselves be packable at random: their solids fraction
  // may not exceed the random close packing limit. Exact for monodisperse packings; for the
  // others generate_random_packing checks it again with the drawn radii.
  if (distribution == SizeDistribution::kMonodisperse) {
    const double padded_phi = phi * std::pow(1.0 + min_gap, 3);
    if (padded_phi > kMaxRandomPhi) {
      return fail(error, "min_gap = " + format_number(min_gap) + " at phi = " + format_number(phi) +
                             " pads the spheres to a solids fraction " + format_number(padded_phi) +
                             " above " + format_number(kMaxRandomPhi) + "; need min_gap <= " +
                             format_number(std::cbrt(kMaxRandomPhi / phi) - 1.0));
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (!in_closed(aspect[a], 0.25, 4.0)) {
      return fail(error, "aspect[" + std::to_string(a) + "] = " + format_number(aspect[a]) +
                             " is outside [0.25, 4]");
    }
  }
  if (equilibration_sweeps < 0 || equilibration_sweeps > 10000000) {
    return fail(error, "equilibration_sweeps = " + std::to_string(equilibration_sweeps) +
                           " is outside [0, 10000000]");
  }
  if (!in_closed(max_crystalline_fraction, 0.0, 1.0)) {
    return fail(error, "max_crystalline_fraction = " + format_number(max_crystalline_fraction) +
                           " is outside [0, 1]");
  }
  if (max_attempts < 1 || max_attempts > 100) {
    return fail(error, "max_attempts = " + std::to_string(max_attempts) + " is outside [1, 100]");
  }
  return true;
}

bool OrderedPackingOptions::IsValid(std::string* error) const {
  const double limit = close_packing_phi(lattice);
  // The close-packing value itself is allowed (touching spheres); allow its last-bit rounding.
  if (!(phi > 0.0 && phi <= limit * (1.0 + 1e-15))) {
    return fail(error, "phi = " + format_number(phi) + " is outside (0, " + format_number(limit) +
                           "] (close packing of " + to_string(lattice) + ")");
  }
  if (cells < 1 || cells > 64) {
    return fail(error, "cells = " + std::to_string(cells) + " is outside [1, 64]");
  }
  return true;
}

std::string GenerationSummary::BriefReport() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%d attempt(s), %lld relaxation iterations, %lld MC sweeps (acceptance %.2f), "
                "Q6 %.3f, crystalline %.1f %%, %.2f s",
                attempts, relaxation_iterations, mc_sweeps, mc_acceptance, q6,
                100.0 * crystalline_fraction, wall_s);
  return buf;
}

std::string GenerationSummary::FullReport() const {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "attempts:               %d\n"
                "relaxation iterations:  %lld (FIRE, all attempts)\n"
                "MC sweeps:              %lld (all attempts)\n"
                "MC acceptance:          %.4f (fixed-step part of the last attempt)\n"
                "MC step:                %.6g d_ref (uniform in a cube of this half-edge)\n"
                "Q6:                     %.5f\n"
                "crystalline fraction:   %.5f\n"
                "wall time:              %.3f s\n",
                attempts, relaxation_iterations, mc_sweeps, mc_acceptance, mc_step, q6,
                crystalline_fraction, wall_s);
  return buf;
}

}  // namespace arrays
}  // namespace draglab
