// lattice.cc: stored-node list (fluid + ghost layer) by x-rows, run-length coded AA neighbour
// table, work ranges, links and the first-touch population buffer.
#include "lattice.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <string>

#include "draglab/error.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(_OPENMP)
#include <omp.h>
#endif

namespace draglab {
namespace lbm {
namespace {

using d3q19::kC;
using d3q19::kOpposite;
using d3q19::kQ;

std::int64_t wrap(std::int64_t i, std::int64_t n) { return i < 0 ? i + n : (i >= n ? i - n : i); }

}  // namespace

std::int64_t SparseLattice::padded_stride(std::int64_t num_stored, std::size_t bytes) {
  // Rows a multiple of 4 KiB plus 192 bytes: the 19 row starts fall on 19 distinct 64-byte
  // lines of a 4 KiB page (19 * 192 = 3648 < 4096) and stay 64-byte aligned.
  const std::int64_t b = static_cast<std::int64_t>(bytes);
  const std::int64_t row_bytes = (num_stored * b + 4095) / 4096 * 4096 + 192;
  return row_bytes / b;
}

std::vector<std::int64_t> split_planes(const arrays::VoxelGrid& grid, int ranks) {
  const std::int64_t nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  ranks = std::max(1, ranks);
  if (nz < kMinPlanesPerRank * ranks) {
    throw Error(ErrorCode::kInvalidArgument,
                "lbm: the box has " + std::to_string(nz) + " z-planes, fewer than " +
                    std::to_string(kMinPlanesPerRank) + " per rank for " + std::to_string(ranks) +
                    " ranks; use at most " + std::to_string(nz / kMinPlanesPerRank) +
                    " ranks for this box (or a higher resolution)");
  }
  std::vector<std::int64_t> fluid(static_cast<std::size_t>(nz), 0);
  for (std::int64_t k = 0; k < nz; ++k) {
    for (std::int64_t n = k * nx * ny; n < (k + 1) * nx * ny; ++n) {
      fluid[static_cast<std::size_t>(k)] += grid.solid[static_cast<std::size_t>(n)] ? 0 : 1;
    }
  }
  std::int64_t total = 0;
  for (std::int64_t f : fluid) total += f;
  std::vector<std::int64_t> begin(static_cast<std::size_t>(ranks) + 1, nz);
  begin[0] = 0;
  std::int64_t k = 0, done = 0;
  for (int r = 1; r < ranks; ++r) {
    const std::int64_t target = total * r / ranks;
    const std::int64_t lowest = begin[static_cast<std::size_t>(r) - 1] + kMinPlanesPerRank;
    const std::int64_t highest = nz - kMinPlanesPerRank * (ranks - r);
    while (k < highest && (k < lowest || done + fluid[static_cast<std::size_t>(k)] <= target)) {
      done += fluid[static_cast<std::size_t>(k)];
      ++k;
    }
    begin[static_cast<std::size_t>(r)] = k;
  }
  return begin;
}

std::int64_t SparseLattice::local_plane(std::int64_t k) const {
  const std::int64_t p = wrap(k - first_plane_, dims_[2]);
  return p < local_planes_ ? p : -1;
}

std::int32_t SparseLattice::stored_index(std::int64_t dense) const {
  const std::int64_t plane_nodes = dims_[0] * dims_[1];
  const std::int64_t p = local_plane(dense / plane_nodes);
  return p < 0 ? -1
               : stored_index_[static_cast<std::size_t>(dense % plane_nodes + plane_nodes * p)];
}

SparseLattice::SparseLattice(const arrays::VoxelGrid& grid, int threads, std::size_t element_bytes,
                             PlaneRange planes)
    : dims_(grid.dims), planes_(planes) {
  const std::int64_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
  const std::int64_t total = nx * ny * nz;
  if (nx <= 0 || ny <= 0 || nz <= 0 || static_cast<std::int64_t>(grid.solid.size()) != total) {
    throw Error(ErrorCode::kInvalidArgument,
                "lbm: voxel grid with inconsistent dimensions (solid flags do not match dims)");
  }
  if (!planes_.decomposed) {
    planes_.begin = 0;
    planes_.end = nz;
    first_plane_ = 0;
    local_planes_ = nz;
  } else {
    if (planes_.begin < 0 || planes_.end > nz || planes_.end - planes_.begin < kMinPlanesPerRank ||
        planes_.end - planes_.begin > nz - 2) {
      throw Error(ErrorCode::kInvalidArgument, "lbm: invalid plane range of a decomposed box");
    }
    first_plane_ = wrap(planes_.begin - 1, nz);
    local_planes_ = planes_.end - planes_.begin + 2;
  }
  threads = std::max(1, threads);
  const auto& solid = grid.solid;
  auto dense = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return wrap(i, nx) + nx * (wrap(j, ny) + ny * wrap(k, nz));
  };
  // Fluid that this rank updates.
  auto owned_fluid = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    if (solid[static_cast<std::size_t>(dense(i, j, k))]) return false;
    const std::int64_t p = local_plane(wrap(k, nz));
    return p >= 0 && owned_plane(p);
  };
  const std::int64_t planes_here = local_planes_;
  const std::int64_t local_total = nx * ny * planes_here;

  // Stored nodes: owned fluid, and the nodes with an owned fluid neighbour (ghosts and halo).
  // D3Q19 neighbourhood is symmetric, so a node is needed exactly when one of its own
  // neighbours is owned fluid.
  std::vector<std::uint8_t> stored(static_cast<std::size_t>(local_total), 0);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t p = 0; p < planes_here; ++p) {
    const std::int64_t k = first_plane_ + p;
    for (std::int64_t j = 0; j < ny; ++j) {
      for (std::int64_t i = 0; i < nx; ++i) {
        bool keep = owned_fluid(i, j, k);
        for (int q = 1; q < kQ && !keep; ++q) {
          keep = owned_fluid(i + kC[q][0], j + kC[q][1], k + kC[q][2]);
        }
        stored[static_cast<std::size_t>(i + nx * (j + ny * p))] = keep ? 1 : 0;
      }
    }
  }

  // Numbering row by row (local rows r = j + ny p, x fastest).
  const std::int64_t rows = ny * planes_here;
  stored_index_.assign(static_cast<std::size_t>(local_total), -1);
  row_storage_begin_.assign(static_cast<std::size_t>(rows) + 1, 0);
  std::int64_t count = 0;
  for (std::int64_t r = 0; r < rows; ++r) {
    row_storage_begin_[static_cast<std::size_t>(r)] = count;
    const std::int64_t row = nx * r;
    const std::int64_t global_row = nx * (r % ny + ny * wrap(first_plane_ + r / ny, nz));
    const bool owned = owned_plane(r / ny);
    for (std::int64_t i = 0; i < nx; ++i) {
      if (!stored[static_cast<std::size_t>(row + i)]) continue;
      if (count >= std::numeric_limits<std::int32_t>::max()) {
        throw Error(ErrorCode::kInvalidArgument,
                    "lbm: more than 2^31 - 1 stored nodes; lower the resolution");
      }
      stored_index_[static_cast<std::size_t>(row + i)] = static_cast<std::int32_t>(count++);
      node_.push_back(global_row + i);
      if (owned && !solid[static_cast<std::size_t>(global_row + i)]) ++num_fluid_;
    }
  }
  row_storage_begin_[static_cast<std::size_t>(rows)] = count;
  std::vector<std::uint8_t>().swap(stored);
  if (num_fluid_ == 0 && !planes_.decomposed) {
    throw Error(ErrorCode::kInvalidArgument, "lbm: the lattice has no fluid node");
  }
  stride_ = padded_stride(count, element_bytes);
  auto local_index = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    const std::int64_t p = local_plane(wrap(k, nz));
    return p < 0
               ? -1
               : stored_index_[static_cast<std::size_t>(wrap(i, nx) + nx * (wrap(j, ny) + ny * p))];
  };

  // Solid-neighbour masks.
  mask_.assign(static_cast<std::size_t>(count), 0);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t n = 0; n < count; ++n) {
    const std::int64_t d = node_[static_cast<std::size_t>(n)];
    const std::int64_t i = d % nx, j = (d / nx) % ny, k = d / (nx * ny);
    if (!owned_fluid(i, j, k)) continue;  // the masked sweep runs over fluid segments only
    std::uint32_t m = 0;
    for (int q = 1; q < kQ; ++q) {
      if (solid[static_cast<std::size_t>(dense(i + kC[q][0], j + kC[q][1], k + kC[q][2]))]) {
        m |= std::uint32_t{1} << q;
      }
    }
    mask_[static_cast<std::size_t>(n)] = m;
  }

  // Segments: fluid x-runs, split at x = 0 and x = nx - 1 (periodic wrap); built per row.
  std::vector<std::vector<Segment>> per_row(static_cast<std::size_t>(rows));
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
  for (std::int64_t r = 0; r < rows; ++r) {
    std::vector<Segment>& out = per_row[static_cast<std::size_t>(r)];
    if (!owned_plane(r / ny)) continue;
    const std::int64_t j = r % ny, k = wrap(first_plane_ + r / ny, nz);
    const std::int64_t row = nx * (j + ny * k);
    std::int64_t i = 0;
    while (i < nx) {
      if (solid[static_cast<std::size_t>(row + i)]) {
        ++i;
        continue;
      }
      std::int64_t end = i + 1;
      if (i != 0) {
        while (end < nx - 1 && !solid[static_cast<std::size_t>(row + end)]) ++end;
      }
      Segment seg;
      seg.first = local_index(i, j, k);
      seg.length = end - i;
      seg.write[0] = seg.first;
      for (int q = 1; q < kQ; ++q) {
        const std::int64_t nb = local_index(i + kC[q][0], j + kC[q][1], k + kC[q][2]);
        seg.write[q] = q * stride_ + nb;
      }
      for (std::int64_t n = seg.first; n < seg.first + seg.length; ++n) {
        seg.wall = seg.wall || mask_[static_cast<std::size_t>(n)] != 0;
      }
      out.push_back(seg);
      i = end;
    }
  }
  row_segment_begin_.assign(static_cast<std::size_t>(rows) + 1, 0);
  for (std::int64_t r = 0; r < rows; ++r) {
    row_segment_begin_[static_cast<std::size_t>(r)] = static_cast<std::int64_t>(segments_.size());
    auto& row_segments = per_row[static_cast<std::size_t>(r)];
    segments_.insert(segments_.end(), row_segments.begin(), row_segments.end());
    std::vector<Segment>().swap(row_segments);
  }
  row_segment_begin_[static_cast<std::size_t>(rows)] = static_cast<std::int64_t>(segments_.size());
  for (std::int64_t n = 0; n < count; ++n) num_wall_ += mask_[static_cast<std::size_t>(n)] != 0;

  // Fluid-node-balanced work ranges of whole rows.
  range_row_begin_.assign(static_cast<std::size_t>(threads) + 1, rows);
  range_row_begin_[0] = 0;
  std::int64_t done = 0, r = 0;
  for (int t = 1; t < threads; ++t) {
    const std::int64_t target = num_fluid_ * t / threads;
    while (r < rows) {
      std::int64_t fluid_in_row = 0;
      for (std::int64_t sg = row_segment_begin_[static_cast<std::size_t>(r)];
           sg < row_segment_begin_[static_cast<std::size_t>(r) + 1]; ++sg) {
        fluid_in_row += segments_[static_cast<std::size_t>(sg)].length;
      }
      if (done + fluid_in_row > target) break;
      done += fluid_in_row;
      ++r;
    }
    range_row_begin_[static_cast<std::size_t>(t)] = r;
  }
  if (planes_.decomposed) build_halo_plan(grid);
}

void SparseLattice::build_halo_plan(const arrays::VoxelGrid& grid) {
  const std::int64_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
  auto fluid = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return !grid.solid[static_cast<std::size_t>(wrap(i, nx) +
                                                nx * (wrap(j, ny) + ny * wrap(k, nz)))];
  };
  // Row i at the fluid nodes of local plane p for every i with c_iz = dz whose upstream node
  // x - c_i (in the plane p - dz) is fluid; nodes in x-fastest order, then direction.
  auto crossing = [&](std::int64_t p, int dz) {
    std::vector<std::int64_t> out;
    const std::int64_t k = first_plane_ + p;
    for (std::int64_t j = 0; j < ny; ++j) {
      for (std::int64_t i = 0; i < nx; ++i) {
        if (!fluid(i, j, k)) continue;
        const std::int32_t n = stored_index_[static_cast<std::size_t>(i + nx * (j + ny * p))];
        for (int q = 1; q < kQ; ++q) {
          if (kC[q][2] != dz || !fluid(i - kC[q][0], j - kC[q][1], k - kC[q][2])) continue;
          if (n < 0) {
            throw Error(ErrorCode::kInternal,
                        "lbm: a halo node is not stored (a bug: please report it)");
          }
          out.push_back(q * stride_ + n);
        }
      }
    }
    return out;
  };
  const std::int64_t last = local_planes_ - 1;
  halo_.low_halo = crossing(0, -1);
  halo_.low_owned = crossing(1, +1);
  halo_.high_owned = crossing(last - 1, -1);
  halo_.high_halo = crossing(last, +1);
  halo_.boundary_rows.clear();
  halo_.interior_rows.clear();
  for (std::int64_t r = ny; r < ny * last; ++r) {
    const std::int64_t p = r / ny;
    (p == 1 || p == last - 1 ? halo_.boundary_rows : halo_.interior_rows).push_back(r);
  }
}

std::array<std::int64_t, 3> SparseLattice::coordinates(std::int64_t n) const {
  const std::int64_t d = node_[static_cast<std::size_t>(n)];
  return {d % dims_[0], (d / dims_[0]) % dims_[1], d / (dims_[0] * dims_[1])};
}

double SparseLattice::mean_segment_length() const {
  return segments_.empty()
             ? 0.0
             : static_cast<double>(num_fluid_) / static_cast<double>(segments_.size());
}

std::size_t SparseLattice::memory_bytes() const {
  return node_.size() * (sizeof(std::int64_t) + sizeof(std::uint32_t)) +
         stored_index_.size() * sizeof(std::int32_t) + segments_.size() * sizeof(Segment) +
         (row_segment_begin_.size() + row_storage_begin_.size()) * sizeof(std::int64_t);
}

std::vector<std::int64_t> LinkTable::chunks(int parts) const {
  parts = std::max(1, parts);
  const std::int64_t n = static_cast<std::int64_t>(size());
  std::vector<std::int64_t> begin(static_cast<std::size_t>(parts) + 1, n);
  begin[0] = 0;
  for (int p = 1; p < parts; ++p) {
    std::int64_t l = std::max(begin[static_cast<std::size_t>(p) - 1], n * p / parts);
    while (l > 0 && l < n &&
           node[static_cast<std::size_t>(l)] == node[static_cast<std::size_t>(l) - 1])
      ++l;
    begin[static_cast<std::size_t>(p)] = l;
  }
  return begin;
}

void wall_weights(WallScheme wall, double q, bool second_node_fluid, double* weight_a,
                  double* weight_b, bool* fallback) {
  *weight_a = *weight_b = 0.0;
  *fallback = false;
  switch (wall) {
    case WallScheme::kBounceBack:
      return;
    case WallScheme::kCentralLinear:
      if (!second_node_fluid) {
        *fallback = true;
        return;
      }
      *weight_a = (1.0 - 2.0 * q) / (1.0 + 2.0 * q);
      *weight_b = -*weight_a;
      return;
    case WallScheme::kBouzidiLinear:
      // q >= 1/2 needs no second node, but with r - c_i solid the opposite link of the same
      // node writes the value it would read (f*_ib(r)'s slot): fall back there too, so that no
      // link reads what another writes and the pass runs in any order.
      if (!second_node_fluid) {
        *fallback = true;
        return;
      }
      if (q >= 0.5) {
        *weight_b = (2.0 * q - 1.0) / (2.0 * q);
      } else {
        *weight_a = 1.0 - 2.0 * q;
      }
      return;
  }
}

LinkTable SparseLattice::build_links(const arrays::VoxelGrid& grid, WallScheme wall) const {
  struct Raw {
    std::int32_t node;
    std::int32_t body;
    std::uint8_t direction;
    double q;
  };
  std::vector<Raw> raw;
  raw.reserve(grid.num_links());
  for (std::size_t s = 0; s < grid.links.size(); ++s) {
    for (const arrays::BoundaryLink& link : grid.links[s]) {
      const std::int64_t d = static_cast<std::int64_t>(link.fluid_node);
      const int q = link.direction;
      if (d < 0 || d >= num_nodes() || q <= 0 || q >= kQ ||
          grid.solid[static_cast<std::size_t>(d)] != 0) {
        throw Error(ErrorCode::kInvalidArgument,
                    "lbm: voxel grid has a boundary link that does not start at a fluid node");
      }
      const std::int64_t p = local_plane(d / (dims_[0] * dims_[1]));
      if (p < 0 || !owned_plane(p)) continue;  // another rank's node
      raw.push_back(
          {stored_index(d), static_cast<std::int32_t>(s), static_cast<std::uint8_t>(q), link.q});
    }
  }
  std::stable_sort(raw.begin(), raw.end(), [](const Raw& x, const Raw& y) {
    return x.node != y.node ? x.node < y.node : x.direction < y.direction;
  });

  LinkTable table;
  table.bodies = grid.links.size();
  const std::size_t total = raw.size();
  table.self.reserve(total);
  table.a.reserve(total);
  table.b.reserve(total);
  table.ghost.reserve(total);
  table.weight_a.reserve(total);
  table.weight_b.reserve(total);
  table.node.reserve(total);
  table.body.reserve(total);
  table.direction.reserve(total);
  const std::int64_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
  for (const Raw& link : raw) {
    const std::int64_t r = link.node;
    const int q = link.direction;
    const int qb = kOpposite[q];
    const std::int64_t self = qb * stride_ + r;
    // Second node of the interpolation: x - c_q.
    const std::int64_t d = node_[static_cast<std::size_t>(r)];
    const std::int64_t i = d % nx, j = (d / nx) % ny, k = d / (nx * ny);
    const std::int64_t d2 =
        wrap(i - kC[q][0], nx) + nx * (wrap(j - kC[q][1], ny) + ny * wrap(k - kC[q][2], nz));
    const std::int32_t r2 = grid.solid[static_cast<std::size_t>(d2)] ? -1 : stored_index(d2);
    const std::int64_t dg =
        wrap(i + kC[q][0], nx) + nx * (wrap(j + kC[q][1], ny) + ny * wrap(k + kC[q][2], nz));
    const std::int32_t g = stored_index(dg);
    if (g < 0 || !grid.solid[static_cast<std::size_t>(dg)]) {
      throw Error(ErrorCode::kInternal, "lbm: a boundary link does not end at a stored solid node");
    }
    double weight_a = 0.0, weight_b = 0.0;
    bool fallback = false;
    wall_weights(wall, link.q, r2 >= 0, &weight_a, &weight_b, &fallback);
    if (fallback) ++table.fallback_links;
    // Without a node behind, a points at the link's own value (read with a zero weight). Both
    // positions are kept where the weights are zero too: rr's wall correction reads them.
    const std::int64_t a = r2 >= 0 ? qb * stride_ + r2 : self;
    const std::int64_t b = q * stride_ + r;
    table.self.push_back(self);
    table.a.push_back(a);
    table.b.push_back(b);
    table.ghost.push_back(q * stride_ + g);
    table.weight_a.push_back(weight_a);
    table.weight_b.push_back(weight_b);
    table.node.push_back(link.node);
    table.body.push_back(link.body);
    table.direction.push_back(static_cast<std::uint8_t>(q));
  }
  // Partners: a node's links are contiguous.
  table.partner.assign(total, -1);
  for (std::size_t begin = 0; begin < total;) {
    std::size_t end = begin;
    while (end < total && table.node[end] == table.node[begin]) ++end;
    for (std::size_t l = begin; l < end; ++l) {
      for (std::size_t m = begin; m < end; ++m) {
        if (table.direction[m] == kOpposite[table.direction[l]]) {
          table.partner[l] = static_cast<std::int64_t>(m);
        }
      }
    }
    begin = end;
  }
  // Per-row ranges (links are sorted by stored index, which rows partition).
  const std::int64_t rows = num_rows();
  table.row_begin.assign(static_cast<std::size_t>(rows) + 1, static_cast<std::int64_t>(total));
  std::size_t l = 0;
  for (std::int64_t row = 0; row < rows; ++row) {
    const std::int64_t first = row_storage_begin_[static_cast<std::size_t>(row)];
    while (l < total && table.node[l] < first) ++l;
    table.row_begin[static_cast<std::size_t>(row)] = static_cast<std::int64_t>(l);
  }
  return table;
}

template <typename T>
void Populations<T>::Free::operator()(T* p) const {
  std::free(p);
}

template <typename T>
Populations<T>::Populations(const SparseLattice& lattice, int threads) : stride_(lattice.stride()) {
  constexpr std::size_t kHugePage = std::size_t{2} << 20;
  bytes_ = static_cast<std::size_t>(d3q19::kQ) * static_cast<std::size_t>(stride_) * sizeof(T);
  const std::size_t alloc = (bytes_ + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, alloc);
  if (p == nullptr) {
    throw Error(ErrorCode::kInvalidArgument, "lbm: cannot allocate " + std::to_string(alloc >> 20) +
                                                 " MiB for the populations; lower the resolution");
  }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Fewer TLB misses over the 19 streams; a hint only (ignored where THP is off).
  madvise(p, alloc, MADV_HUGEPAGE);
#endif
  data_.reset(static_cast<T*>(p));
  T* base = data_.get();
  const int ranges = lattice.num_ranges();
  // First touch by the threads that update the nodes (the same static ranges as the kernels).
#pragma omp parallel num_threads(std::max(1, threads))
  {
#if defined(_OPENMP)
    const int tid = omp_get_thread_num(), team = omp_get_num_threads();
#else
    const int tid = 0, team = 1;
#endif
    for (int r = tid; r < ranges; r += team) {
      const std::int64_t begin = lattice.range_storage_begin(r);
      const std::int64_t end = r + 1 == ranges ? stride_ : lattice.range_storage_begin(r + 1);
      for (int i = 0; i < d3q19::kQ; ++i) {
        std::memset(static_cast<void*>(base + i * stride_ + begin), 0,
                    static_cast<std::size_t>(end - begin) * sizeof(T));
      }
    }
  }
}

template class Populations<double>;
template class Populations<float>;

}  // namespace lbm
}  // namespace draglab
