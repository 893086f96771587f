// draglab/arrays/voxelization.h: a packing turned into lattice boundary information, once per run.
//
// Lattice: nx * ny * nz nodes with spacing dx (in d_ref), node (i, j, k) at
// ((i + 1/2) dx, (j + 1/2) dx, (k + 1/2) dx), periodic. Linear index i + nx (j + ny k).
// The resolution is d_ref/dx, lattice units per reference diameter; the box edge is an integer
// number of nodes, so dx = box_length / n per axis (the requested resolution is rounded to the
// nearest node count of the x edge; every edge must come out as a whole number of nodes within
// 1e-9 relative, otherwise the box is rejected).
//
// Solid nodes: centre strictly inside a sphere. Boundary link: from a fluid node x along a D3Q19
// velocity c_q to a solid node x + c_q; q = |x - x_wall| / |c_q| in (0, 1] is the exact fraction
// of the link at which it crosses the sphere surface (analytic ray-sphere intersection with
// periodic wrap-around), as interpolated bounce-back needs it. Links are listed per sphere (the
// sphere owning the solid node), so momentum exchange gives the force on each sphere.
//
// Degenerate cases. A node exactly on a sphere surface is fluid (strictly inside -> solid); a
// link from it into that sphere has its wall at the fluid node itself, q = 0 exactly, which is
// stored as kMinLinkFraction so that q stays in (0, 1] (the wall is still at the fluid node to
// working precision; putting it at q = 1 would misplace it by a whole link). Because the solid
// node is strictly inside, q < 1 mathematically; rounding can give at most q = 1. Links are
// assigned to the sphere whose surface the link crosses first: q is the first surface crossing
// along the link over the owner of the solid node and every sphere image near it. Where spheres
// are closer than a lattice spacing (touching, in contact, or with sub-node gaps, the normal
// case of dense random packings), a link from a fluid node in the gap can clip a neighbour
// before it reaches the sphere that owns its solid node; its wall is then on that neighbour, and
// so is its momentum exchange. Where two spheres overlap (touching spheres can share a node
// through rounding) the lowest sphere index owns the solid node.
//
// Under-resolved gaps are measured, not refused: VoxelGrid::gaps counts the sphere pairs (and
// image pairs) whose surface gap is below one lattice spacing, and the fluid nodes with solid
// nodes on both sides along a lattice direction (a gap one node wide there, where interpolated
// bounce-back falls back to the halfway rule).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "draglab/arrays/packing.h"

namespace draglab {
namespace arrays {

/// D3Q19 velocities: 0 rest, 1..6 axis directions, 7..18 face diagonals; opposite pairs are
/// adjacent (1/2, 3/4, ..., 17/18).
constexpr int kD3Q19 = 19;
constexpr std::array<std::array<int, 3>, kD3Q19> kD3Q19Velocities{{
    {0, 0, 0},  {1, 0, 0},   {-1, 0, 0},  {0, 1, 0},  {0, -1, 0}, {0, 0, 1},   {0, 0, -1},
    {1, 1, 0},  {-1, -1, 0}, {1, -1, 0},  {-1, 1, 0}, {1, 0, 1},  {-1, 0, -1}, {1, 0, -1},
    {-1, 0, 1}, {0, 1, 1},   {0, -1, -1}, {0, 1, -1}, {0, -1, 1},
}};
/// Index of the opposite velocity.
constexpr std::array<int, kD3Q19> kD3Q19Opposite{0, 2,  1,  4,  3,  6,  5,  8,  7, 10,
                                                 9, 12, 11, 14, 13, 16, 15, 18, 17};

/// Smallest stored q: the value a link gets whose fluid node lies exactly on the surface (q = 0).
constexpr double kMinLinkFraction = 2.220446049250313e-16;  // 2^-52

/// A link from a fluid node towards a solid node of one sphere.
struct BoundaryLink {
  std::uint64_t fluid_node = 0;  ///< Linear index of the fluid node.
  double q = 0.5;                ///< Wall position along the link, fraction in (0, 1].
  std::uint8_t direction = 0;    ///< D3Q19 index of c_q (fluid -> solid).
};

struct VoxelizationOptions {
  double resolution = 16.0;  ///< Lattice units per reference diameter d_ref, [2, 1024].
  bool IsValid(std::string* error) const;
};

/// Sub-node gaps of a voxelized packing (see the header comment).
struct GapSummary {
  /// Sphere pairs (a pair of distinct images counted once, a sphere's own images included) whose
  /// surface gap is below one lattice spacing (touching and overlapping pairs included).
  std::int64_t narrow_pairs = 0;
  /// Smallest surface gap over pairs closer than one link (sqrt 2 lattice spacings), in lattice
  /// units (< 0: overlap); +infinity if no pair is that close.
  double smallest_gap_nodes = 0.0;
  /// Fluid nodes whose two neighbours along some D3Q19 direction are both solid.
  std::int64_t narrow_fluid_nodes = 0;
  std::int64_t fluid_nodes = 0;
  double narrow_fluid_fraction() const {
    return fluid_nodes > 0 ? static_cast<double>(narrow_fluid_nodes) / fluid_nodes : 0.0;
  }
};

/// Solid flags and boundary links of a packing on a lattice.
struct VoxelGrid {
  std::array<std::int64_t, 3> dims{0, 0, 0};
  double dx = 1.0;                               ///< Node spacing in d_ref.
  std::vector<std::uint8_t> solid;               ///< 1 = solid, 0 = fluid; size nx*ny*nz.
  std::vector<std::vector<BoundaryLink>> links;  ///< links[s]: boundary links of sphere s.
  /// diameters[s]: the diameter of sphere s in d_ref (empty for a grid not made by voxelize).
  std::vector<double> diameters;
  GapSummary gaps;  ///< Filled by voxelize().

  std::int64_t num_nodes() const { return dims[0] * dims[1] * dims[2]; }
  std::int64_t index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return i + dims[0] * (j + dims[1] * k);
  }
  double resolution() const { return 1.0 / dx; }
  /// Fraction of solid nodes (compare with the exact Packing::phi()).
  double phi_lattice() const;
  std::size_t num_links() const;
  /// Bytes held by the flags and link lists.
  std::size_t memory_bytes() const;
};

/// Voxelizes a packing. Throws draglab::Error(kInvalidArgument) if the box is not a whole number
/// of nodes at this resolution (the message names the edge and the nearest valid resolutions),
/// if the lattice would exceed 2^40 nodes, or for a sphere with a non-positive radius, a radius
/// above half the shortest box edge (it would overlap its own image) or a non-finite centre.
/// Output is deterministic (independent of the number of OpenMP threads): links[s] is sorted
/// by fluid node, then direction. Cost: one visit per node of each sphere's bounding box plus
/// 18 neighbour checks per surface node. Memory: 1 byte per node plus sizeof(BoundaryLink) =
/// 24 bytes per link, about 72 R^2 links per sphere of radius R lattice units (256^3 nodes at
/// phi = 0.4 and 14.7 nodes per diameter: 374 MiB). `progress` receives the fraction of
/// spheres done in the stages "voxelize: solid nodes" and "voxelize: boundary links", at most
/// every 0.2 s, on the calling thread; an exception it throws aborts the voxelization.
VoxelGrid voxelize(const Packing& packing, const VoxelizationOptions& options,
                   const ProgressCallback& progress = nullptr);

/// Smallest surface gap between spheres, |r_ij| - r_i - r_j over all pairs of distinct sphere
/// images (including a sphere and its own nearest image), times `resolution` (lattice units per
/// d_ref, > 0): the gap in lattice units, for "resolution too low for the gaps" diagnoses.
/// Negative for overlapping spheres; +infinity for an empty packing. O(N^2) up to 5000 spheres,
/// a cell list above. Throws Error(kInvalidArgument) for a non-positive resolution or a
/// malformed packing (as voxelize).
double min_gap_lattice_units(const Packing& packing, double resolution);

}  // namespace arrays
}  // namespace draglab
