// Resolution extrapolation, deterministic seeds, content hashes and the unit cost model.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "campaign_internal.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "draglab/lbm/lbm.h"

namespace draglab {
namespace campaign {
namespace internal {
namespace {

/// Indices of d sorted ascending (coarsest first).
std::vector<std::size_t> ascending(const std::vector<double>& d) {
  std::vector<std::size_t> idx(d.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&d](std::size_t a, std::size_t b) { return d[a] < d[b]; });
  return idx;
}

void check_inputs(const std::vector<double>& d, const std::vector<double>& F) {
  if (d.empty() || d.size() != F.size()) {
    throw Error(ErrorCode::kInternal, "extrapolation: need as many F values as resolutions (> 0)");
  }
}

}  // namespace

Extrapolation extrapolate_inverse_d(const std::vector<double>& d, const std::vector<double>& F) {
  check_inputs(d, F);
  const std::vector<std::size_t> idx = ascending(d);
  const double F_finest = F[idx.back()];
  Extrapolation e;
  if (d.size() == 1) {
    e.F_inf = F_finest;
    e.method = "finest";
    e.note = "one resolution: no extrapolation";
    return e;
  }
  // Least squares in x = 1/d: F = F_inf + a x.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double x = 1.0 / d[i];
    sx += x;
    sy += F[i];
    sxx += x * x;
    sxy += x * F[i];
  }
  const double a = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  e.F_inf = (sy - a * sx) / n;
  e.order = 1.0;
  e.method = "inverse_d";
  e.discretisation_error = std::fabs(e.F_inf - F_finest);
  return e;
}

Extrapolation extrapolate_richardson(const std::vector<double>& d, const std::vector<double>& F) {
  check_inputs(d, F);
  if (d.size() < 3) {
    Extrapolation e = extrapolate_inverse_d(d, F);
    if (d.size() == 2) e.note = "2 resolutions: richardson needs 3, used inverse_d";
    return e;
  }
  const std::vector<std::size_t> idx = ascending(d);
  const std::size_t m = idx.size();
  const double d1 = d[idx[m - 3]], d2 = d[idx[m - 2]], d3 = d[idx[m - 1]];
  const double F1 = F[idx[m - 3]], F2 = F[idx[m - 2]], F3 = F[idx[m - 1]];
  const double ratio = (F1 - F2) / (F2 - F3);
  // g(p) = (d1^-p - d2^-p)/(d2^-p - d3^-p) increases monotonically with p for d1 < d2 < d3.
  auto g = [&](double p) {
    return (std::pow(d1, -p) - std::pow(d2, -p)) / (std::pow(d2, -p) - std::pow(d3, -p));
  };
  double lo = 0.25, hi = 6.0;
  if (!(std::isfinite(ratio) && ratio > 0.0) || ratio < g(lo) || ratio > g(hi)) {
    Extrapolation e = extrapolate_inverse_d(d, F);
    e.note = "richardson: F(d) not monotone or order outside [0.25, 6]; used inverse_d";
    return e;
  }
  for (int it = 0; it < 200 && hi - lo > 1e-12; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) < ratio ? lo : hi) = mid;
  }
  const double p = 0.5 * (lo + hi);
  if (p < 0.5 || p > 4.0) {
    Extrapolation e = extrapolate_inverse_d(d, F);
    char buf[96];
    std::snprintf(buf, sizeof buf,
                  "richardson: measured order %.3g outside [0.5, 4]; used inverse_d", p);
    e.note = buf;
    return e;
  }
  Extrapolation e;
  e.order = p;
  e.F_inf = F3 - (F2 - F3) * std::pow(d3, -p) / (std::pow(d2, -p) - std::pow(d3, -p));
  e.method = "richardson";
  e.discretisation_error = std::fabs(e.F_inf - F3);
  return e;
}

std::uint64_t packing_seed(std::uint64_t spec_seed, int phi_index, int realization) {
  // splitmix64 finalizer over a combination that cannot collide for indices < 2^20.
  std::uint64_t z = spec_seed * 0x9E3779B97F4A7C15ull +
                    (static_cast<std::uint64_t>(phi_index) << 20) +
                    static_cast<std::uint64_t>(realization) + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return z & 0x7FFFFFFFFFFFFFFFull;
}

std::string packing_hash(const arrays::Packing& packing) {
  std::string text;
  char buf[64];
  auto add = [&](double x) {
    std::snprintf(buf, sizeof buf, "%.17g ", x);
    text += buf;
  };
  for (double l : packing.box_length) add(l);
  text += '\n';
  for (std::size_t i = 0; i < packing.size(); ++i) {
    for (double c : packing.centers[i]) add(c);
    add(2.0 * packing.radii[i]);
    text += '\n';
  }
  return draglab::sha256_hex(text);
}

double effective_min_gap(const CampaignSpec& spec) { return spec.min_gap; }

arrays::RandomPackingOptions packing_options(const CampaignSpec& spec, double phi,
                                             std::uint64_t seed) {
  arrays::RandomPackingOptions o;
  o.phi = phi;
  o.seed = seed;
  o.distribution = arrays::size_distribution_from_string(spec.distribution);
  o.size_ratio = spec.size_ratio;
  o.large_volume_fraction = spec.large_fraction;
  o.lognormal_sigma = spec.sigma;
  o.min_gap = effective_min_gap(spec);
  if (spec.box_size > 0.0) {
    // Sphere count whose total volume fills box_size^3 at phi (monodisperse count; the generator
    // then sets the exact box from the drawn volumes, so other distributions come out near it).
    const double n = phi * std::pow(spec.box_size, 3) / (M_PI / 6.0);
    o.n = std::max(1, static_cast<int>(std::lround(n)));
  } else {
    o.n = spec.spheres;
  }
  return o;
}

double unit_cost_estimate(const CampaignSpec& spec, double phi, double re, double resolution) {
  const int n = packing_options(spec, phi, 1).n;
  const double edge = std::cbrt(n * M_PI / (6.0 * phi));  // box edge in diameters
  const double fluid_nodes = std::pow(edge * resolution, 3) * (1.0 - phi);
  return fluid_nodes *
         lbm::predicted_steps(phi, re, resolution, lbm::collision_from_string(spec.collision));
}

}  // namespace internal
}  // namespace campaign
}  // namespace draglab
