// Statistics of a periodic sphere packing: exact phi, minimum surface gap, overlaps, the pair
// correlation g(x) of the contact-scaled distance x = r_ij / (r_i + r_j) and its contact value,
// and the Steinhardt bond-orientational order (global Q6, ten Wolde-Frenkel crystal criterion).
//
// Neighbours (bonds) for the bond order: pairs with x < x_c, where
//   x_c = (1 + sqrt 2)/2 * (phi_fcc / phi)^(1/3),  phi_fcc = sqrt(2) pi / 6.
// For a monodisperse packing, d (phi_fcc / phi)^(1/3) is the nearest-neighbour distance of the
// FCC crystal at the same number density, and (1 + sqrt 2)/2 puts the cutoff halfway between
// its first (12) and second (6, at sqrt 2 times the first) neighbour shells. The same cutoff
// keeps exactly the classic shells of the ordered lattices at any phi: 6 for SC, 8 + 6 for BCC,
// 12 for FCC (the shells behind the literature values Q6 = 0.3536, 0.5107, 0.5745), and it scales
// with the mean spacing of a fluid, giving about 12-14 neighbours at any density. For polydisperse
// packings the cutoff applies to x, i.e. the pair distance is measured in units of r_i + r_j.
//
// The cutoff also bounds the closest pair: if every pair (periodic images included) had
// x > x_c, balls of radius x_c r_i would be disjoint, so phi x_c^3 <= 1; but
// x_c^3 phi = 1.207^3 * 0.7405 = 1.30 > 1. Hence the pair of smallest x, and the smallest surface
// gap pair of the monodisperse case, always lies among the enumerated neighbours, and one cell-list
// pass (O(N)) gives the exact minimum gap for every box size (images are enumerated explicitly).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "cell_list.h"
#include "draglab/arrays/packing.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;
/// (1 + sqrt 2) / 2: halfway between the first and second FCC neighbour shells.
constexpr double kNeighbourShellFactor = 1.2071067811865475;
/// A pair counts as overlapping when its gap is below -kOverlapTolerance (r_i + r_j): touching
/// spheres of a close-packed lattice would otherwise count as overlapping through round-off.
constexpr double kOverlapTolerance = 1e-12;
/// ten Wolde-Frenkel criterion: a bond is "connected" if the normalised q6(i).q6(j) exceeds
/// kConnectionThreshold; a sphere is crystal-like with at least kMinConnections such bonds.
constexpr double kConnectionThreshold = 0.7;
constexpr int kMinConnections = 7;
/// Smallest N for which the loops run in parallel (below it, thread start-up and barriers on a
/// busy machine cost more than they save).
constexpr std::size_t kMinParallelSpheres = 8192;

using Q6Vector = std::array<std::complex<double>, 7>;  // m = 0..6; m < 0 follow by symmetry.

using core::format_number;

/// Spherical harmonics Y_6^m of the direction of v (|v| > 0), m = 0..6, orthonormal on the unit
/// sphere. Y_6^{-m} = (-1)^m conj(Y_6^m), so m >= 0 suffices for |q|^2 and q(i).q(j)*.
void add_y6(const Vec3& v, double length, Q6Vector* sum) {
  // sqrt((13 / 4 pi) (6 - m)! / (6 + m)!), m = 0..6.
  static const std::array<double, 7> kNorm = [] {
    std::array<double, 7> k{};
    for (int m = 0; m <= 6; ++m) {
      double ratio = 1.0;  // (6 - m)! / (6 + m)!
      for (int f = 6 - m + 1; f <= 6 + m; ++f) ratio /= f;
      k[m] = std::sqrt(13.0 / (4.0 * kPi) * ratio);
    }
    return k;
  }();
  const double z = v[2] / length;
  const std::complex<double> e(v[0] / length, v[1] / length);  // sin(theta) e^{i phi}
  std::complex<double> e_power(1.0, 0.0);
  double double_factorial = 1.0;  // (2m - 1)!!
  for (int m = 0; m <= 6; ++m) {
    if (m > 0) {
      e_power *= e;
      double_factorial *= (2 * m - 1);
    }
    // P_6^m(z) / sin^m(theta) by the upward recursion in l (Condon-Shortley phase omitted: it
    // is a per-m sign that cancels in every quantity computed here).
    double p_prev = double_factorial;  // l = m
    double p = p_prev;
    if (m < 6) {
      double p_cur = z * (2 * m + 1) * p_prev;  // l = m + 1
      for (int l = m + 2; l <= 6; ++l) {
        const double p_next = (z * (2 * l - 1) * p_cur - (l + m - 1) * p_prev) / (l - m);
        p_prev = p_cur;
        p_cur = p_next;
      }
      p = p_cur;
    }
    (*sum)[m] += kNorm[m] * p * e_power;
  }
}

/// sum over m = -6..6 of a_m conj(b_m), real part (the imaginary parts cancel).
double q6_dot(const Q6Vector& a, const Q6Vector& b) {
  double s = (a[0] * std::conj(b[0])).real();
  for (int m = 1; m <= 6; ++m) s += 2.0 * (a[m] * std::conj(b[m])).real();
  return s;
}

void check_options(const StatisticsOptions& o) {
  if (!(o.g_r_bin > 0.0 && o.g_r_bin <= 0.5)) {
    throw Error(ErrorCode::kInvalidArgument,
                "g_r_bin = " + format_number(o.g_r_bin) + " is outside (0, 0.5]");
  }
  if (!(o.contact_fit_width >= 2.0 * o.g_r_bin && o.contact_fit_width <= 1.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "contact_fit_width = " + format_number(o.contact_fit_width) +
                    " is outside [2 g_r_bin, 1] = [" + format_number(2.0 * o.g_r_bin) + ", 1]");
  }
  if (!(o.g_r_max >= 1.0 + o.contact_fit_width && o.g_r_max <= 20.0)) {
    throw Error(ErrorCode::kInvalidArgument, "g_r_max = " + format_number(o.g_r_max) +
                                                 " is outside [1 + contact_fit_width, 20] = [" +
                                                 format_number(1.0 + o.contact_fit_width) +
                                                 ", 20]");
  }
}

void check_packing(const Packing& p) {
  if (p.radii.empty()) throw Error(ErrorCode::kInvalidArgument, "packing has no spheres");
  if (p.centers.size() != p.radii.size()) {
    throw Error(ErrorCode::kInvalidArgument, "packing has " + std::to_string(p.centers.size()) +
                                                 " centres but " + std::to_string(p.radii.size()) +
                                                 " radii");
  }
  for (int a = 0; a < 3; ++a) {
    if (!(p.box_length[a] > 0.0 && std::isfinite(p.box_length[a]))) {
      throw Error(ErrorCode::kInvalidArgument, "box_length[" + std::to_string(a) +
                                                   "] = " + format_number(p.box_length[a]) +
                                                   " must be positive and finite");
    }
  }
  for (std::size_t i = 0; i < p.radii.size(); ++i) {
    if (!(p.radii[i] > 0.0 && std::isfinite(p.radii[i]))) {
      throw Error(ErrorCode::kInvalidArgument, "radius of sphere " + std::to_string(i) + " = " +
                                                   format_number(p.radii[i]) +
                                                   " must be positive and finite");
    }
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(p.centers[i][a])) {
        throw Error(ErrorCode::kInvalidArgument,
                    "centre of sphere " + std::to_string(i) + " is not finite");
      }
    }
  }
}

}  // namespace

double carnahan_starling_contact(double phi) {
  if (!(phi >= 0.0 && phi < 1.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "carnahan_starling_contact: phi = " + format_number(phi) + " is outside [0, 1)");
  }
  const double e = 1.0 - phi;
  return (1.0 - 0.5 * phi) / (e * e * e);
}

PackingStatistics compute_statistics(const Packing& packing, const StatisticsOptions& options) {
  check_options(options);
  check_packing(packing);

  const std::size_t n = packing.size();
  PackingStatistics stats;
  stats.n = n;
  stats.phi = packing.phi();

  // Centres wrapped into the box (files may hold centres on the upper edge or outside).
  std::vector<Vec3> centers(packing.centers);
  for (Vec3& c : centers) {
    for (int a = 0; a < 3; ++a) c[a] = internal::wrap_into_box(c[a], packing.box_length[a]);
  }
  const double r_max = *std::max_element(packing.radii.begin(), packing.radii.end());
  const double r_min = *std::min_element(packing.radii.begin(), packing.radii.end());
  const double fcc_phi = std::sqrt(2.0) * kPi / 6.0;
  const double x_cut = kNeighbourShellFactor * std::cbrt(fcc_phi / stats.phi);
  const double x_reach = std::max(x_cut, options.g_r_max);

  const int num_bins = static_cast<int>(std::ceil(options.g_r_max / options.g_r_bin - 1e-9));
  internal::PeriodicCellList cells(packing.box_length, 0.5 * x_reach * (r_min + r_max), n);
  cells.Build(centers);

  std::vector<Q6Vector> q(n);
  std::vector<std::vector<int>> bonds(n);  // Neighbour indices (a self-image appears as i).
  std::vector<double> min_gap(n, std::numeric_limits<double>::infinity());
  std::vector<long long> overlaps(n, 0);
  std::vector<long long> histogram(static_cast<std::size_t>(num_bins), 0);

#pragma omp parallel if (n >= kMinParallelSpheres)
  {
    std::vector<long long> local_histogram(static_cast<std::size_t>(num_bins), 0);
#pragma omp for schedule(dynamic, 64)
    for (long long ii = 0; ii < static_cast<long long>(n); ++ii) {
      const std::size_t i = static_cast<std::size_t>(ii);
      const Vec3& ci = centers[i];
      const double ri = packing.radii[i];
      Q6Vector qi{};
      double gap_i = std::numeric_limits<double>::infinity();
      long long overlaps_i = 0;
      cells.ForEachNear(ci, x_reach * (ri + r_max), [&](int j, const Vec3& shift) {
        const Vec3& cj = centers[static_cast<std::size_t>(j)];
        const Vec3 d{cj[0] + shift[0] - ci[0], cj[1] + shift[1] - ci[1], cj[2] + shift[2] - ci[2]};
        const double dist2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (static_cast<std::size_t>(j) == i && dist2 == 0.0) return;  // The sphere itself.
        const double sigma = ri + packing.radii[static_cast<std::size_t>(j)];
        const double dist = std::sqrt(dist2);
        const double gap = dist - sigma;
        gap_i = std::min(gap_i, gap);
        if (gap < -kOverlapTolerance * sigma) ++overlaps_i;
        const double x = dist / sigma;
        if (x < options.g_r_max) {
          const int bin = static_cast<int>(x / options.g_r_bin);
          if (bin < num_bins) ++local_histogram[static_cast<std::size_t>(bin)];
        }
        if (x < x_cut && dist > 0.0) {
          add_y6(d, dist, &qi);
          bonds[i].push_back(j);
        }
      });
      q[i] = qi;
      min_gap[i] = gap_i;
      overlaps[i] = overlaps_i;
    }
#pragma omp critical
    for (int b = 0; b < num_bins; ++b) histogram[b] += local_histogram[b];
  }

  // Each unordered pair (i, j, image) was seen from both ends.
  long long overlap_total = 0;
  double gap_total = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    overlap_total += overlaps[i];
    gap_total = std::min(gap_total, min_gap[i]);
  }
  stats.overlapping_pairs = static_cast<std::size_t>(overlap_total / 2);
  stats.min_gap = gap_total;

  // Global Q6: the average of Y_6m over all bonds (each bond seen from both ends adds the same
  // Y_6m, l being even), Q6 = sqrt(4 pi / 13 sum_m |Q_6m|^2).
  Q6Vector q_total{};
  long long bond_total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int m = 0; m <= 6; ++m) q_total[m] += q[i][m];
    bond_total += static_cast<long long>(bonds[i].size());
  }
  if (bond_total > 0) {
    for (auto& c : q_total) c /= static_cast<double>(bond_total);
    stats.q6 = std::sqrt(4.0 * kPi / 13.0 * q6_dot(q_total, q_total));
  }
  stats.mean_neighbours = static_cast<double>(bond_total) / static_cast<double>(n);

  // ten Wolde-Frenkel: q6m(i) = mean of Y_6m over the bonds of i, normalised to unit length.
  for (std::size_t i = 0; i < n; ++i) {
    const double norm2 = q6_dot(q[i], q[i]);
    if (norm2 > 0.0) {
      const double inv = 1.0 / std::sqrt(norm2);
      for (auto& c : q[i]) c *= inv;
    }
  }
  long long crystal_like = 0;
#pragma omp parallel for reduction(+ : crystal_like) schedule(static) if (n >= kMinParallelSpheres)
  for (long long ii = 0; ii < static_cast<long long>(n); ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    int connections = 0;
    for (int j : bonds[i]) {
      if (q6_dot(q[i], q[static_cast<std::size_t>(j)]) > kConnectionThreshold) ++connections;
    }
    if (connections >= kMinConnections) ++crystal_like;
  }
  stats.crystalline_fraction = static_cast<double>(crystal_like) / static_cast<double>(n);

  // g(x): pair counts over the ideal-gas expectation. For uncorrelated centres the number of pairs
  // with x in [a, b) is sum_{i<j} sigma_ij^3 (4 pi / 3)(b^3 - a^3) / V, sigma_ij = r_i + r_j.
  // For monodisperse spheres this is the usual g(r) with r in units of d (canonical N(N - 1)
  // normalisation); for polydisperse ones it is the sigma_ij^3-weighted mean of the partial
  // g_ab(x sigma_ab), so g(1+) is the weighted mean of the partial contact values.
  if (n >= 2) {
    long double s1 = 0.0L, s2 = 0.0L, s3 = 0.0L;
    for (double r : packing.radii) {
      s1 += r;
      s2 += static_cast<long double>(r) * r;
      s3 += static_cast<long double>(r) * r * r;
    }
    // sum_{i<j} (r_i + r_j)^3 = (1/2)[sum_i sum_j (r_i + r_j)^3 - sum_i (2 r_i)^3]
    //                         = (1/2)[2 N S3 + 6 S1 S2 - 8 S3].
    const long double nn = static_cast<long double>(n);
    const double pair_sigma3 =
        static_cast<double>(0.5L * (2.0L * nn * s3 + 6.0L * s1 * s2 - 8.0L * s3));
    stats.g_r_x.resize(static_cast<std::size_t>(num_bins));
    stats.g_r.resize(static_cast<std::size_t>(num_bins));
    for (int b = 0; b < num_bins; ++b) {
      const double lo = b * options.g_r_bin;
      const double hi = std::min((b + 1) * options.g_r_bin, options.g_r_max);
      const double ideal =
          pair_sigma3 * (4.0 * kPi / 3.0) * (hi * hi * hi - lo * lo * lo) / packing.box_volume();
      stats.g_r_x[b] = 0.5 * (lo + hi);
      stats.g_r[b] = 0.5 * static_cast<double>(histogram[b]) / ideal;
    }
    // Contact value: least-squares line through the bins lying inside [1, 1 + width],
    // evaluated at x = 1.
    double sw = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    for (int b = 0; b < num_bins; ++b) {
      const double lo = b * options.g_r_bin;
      const double hi = lo + options.g_r_bin;
      if (lo < 1.0 - 1e-9 || hi > 1.0 + options.contact_fit_width + 1e-9) continue;
      const double t = stats.g_r_x[b] - 1.0;
      sw += 1.0;
      sx += t;
      sy += stats.g_r[b];
      sxx += t * t;
      sxy += t * stats.g_r[b];
    }
    const double det = sw * sxx - sx * sx;
    if (sw >= 2.0 && det > 0.0) stats.g_contact = (sxx * sy - sx * sxy) / det;
  }
  return stats;
}

}  // namespace arrays
}  // namespace draglab
