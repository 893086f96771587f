// Voxelization of periodic sphere packings (voxelization.h).
//
// Set-up: spheres in periodic boxes, lattice nodes at (i + 1/2) dx; a node is solid when its
// centre is strictly inside a sphere; a boundary link runs from a fluid node x along a D3Q19
// velocity c into a solid node, with wall fraction q: the wall point x + q c dx is the first
// surface the link enters (of any sphere image), and the link belongs to that sphere.
//
// References, all independent of the code under test:
//  - q on analytic cases from hand-solved ray-sphere intersections, e.g. from the node at
//    (a, b, z) relative to the centre along c = (-1, -1, 0):
//        (a - t)^2 + (b - t)^2 + z^2 = R^2  =>  t = [(a + b) - sqrt(2 R^2 - (a - b)^2 - 2 z^2)]
//        / 2.
//  - For general links: the wall point must lie on the sphere surface and the ray must be
//    entering there (a backward-error check, well conditioned even for grazing links), and the
//    links must be exactly the (fluid, solid) neighbour pairs of the flags, each once.
//  - Solid volume: the number N of lattice points inside a ball of radius R (lattice units)
//    placed at a uniformly random offset has mean exactly V = 4/3 pi R^3 and variance
//        Var N = sum_{xi in Z^3, xi != 0} |chi(xi)|^2,  chi(xi) = 4 pi R^3 j1(z) / z,
//    z = 2 pi R |xi| (Parseval over the offset; chi is the Fourier transform of the ball,
//    j1 the spherical Bessel function). For large R, j1(z) ~ -cos(z)/z gives
//        Var N ~ R^2 / (2 pi^2) * Z(4),  Z(4) = sum |xi|^-4 = 16.53  =>  sd N ~ 0.915 R,
//    a surface effect with random signs, so the RMS relative error of the solid volume is
//        RMS (N - V)/V ~ 0.915 R / (4/3 pi R^3) = 0.874 (d/dx)^-2,
//    i.e. slope -2 in log-log against the resolution d/dx. The test evaluates the exact series
//    (shell sums up to |xi| = 40 plus the asymptotic tail) for each sampled radius.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;

Packing make_packing(const Vec3& box, std::vector<Vec3> centers, std::vector<double> radii) {
  Packing packing;
  packing.box_length = box;
  packing.centers = std::move(centers);
  packing.radii = std::move(radii);
  return packing;
}

/// Exact solids fraction, computed here rather than through Packing::phi().
double exact_phi(const Packing& packing) {
  double volume = 0.0;
  for (double r : packing.radii) volume += 4.0 / 3.0 * kPi * r * r * r;
  return volume / (packing.box_length[0] * packing.box_length[1] * packing.box_length[2]);
}

/// Simple cubic arrangement of m[0] x m[1] x m[2] spheres of diameter 1 at spacing a, each
/// displaced by a random vector in a cube of half-width h; h <= (a - 1)/(2 sqrt 3) keeps every
/// pair apart. The whole arrangement is shifted by a random offset.
Packing jittered_cubic(const std::array<int, 3>& m, double a, double h, std::uint64_t seed,
                       double diameter = 1.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Packing packing;
  packing.box_length = {m[0] * a, m[1] * a, m[2] * a};
  const Vec3 offset{unit(rng) * a, unit(rng) * a, unit(rng) * a};
  for (int k = 0; k < m[2]; ++k) {
    for (int j = 0; j < m[1]; ++j) {
      for (int i = 0; i < m[0]; ++i) {
        Vec3 c{(i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a};
        for (int d = 0; d < 3; ++d) {
          c[d] += offset[d] + h * (2.0 * unit(rng) - 1.0);
          c[d] = std::fmod(c[d], packing.box_length[d]);
          if (c[d] < 0.0) c[d] += packing.box_length[d];
        }
        packing.centers.push_back(c);
        packing.radii.push_back(0.5 * diameter);
      }
    }
  }
  return packing;
}

std::int64_t wrap(std::int64_t i, std::int64_t n) { return ((i % n) + n) % n; }

std::array<std::int64_t, 3> coordinates(const VoxelGrid& grid, std::int64_t index) {
  return {index % grid.dims[0], (index / grid.dims[0]) % grid.dims[1],
          index / (grid.dims[0] * grid.dims[1])};
}

std::int64_t neighbour(const VoxelGrid& grid, std::int64_t index, int direction) {
  const auto x = coordinates(grid, index);
  const auto& c = kD3Q19Velocities[direction];
  return grid.index(wrap(x[0] + c[0], grid.dims[0]), wrap(x[1] + c[1], grid.dims[1]),
                    wrap(x[2] + c[2], grid.dims[2]));
}

/// Minimum-image vector from sphere s's centre to node `index`, in lattice units.
std::array<double, 3> node_minus_center(const Packing& packing, const VoxelGrid& grid,
                                        std::size_t s, std::int64_t index) {
  const auto x = coordinates(grid, index);
  std::array<double, 3> w{};
  for (int a = 0; a < 3; ++a) {
    const double n = static_cast<double>(grid.dims[a]);
    double d = (static_cast<double>(x[a]) + 0.5) - packing.centers[s][a] / grid.dx;
    d -= n * std::round(d / n);
    w[a] = d;
  }
  return w;
}

double norm(const std::array<double, 3>& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

bool inside(const Packing& packing, const VoxelGrid& grid, std::size_t s, std::int64_t index) {
  const double radius = packing.radii[s] / grid.dx;
  return norm(node_minus_center(packing, grid, s, index)) < radius;
}

/// The link of sphere s from `fluid_node` along `direction`, or nullptr.
const BoundaryLink* find_link(const VoxelGrid& grid, std::size_t s, std::int64_t fluid_node,
                              int direction) {
  for (const BoundaryLink& link : grid.links[s]) {
    if (link.fluid_node == static_cast<std::uint64_t>(fluid_node) && link.direction == direction) {
      return &link;
    }
  }
  return nullptr;
}

/// Where the segment from fluid node x along c (lattice units, t in [0, 1]) first enters sphere
/// s through any of its 27 nearest periodic images: brute force, +infinity if it does not.
double entry_fraction(const Packing& packing, const VoxelGrid& grid, std::size_t s, std::int64_t x,
                      int direction) {
  const auto& c = kD3Q19Velocities[direction];
  const auto w0 = node_minus_center(packing, grid, s, x);
  const double r = packing.radii[s] / grid.dx;
  const double a = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  double best = std::numeric_limits<double>::infinity();
  for (int kz = -1; kz <= 1; ++kz) {
    for (int ky = -1; ky <= 1; ++ky) {
      for (int kx = -1; kx <= 1; ++kx) {
        const double wx = w0[0] + kx * static_cast<double>(grid.dims[0]);
        const double wy = w0[1] + ky * static_cast<double>(grid.dims[1]);
        const double wz = w0[2] + kz * static_cast<double>(grid.dims[2]);
        const double b = wx * c[0] + wy * c[1] + wz * c[2];
        const double g = wx * wx + wy * wy + wz * wz - r * r;
        const double disc = b * b - a * g;
        if (disc < 0.0 || b >= 0.0) continue;
        const double t = g <= 0.0 ? 0.0 : (-b - std::sqrt(disc)) / a;
        if (t <= 1.0 + 1e-12) best = std::min(best, t);
      }
    }
  }
  return best;
}

/// Every structural property of a voxelization, against brute-force geometry:
///  - flags are 0/1 and equal "strictly inside some sphere" at every node;
///  - each sphere's links are sorted by (fluid node, direction) without repeats;
///  - every link runs from a fluid node into a solid node, with q in (0, 1];
///  - q is the first surface entry along the link over all spheres and images (brute force),
///    and the link belongs to a sphere entered there;
///  - every (fluid node, direction) pair with a solid neighbour has exactly one link.
void expect_consistent(const Packing& packing, const VoxelGrid& grid) {
  const std::int64_t num_nodes = grid.num_nodes();
  ASSERT_EQ(grid.solid.size(), static_cast<std::size_t>(num_nodes));
  ASSERT_EQ(grid.links.size(), packing.size());
  std::vector<std::int32_t> owner(num_nodes, -1);
  for (std::int64_t p = 0; p < num_nodes; ++p) {
    for (std::size_t s = 0; s < packing.size(); ++s) {
      if (inside(packing, grid, s, p)) {
        owner[p] = static_cast<std::int32_t>(s);
        break;
      }
    }
    ASSERT_EQ(grid.solid[p], owner[p] >= 0 ? 1 : 0) << "node " << p;
  }
  // Surface tolerance: lattice coordinates below 2^8 carry rounding <= 2^-44 ~ 6e-14 each, so
  // the wall point's distance to the surface is exact to ~1e-13; 1e-11 leaves two orders.
  constexpr double kSurfaceTolerance = 1e-11;
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(num_nodes) * kD3Q19, 0);
  for (std::size_t s = 0; s < packing.size(); ++s) {
    const double radius = packing.radii[s] / grid.dx;
    const auto& links = grid.links[s];
    for (std::size_t l = 0; l < links.size(); ++l) {
      const BoundaryLink& link = links[l];
      if (l > 0) {
        const BoundaryLink& prev = links[l - 1];
        ASSERT_TRUE(prev.fluid_node < link.fluid_node ||
                    (prev.fluid_node == link.fluid_node && prev.direction < link.direction))
            << "sphere " << s << " link " << l << " out of order";
      }
      ASSERT_GE(link.direction, 1);
      ASSERT_LT(link.direction, kD3Q19);
      const auto x = static_cast<std::int64_t>(link.fluid_node);
      ASSERT_LT(x, num_nodes);
      const std::int64_t y = neighbour(grid, x, link.direction);
      ASSERT_EQ(grid.solid[x], 0) << "link from a solid node";
      ASSERT_GE(owner[y], 0) << "link into a fluid node";
      ASSERT_GT(link.q, 0.0);
      ASSERT_LE(link.q, 1.0);
      double first = std::numeric_limits<double>::infinity();
      for (std::size_t t = 0; t < packing.size(); ++t) {
        first = std::min(first, entry_fraction(packing, grid, t, x, link.direction));
      }
      // Wall fractions near 0 are stored as kMinLinkFraction.
      first = std::max(first, kMinLinkFraction);
      EXPECT_NEAR(link.q, first, kSurfaceTolerance) << "sphere " << s << " link " << l;
      EXPECT_NEAR(std::max(entry_fraction(packing, grid, s, x, link.direction), kMinLinkFraction),
                  link.q, kSurfaceTolerance)
          << "sphere " << s << " link " << l << " is not on its own sphere's surface";
      (void)radius;
      std::uint8_t& mark = seen[static_cast<std::size_t>(x) * kD3Q19 + link.direction];
      ASSERT_EQ(mark, 0) << "duplicate link";
      mark = 1;
    }
  }
  for (std::int64_t x = 0; x < num_nodes; ++x) {
    if (grid.solid[x]) continue;
    for (int q = 1; q < kD3Q19; ++q) {
      const bool to_solid = grid.solid[neighbour(grid, x, q)] != 0;
      ASSERT_EQ(seen[static_cast<std::size_t>(x) * kD3Q19 + q], to_solid ? 1 : 0)
          << "node " << x << " direction " << q;
    }
  }
}

// ---- options and input errors -------------------------------------------------------------------

TEST(Voxelization, RejectsResolutionOutsideItsRange) {
  for (double resolution : {1.9, 1025.0, std::nan(""), -3.0}) {
    VoxelizationOptions options;
    options.resolution = resolution;
    std::string error;
    EXPECT_FALSE(options.IsValid(&error));
    EXPECT_NE(error.find("resolution"), std::string::npos) << error;
    EXPECT_NE(error.find("[2, 1024]"), std::string::npos) << error;
    try {
      voxelize(make_packing({4, 4, 4}, {{2, 2, 2}}, {0.5}), options);
      ADD_FAILURE() << "no error for resolution " << resolution;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    }
  }
  VoxelizationOptions good;
  EXPECT_TRUE(good.IsValid(nullptr));
}

TEST(Voxelization, RejectsMalformedPackings) {
  VoxelizationOptions options;
  const std::vector<Packing> bad = {
      make_packing({4, 4, 4}, {{2, 2, 2}}, {-0.5}),            // negative radius
      make_packing({4, 4, 4}, {{2, 2, 2}}, {2.01}),            // overlaps its own image
      make_packing({4, 4, 4}, {{2, std::nan(""), 2}}, {0.5}),  // centre not finite
      make_packing({4, 4, 4}, {{2, 2, 2}, {1, 1, 1}}, {0.5}),  // sizes differ
      make_packing({4, 0, 4}, {{2, 0, 2}}, {0.5}),             // empty box edge
  };
  const std::vector<std::string> field = {"radii[0]", "radii[0]", "centers[0][1]", "radii",
                                          "box_length[1]"};
  for (std::size_t b = 0; b < bad.size(); ++b) {
    try {
      voxelize(bad[b], options);
      ADD_FAILURE() << "case " << b << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(field[b]), std::string::npos) << e.what();
    }
  }
}

TEST(Voxelization, BoxEdgesMustBeWholeNodeCounts) {
  // Box 1 x 1.5 x 1 at resolution 5: 5 nodes along x give dx = 0.2 and 7.5 nodes along y.
  // Valid resolutions are the even ones (1.5 r whole): the nearest are 4 and 6.
  const Packing packing = make_packing({1.0, 1.5, 1.0}, {{0.5, 0.5, 0.5}}, {0.3});
  VoxelizationOptions options;
  options.resolution = 5.0;
  try {
    voxelize(packing, options);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(message.find("box_length[1]"), std::string::npos) << message;
    EXPECT_NE(message.find("nearest valid resolutions: 4 and 6"), std::string::npos) << message;
  }
  options.resolution = 6.0;
  const VoxelGrid grid = voxelize(packing, options);
  EXPECT_EQ(grid.dims, (std::array<std::int64_t, 3>{6, 9, 6}));
  EXPECT_DOUBLE_EQ(grid.dx, 1.0 / 6.0);
  // A requested resolution is rounded to a whole node count along x: 5.9 -> 6 nodes.
  options.resolution = 5.9;
  EXPECT_EQ(voxelize(packing, options).dims, grid.dims);
  // An edge off by 1e-6 relative is not a whole number of nodes at any nearby resolution.
  const Packing skewed = make_packing({1.0, 1.5 * (1 + 1e-6), 1.0}, {{0.5, 0.5, 0.5}}, {0.3});
  options.resolution = 6.0;
  EXPECT_THROW(voxelize(skewed, options), Error);
  // ... but 1e-11 relative is within the tolerance (1e-9): round-off in a box built from phi.
  const Packing rounded = make_packing({1.0, 1.5 * (1 + 1e-11), 1.0}, {{0.5, 0.5, 0.5}}, {0.3});
  EXPECT_EQ(voxelize(rounded, options).dims, grid.dims);
}

// ---- q on analytic cases ------------------------------------------------------------------------

// Box 4 d_ref at resolution 16: 64^3 nodes, dx = 1/16. All coordinates below are exact binary
// fractions, so the analytic values are compared to 1e-12 (the arithmetic on lattice
// coordinates below 2^7 is exact to ~1e-14; q's conditioning is O(1) for these links).
constexpr double kExactQ = 1e-12;

TEST(Voxelization, QExactForSphereCentredOnANode) {
  // Radius 0.45 d_ref = 7.2 lattice units, centre on node (32, 32, 32).
  const double centre = 32.5 / 16.0;
  const Packing packing = make_packing({4, 4, 4}, {{centre, centre, centre}}, {0.45});
  VoxelizationOptions options;
  options.resolution = 16.0;
  const VoxelGrid grid = voxelize(packing, options);
  ASSERT_EQ(grid.dims, (std::array<std::int64_t, 3>{64, 64, 64}));
  const double R = 7.2;
  auto node = [&](int a, int b, int c) { return grid.index(32 + a, 32 + b, 32 + c); };
  // Axis links: node 8 away along an axis is outside (8 > 7.2), node 7 inside: q = 8 - R.
  struct Case {
    std::array<int, 3> offset;
    int direction;
    double q;
  };
  const std::vector<Case> cases = {
      {{8, 0, 0}, 2, 8 - R},
      {{-8, 0, 0}, 1, 8 - R},
      {{0, 0, -8}, 5, 8 - R},
      // Off-axis line y = 3: (x - t)^2 + 9 = R^2 from x = 7 (58 > 51.84) -> t = 7 - sqrt(R^2-9).
      {{7, 3, 0}, 2, 7 - std::sqrt(R * R - 9)},
      // Diagonal c = (-1, -1, 0) from (6, 5, 0): t = [(a+b) - sqrt(2R^2 - (a-b)^2 - 2z^2)] / 2.
      {{6, 5, 0}, 8, (11 - std::sqrt(2 * R * R - 1)) / 2},
      {{2, 5, 5}, 8, (7 - std::sqrt(2 * R * R - 9 - 50)) / 2},
      // Diagonal c = (0, 1, -1) from (1, -4, 6): (-4 + t)^2 + (6 - t)^2 + 1 = R^2.
      {{1, -4, 6}, 17, (10 - std::sqrt(2 * R * R - 4 - 2)) / 2},
  };
  for (const Case& c : cases) {
    const std::int64_t x = node(c.offset[0], c.offset[1], c.offset[2]);
    ASSERT_EQ(grid.solid[x], 0);
    ASSERT_EQ(grid.solid[neighbour(grid, x, c.direction)], 1);
    const BoundaryLink* link = find_link(grid, 0, x, c.direction);
    ASSERT_NE(link, nullptr) << "offset " << c.offset[0] << "," << c.offset[1] << ","
                             << c.offset[2];
    EXPECT_NEAR(link->q, c.q, kExactQ);
  }
  // Symmetry: the 48 cube symmetries about a node map the link set onto itself, so each
  // axis direction has the same number of links (the number of lattice lines through the
  // sphere's cross-section), and so does each diagonal direction.
  std::array<int, kD3Q19> per_direction{};
  for (const BoundaryLink& link : grid.links[0]) ++per_direction[link.direction];
  for (int q = 2; q <= 6; ++q) EXPECT_EQ(per_direction[q], per_direction[1]);
  for (int q = 8; q <= 18; ++q) EXPECT_EQ(per_direction[q], per_direction[7]);
  // Axis lines through a disc of radius 7.2 centred on a lattice line: integer (y, z) with
  // y^2 + z^2 < 51.84, counted here directly.
  int lines = 0;
  for (int y = -8; y <= 8; ++y) {
    for (int z = -8; z <= 8; ++z) lines += (y * y + z * z < R * R) ? 1 : 0;
  }
  EXPECT_EQ(per_direction[1], lines);
  expect_consistent(packing, grid);
}

TEST(Voxelization, QExactForSphereCentredBetweenNodes) {
  // Centre on a lattice-cell corner (2.0, 2.0, 2.0) = lattice coordinate 32: nodes sit at
  // half-integer offsets. Radius 7.2 lattice units.
  const Packing packing = make_packing({4, 4, 4}, {{2.0, 2.0, 2.0}}, {0.45});
  VoxelizationOptions options;
  options.resolution = 16.0;
  const VoxelGrid grid = voxelize(packing, options);
  const double R = 7.2;
  // Node with offset (7.5, 0.5, 0.5) is grid node (39, 32, 32): |w|^2 = 56.75 > R^2 = 51.84.
  // Along -x: (7.5 - t)^2 + 0.5 = R^2 -> t = 7.5 - sqrt(R^2 - 0.5).
  const std::int64_t x1 = grid.index(39, 32, 32);
  const BoundaryLink* axis = find_link(grid, 0, x1, 2);
  ASSERT_NE(axis, nullptr);
  EXPECT_NEAR(axis->q, 7.5 - std::sqrt(R * R - 0.5), kExactQ);
  // Node offset (5.5, 5.5, -0.5) = grid (37, 37, 31): 60.75 > 51.84; along (-1, -1, 0):
  // 2 (5.5 - t)^2 + 0.25 = R^2 -> t = 5.5 - sqrt((R^2 - 0.25) / 2).
  const std::int64_t x2 = grid.index(37, 37, 31);
  const BoundaryLink* diagonal = find_link(grid, 0, x2, 8);
  ASSERT_NE(diagonal, nullptr);
  EXPECT_NEAR(diagonal->q, 5.5 - std::sqrt((R * R - 0.25) / 2), kExactQ);
  expect_consistent(packing, grid);
}

TEST(Voxelization, NodeOnTheSurfaceIsFluidWithWallAtTheNode) {
  // Radius 0.5 d_ref = 8 lattice units centred on a node: the six axis nodes 8 away lie
  // exactly on the surface (exact binary arithmetic). They are fluid; every link from them
  // into the sphere has its wall at the fluid node itself, q = 0, stored as kMinLinkFraction.
  const double centre = 32.5 / 16.0;
  const Packing packing = make_packing({4, 4, 4}, {{centre, centre, centre}}, {0.5});
  VoxelizationOptions options;
  options.resolution = 16.0;
  const VoxelGrid grid = voxelize(packing, options);
  const std::int64_t x = grid.index(40, 32, 32);  // offset (8, 0, 0)
  EXPECT_EQ(grid.solid[x], 0);
  EXPECT_EQ(grid.solid[grid.index(39, 32, 32)], 1);
  // Inward directions from (8, 0, 0): -x (2), (-1,-1,0) (8), (-1,1,0) (10), (-1,0,-1) (12),
  // (-1,0,1) (14). Sideways/outward directions find fluid or no sphere crossing.
  for (int direction : {2, 8, 10, 12, 14}) {
    const BoundaryLink* link = find_link(grid, 0, x, direction);
    ASSERT_NE(link, nullptr) << direction;
    EXPECT_EQ(link->q, kMinLinkFraction) << direction;
  }
  for (int direction : {1, 3, 4, 5, 6, 7, 9, 11, 13, 15, 16, 17, 18}) {
    EXPECT_EQ(find_link(grid, 0, x, direction), nullptr) << direction;
  }
  expect_consistent(packing, grid);

  // Just inside the surface by 2^-30 lattice units (radius 8 + 2^-30): the axis node is now
  // solid and the link from offset 9 has q = 1 - 2^-30, below 1 as required.
  const Packing grown =
      make_packing({4, 4, 4}, {{centre, centre, centre}}, {0.5 + std::ldexp(1.0, -34)});
  const VoxelGrid grown_grid = voxelize(grown, options);
  EXPECT_EQ(grown_grid.solid[x], 1);
  const BoundaryLink* near_one = find_link(grown_grid, 0, grown_grid.index(41, 32, 32), 2);
  ASSERT_NE(near_one, nullptr);
  EXPECT_NEAR(near_one->q, 1.0 - std::ldexp(1.0, -30), kExactQ);
  EXPECT_LT(near_one->q, 1.0);

  // Just outside by 2^-30 (radius 8 - 2^-30): the wall is 2^-30 from the fluid node. The
  // stable form resolves it (absolute error ~1e-15, far below the value ~9.3e-10).
  const Packing shrunk =
      make_packing({4, 4, 4}, {{centre, centre, centre}}, {0.5 - std::ldexp(1.0, -34)});
  const VoxelGrid shrunk_grid = voxelize(shrunk, options);
  const BoundaryLink* near_zero = find_link(shrunk_grid, 0, x, 2);
  ASSERT_NE(near_zero, nullptr);
  EXPECT_NEAR(near_zero->q, std::ldexp(1.0, -30), 1e-14);
}

// ---- periodic wrap-around and cuboid boxes ------------------------------------------------------

TEST(Voxelization, SphereAcrossTheBoxCornerGivesTheShiftedLinks) {
  // The same sphere centred in the box and shifted by (-32, -31, -33) nodes so that it
  // straddles all three pairs of faces near a corner. Centres are exact binary fractions, so
  // the lattice-unit geometry is identical up to the integer shift and the links must agree
  // exactly after mapping the node indices.
  VoxelizationOptions options;
  options.resolution = 16.0;
  const Vec3 middle{(32 + 0.3125) / 16.0, (31 + 0.71875) / 16.0, (33 + 0.0625) / 16.0};
  const Vec3 corner{0.3125 / 16.0, 0.71875 / 16.0, 0.0625 / 16.0};
  const std::array<int, 3> shift{32, 31, 33};
  const double radius = 0.437;
  const VoxelGrid a = voxelize(make_packing({4, 4, 4}, {middle}, {radius}), options);
  const VoxelGrid b = voxelize(make_packing({4, 4, 4}, {corner}, {radius}), options);
  ASSERT_EQ(a.num_links(), b.num_links());
  std::map<std::pair<std::int64_t, int>, double> shifted;
  for (const BoundaryLink& link : b.links[0]) {
    const auto x = coordinates(b, static_cast<std::int64_t>(link.fluid_node));
    const std::int64_t moved =
        a.index((x[0] + shift[0]) % 64, (x[1] + shift[1]) % 64, (x[2] + shift[2]) % 64);
    shifted[{moved, link.direction}] = link.q;
  }
  for (const BoundaryLink& link : a.links[0]) {
    const auto it = shifted.find({static_cast<std::int64_t>(link.fluid_node), link.direction});
    ASSERT_NE(it, shifted.end());
    EXPECT_EQ(it->second, link.q);
  }
  EXPECT_EQ(a.phi_lattice(), b.phi_lattice());
  expect_consistent(make_packing({4, 4, 4}, {corner}, {radius}), b);
}

TEST(Voxelization, CuboidBoxAndSphereTouchingItsOwnImage) {
  VoxelizationOptions options;
  options.resolution = 10.0;
  // Cuboid 2 x 3 x 1.5 -> 20 x 30 x 15 nodes; a sphere crossing the z faces, one crossing x.
  const Packing cuboid =
      make_packing({2.0, 3.0, 1.5}, {{1.03, 1.51, 1.45}, {0.07, 0.4, 0.6}}, {0.5, 0.31});
  const VoxelGrid grid = voxelize(cuboid, options);
  EXPECT_EQ(grid.dims, (std::array<std::int64_t, 3>{20, 30, 15}));
  expect_consistent(cuboid, grid);
  // A sphere of diameter equal to the box edge touches its own images: it must be covered
  // once, not twice through two images, with all invariants intact.
  const Packing touching = make_packing({1.0, 1.0, 1.0}, {{0.513, 0.27, 0.9}}, {0.5});
  expect_consistent(touching, voxelize(touching, options));
}

TEST(Voxelization, OverlappingSpheresShareNothing) {
  // Not a valid packing, but the output must stay well defined: nodes inside both spheres
  // belong to the lower index, and no link appears twice.
  const Packing overlap = make_packing(
      {4, 4, 4}, {{2.0, 2.0, 2.0}, {2.61, 2.13, 1.95}, {3.9, 0.1, 0.2}}, {0.45, 0.4, 0.3});
  VoxelizationOptions options;
  options.resolution = 12.0;
  const VoxelGrid grid = voxelize(overlap, options);
  expect_consistent(overlap, grid);
}

// ---- a multi-sphere packing at 64^3 -------------------------------------------------------------

TEST(Voxelization, JitteredPacking64CubedIsConsistentAndDeterministic) {
  // 4^3 spheres of diameter 1 at spacing 1.25 (phi = 0.268), jitter up to the non-overlap
  // limit, resolution 12.8 -> 64^3 nodes.
  const Packing packing = jittered_cubic({4, 4, 4}, 1.25, 0.25 / (2 * std::sqrt(3.0)), 7);
  VoxelizationOptions options;
  options.resolution = 12.8;
  const auto start = std::chrono::steady_clock::now();
  const VoxelGrid grid = voxelize(packing, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("voxelize_64cubed_seconds", std::to_string(seconds));
  ASSERT_EQ(grid.dims, (std::array<std::int64_t, 3>{64, 64, 64}));
  expect_consistent(packing, grid);
  // Repeat runs (with however many threads) give bit-identical output.
  const VoxelGrid again = voxelize(packing, options);
  EXPECT_EQ(again.solid, grid.solid);
  ASSERT_EQ(again.links.size(), grid.links.size());
  for (std::size_t s = 0; s < grid.links.size(); ++s) {
    ASSERT_EQ(again.links[s].size(), grid.links[s].size());
    for (std::size_t l = 0; l < grid.links[s].size(); ++l) {
      EXPECT_EQ(again.links[s][l].fluid_node, grid.links[s][l].fluid_node);
      EXPECT_EQ(again.links[s][l].direction, grid.links[s][l].direction);
      EXPECT_EQ(again.links[s][l].q, grid.links[s][l].q);
    }
  }
  // memory_bytes counts at least the flags and the link payload.
  EXPECT_GE(grid.memory_bytes(), grid.solid.size() + grid.num_links() * sizeof(BoundaryLink));
}

TEST(Voxelization, LatticeSolidFractionMatchesExactPhi) {
  // 5 x 4 x 3 spheres (cuboid box) at resolution 16. Each sphere's node count deviates from its
  // volume by an independent error of sd ~0.915 R = 7.3 nodes (header); the sum over 60 spheres
  // has sd 7.3 sqrt(60) = 57 nodes. Tolerance 5 sd on the count, divided by the node count.
  const Packing packing = jittered_cubic({5, 4, 3}, 1.25, 0.07, 11);
  VoxelizationOptions options;
  options.resolution = 16.0;
  const VoxelGrid grid = voxelize(packing, options);
  const double sd_count = 0.915 * (0.5 * options.resolution) * std::sqrt(60.0);
  const double tolerance = 5.0 * sd_count / static_cast<double>(grid.num_nodes());
  EXPECT_NEAR(grid.phi_lattice(), exact_phi(packing), tolerance);
  // And it is not exact: the count error is a surface effect (guards against a lattice phi
  // taken from the spheres rather than from the flags).
  EXPECT_NE(grid.phi_lattice(), exact_phi(packing));
}

// ---- convergence of the solid volume with resolution --------------------------------------------

/// Exact Var N / R^2 for a ball of radius R at a uniformly random lattice offset (header).
class CountVarianceSeries {
 public:
  CountVarianceSeries() : multiplicity_(kMaxShell + 1, 0) {
    const int k = static_cast<int>(std::sqrt(static_cast<double>(kMaxShell)));
    for (int a = -k; a <= k; ++a) {
      for (int b = -k; b <= k; ++b) {
        for (int c = -k; c <= k; ++c) {
          const int m = a * a + b * b + c * c;
          if (m > 0 && m <= kMaxShell) ++multiplicity_[m];
        }
      }
    }
  }
  double variance(double R) const {
    double sum = 0.0;
    for (int m = 1; m <= kMaxShell; ++m) {
      if (multiplicity_[m] == 0) continue;
      const double z = 2.0 * kPi * R * std::sqrt(static_cast<double>(m));
      const double j1 = std::sin(z) / (z * z) - std::cos(z) / z;
      const double chi = 4.0 * kPi * R * R * R * j1 / z;
      sum += multiplicity_[m] * chi * chi;
    }
    // Tail |xi| > K: R^2 cos^2 / (pi^2 |xi|^4) averaged, integrated over shells 4 pi k^2 dk.
    const double K = std::sqrt(static_cast<double>(kMaxShell));
    return sum + R * R / (2.0 * kPi * kPi) * 4.0 * kPi / K;
  }

 private:
  static constexpr int kMaxShell = 1600;  // |xi| <= 40
  std::vector<int> multiplicity_;
};

TEST(Voxelization, SolidVolumeConvergesAtTheSurfaceRate) {
  // One sphere of diameter D lattice units (d_ref = 1, resolution D) at uniformly random
  // offsets; D jittered by +-5% within each group so that the measurement averages over the
  // oscillating terms cos^2(2 pi R |xi|) instead of sampling them at one radius.
  const std::vector<double> nominal = {4.0, 5.66, 8.0, 11.3, 16.0, 22.6, 32.0};
  constexpr int kSamples = 300;
  const CountVarianceSeries series;
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> log_d, log_rms, log_rms_predicted, log_rms_error;
  for (double d_nominal : nominal) {
    double sum_error = 0.0, sum_squared = 0.0, sum_fourth = 0.0, sum_predicted = 0.0;
    for (int s = 0; s < kSamples; ++s) {
      const double D = d_nominal * (0.95 + 0.1 * unit(rng));
      const int n = static_cast<int>(std::ceil(D)) + 4;
      const double box = n / D;
      const Packing packing = make_packing(
          {box, box, box}, {{unit(rng) * box, unit(rng) * box, unit(rng) * box}}, {0.5});
      VoxelizationOptions options;
      options.resolution = D;
      const VoxelGrid grid = voxelize(packing, options);
      const double R = 0.5 / grid.dx;
      const double volume = 4.0 / 3.0 * kPi * R * R * R;
      const double count = grid.phi_lattice() * static_cast<double>(grid.num_nodes());
      const double relative = (count - volume) / volume;
      sum_error += relative;
      sum_squared += relative * relative;
      sum_fourth += relative * relative * relative * relative;
      sum_predicted += series.variance(R) / (volume * volume);
    }
    const double mean = sum_error / kSamples;
    const double mean_square = sum_squared / kSamples;
    const double predicted = sum_predicted / kSamples;
    // Unbiased: E[N] = V exactly for a random offset. The mean of 300 samples has standard
    // error sqrt(predicted / 300); 5 standard errors.
    EXPECT_LT(std::abs(mean), 5.0 * std::sqrt(predicted / kSamples)) << "D = " << d_nominal;
    // The mean square error matches the Fourier series within 5 standard errors of the
    // sample mean square, sqrt((kurtosis - 1) / 300) relative (8% for Gaussian errors; the
    // measured kurtosis is used since the count errors have somewhat heavier tails).
    const double kurtosis = (sum_fourth / kSamples) / (mean_square * mean_square);
    const double relative_error = std::sqrt((kurtosis - 1.0) / kSamples);
    EXPECT_NEAR(mean_square / predicted, 1.0, 5.0 * relative_error) << "D = " << d_nominal;
    RecordProperty("mean_square_over_series_D" + std::to_string(static_cast<int>(d_nominal)),
                   std::to_string(mean_square / predicted));
    log_d.push_back(std::log(d_nominal));
    log_rms.push_back(0.5 * std::log(mean_square));
    log_rms_predicted.push_back(0.5 * std::log(predicted));
    log_rms_error.push_back(0.5 * relative_error);  // d log RMS = d(mean square) / (2 ms)
  }
  // Least-squares slope of y against log D, and its standard error from the per-group errors.
  double mean_x = 0.0;
  for (double x : log_d) mean_x += x / log_d.size();
  double sxx = 0.0;
  for (double x : log_d) sxx += (x - mean_x) * (x - mean_x);
  auto slope = [&](const std::vector<double>& y) {
    double sxy = 0.0;
    for (std::size_t i = 0; i < y.size(); ++i) sxy += (log_d[i] - mean_x) * y[i];
    return sxy / sxx;
  };
  double slope_variance = 0.0;
  for (std::size_t i = 0; i < log_d.size(); ++i) {
    const double weight = (log_d[i] - mean_x) / sxx;
    slope_variance += weight * weight * log_rms_error[i] * log_rms_error[i];
  }
  const double slope_error = std::sqrt(slope_variance);
  const double measured = slope(log_rms);
  const double predicted = slope(log_rms_predicted);
  RecordProperty("rms_slope_measured", std::to_string(measured));
  RecordProperty("rms_slope_series", std::to_string(predicted));
  RecordProperty("rms_slope_standard_error", std::to_string(slope_error));
  // Rate. Sampling: measured and series slopes agree within 5 standard errors (about 0.03 with
  // 300 samples per group: ~5% error on each group's RMS over log D spanning ln 8).
  // Pre-asymptotics: the series' prefactor C = RMS (d/dx)^2 stays within [0.84, 0.98] over
  // D = 4..32 (jitter-averaged; 0.874 asymptotically), so its slope differs from -2 by at most
  // ln(0.98/0.84)/ln 8 = 0.075. The measured slope therefore lies within 0.075 + 5 standard
  // errors of the asymptotic -2.
  EXPECT_NEAR(predicted, -2.0, 0.075);
  EXPECT_NEAR(measured, predicted, 5.0 * slope_error);
  EXPECT_NEAR(measured, -2.0, 0.075 + 5.0 * slope_error);
}

// ---- progress and minimum gap -------------------------------------------------------------------

TEST(Voxelization, ProgressReportsEachStageFromZeroToOne) {
  const Packing packing = jittered_cubic({6, 6, 6}, 1.3, 0.05, 3);
  VoxelizationOptions options;
  options.resolution = 8.0;
  std::map<std::string, std::vector<double>> calls;
  voxelize(packing, options,
           [&](double fraction, const std::string& stage) { calls[stage].push_back(fraction); });
  ASSERT_EQ(calls.size(), 2u);
  for (const auto& [stage, fractions] : calls) {
    ASSERT_GE(fractions.size(), 2u) << stage;
    EXPECT_EQ(fractions.front(), 0.0) << stage;
    EXPECT_EQ(fractions.back(), 1.0) << stage;
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end())) << stage;
  }
}

TEST(Voxelization, ExceptionFromProgressAbortsTheRun) {
  // A progress callback may cancel a long voxelization by throwing; the exception reaches the
  // caller unchanged (here thrown when the second stage starts).
  const Packing packing = jittered_cubic({3, 3, 3}, 1.3, 0.05, 4);
  VoxelizationOptions options;
  options.resolution = 8.0;
  struct Cancelled {};
  EXPECT_THROW(voxelize(packing, options,
                        [](double, const std::string& stage) {
                          if (stage == "voxelize: boundary links") throw Cancelled();
                        }),
               Cancelled);
}

TEST(Voxelization, MinimumGapInLatticeUnits) {
  // Two unit spheres 1.3 apart: gap 0.3 d_ref = 4.8 lattice units at resolution 16.
  EXPECT_NEAR(
      min_gap_lattice_units(make_packing({10, 10, 10}, {{1, 5, 5}, {2.3, 5, 5}}, {0.5, 0.5}), 16.0),
      0.3 * 16.0, 1e-12);
  // Across the periodic boundary: x = 0.2 and 9.0 are 1.2 apart through the face.
  EXPECT_NEAR(min_gap_lattice_units(
                  make_packing({10, 10, 10}, {{0.2, 5, 5}, {9.0, 5, 4.9}}, {0.5, 0.5}), 10.0),
              (std::sqrt(1.2 * 1.2 + 0.01) - 1.0) * 10.0, 1e-12);
  // One sphere: the gap to its own image one box edge away (shortest edge 1.5).
  EXPECT_NEAR(min_gap_lattice_units(make_packing({2, 1.5, 3}, {{1, 1, 1}}, {0.5}), 8.0), 0.5 * 8.0,
              1e-12);
  EXPECT_THROW(min_gap_lattice_units(make_packing({2, 2, 2}, {{1, 1, 1}}, {0.5}), 0.0), Error);
}

TEST(Voxelization, MinimumGapCellListMatchesBruteForce) {
  // 18^3 = 5832 spheres (above the brute-force limit of the library), polydisperse radii,
  // compared with an O(N^2) search done here.
  Packing packing = jittered_cubic({18, 18, 18}, 1.2, 0.05, 5);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> radius(0.3, 0.5);
  for (double& r : packing.radii) r = radius(rng);
  double expected = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < packing.size(); ++i) {
    for (std::size_t j = i + 1; j < packing.size(); ++j) {
      double sum = 0.0;
      for (int a = 0; a < 3; ++a) {
        double d = packing.centers[j][a] - packing.centers[i][a];
        d -= packing.box_length[a] * std::round(d / packing.box_length[a]);
        sum += d * d;
      }
      expected = std::min(expected, std::sqrt(sum) - packing.radii[i] - packing.radii[j]);
    }
  }
  EXPECT_NEAR(min_gap_lattice_units(packing, 20.0), expected * 20.0, 1e-12);
}

// ---- sub-node gaps ------------------------------------------------------------------------------

TEST(Voxelization, TouchingSimpleCubicReportsItsContactsAsSubNodeGaps) {
  // One sphere of diameter 1 in a unit cube: close packing (phi = pi/6), touching its own images
  // along x, y and z: three image pairs at gap 0, none closer than one node otherwise.
  const Packing sc = make_packing({1.0, 1.0, 1.0}, {{0.5, 0.5, 0.5}}, {0.5});
  VoxelizationOptions options;
  options.resolution = 12.0;
  const VoxelGrid grid = voxelize(sc, options);
  expect_consistent(sc, grid);
  EXPECT_EQ(grid.gaps.narrow_pairs, 3);
  EXPECT_NEAR(grid.gaps.smallest_gap_nodes, 0.0, 1e-9);
  // Fluid nodes near the contacts have solid neighbours on both sides along some direction.
  EXPECT_GT(grid.gaps.narrow_fluid_nodes, 0);
  EXPECT_LT(grid.gaps.narrow_fluid_fraction(), 0.5);
  std::int64_t fluid = 0;
  for (auto f : grid.solid) fluid += f == 0;
  EXPECT_EQ(grid.gaps.fluid_nodes, fluid);
}

TEST(Voxelization, LinksInSubNodeGapsTakeTheFirstSurfaceTheyCross) {
  // Two spheres with a surface gap of 0.3 lattice units, off the lattice planes, and a third
  // touching the second: diagonal links from the gap can clip the neighbour before they reach
  // the sphere that owns their solid node; expect_consistent checks q and the owner of every
  // link against brute force over all spheres and images.
  const double resolution = 10.0, gap = 0.3 / resolution;
  const Packing packing = make_packing({3.0, 3.0, 3.0},
                                       {{1.013, 1.27, 1.41},
                                        {1.013 + 1.0 + gap, 1.27 + 0.031, 1.41 - 0.017},
                                        {1.013 + 1.0 + gap, 1.27 + 0.031 + 1.0, 1.41 - 0.017}},
                                       {0.5, 0.5, 0.5});
  VoxelizationOptions options;
  options.resolution = resolution;
  const VoxelGrid grid = voxelize(packing, options);
  expect_consistent(packing, grid);
  EXPECT_EQ(grid.gaps.narrow_pairs, 2);
  EXPECT_NEAR(grid.gaps.smallest_gap_nodes, 0.0, 0.31);
  EXPECT_GT(grid.gaps.narrow_fluid_nodes, 0);
  // A dense hard-sphere packing (phi = 0.55, near contacts) at a coarse resolution: some links do
  // clip a neighbour first, i.e. belong to a sphere that does not contain their solid node.
  RandomPackingOptions dense;
  dense.phi = 0.55;
  dense.n = 27;
  dense.seed = 3;
  const Packing random = generate_random_packing(dense);
  for (double resolution : {6.0, 8.0}) {
    VoxelizationOptions coarse;
    coarse.resolution = resolution;
    const VoxelGrid g = voxelize(random, coarse);
    expect_consistent(random, g);
    int clipped = 0;
    for (std::size_t s = 0; s < random.size(); ++s) {
      for (const BoundaryLink& link : g.links[s]) {
        const std::int64_t y =
            neighbour(g, static_cast<std::int64_t>(link.fluid_node), link.direction);
        clipped += inside(random, g, s, y) ? 0 : 1;
      }
    }
    std::printf("resolution %g: %d of %zu links clip a neighbour first; %lld narrow pairs\n",
                resolution, clipped, g.num_links(), static_cast<long long>(g.gaps.narrow_pairs));
    EXPECT_GT(g.gaps.narrow_pairs, 0);
    EXPECT_GT(clipped, 0);
  }
  // Well-separated spheres report no narrow gap.
  const Packing apart =
      make_packing({3.0, 3.0, 3.0}, {{0.75, 0.75, 0.75}, {2.25, 2.25, 2.25}}, {0.5, 0.5});
  const VoxelGrid far = voxelize(apart, options);
  EXPECT_EQ(far.gaps.narrow_pairs, 0);
  EXPECT_EQ(far.gaps.narrow_fluid_nodes, 0);
}

}  // namespace
}  // namespace arrays
}  // namespace draglab
