// lattice.h: fluid-only (sparse) storage of the D3Q19 populations with in-place AA streaming.
//
// Storage. Stored nodes are the fluid nodes plus a one-node "ghost" layer: the solid nodes that
// are D3Q19 neighbours of a fluid node (about one surface shell per sphere). Deeper solid nodes
// cost neither memory nor time. Stored nodes are numbered row by row (an x-row is the nodes
// (*, j, k); rows in the order r = j + ny k, x fastest), and the populations are 19 padded
// structure-of-arrays rows of length `stride` in one buffer: population i of stored node n lives
// at flat offset i * stride + n. The row stride is padded so that consecutive rows start 192
// bytes apart modulo 4 KiB (unpadded rows at multiples of 4 KiB alias in the caches and the TLB:
// a 10x loss on this kind of machine). Ghost nodes keep the neighbour offsets of a fluid x-run
// contiguous (every neighbour of a fluid node is stored, so the neighbour row of a run is stored
// without gaps); the even sweep collides them along with the fluid nodes of their row (one loop
// per row, solver.cc), and nothing reads what that leaves in them.
//
// Blocks. The x-rows are grouped into slabs of kSlabPlanes z-planes; a slab's stored nodes,
// segments and links are contiguous and every neighbour of a slab lies in the slab or the two
// adjacent ones. OpenMP threads get contiguous, fluid-node-balanced ranges of x-rows (static
// schedule), and the same ranges first-touch the memory. Within its range a thread sweeps the
// rows in tiles of a few y-rows (solver.cc, SweepPlan).
//
// Decomposition across ranks (PlaneRange): a rank owns the z-planes [begin, end) and stores two
// halo planes besides, begin - 1 and end (periodic). Its lattice is built exactly as above with
// "fluid" read as "owned fluid": halo nodes are stored when an owned fluid node neighbours them
// and are never collided (their rows are not swept), so the kernels run unchanged; only the
// populations that cross the two plane interfaces travel between ranks (HaloPlan, solver.cc). Rows,
// segments and links are local (the halo planes are the first and last local planes); node() stays
// the dense index in the whole box.
//
// AA pattern (Bailey et al. 2009), one buffer, no write-allocate traffic:
//  - even step: node n reads f_i from row i at n, collides, and writes the post-collision f*_i to
//    row opp(i) at n (no neighbour access);
//  - odd step: node x reads f_i from row opp(i) at x - c_i (the f*_i its neighbour wrote in the
//    even step), collides, and writes f*_i to row i at x + c_i. Halfway bounce-back: if x - c_i
//    is solid, f_i is read from row i at x instead, and if x + c_i is solid, f*_i is written to
//    row opp(i) at x as well (the copy written to the ghost is never read). The kernel selects
//    these with the node's 18-bit solid-neighbour mask, only in segments that touch a wall.
// After either step the post-collision population leaving x along a boundary link i (x + c_i
// solid) sits at row opp(i), node x: that is where the momentum exchange reads it.
// Interpolated walls do without the masks: every wall value goes through the link pass, which
// reads the leaving value and writes the one coming back where the plain sweeps put and take
// them (after an even step: row opp(i) at x and row i at the ghost x + c_i; after an odd step
// the other way round; solver.h).
//
// Segments (run-length coded neighbour table): a Segment is a run of consecutive fluid nodes of
// one x-row (split at x = 0 and x = nx - 1, where the periodic wrap breaks the contiguity). Its
// 18 neighbour offsets advance by one per node, so one offset per direction serves the whole run
// and the inner loop is a unit-stride SIMD loop. The read offset of direction i is the write
// offset of opp(i). Runs without a wall node take the plain kernel, the others the masked one.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "d3q19.h"
#include "draglab/arrays/voxelization.h"

namespace draglab {
namespace lbm {

/// A run of consecutive fluid nodes of one x-row (see the file comment).
struct Segment {
  std::int64_t first = 0;  ///< Stored index of the first node.
  std::int64_t length = 0;
  /// Flat offset of row i at the neighbour x + c_i of node `first` (fluid or ghost); write[0] is
  /// the node itself (row 0).
  std::int64_t write[d3q19::kQ] = {};
  bool wall = false;  ///< Some node of the run has a solid neighbour (use the masked kernel).
};

/// How a boundary link places its wall (solver.h): halfway bounce-back, or a linear
/// interpolation in the wall fraction q.
enum class WallScheme {
  kBounceBack,     ///< Wall at q = 1/2 whatever the geometry.
  kCentralLinear,  ///< Ginzburg's central linear interpolation (CLI).
  kBouzidiLinear,  ///< Bouzidi, Firdaouss & Lallemand's linear interpolation (BFL).
};

/// The weights of a link with wall fraction q in (0, 1] (LinkTable::weight_a, weight_b).
/// `second_node_fluid`: whether r - c_i is fluid; the interpolations fall back to halfway
/// bounce-back (both weights 0) when it is not (a one-node gap), and *fallback is set.
///   CLI: a = kappa, b = -kappa, kappa = (1 - 2q)/(1 + 2q) (b < 0 for q < 1/2, a < 0 above).
///   BFL: q < 1/2: a = 1 - 2q, b = 0 (2q f + (1 - 2q) f_a);
///        q >= 1/2: a = 0, b = (2q - 1)/(2q) (f/(2q) + (2q - 1)/(2q) f_b): no negative weight.
void wall_weights(WallScheme wall, double q, bool second_node_fluid, double* weight_a,
                  double* weight_b, bool* fallback);

/// Boundary links in the form the link pass needs (see solver.h), sorted by fluid node so that
/// a node's links are contiguous (its mass correction is then race-free and deterministic) and
/// the pass sweeps memory in order.
struct LinkTable {
  std::vector<std::int64_t> self;   ///< Row opp(i), node r: f*_i(r); receives the reflected value.
  std::vector<std::int64_t> a;      ///< Row opp(i), node r - c_i.
  std::vector<std::int64_t> b;      ///< Row i, node r.
  std::vector<std::int64_t> ghost;  ///< Row i, solid node r + c_i (a ghost: see solver.h).
  /// Interpolation weights: the reflected value is f + weight_a (f_a - f) + weight_b (f_b - f)
  /// with f = f*_i(r), f_a = f*_i(r - c_i), f_b = f*_ib(r) (both 0: halfway bounce-back).
  std::vector<double> weight_a;
  std::vector<double> weight_b;
  std::vector<std::int32_t> node;  ///< Fluid index r (row 0 at r holds its rest population).
  std::vector<std::int32_t> body;  ///< Body (sphere) the link belongs to.
  std::vector<std::uint8_t> direction;
  /// The link of the same node along the opposite direction (both ends of the lattice line
  /// through the node are walls: a one-node gap), or -1.
  std::vector<std::int64_t> partner;
  std::size_t bodies = 0;
  std::int64_t fallback_links = 0;  ///< Interpolated links that fell back to bounce-back.
  /// Links of x-row r (of the lattice that built the table): [row_begin[r], row_begin[r+1]).
  std::vector<std::int64_t> row_begin;
  std::size_t size() const { return self.size(); }
  std::size_t num_bodies() const { return bodies; }
  /// Splits the links into `parts` contiguous chunks of about equal size that never split the
  /// links of one node: chunk p is [result[p], result[p+1]).
  std::vector<std::int64_t> chunks(int parts) const;
  std::size_t memory_bytes() const {
    return size() * (5 * sizeof(std::int64_t) + 2 * sizeof(double) + 2 * sizeof(std::int32_t) + 1);
  }
};

/// The z-planes [begin, end) of a box one rank owns; `decomposed` false: the whole periodic box
/// on one rank (no halo planes).
struct PlaneRange {
  std::int64_t begin = 0;
  std::int64_t end = 0;
  bool decomposed = false;
};

/// Contiguous plane ranges for `ranks` ranks, balanced by fluid nodes, at least
/// kMinPlanesPerRank planes each: result[r] .. result[r + 1] for rank r. Throws
/// Error(kInvalidArgument) when the box has fewer than kMinPlanesPerRank planes per rank.
constexpr std::int64_t kMinPlanesPerRank = 2;
std::vector<std::int64_t> split_planes(const arrays::VoxelGrid& grid, int ranks);

/// The populations that cross a rank's two plane interfaces, as flat offsets (row i * stride +
/// stored node) in the order both ranks of an interface enumerate them (the plane's nodes in
/// x-fastest order, then direction). For the lower interface (between the low halo plane and
/// the first owned plane): `low_halo` lists row i at halo fluid node h for c_i pointing down
/// with h - c_i owned fluid, `low_owned` row i at first-plane fluid node y for c_i pointing up
/// with y - c_i halo fluid; the upper interface the same with up and down swapped. After an
/// even step a rank sends its `*_owned` values and receives its `*_halo` ones (the post-
/// collision values the odd step reads across the interface); after an odd step it sends its
/// `*_halo` values (written there by its own nodes) and receives its `*_owned` ones. Each list
/// equals the neighbour's opposite list entry by entry.
struct HaloPlan {
  std::vector<std::int64_t> low_halo, low_owned, high_owned, high_halo;
  /// Local rows of the first and last owned planes (updated first, so that the exchange
  /// overlaps the interior), and of the planes in between.
  std::vector<std::int64_t> boundary_rows, interior_rows;
};

class SparseLattice {
 public:
  /// z-planes per slab (the unit an MPI decomposition would distribute).
  static constexpr std::int64_t kSlabPlanes = 4;

  /// Builds the stored-node list, segments and thread ranges. `threads` >= 1 is the number of
  /// work ranges (one per OpenMP thread); `element_bytes` (4 or 8) the population storage size,
  /// which sets the padded row stride the offsets use. Throws Error(kInvalidArgument) if the
  /// lattice has no fluid node or more than 2^31 - 1 stored nodes. `planes` selects a rank's
  /// share of a decomposed box (default: the whole box).
  SparseLattice(const arrays::VoxelGrid& grid, int threads, std::size_t element_bytes,
                PlaneRange planes = {});

  const std::array<std::int64_t, 3>& dims() const { return dims_; }
  std::int64_t num_nodes() const { return dims_[0] * dims_[1] * dims_[2]; }
  /// Owned fluid nodes (all of them without decomposition).
  std::int64_t num_fluid() const { return num_fluid_; }
  const PlaneRange& planes() const { return planes_; }
  bool decomposed() const { return planes_.decomposed; }
  /// Empty without decomposition.
  const HaloPlan& halo() const { return halo_; }
  /// Fluid plus ghost nodes.
  std::int64_t num_stored() const { return static_cast<std::int64_t>(node_.size()); }
  /// Row length of the population buffer (>= num_stored(), padded).
  std::int64_t stride() const { return stride_; }
  /// Stride for storage of element size `bytes` (4 or 8).
  static std::int64_t padded_stride(std::int64_t num_stored, std::size_t bytes);
  /// Dense (voxel) index of stored node n.
  std::int64_t node(std::int64_t n) const { return node_[static_cast<std::size_t>(n)]; }
  /// Stored index of a dense node (of the whole box), -1 if not stored here.
  std::int32_t stored_index(std::int64_t dense) const;
  /// Bit i set: the neighbour x + c_i of stored fluid node n is solid (0 for ghosts).
  std::uint32_t solid_mask(std::int64_t n) const { return mask_[static_cast<std::size_t>(n)]; }
  const std::uint32_t* solid_masks() const { return mask_.data(); }
  std::array<std::int64_t, 3> coordinates(std::int64_t n) const;

  /// Local x-rows (ny per local plane); row r = j + ny p, p the local plane.
  std::int64_t num_rows() const { return dims_[1] * local_planes_; }
  /// Segments of row r: [row_segment_begin(r), row_segment_begin(r+1)).
  std::int64_t row_segment_begin(std::int64_t r) const {
    return row_segment_begin_[static_cast<std::size_t>(r)];
  }
  /// First stored index of row r (num_stored() for r = num_rows()).
  std::int64_t row_storage_begin(std::int64_t r) const {
    return row_storage_begin_[static_cast<std::size_t>(r)];
  }
  const std::vector<Segment>& segments() const { return segments_; }
  int num_ranges() const { return static_cast<int>(range_row_begin_.size()) - 1; }
  /// Rows [range_row_begin(t), range_row_begin(t+1)) belong to work range t.
  std::int64_t range_row_begin(int t) const {
    return range_row_begin_[static_cast<std::size_t>(t)];
  }
  std::int64_t range_segment_begin(int t) const { return row_segment_begin(range_row_begin(t)); }
  std::int64_t range_storage_begin(int t) const { return row_storage_begin(range_row_begin(t)); }
  std::int64_t num_slabs() const { return (local_planes_ + kSlabPlanes - 1) / kSlabPlanes; }
  /// Fluid nodes with a solid neighbour.
  std::int64_t num_wall() const { return num_wall_; }
  /// Mean segment length (fluid nodes per run of the neighbour table).
  double mean_segment_length() const;

  /// Link table for this lattice's offsets with the weights of `wall` (WallScheme).
  LinkTable build_links(const arrays::VoxelGrid& grid, WallScheme wall) const;

  /// Bytes held by the topology (node maps, masks, segments); the populations are extra.
  std::size_t memory_bytes() const;

 private:
  /// Local plane of global plane k, -1 if not stored here.
  std::int64_t local_plane(std::int64_t k) const;
  bool owned_plane(std::int64_t p) const {
    return !planes_.decomposed || (p > 0 && p + 1 < local_planes_);
  }
  void build_halo_plan(const arrays::VoxelGrid& grid);

  std::array<std::int64_t, 3> dims_{0, 0, 0};
  PlaneRange planes_;
  std::int64_t first_plane_ = 0;   ///< Global plane of local plane 0.
  std::int64_t local_planes_ = 0;  ///< Stored planes (owned plus halo).
  HaloPlan halo_;
  std::int64_t stride_ = 0;
  std::int64_t num_fluid_ = 0;
  std::int64_t num_wall_ = 0;
  std::vector<std::int64_t> node_;
  std::vector<std::int32_t> stored_index_;
  std::vector<std::uint32_t> mask_;
  std::vector<Segment> segments_;
  std::vector<std::int64_t> row_segment_begin_;
  std::vector<std::int64_t> row_storage_begin_;
  std::vector<std::int64_t> range_row_begin_;
};

/// The population buffer: 19 rows of `stride` elements of T, 64-byte aligned, transparent huge
/// pages requested, zero-initialised (the rest state, populations being shifted by w_i) by the
/// threads of the work ranges that will update them (first touch).
template <typename T>
class Populations {
 public:
  Populations(const SparseLattice& lattice, int threads);
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  std::int64_t stride() const { return stride_; }
  std::size_t bytes() const { return bytes_; }

 private:
  struct Free {
    void operator()(T* p) const;
  };
  std::unique_ptr<T, Free> data_;
  std::int64_t stride_ = 0;
  std::size_t bytes_ = 0;
};

}  // namespace lbm
}  // namespace draglab
