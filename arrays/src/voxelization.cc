// Voxelization of a periodic sphere packing: solid flags, per-sphere boundary links and the exact
// wall fractions q for interpolated bounce-back.
//
// All geometry is done in lattice units (lengths divided by dx), where node (i, j, k) sits at
// (i + 1/2, j + 1/2, k + 1/2) and the D3Q19 velocities are integer vectors. Each sphere is visited
// through the unwrapped integer node coordinates of its bounding box; the vector from the sphere
// centre to an unwrapped node is then the vector to the periodic image of that node, so no
// minimum-image search is needed and spheres crossing the box faces need no special case. Only
// the flag array is indexed with wrapped coordinates.
//
// Pass 1 (parallel over spheres) sets the solid flags; pass 2 (parallel over spheres, after all
// flags are known) visits each sphere's solid nodes near its surface and emits a link for every
// D3Q19 neighbour that is fluid. Both passes classify a node with the same arithmetic
// (for_each_inside_node and add_square), so a node is solid in pass 1 exactly when pass 2 counts
// it as inside.
#include "draglab/arrays/voxelization.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cell_list.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace draglab {
namespace arrays {
namespace {

constexpr double kMinResolution = 2.0;
constexpr double kMaxResolution = 1024.0;
/// Relative tolerance for "the edge is a whole number of nodes".
constexpr double kEdgeTolerance = 1e-9;
constexpr double kMaxNodes = 1099511627776.0;  // 2^40
/// Brute-force pair search up to this many spheres in min_gap_lattice_units.
constexpr std::size_t kBruteForcePairsUpTo = 5000;
/// Below these sizes a parallel region costs more than it saves (thread wake-up is ~10 us on an
/// idle machine and a scheduler time slice when the cores are busy).
constexpr std::int64_t kParallelMinNodes = std::int64_t{1} << 20;  ///< Byte-per-node loops.
constexpr std::int64_t kParallelMinWork = std::int64_t{1} << 15;   ///< Bounding-box nodes.
constexpr std::size_t kParallelMinSpheres = 2000;
/// Seconds between progress reports.
constexpr double kProgressInterval = 0.2;

// Flag bits while voxelizing; only kSolidBit survives into VoxelGrid::solid.
constexpr std::uint8_t kSolidBit = 1;
constexpr std::uint8_t kSharedBit = 2;  ///< Inside more than one sphere (overlap or rounding).

std::string number(double x) { return core::format_number(x, 12); }

[[noreturn]] void invalid(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

/// w * w + acc, evaluated identically wherever a node is classified. With a fused multiply-add
/// in hardware the compiler could otherwise contract some call sites and not others, and a node
/// at the surface could then be solid in one pass and fluid in the other.
inline double add_square(double w, double acc) {
#if defined(FP_FAST_FMA)
  return std::fma(w, w, acc);
#else
  return w * w + acc;
#endif
}

inline std::int64_t wrap(std::int64_t i, std::int64_t n) {
  const std::int64_t r = i % n;
  return r < 0 ? r + n : r;
}

/// Node counts and spacing of the lattice for a box and a requested resolution.
struct LatticeShape {
  std::array<std::int64_t, 3> n{0, 0, 0};
  double dx = 0.0;
};

/// True if x_nodes nodes along edge 0 give a whole number of nodes along edges 1 and 2.
bool whole_node_counts(const Vec3& box, double x_nodes) {
  for (int a = 1; a < 3; ++a) {
    const double exact = x_nodes * box[a] / box[0];
    const double rounded = std::round(exact);
    if (rounded < 1.0 || std::abs(exact - rounded) > kEdgeTolerance * exact) return false;
  }
  return true;
}

/// The valid resolutions nearest to the requested one (below and above), as text.
std::string nearest_valid_resolutions(const Vec3& box, double x_nodes) {
  const double lowest = std::max(1.0, std::ceil(kMinResolution * box[0]));
  const double highest = std::floor(kMaxResolution * box[0]);
  // The search is bounded: 2^22 node counts on each side take well under a second.
  constexpr double kMaxSteps = 4194304.0;
  double below = 0.0;
  for (double m = x_nodes - 1.0; m >= lowest && x_nodes - m <= kMaxSteps; m -= 1.0) {
    if (whole_node_counts(box, m)) {
      below = m;
      break;
    }
  }
  double above = 0.0;
  for (double m = x_nodes + 1.0; m <= highest && m - x_nodes <= kMaxSteps; m += 1.0) {
    if (whole_node_counts(box, m)) {
      above = m;
      break;
    }
  }
  if (below == 0.0 && above == 0.0) {
    return "no resolution in [" + number(kMinResolution) + ", " + number(kMaxResolution) +
           "] near the requested one fits all edges (edge ratios box_length[1]/box_length[0] = " +
           number(box[1] / box[0]) + ", box_length[2]/box_length[0] = " + number(box[2] / box[0]) +
           ")";
  }
  std::string text = "nearest valid resolutions:";
  if (below > 0.0) text += " " + number(below / box[0]);
  if (below > 0.0 && above > 0.0) text += " and";
  if (above > 0.0) text += " " + number(above / box[0]);
  return text;
}

LatticeShape lattice_shape(const Vec3& box, double resolution) {
  LatticeShape shape;
  const double x_nodes = std::round(box[0] * resolution);
  if (x_nodes < 1.0) {
    invalid("voxelize: box_length[0] = " + number(box[0]) + " is shorter than half a node at " +
            "resolution " + number(resolution) + "; use a resolution of at least " +
            number(1.0 / box[0]));
  }
  const double dx = box[0] / x_nodes;
  double total = x_nodes;
  shape.n[0] = static_cast<std::int64_t>(x_nodes);
  for (int a = 1; a < 3; ++a) {
    const double exact = box[a] / dx;
    const double rounded = std::round(exact);
    if (rounded < 1.0 || std::abs(exact - rounded) > kEdgeTolerance * exact) {
      invalid("voxelize: box_length[" + std::to_string(a) + "] = " + number(box[a]) +
              " is not a whole number of nodes at resolution " + number(resolution) + " (" +
              number(x_nodes) + " nodes along box_length[0] = " + number(box[0]) +
              " give dx = " + number(dx) + " and " + number(exact) + " nodes along edge " +
              std::to_string(a) + "; whole within " + number(kEdgeTolerance) +
              " relative is required); " + nearest_valid_resolutions(box, x_nodes));
    }
    shape.n[a] = static_cast<std::int64_t>(rounded);
    total *= rounded;
  }
  if (total > kMaxNodes) {
    invalid("voxelize: the lattice would have " + number(total) + " nodes (" +
            std::to_string(shape.n[0]) + " x " + std::to_string(shape.n[1]) + " x " +
            std::to_string(shape.n[2]) + "), more than the limit 2^40; lower the resolution");
  }
  shape.dx = dx;
  return shape;
}

/// Checks what the lattice geometry relies on; `caller` prefixes the messages.
void validate_packing(const Packing& packing, const std::string& caller) {
  for (int a = 0; a < 3; ++a) {
    const double length = packing.box_length[a];
    if (!std::isfinite(length) || length <= 0.0) {
      invalid(caller + ": box_length[" + std::to_string(a) + "] = " + number(length) +
              " must be finite and > 0");
    }
  }
  if (packing.centers.size() != packing.radii.size()) {
    invalid(caller + ": packing has " + std::to_string(packing.centers.size()) + " centers but " +
            std::to_string(packing.radii.size()) + " radii");
  }
  const double shortest_edge =
      std::min({packing.box_length[0], packing.box_length[1], packing.box_length[2]});
  for (std::size_t s = 0; s < packing.size(); ++s) {
    const double r = packing.radii[s];
    if (!std::isfinite(r) || r <= 0.0 || 2.0 * r > shortest_edge) {
      invalid(caller + ": radii[" + std::to_string(s) + "] = " + number(r) + " must be in (0, " +
              number(0.5 * shortest_edge) +
              "] (half the shortest box edge; a larger sphere would overlap its own periodic "
              "image)");
    }
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(packing.centers[s][a])) {
        invalid(caller + ": centers[" + std::to_string(s) + "][" + std::to_string(a) +
                "] is not finite");
      }
    }
  }
}

/// A sphere in lattice units with the unwrapped node ranges that can lie inside it.
struct LatticeSphere {
  std::array<double, 3> center{};  ///< In [0, n) per axis.
  double radius = 0.0;
  double radius_squared = 0.0;
  /// Nodes closer to the centre than this (squared) have all 18 neighbours inside the sphere.
  double deep_squared = -1.0;
  std::array<std::int64_t, 3> lo{}, hi{};  ///< Inclusive unwrapped node ranges.
};

LatticeSphere lattice_sphere(const Vec3& center, double radius, const LatticeShape& shape) {
  LatticeSphere sphere;
  sphere.radius = radius / shape.dx;
  sphere.radius_squared = sphere.radius * sphere.radius;
  // A neighbour is at most sqrt(2) away; the margin keeps rounding from ever claiming a node
  // deep whose neighbour the flag pass saw as outside.
  const double deep = sphere.radius - std::sqrt(2.0) - 1e-6;
  if (deep > 0.0) sphere.deep_squared = deep * deep;
  for (int a = 0; a < 3; ++a) {
    const double n = static_cast<double>(shape.n[a]);
    double c = std::fmod(center[a] / shape.dx, n);
    if (c < 0.0) c += n;
    sphere.center[a] = c;
    // Nodes strictly inside satisfy |i + 1/2 - c| < radius; the range is padded by one node
    // against rounding, the exact test is done per node.
    auto lo = static_cast<std::int64_t>(std::floor(c - sphere.radius - 0.5));
    auto hi = static_cast<std::int64_t>(std::ceil(c + sphere.radius - 0.5));
    // Window of n consecutive nodes centred on the sphere: every node strictly inside a sphere
    // of radius <= n/2 lies in it, so no node is visited twice through two of its images.
    const auto window_lo = static_cast<std::int64_t>(std::ceil(c - 0.5 * n - 0.5));
    lo = std::max(lo, window_lo);
    hi = std::min(hi, window_lo + shape.n[a] - 1);
    sphere.lo[a] = lo;
    sphere.hi[a] = hi;
  }
  return sphere;
}

/// A node strictly inside a sphere, with its wrapped coordinates and the vector from the centre.
struct InsideNode {
  std::int64_t index;
  std::int64_t i, j, k;  ///< Wrapped coordinates.
  double wx, wy, wz;     ///< Node minus centre, lattice units.
  double distance_squared;
};

/// Calls visit(InsideNode) for every node strictly inside the sphere, z slowest, x fastest.
template <typename Visit>
void for_each_inside_node(const LatticeSphere& sphere, const LatticeShape& shape, Visit&& visit) {
  const std::int64_t nx = shape.n[0], ny = shape.n[1], nz = shape.n[2];
  const double r2 = sphere.radius_squared;
  for (std::int64_t k = sphere.lo[2]; k <= sphere.hi[2]; ++k) {
    const double wz = static_cast<double>(k) + 0.5 - sphere.center[2];
    const double z_part = wz * wz;
    if (!(z_part < r2)) continue;
    const std::int64_t kw = wrap(k, nz);
    for (std::int64_t j = sphere.lo[1]; j <= sphere.hi[1]; ++j) {
      const double wy = static_cast<double>(j) + 0.5 - sphere.center[1];
      const double yz_part = add_square(wy, z_part);
      if (!(yz_part < r2)) continue;  // every x adds a non-negative square
      const std::int64_t jw = wrap(j, ny);
      const std::int64_t row = nx * (jw + ny * kw);
      std::int64_t iw = wrap(sphere.lo[0], nx);
      for (std::int64_t i = sphere.lo[0]; i <= sphere.hi[0]; ++i) {
        const double wx = static_cast<double>(i) + 0.5 - sphere.center[0];
        const double d2 = add_square(wx, yz_part);
        if (d2 < r2) visit(InsideNode{row + iw, iw, jw, kw, wx, wy, wz, d2});
        if (++iw == nx) iw = 0;
      }
    }
  }
}

/// Wall fraction of the link from a fluid node at w (relative to the centre, lattice units)
/// along the integer velocity c into a sphere of squared radius r2 that contains w + c.
///
/// |w + t c|^2 = r^2 is a t^2 + 2 b t + g = 0 with a = |c|^2, b = w.c, g = |w|^2 - r^2. The
/// fluid node is outside (g >= 0) and the solid node inside (a + 2b + g < 0), so b < -a/2 < 0
/// and the entry root t = (-b - sqrt(b^2 - a g)) / a lies in [0, 1). It is evaluated as
/// t = g / (-b + sqrt(b^2 - a g)), which has no cancellation (both terms of the denominator are
/// >= 0, and -b > 1/2), unlike the textbook form when g is small (node near the surface).
double wall_fraction(double wx, double wy, double wz, const std::array<int, 3>& c, double r2) {
  const double a = static_cast<double>(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  const double b = wx * c[0] + wy * c[1] + wz * c[2];
  const double g = (wx * wx + wy * wy + wz * wz) - r2;
  const double discriminant = std::max(0.0, b * b - a * g);
  const double denominator = std::sqrt(discriminant) - b;
  double t = denominator > 0.0 ? g / denominator : 0.0;
  // Rounding near the degenerate ends (g ~ 0: fluid node on the surface; solid node just
  // inside) is clamped into (0, 1]; see the header for why q = 0 becomes kMinLinkFraction.
  if (!(t >= kMinLinkFraction)) t = kMinLinkFraction;
  if (t > 1.0) t = 1.0;
  return t;
}

/// An image of a sphere whose surface comes within one link of another sphere's surface: its
/// index, its centre relative to that sphere's centre and its squared radius (lattice units).
struct NearSphere {
  std::int64_t index;
  double ox, oy, oz;
  double radius_squared;
};

/// For each sphere, the images of the spheres (its own other images included) whose surface gap
/// to it is below one D3Q19 link (sqrt 2 lattice spacings): the only surfaces a boundary link of
/// that sphere can cross before its own. Fills the pair part of `gaps`.
std::vector<std::vector<NearSphere>> near_spheres(const Packing& packing, const LatticeShape& shape,
                                                  GapSummary* gaps) {
  const std::size_t n = packing.size();
  std::vector<std::vector<NearSphere>> near(n);
  gaps->narrow_pairs = 0;
  gaps->smallest_gap_nodes = std::numeric_limits<double>::infinity();
  if (n == 0) return near;
  const double link = std::sqrt(2.0) * shape.dx * (1.0 + 1e-9);
  const double largest_radius = *std::max_element(packing.radii.begin(), packing.radii.end());
  std::vector<Vec3> centers(n);
  for (std::size_t s = 0; s < n; ++s) {
    for (int a = 0; a < 3; ++a) {
      centers[s][a] = internal::wrap_into_box(packing.centers[s][a], packing.box_length[a]);
    }
  }
  internal::PeriodicCellList cells(packing.box_length, 2.0 * largest_radius + link, n);
  cells.Build(centers);
  for (std::size_t s = 0; s < n; ++s) {
    const double reach = packing.radii[s] + largest_radius + link;
    cells.ForEachNear(centers[s], reach, [&](int j, const Vec3& shift) {
      const bool self = static_cast<std::size_t>(j) == s;
      if (self && shift[0] == 0.0 && shift[1] == 0.0 && shift[2] == 0.0) return;
      Vec3 offset;
      double distance2 = 0.0;
      for (int a = 0; a < 3; ++a) {
        offset[a] = centers[static_cast<std::size_t>(j)][a] + shift[a] - centers[s][a];
        distance2 += offset[a] * offset[a];
      }
      const double rj = packing.radii[static_cast<std::size_t>(j)];
      const double gap = std::sqrt(distance2) - packing.radii[s] - rj;
      if (!(gap < link)) return;
      near[s].push_back({j, offset[0] / shape.dx, offset[1] / shape.dx, offset[2] / shape.dx,
                         (rj / shape.dx) * (rj / shape.dx)});
      // Each unordered pair of images once: from its lower index, or (own images) from the
      // image whose shift is lexicographically positive.
      const bool first =
          self ? (shift[0] != 0.0 ? shift[0] > 0.0
                                  : (shift[1] != 0.0 ? shift[1] > 0.0 : shift[2] > 0.0))
               : static_cast<std::size_t>(j) > s;
      if (first) {
        gaps->smallest_gap_nodes = std::min(gaps->smallest_gap_nodes, gap / shape.dx);
        if (gap < shape.dx) ++gaps->narrow_pairs;
      }
    });
  }
  return near;
}

/// Where a link from a fluid node at w (relative to the owner's centre, lattice units) along c
/// first enters one of the near spheres, if before `best` (the owner's wall fraction): updates
/// best and the sphere that owns the link. Same root formula as wall_fraction.
void first_crossing(double wx, double wy, double wz, const std::array<int, 3>& c,
                    const std::vector<NearSphere>& near, double* best, std::int64_t* owner) {
  const double a = static_cast<double>(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  for (const NearSphere& other : near) {
    const double x = wx - other.ox, y = wy - other.oy, z = wz - other.oz;
    const double b = x * c[0] + y * c[1] + z * c[2];
    if (!(b < 0.0)) continue;  // moving away from that centre: no entry ahead
    const double g = (x * x + y * y + z * z) - other.radius_squared;
    const double discriminant = b * b - a * g;
    if (!(discriminant >= 0.0)) continue;  // the line misses it
    double t = g > 0.0 ? g / (std::sqrt(discriminant) - b) : 0.0;
    if (!(t >= kMinLinkFraction)) t = kMinLinkFraction;
    if (t < *best) {
      *best = t;
      *owner = other.index;
    }
  }
}

/// Fluid nodes with solid nodes on both sides along some D3Q19 direction.
std::int64_t count_narrow_fluid_nodes(const VoxelGrid& grid, std::int64_t* fluid) {
  const std::int64_t nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  std::int64_t narrow = 0, fluid_count = 0;
  const std::uint8_t* solid = grid.solid.data();
#pragma omp parallel for reduction(+ : narrow, fluid_count) if (grid.num_nodes() > kParallelMinNodes)
  for (std::int64_t k = 0; k < nz; ++k) {
    for (std::int64_t j = 0; j < ny; ++j) {
      for (std::int64_t i = 0; i < nx; ++i) {
        if (solid[i + nx * (j + ny * k)]) continue;
        ++fluid_count;
        for (int q = 1; q < kD3Q19; q += 2) {
          const auto& c = kD3Q19Velocities[q];
          const std::int64_t f =
              wrap(i + c[0], nx) + nx * (wrap(j + c[1], ny) + ny * wrap(k + c[2], nz));
          const std::int64_t b =
              wrap(i - c[0], nx) + nx * (wrap(j - c[1], ny) + ny * wrap(k - c[2], nz));
          if (solid[f] && solid[b]) {
            ++narrow;
            break;
          }
        }
      }
    }
  }
  *fluid = fluid_count;
  return narrow;
}

/// Links ordered by fluid node, then direction: one integer comparison (nodes < 2^40), and a
/// function object so that std::sort inlines it.
struct LinkOrder {
  static std::uint64_t key(const BoundaryLink& link) {
    return (link.fluid_node << 5) | link.direction;
  }
  bool operator()(const BoundaryLink& a, const BoundaryLink& b) const { return key(a) < key(b); }
};

/// Rank of a wrapped coordinate among the wrapped images of an unwrapped range [a, b], in
/// increasing wrapped order. With it a sphere's links are sorted by node index with two
/// counting-sort passes instead of comparisons (the sort was a third of the run time).
class AxisRank {
 public:
  AxisRank(std::int64_t a, std::int64_t b, std::int64_t n) : size_(b - a + 1) {
    if (size_ >= n) {  // every wrapped value occurs: rank = value
      size_ = n;
      return;
    }
    start_ = wrap(a, n);
    crossing_ = start_ + size_ > n;
    last_low_ = start_ + size_ - 1 - n;  // with crossing_: values 0..last_low_ come first
  }
  std::int64_t size() const { return size_; }
  std::int64_t operator()(std::int64_t w) const {
    if (!crossing_) return w - start_;
    return w <= last_low_ ? w : w - start_ + last_low_ + 1;
  }

 private:
  std::int64_t size_;
  std::int64_t start_ = 0;
  bool crossing_ = false;
  std::int64_t last_low_ = -1;
};

/// A link while its sphere is being processed, with its sort keys: row = rank of the fluid
/// node's (z, y) line, column = rank of its x coordinate * 32 + direction.
struct PendingLink {
  BoundaryLink link;
  std::uint32_t row;
  std::uint32_t column;
};

/// Stable counting sort of `links` by column, then by row: the result is ordered by fluid node
/// index, then direction. Returns the sorted links.
std::vector<BoundaryLink> sort_links(const std::vector<PendingLink>& links, std::uint32_t num_rows,
                                     std::uint32_t num_columns) {
  const std::size_t count = links.size();
  std::vector<std::uint32_t> by_column(count), by_row(count);
  std::vector<std::uint32_t> start(std::max(num_rows, num_columns) + 1);
  auto counting_pass = [&](auto key, const std::uint32_t* input, std::uint32_t* output,
                           std::uint32_t num_keys) {
    std::fill(start.begin(), start.begin() + num_keys + 1, 0u);
    for (std::size_t m = 0; m < count; ++m) ++start[key(input ? input[m] : m) + 1];
    for (std::uint32_t k = 0; k < num_keys; ++k) start[k + 1] += start[k];
    for (std::size_t m = 0; m < count; ++m) {
      const std::uint32_t item = input ? input[m] : static_cast<std::uint32_t>(m);
      output[start[key(item)]++] = item;
    }
  };
  counting_pass([&](std::size_t m) { return links[m].column; }, nullptr, by_column.data(),
                num_columns);
  counting_pass([&](std::size_t m) { return links[m].row; }, by_column.data(), by_row.data(),
                num_rows);
  std::vector<BoundaryLink> sorted(count);
  for (std::size_t m = 0; m < count; ++m) sorted[m] = links[by_row[m]].link;
  return sorted;
}

/// Calls progress for one stage at most every kProgressInterval seconds (and always at 0 and 1).
class ThrottledProgress {
 public:
  ThrottledProgress(const ProgressCallback& progress, std::string stage)
      : progress_(progress), stage_(std::move(stage)) {
    if (progress_) progress_(0.0, stage_);
    last_ = std::chrono::steady_clock::now();
  }
  void report(double fraction) {
    if (!progress_) return;
    const auto now = std::chrono::steady_clock::now();
    if (fraction >= 1.0 ||
        std::chrono::duration<double>(now - last_).count() >= kProgressInterval) {
      progress_(std::min(fraction, 1.0), stage_);
      last_ = now;
    }
  }

 private:
  const ProgressCallback& progress_;
  std::string stage_;
  std::chrono::steady_clock::time_point last_;
};

/// Nodes in the bounding boxes of all spheres: the work of one pass.
std::int64_t total_box_nodes(const std::vector<LatticeSphere>& spheres) {
  std::int64_t nodes = 0;
  for (const LatticeSphere& sphere : spheres) {
    nodes += (sphere.hi[0] - sphere.lo[0] + 1) * (sphere.hi[1] - sphere.lo[1] + 1) *
             (sphere.hi[2] - sphere.lo[2] + 1);
  }
  return nodes;
}

/// Runs body(s) for every sphere, in parallel (dynamic schedule: sphere sizes differ) when
/// `parallel`. Progress is reported by the calling thread (OpenMP thread 0) as it finishes
/// spheres, so there is no barrier per block. An exception from the progress callback (for
/// example a cancellation) stops the remaining spheres and is rethrown here; `body` must not
/// throw.
template <typename Body>
void for_each_sphere(std::int64_t num_spheres, bool parallel, ThrottledProgress& throttle,
                     Body&& body) {
  static_cast<void>(parallel);  // only read by the OpenMP pragma
  std::atomic<std::int64_t> finished{0};
  std::atomic<bool> cancelled{false};
  std::exception_ptr failure;
#pragma omp parallel if (parallel)
  {
#if defined(_OPENMP)
    const bool reporter = omp_get_thread_num() == 0;
#else
    const bool reporter = true;
#endif
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t s = 0; s < num_spheres; ++s) {
      if (cancelled.load(std::memory_order_relaxed)) continue;
      body(s);
      const std::int64_t done = finished.fetch_add(1, std::memory_order_relaxed) + 1;
      if (reporter && done < num_spheres) {
        try {
          throttle.report(static_cast<double>(done) / static_cast<double>(num_spheres));
        } catch (...) {
          failure = std::current_exception();
          cancelled.store(true, std::memory_order_relaxed);
        }
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
  throttle.report(1.0);
}

/// Minimum-image centre distance between spheres i and j.
double center_distance(const Packing& packing, std::size_t i, std::size_t j) {
  double sum = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double length = packing.box_length[a];
    double d = packing.centers[j][a] - packing.centers[i][a];
    d -= length * std::round(d / length);
    sum += d * d;
  }
  return std::sqrt(sum);
}

double min_gap_brute_force(const Packing& packing) {
  double gap = std::numeric_limits<double>::infinity();
  const std::size_t n = packing.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      gap = std::min(gap, center_distance(packing, i, j) - packing.radii[i] - packing.radii[j]);
    }
  }
  return gap;
}

/// Cell-list search over centre distances up to `cutoff`; returns +inf if no pair is that close
/// or if the box has fewer than 3 cells along an axis (the caller then uses brute force).
double min_gap_cell_list(const Packing& packing, double cutoff) {
  std::array<std::int64_t, 3> cells{};
  for (int a = 0; a < 3; ++a) {
    cells[a] = static_cast<std::int64_t>(std::floor(packing.box_length[a] / cutoff));
    if (cells[a] < 3) return std::numeric_limits<double>::infinity();
    cells[a] = std::min<std::int64_t>(cells[a], 1024);
  }
  const std::size_t n = packing.size();
  std::vector<std::array<std::int64_t, 3>> cell_of(n);
  std::vector<std::int64_t> cell_index(n);
  for (std::size_t s = 0; s < n; ++s) {
    for (int a = 0; a < 3; ++a) {
      const double u = packing.centers[s][a] / packing.box_length[a];
      const auto c = static_cast<std::int64_t>(std::floor((u - std::floor(u)) * cells[a]));
      cell_of[s][a] = std::min(c, cells[a] - 1);
    }
    cell_index[s] = cell_of[s][0] + cells[0] * (cell_of[s][1] + cells[1] * cell_of[s][2]);
  }
  // Spheres sorted by cell; start[c] .. start[c + 1] are the members of cell c.
  const std::int64_t num_cells = cells[0] * cells[1] * cells[2];
  std::vector<std::size_t> start(static_cast<std::size_t>(num_cells) + 1, 0);
  for (std::size_t s = 0; s < n; ++s) ++start[static_cast<std::size_t>(cell_index[s]) + 1];
  for (std::int64_t c = 0; c < num_cells; ++c) start[c + 1] += start[c];
  std::vector<std::size_t> members(n);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t s = 0; s < n; ++s) members[fill[cell_index[s]]++] = s;
  }
  double gap = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(dynamic, 256) reduction(min : gap) if (n > kParallelMinSpheres)
  for (std::int64_t si = 0; si < static_cast<std::int64_t>(n); ++si) {
    const auto i = static_cast<std::size_t>(si);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const std::int64_t cx = wrap(cell_of[i][0] + dx, cells[0]);
          const std::int64_t cy = wrap(cell_of[i][1] + dy, cells[1]);
          const std::int64_t cz = wrap(cell_of[i][2] + dz, cells[2]);
          const std::int64_t c = cx + cells[0] * (cy + cells[1] * cz);
          for (std::size_t m = start[c]; m < start[c + 1]; ++m) {
            const std::size_t j = members[m];
            if (j <= i) continue;
            const double d = center_distance(packing, i, j);
            if (d <= cutoff) gap = std::min(gap, d - packing.radii[i] - packing.radii[j]);
          }
        }
      }
    }
  }
  return gap;
}

}  // namespace

bool VoxelizationOptions::IsValid(std::string* error) const {
  if (!std::isfinite(resolution) || resolution < kMinResolution || resolution > kMaxResolution) {
    if (error) {
      *error = "resolution = " + number(resolution) + " must be in [" + number(kMinResolution) +
               ", " + number(kMaxResolution) + "] lattice units per reference diameter";
    }
    return false;
  }
  return true;
}

double VoxelGrid::phi_lattice() const {
  if (solid.empty()) return 0.0;
  std::int64_t count = 0;
  const auto size = static_cast<std::int64_t>(solid.size());
#pragma omp parallel for reduction(+ : count) if (size > kParallelMinNodes)
  for (std::int64_t p = 0; p < size; ++p) count += solid[p];
  return static_cast<double>(count) / static_cast<double>(size);
}

std::size_t VoxelGrid::num_links() const {
  std::size_t total = 0;
  for (const auto& sphere_links : links) total += sphere_links.size();
  return total;
}

std::size_t VoxelGrid::memory_bytes() const {
  std::size_t bytes = solid.capacity() * sizeof(std::uint8_t) +
                      links.capacity() * sizeof(std::vector<BoundaryLink>);
  for (const auto& sphere_links : links) bytes += sphere_links.capacity() * sizeof(BoundaryLink);
  return bytes;
}

VoxelGrid voxelize(const Packing& packing, const VoxelizationOptions& options,
                   const ProgressCallback& progress) {
  std::string error;
  if (!options.IsValid(&error)) invalid("voxelize: " + error);
  validate_packing(packing, "voxelize");
  const LatticeShape shape = lattice_shape(packing.box_length, options.resolution);

  VoxelGrid grid;
  grid.dims = shape.n;
  grid.dx = shape.dx;
  grid.solid.assign(static_cast<std::size_t>(grid.num_nodes()), 0);
  const std::int64_t num_spheres = static_cast<std::int64_t>(packing.size());
  grid.links.resize(packing.size());
  grid.diameters.resize(packing.size());
  for (std::size_t s = 0; s < packing.size(); ++s) grid.diameters[s] = 2.0 * packing.radii[s];

  std::vector<LatticeSphere> spheres(packing.size());
  for (std::size_t s = 0; s < packing.size(); ++s) {
    spheres[s] = lattice_sphere(packing.centers[s], packing.radii[s], shape);
  }
  const bool parallel = num_spheres > 1 && total_box_nodes(spheres) > kParallelMinWork;
  std::uint8_t* const flags = grid.solid.data();

  // Pass 1: solid flags. A node found already solid is marked shared; ownership of shared nodes
  // is settled after pass 2, deterministically.
  std::atomic<bool> any_shared{false};
  {
    ThrottledProgress throttle(progress, "voxelize: solid nodes");
    for_each_sphere(num_spheres, parallel, throttle, [&](std::int64_t s) {
      for_each_inside_node(spheres[s], shape, [&](const InsideNode& node) {
        std::uint8_t before;
#pragma omp atomic capture
        {
          before = flags[node.index];
          flags[node.index] |= kSolidBit;
        }
        if (before & kSolidBit) {
#pragma omp atomic update
          flags[node.index] |= kSharedBit;
          any_shared.store(true, std::memory_order_relaxed);
        }
      });
    });
  }

  // Pass 2: links. Shared nodes are set aside with the spheres that contain them.
  const bool has_shared = any_shared.load();
  std::vector<std::vector<std::int64_t>> shared_nodes(has_shared ? packing.size() : 0);
  // A link kept aside: of a shared solid node (kept only by that node's owner), or one whose
  // first surface crossing is another sphere's (`target`).
  struct AsideLink {
    std::int64_t solid_node;
    std::int64_t target;
    BoundaryLink link;
  };
  std::vector<std::vector<AsideLink>> shared_links(shared_nodes.size());
  std::vector<std::vector<AsideLink>> foreign_links(packing.size());
  const std::vector<std::vector<NearSphere>> near = near_spheres(packing, shape, &grid.gaps);
  {
    ThrottledProgress throttle(progress, "voxelize: boundary links");
    const std::int64_t nx = shape.n[0], ny = shape.n[1], nz = shape.n[2];
    for_each_sphere(num_spheres, parallel, throttle, [&](std::int64_t s) {
      const LatticeSphere& sphere = spheres[s];
      // Fluid nodes of this sphere's links lie within one node of its solid nodes.
      const AxisRank rank_i(sphere.lo[0] - 1, sphere.hi[0] + 1, nx);
      const AxisRank rank_j(sphere.lo[1] - 1, sphere.hi[1] + 1, ny);
      const AxisRank rank_k(sphere.lo[2] - 1, sphere.hi[2] + 1, nz);
      std::vector<PendingLink> pending;
      // About 72 R^2 links for a sphere of radius R lattice units (a surface count).
      pending.reserve(static_cast<std::size_t>(80.0 * sphere.radius_squared) + 64);
      for_each_inside_node(sphere, shape, [&](const InsideNode& node) {
        if (node.distance_squared < sphere.deep_squared) return;
        const bool shared = has_shared && (flags[node.index] & kSharedBit) != 0;
        if (shared) shared_nodes[s].push_back(node.index);
        for (int q = 1; q < kD3Q19; ++q) {
          const auto& c = kD3Q19Velocities[q];
          // Fluid node x = y - c (wrapped); the link runs from x along c into y.
          std::int64_t xi = node.i - c[0], xj = node.j - c[1], xk = node.k - c[2];
          xi += xi < 0 ? nx : (xi >= nx ? -nx : 0);
          xj += xj < 0 ? ny : (xj >= ny ? -ny : 0);
          xk += xk < 0 ? nz : (xk >= nz ? -nz : 0);
          const std::int64_t x_index = xi + nx * (xj + ny * xk);
          if (flags[x_index] & kSolidBit) continue;
          BoundaryLink link;
          link.fluid_node = static_cast<std::uint64_t>(x_index);
          link.direction = static_cast<std::uint8_t>(q);
          const double fx = node.wx - c[0], fy = node.wy - c[1], fz = node.wz - c[2];
          link.q = wall_fraction(fx, fy, fz, c, sphere.radius_squared);
          std::int64_t target = s;
          if (!near[s].empty()) first_crossing(fx, fy, fz, c, near[s], &link.q, &target);
          if (shared) {
            shared_links[s].push_back({node.index, target, link});
          } else if (target != s) {
            foreign_links[s].push_back({node.index, target, link});
          } else {
            pending.push_back({link,
                               static_cast<std::uint32_t>(rank_k(xk) * rank_j.size() + rank_j(xj)),
                               static_cast<std::uint32_t>(rank_i(xi) * 32 + q)});
          }
        }
      });
      grid.links[s] = sort_links(pending, static_cast<std::uint32_t>(rank_k.size() * rank_j.size()),
                                 static_cast<std::uint32_t>(rank_i.size() * 32));
    });
  }

  // Links whose wall is on another sphere, and links of shared nodes kept by their owner (the
  // lowest-index sphere that contains the node), move to the sphere they belong to.
  std::vector<char> touched(packing.size(), 0);
  for (std::int64_t s = 0; s < num_spheres; ++s) {
    for (const AsideLink& aside : foreign_links[s]) {
      grid.links[aside.target].push_back(aside.link);
      touched[aside.target] = 1;
    }
  }
  if (has_shared) {
    std::vector<std::pair<std::int64_t, std::int64_t>> node_owner;  // (node, sphere)
    for (std::int64_t s = 0; s < num_spheres; ++s) {
      for (std::int64_t node : shared_nodes[s]) node_owner.emplace_back(node, s);
    }
    std::sort(node_owner.begin(), node_owner.end());
    for (std::int64_t s = 0; s < num_spheres; ++s) {
      for (const AsideLink& aside : shared_links[s]) {
        const auto owner = std::lower_bound(node_owner.begin(), node_owner.end(),
                                            std::make_pair(aside.solid_node, std::int64_t{-1}));
        if (owner != node_owner.end() && owner->first == aside.solid_node && owner->second == s) {
          grid.links[aside.target].push_back(aside.link);
          touched[aside.target] = 1;
        }
      }
    }
    const std::int64_t num_nodes = grid.num_nodes();
#pragma omp parallel for if (num_nodes > kParallelMinNodes)
    for (std::int64_t p = 0; p < num_nodes; ++p) flags[p] &= kSolidBit;
  }
  for (std::size_t s = 0; s < packing.size(); ++s) {
    if (!touched[s]) continue;
    std::sort(grid.links[s].begin(), grid.links[s].end(), LinkOrder());
    grid.links[s].shrink_to_fit();
  }
  grid.gaps.narrow_fluid_nodes = count_narrow_fluid_nodes(grid, &grid.gaps.fluid_nodes);
  return grid;
}

double min_gap_lattice_units(const Packing& packing, double resolution) {
  if (!std::isfinite(resolution) || resolution <= 0.0) {
    invalid("min_gap_lattice_units: resolution = " + number(resolution) +
            " must be finite and > 0 (lattice units per reference diameter)");
  }
  validate_packing(packing, "min_gap_lattice_units");
  const std::size_t n = packing.size();
  if (n == 0) return std::numeric_limits<double>::infinity();
  // A sphere and its own nearest periodic image (one box edge away) also bound the gap.
  const double shortest_edge =
      std::min({packing.box_length[0], packing.box_length[1], packing.box_length[2]});
  const double largest_radius = *std::max_element(packing.radii.begin(), packing.radii.end());
  double gap = shortest_edge - 2.0 * largest_radius;
  if (n <= kBruteForcePairsUpTo) {
    gap = std::min(gap, min_gap_brute_force(packing));
  } else {
    // Pairs with centres further apart than the cutoff have gaps above cutoff - 2 r_max; if the
    // closest pair within the cutoff beats that, it is the global minimum.
    const double spacing = std::cbrt(packing.box_volume() / static_cast<double>(n));
    const double cutoff = 2.0 * largest_radius + spacing;
    const double near_gap = min_gap_cell_list(packing, cutoff);
    if (near_gap <= cutoff - 2.0 * largest_radius) {
      gap = std::min(gap, near_gap);
    } else {
      gap = std::min(gap, min_gap_brute_force(packing));
    }
  }
  return gap * resolution;
}

}  // namespace arrays
}  // namespace draglab
