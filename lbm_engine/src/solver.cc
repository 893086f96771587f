// solver.cc: the AA sweeps (SIMD over nodes), the link pass and the moment sweep.
#include "solver.h"

#include "draglab/error.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace draglab {
namespace lbm {
namespace {

using d3q19::kC;
using d3q19::kOpposite;
using d3q19::kQ;

inline int thread_id() {
#if defined(_OPENMP)
  return omp_get_thread_num();
#else
  return 0;
#endif
}
inline int team_size() {
#if defined(_OPENMP)
  return omp_get_num_threads();
#else
  return 1;
#endif
}

// The sweeps name their 19 row pointers one by one: with an array of pointers GCC 12 reloads
// them inside the loop and does not vectorize it. Written out, each loop over nodes is a plain
// unit-stride SIMD loop over 19 streams (checked with -fopt-info-vec: 64-byte vectors).

/// Even step over the stored nodes [first, first + length): read row i, write row opp(i), same
/// node. The step touches no neighbour, so it runs over an x-row's whole stored range, ghosts
/// included, as one unit-stride loop, instead of over the row's fluid segments (short in a dense
/// packing, where each pays the loop's ends). A ghost's values are never read before they are
/// written again: the link pass of this step writes the slots of a ghost that the next step
/// reads (interpolated walls), and the masked odd sweep reads none (halfway bounce-back), so
/// what the collision leaves there does not matter.
template <typename T, CollisionKernel K, bool kStokes>
void even_sweep(T* base, std::int64_t stride, std::int64_t first, std::int64_t length,
                const KernelParams<T>& p) {
  const KernelParams<T> params = p;
  T* const r0 = base + 0 * stride + first;
  T* const r1 = base + 1 * stride + first;
  T* const r2 = base + 2 * stride + first;
  T* const r3 = base + 3 * stride + first;
  T* const r4 = base + 4 * stride + first;
  T* const r5 = base + 5 * stride + first;
  T* const r6 = base + 6 * stride + first;
  T* const r7 = base + 7 * stride + first;
  T* const r8 = base + 8 * stride + first;
  T* const r9 = base + 9 * stride + first;
  T* const r10 = base + 10 * stride + first;
  T* const r11 = base + 11 * stride + first;
  T* const r12 = base + 12 * stride + first;
  T* const r13 = base + 13 * stride + first;
  T* const r14 = base + 14 * stride + first;
  T* const r15 = base + 15 * stride + first;
  T* const r16 = base + 16 * stride + first;
  T* const r17 = base + 17 * stride + first;
  T* const r18 = base + 18 * stride + first;
#pragma GCC ivdep
  for (std::int64_t k = 0; k < length; ++k) {
    T g[kQ], o[kQ];
    g[0] = r0[k];
    g[1] = r1[k];
    g[2] = r2[k];
    g[3] = r3[k];
    g[4] = r4[k];
    g[5] = r5[k];
    g[6] = r6[k];
    g[7] = r7[k];
    g[8] = r8[k];
    g[9] = r9[k];
    g[10] = r10[k];
    g[11] = r11[k];
    g[12] = r12[k];
    g[13] = r13[k];
    g[14] = r14[k];
    g[15] = r15[k];
    g[16] = r16[k];
    g[17] = r17[k];
    g[18] = r18[k];
    collide_node<T, K, kStokes>(g, o, params);
    r0[k] = o[0];
    r2[k] = o[1];
    r1[k] = o[2];
    r4[k] = o[3];
    r3[k] = o[4];
    r6[k] = o[5];
    r5[k] = o[6];
    r8[k] = o[7];
    r7[k] = o[8];
    r10[k] = o[9];
    r9[k] = o[10];
    r12[k] = o[11];
    r11[k] = o[12];
    r14[k] = o[13];
    r13[k] = o[14];
    r16[k] = o[15];
    r15[k] = o[16];
    r18[k] = o[17];
    r17[k] = o[18];
  }
}

/// Odd step over the segments [first, last): read row opp(i) at x - c_i (= the write location
/// of opp(i)), write row i at x + c_i. Segments touching a wall take the masked variant: a solid
/// x - c_i makes the read come from row i at x, and a solid x + c_i adds a write of f*_i to row
/// opp(i) at x (halfway bounce-back; the write to the ghost is harmless). With `masked` false
/// (interpolated walls) every segment takes the plain loop: the link pass handles the walls.
template <typename T, CollisionKernel K, bool kStokes>
void odd_sweep(T* base, std::int64_t stride, const std::uint32_t* masks, const Segment* first,
               const Segment* last, const KernelParams<T>& p, bool masked) {
  const KernelParams<T> params = p;
  for (const Segment* s = first; s != last; ++s) {
    T* const w0 = base + s->write[0];
    T* const w1 = base + s->write[1];
    T* const w2 = base + s->write[2];
    T* const w3 = base + s->write[3];
    T* const w4 = base + s->write[4];
    T* const w5 = base + s->write[5];
    T* const w6 = base + s->write[6];
    T* const w7 = base + s->write[7];
    T* const w8 = base + s->write[8];
    T* const w9 = base + s->write[9];
    T* const w10 = base + s->write[10];
    T* const w11 = base + s->write[11];
    T* const w12 = base + s->write[12];
    T* const w13 = base + s->write[13];
    T* const w14 = base + s->write[14];
    T* const w15 = base + s->write[15];
    T* const w16 = base + s->write[16];
    T* const w17 = base + s->write[17];
    T* const w18 = base + s->write[18];
    const std::int64_t length = s->length;
    if (!s->wall || !masked) {
#pragma GCC ivdep
      for (std::int64_t k = 0; k < length; ++k) {
        T g[kQ], o[kQ];
        g[0] = w0[k];
        g[1] = w2[k];
        g[2] = w1[k];
        g[3] = w4[k];
        g[4] = w3[k];
        g[5] = w6[k];
        g[6] = w5[k];
        g[7] = w8[k];
        g[8] = w7[k];
        g[9] = w10[k];
        g[10] = w9[k];
        g[11] = w12[k];
        g[12] = w11[k];
        g[13] = w14[k];
        g[14] = w13[k];
        g[15] = w16[k];
        g[16] = w15[k];
        g[17] = w18[k];
        g[18] = w17[k];
        collide_node<T, K, kStokes>(g, o, params);
        w0[k] = o[0];
        w1[k] = o[1];
        w2[k] = o[2];
        w3[k] = o[3];
        w4[k] = o[4];
        w5[k] = o[5];
        w6[k] = o[6];
        w7[k] = o[7];
        w8[k] = o[8];
        w9[k] = o[9];
        w10[k] = o[10];
        w11[k] = o[11];
        w12[k] = o[12];
        w13[k] = o[13];
        w14[k] = o[14];
        w15[k] = o[15];
        w16[k] = o[16];
        w17[k] = o[17];
        w18[k] = o[18];
      }
      continue;
    }
    T* const h1 = base + 1 * stride + s->first;
    T* const h2 = base + 2 * stride + s->first;
    T* const h3 = base + 3 * stride + s->first;
    T* const h4 = base + 4 * stride + s->first;
    T* const h5 = base + 5 * stride + s->first;
    T* const h6 = base + 6 * stride + s->first;
    T* const h7 = base + 7 * stride + s->first;
    T* const h8 = base + 8 * stride + s->first;
    T* const h9 = base + 9 * stride + s->first;
    T* const h10 = base + 10 * stride + s->first;
    T* const h11 = base + 11 * stride + s->first;
    T* const h12 = base + 12 * stride + s->first;
    T* const h13 = base + 13 * stride + s->first;
    T* const h14 = base + 14 * stride + s->first;
    T* const h15 = base + 15 * stride + s->first;
    T* const h16 = base + 16 * stride + s->first;
    T* const h17 = base + 17 * stride + s->first;
    T* const h18 = base + 18 * stride + s->first;
    const std::uint32_t* mask = masks + s->first;
#pragma GCC ivdep
    for (std::int64_t k = 0; k < length; ++k) {
      T g[kQ], o[kQ];
      const std::uint32_t m = mask[k];
      g[0] = w0[k];
      g[1] = (m >> 2) & 1u ? h1[k] : w2[k];
      g[2] = (m >> 1) & 1u ? h2[k] : w1[k];
      g[3] = (m >> 4) & 1u ? h3[k] : w4[k];
      g[4] = (m >> 3) & 1u ? h4[k] : w3[k];
      g[5] = (m >> 6) & 1u ? h5[k] : w6[k];
      g[6] = (m >> 5) & 1u ? h6[k] : w5[k];
      g[7] = (m >> 8) & 1u ? h7[k] : w8[k];
      g[8] = (m >> 7) & 1u ? h8[k] : w7[k];
      g[9] = (m >> 10) & 1u ? h9[k] : w10[k];
      g[10] = (m >> 9) & 1u ? h10[k] : w9[k];
      g[11] = (m >> 12) & 1u ? h11[k] : w12[k];
      g[12] = (m >> 11) & 1u ? h12[k] : w11[k];
      g[13] = (m >> 14) & 1u ? h13[k] : w14[k];
      g[14] = (m >> 13) & 1u ? h14[k] : w13[k];
      g[15] = (m >> 16) & 1u ? h15[k] : w16[k];
      g[16] = (m >> 15) & 1u ? h16[k] : w15[k];
      g[17] = (m >> 18) & 1u ? h17[k] : w18[k];
      g[18] = (m >> 17) & 1u ? h18[k] : w17[k];
      collide_node<T, K, kStokes>(g, o, params);
      w0[k] = o[0];
      w1[k] = o[1];
      w2[k] = o[2];
      w3[k] = o[3];
      w4[k] = o[4];
      w5[k] = o[5];
      w6[k] = o[6];
      w7[k] = o[7];
      w8[k] = o[8];
      w9[k] = o[9];
      w10[k] = o[10];
      w11[k] = o[11];
      w12[k] = o[12];
      w13[k] = o[13];
      w14[k] = o[14];
      w15[k] = o[15];
      w16[k] = o[16];
      w17[k] = o[17];
      w18[k] = o[18];
      if ((m >> 1) & 1u) h2[k] = o[1];
      if ((m >> 2) & 1u) h1[k] = o[2];
      if ((m >> 3) & 1u) h4[k] = o[3];
      if ((m >> 4) & 1u) h3[k] = o[4];
      if ((m >> 5) & 1u) h6[k] = o[5];
      if ((m >> 6) & 1u) h5[k] = o[6];
      if ((m >> 7) & 1u) h8[k] = o[7];
      if ((m >> 8) & 1u) h7[k] = o[8];
      if ((m >> 9) & 1u) h10[k] = o[9];
      if ((m >> 10) & 1u) h9[k] = o[10];
      if ((m >> 11) & 1u) h12[k] = o[11];
      if ((m >> 12) & 1u) h11[k] = o[12];
      if ((m >> 13) & 1u) h14[k] = o[13];
      if ((m >> 14) & 1u) h13[k] = o[14];
      if ((m >> 15) & 1u) h16[k] = o[15];
      if ((m >> 16) & 1u) h15[k] = o[16];
      if ((m >> 17) & 1u) h18[k] = o[17];
      if ((m >> 18) & 1u) h17[k] = o[18];
    }
  }
}

/// Interior rows between two calls that let the halo exchange progress.
constexpr std::int64_t kProgressRows = 64;

/// Per-step relaxation of rr's wall correction towards its steady value (Solver::wall_correction).
/// Any value in (0, 1] gives the same steady state; 1 (no filter) diverges in dense packings at
/// finite Re, where the correction's feedback through the moments of a node with several wall
/// links exceeds one.
constexpr double kWallCorrectionRate = 0.1;
/// The feedback grows with the correction's factor c (large as tau -> 1/2): the rate is also
/// held to kWallCorrectionGain / c, which keeps rate x c, the filtered loop gain, bounded.
constexpr double kWallCorrectionGain = 5.0;

/// Links ahead that the link pass prefetches.
constexpr std::int64_t kLinkPrefetch = 16;

/// y-rows of a sweep tile (see SweepPlan).
constexpr std::int64_t kTileRows = 8;

/// The order in which one work range sweeps its x-rows and, after each row, the rows whose link
/// pass may then run. A link of row (j, p) reads and writes nodes of the rows (j + c_y, p + c_z)
/// only (|c_y|, |c_z| <= 1, periodic), so its pass may run once those are swept; run then, it finds
/// them cached. Rows are swept in tiles of kTileRows y-rows, plane by plane through the range
/// (tile by tile), so that a row's neighbours are swept a few rows after it, and not a plane or
/// two (the x-row order) after it, while the sweeps still walk a few whole rows of storage at a
/// time. Rows whose neighbours another range sweeps run after the step's barrier.
struct SweepPlan {
  std::vector<std::int64_t> order;        ///< Rows in sweep order.
  std::vector<std::int64_t> ready_begin;  ///< Link rows after order[s]: ready[ready_begin[s] ..).
  std::vector<std::int64_t> ready;
  std::vector<std::int64_t> after_barrier;
};

/// The last position in a range's sweep order (`position`: by row - r0) of the rows that the
/// links of row r touch, or -1 if another range sweeps one of them.
std::int64_t ready_position(std::int64_t r, std::int64_t ny, std::int64_t planes, std::int64_t r0,
                            std::int64_t r1, const std::vector<std::int64_t>& position) {
  const std::int64_t j = r % ny, p = r / ny;
  std::int64_t last = -1;
  for (std::int64_t cz = -1; cz <= 1; ++cz) {
    for (std::int64_t cy = -1; cy <= 1; ++cy) {
      const std::int64_t n = (j + cy + ny) % ny + ny * ((p + cz + planes) % planes);
      if (n < r0 || n >= r1) return -1;
      last = std::max(last, position[static_cast<std::size_t>(n - r0)]);
    }
  }
  return last;
}

SweepPlan plan_sweep(const SparseLattice& lattice, const LinkTable& links, int range) {
  const std::int64_t ny = lattice.dims()[1];
  const std::int64_t planes = lattice.num_rows() / ny;
  const std::int64_t r0 = lattice.range_row_begin(range);
  const std::int64_t r1 = lattice.range_row_begin(range + 1);
  SweepPlan plan;
  for (std::int64_t r = r0; r < r1; ++r) plan.order.push_back(r);
  std::stable_sort(plan.order.begin(), plan.order.end(), [ny](std::int64_t a, std::int64_t b) {
    return (a % ny) / kTileRows < (b % ny) / kTileRows;
  });
  std::vector<std::int64_t> position(static_cast<std::size_t>(r1 - r0));
  for (std::size_t s = 0; s < plan.order.size(); ++s) {
    position[static_cast<std::size_t>(plan.order[s] - r0)] = static_cast<std::int64_t>(s);
  }
  std::vector<std::vector<std::int64_t>> after(plan.order.size());
  for (std::int64_t r = r0; r < r1; ++r) {
    const std::size_t row = static_cast<std::size_t>(r);
    if (links.row_begin[row] == links.row_begin[row + 1]) continue;
    const std::int64_t last = ready_position(r, ny, planes, r0, r1, position);
    (last < 0 ? plan.after_barrier : after[static_cast<std::size_t>(last)]).push_back(r);
  }
  plan.ready_begin.push_back(0);
  for (const auto& rows : after) {
    plan.ready.insert(plan.ready.end(), rows.begin(), rows.end());
    plan.ready_begin.push_back(static_cast<std::int64_t>(plan.ready.size()));
  }
  return plan;
}

template <typename T>
class Solver final : public SolverBase {
 public:
  Solver(const SparseLattice& lattice, const LinkTable& links, const SolverSettings& settings,
         int threads, const mpi::Communicator& group)
      : lattice_(lattice),
        links_(links),
        settings_(settings),
        threads_(std::max(1, threads)),
        group_(group),
        populations_(lattice, threads_) {
    // Small lattices: below ~32k fluid nodes per thread a step takes well under a millisecond
    // and the parallel region costs more than it saves (and much more when other processes
    // share the cores: a descheduled thread stalls the barrier).
    threads_ = static_cast<int>(std::clamp<std::int64_t>(lattice.num_fluid() / 32768, 1, threads_));
    const int ranges = lattice.num_ranges();
    partial_force_.resize(static_cast<std::size_t>(ranges));
    partial_defect_.assign(static_cast<std::size_t>(ranges), 0.0);
    for (std::size_t l = 0; l < links.size(); ++l) {
      if (l == 0 || links.node[l] != links.node[l - 1]) ++boundary_nodes_;
    }
    if (lattice.decomposed() != (group.size() > 1)) {
      throw Error(ErrorCode::kInternal,
                  "lbm: a decomposed lattice needs the group of its ranks, and only it does");
    }
    const HaloPlan& plan = lattice.halo();
    send_down_.resize(std::max(plan.low_owned.size(), plan.low_halo.size()));
    send_up_.resize(std::max(plan.high_owned.size(), plan.high_halo.size()));
    receive_down_.resize(send_down_.size());
    receive_up_.resize(send_up_.size());
    set_force(settings.force_x);
    if (!lattice.decomposed()) {
      for (int t = 0; t < ranges; ++t) sweep_plans_.push_back(plan_sweep(lattice, links, t));
    }
    if (settings.interpolated && settings.wall_correction > 0.0) {
      wall_state_.assign(links.size(), 0.0);
      wall_rate_ = std::min(kWallCorrectionRate, kWallCorrectionGain / settings.wall_correction);
      wall_gain_ = wall_gains(links, settings.wall_correction);
    }
  }

  /// Per link, the factor of wall_correction()'s steady value (its division done once):
  /// c0 / (1 + c0) on a link of a one-node gap, c / (1 + c/2) with c = (1 - b) c0 elsewhere.
  static std::vector<double> wall_gains(const LinkTable& links, double c0) {
    std::vector<double> gain(links.size());
    for (std::size_t l = 0; l < gain.size(); ++l) {
      const double c = (1.0 - links.weight_b[l]) * c0;
      gain[l] = links.partner[l] >= 0 ? c0 / (1.0 + c0) : c / (1.0 + 0.5 * c);
    }
    return gain;
  }

  void set_force(double force_x) override {
    settings_.force_x = force_x;
    params_.omega_plus = static_cast<T>(settings_.omega_plus);
    params_.omega_minus = static_cast<T>(settings_.omega_minus);
    params_.force_x = static_cast<T>(force_x);
    params_.force_even = static_cast<T>((1.0 - 0.5 * settings_.omega_plus) * force_x);
    params_.force_odd = static_cast<T>((1.0 - 0.5 * settings_.omega_minus) * force_x);
  }

  void advance_pair(std::vector<double>* body_force) override {
    step(0, body_force != nullptr ? &even_force_ : nullptr);
    step(1, body_force);
    if (body_force != nullptr) {
      // Mean over the pair: the steady state of the AA pair map may carry a period-2
      // (checkerboard) component, whose momentum exchange cancels only over two steps.
      for (std::size_t k = 0; k < body_force->size(); ++k) {
        (*body_force)[k] = 0.5 * ((*body_force)[k] + even_force_[k]);
      }
    }
  }

  double force_magnitude() const override { return force_magnitude_; }

  /// Boundary nodes of the whole box (summed over the ranks at the first step: the constructor
  /// stays local, so that a rank that cannot build its solver fails alone and reports it).
  std::int64_t boundary_nodes() {
    if (global_boundary_nodes_ < 0) {
      global_boundary_nodes_ = std::max<std::int64_t>(1, group_.sum(boundary_nodes_));
    }
    return global_boundary_nodes_;
  }

  MomentSummary moments() const override {
    const int ranges = lattice_.num_ranges();
    std::vector<MomentSummary> partial(static_cast<std::size_t>(ranges));
    const T* base = populations_.data();
    const std::int64_t stride = populations_.stride();
    const bool stokes = settings_.stokes;
    const double half_force = 0.5 * settings_.force_x;
    const auto& segments = lattice_.segments();
#pragma omp parallel num_threads(threads_)
    {
      for (int r = thread_id(); r < ranges; r += team_size()) {
        MomentSummary m;
        double sum_drho = 0.0, sx = 0.0, sy = 0.0, sz = 0.0;
        for (std::int64_t seg = lattice_.range_segment_begin(r);
             seg < lattice_.range_segment_begin(r + 1); ++seg) {
          const Segment& sg = segments[static_cast<std::size_t>(seg)];
          for (std::int64_t n = sg.first; n < sg.first + sg.length; ++n) {
            double drho = 0.0, jx = half_force, jy = 0.0, jz = 0.0;
            bool finite = true;
            for (int i = 0; i < kQ; ++i) {
              const double g = base[i * stride + n];
              finite = finite && std::isfinite(g);
              drho += g;
              jx += g * kC[i][0];
              jy += g * kC[i][1];
              jz += g * kC[i][2];
            }
            if (!finite) {
              if (m.nonfinite_node < 0) m.nonfinite_node = lattice_.node(n);
              continue;
            }
            const double rho = 1.0 + drho;
            const double inv = stokes ? 1.0 : 1.0 / rho;
            const double ux = jx * inv, uy = jy * inv, uz = jz * inv;
            sx += ux;
            sy += uy;
            sz += uz;
            sum_drho += drho;
            const double speed2 = ux * ux + uy * uy + uz * uz;
            if (speed2 > m.max_speed2 || m.max_speed_node < 0) {
              m.max_speed2 = speed2;
              m.max_speed_node = lattice_.node(n);
            }
            if (rho < m.min_rho || m.min_rho_node < 0) {
              m.min_rho = rho;
              m.min_rho_node = lattice_.node(n);
            }
          }
        }
        m.sum_u[0] = sx;
        m.sum_u[1] = sy;
        m.sum_u[2] = sz;
        m.sum_drho = sum_drho;
        partial[static_cast<std::size_t>(r)] = m;
      }
    }
    if (group_.size() > 1) partial = gather_moments(partial);
    MomentSummary total;
    for (const MomentSummary& m : partial) {
      for (int c = 0; c < 3; ++c) total.sum_u[c] += m.sum_u[c];
      total.sum_drho += m.sum_drho;
      if (m.nonfinite_node >= 0 && total.nonfinite_node < 0)
        total.nonfinite_node = m.nonfinite_node;
      if (m.max_speed_node >= 0 && (total.max_speed_node < 0 || m.max_speed2 > total.max_speed2)) {
        total.max_speed2 = m.max_speed2;
        total.max_speed_node = m.max_speed_node;
      }
      if (m.min_rho_node >= 0 && (total.min_rho_node < 0 || m.min_rho < total.min_rho)) {
        total.min_rho = m.min_rho;
        total.min_rho_node = m.min_rho_node;
      }
    }
    return total;
  }

  void scale_deviations(double factor) override {
    T* base = populations_.data();
    const std::int64_t stride = populations_.stride();
    const T f = static_cast<T>(factor);
    const int ranges = lattice_.num_ranges();
#pragma omp parallel num_threads(threads_)
    {
      for (int r = thread_id(); r < ranges; r += team_size()) {
        const std::int64_t begin = lattice_.range_storage_begin(r);
        const std::int64_t end = lattice_.range_storage_begin(r + 1);
        for (int i = 0; i < kQ; ++i) {
          T* row = base + i * stride;
#pragma omp simd
          for (std::int64_t n = begin; n < end; ++n) row[n] *= f;
        }
      }
    }
    pending_defect_ *= factor;  // the leak is linear in the deviations too
  }

  void fill_fields(Fields* fields) const override {
    // This rank's planes of the dense grid (all of them without decomposition).
    const PlaneRange& planes = lattice_.planes();
    const std::int64_t plane_nodes = lattice_.dims()[0] * lattice_.dims()[1];
    const std::int64_t offset = planes.begin * plane_nodes;
    const std::int64_t total = (planes.end - planes.begin) * plane_nodes;
    Fields local;
    local.velocity.assign(static_cast<std::size_t>(3 * total), 0.0f);
    local.density.assign(static_cast<std::size_t>(total), 0.0f);
    local.solid.assign(static_cast<std::size_t>(total), 1);
    const T* base = populations_.data();
    const std::int64_t stride = populations_.stride();
    const double half_force = 0.5 * settings_.force_x;
    for (const Segment& sg : lattice_.segments()) {
      for (std::int64_t n = sg.first; n < sg.first + sg.length; ++n) {
        const std::size_t d = static_cast<std::size_t>(lattice_.node(n) - offset);
        double drho = 0.0, j[3] = {half_force, 0.0, 0.0};
        for (int i = 0; i < kQ; ++i) {
          const double g = base[i * stride + n];
          drho += g;
          for (int c = 0; c < 3; ++c) j[c] += g * kC[i][c];
        }
        const double inv = settings_.stokes ? 1.0 : 1.0 / (1.0 + drho);
        for (int c = 0; c < 3; ++c) local.velocity[3 * d + c] = static_cast<float>(j[c] * inv);
        local.density[d] = static_cast<float>(1.0 + drho);
        local.solid[d] = 0;
      }
    }
    fields->dims = lattice_.dims();
    if (group_.size() == 1) {
      fields->velocity = std::move(local.velocity);
      fields->density = std::move(local.density);
      fields->solid = std::move(local.solid);
      return;
    }
    // Rank r owns the planes after rank r - 1's: the gather in rank order is the dense order.
    const std::size_t plane = static_cast<std::size_t>(plane_nodes);
    group_.gather_to_root(local.velocity, 3 * plane, &fields->velocity);
    group_.gather_to_root(local.density, plane, &fields->density);
    group_.gather_to_root(local.solid, plane, &fields->solid);
  }

  std::size_t bytes() const override {
    return populations_.bytes() + (wall_state_.size() + wall_gain_.size()) * sizeof(double);
  }
  std::vector<StateSection> state() override {
    std::vector<StateSection> sections = {
        {"populations", populations_.data(), populations_.bytes()},
        {"mass_defect", &pending_defect_, sizeof pending_defect_},
        {"force_magnitude", &force_magnitude_, sizeof force_magnitude_}};
    if (!wall_state_.empty()) {
      sections.push_back(
          {"wall_correction", wall_state_.data(), wall_state_.size() * sizeof(double)});
    }
    return sections;
  }
  double deviation(int i, std::int64_t n) const override {
    return populations_.data()[i * populations_.stride() + n];
  }
  void set_deviation(int i, std::int64_t n, double value) override {
    populations_.data()[i * populations_.stride() + n] = static_cast<T>(value);
  }

 private:
  /// One time step in one parallel region: the collision sweep of the given parity and, when
  /// interpolating or when body_force != nullptr, the link pass, each thread over the links of
  /// its own x-rows, each row's as soon as the rows it touches are swept (SweepPlan; the rows at
  /// the ends of its range after a barrier). With interpolated walls the sweeps run without the
  /// solid-neighbour masks.
  /// (docs/scaling.md has what each part costs.)
  void step(int parity, std::vector<double>* body_force) {
    switch (settings_.kernel) {
      case CollisionKernel::kTrt:
        settings_.stokes ? step_with<CollisionKernel::kTrt, true>(parity, body_force)
                         : step_with<CollisionKernel::kTrt, false>(parity, body_force);
        break;
      case CollisionKernel::kRegularized:
        settings_.stokes ? step_with<CollisionKernel::kRegularized, true>(parity, body_force)
                         : step_with<CollisionKernel::kRegularized, false>(parity, body_force);
        break;
    }
  }

  template <CollisionKernel K, bool kStokes>
  void step_with(int parity, std::vector<double>* body_force) {
    if (lattice_.decomposed()) {
      step_decomposed<K, kStokes>(parity, body_force);
      return;
    }
    T* base = populations_.data();
    const std::int64_t stride = populations_.stride();
    const KernelParams<T> p = params_;
    const int ranges = lattice_.num_ranges();
    const Segment* segments = lattice_.segments().data();
    const std::uint32_t* masks = lattice_.solid_masks();
    const bool update = settings_.interpolated;
    const bool masked = !settings_.interpolated;
    const bool links = update || body_force != nullptr;
    const double correction = begin_step(body_force);
    const bool forces = body_force != nullptr;
    // Each range sweeps its rows in its plan's order and runs the link pass of a row as soon as
    // the rows it touches are swept (SweepPlan), those next to another range after the barrier.
#pragma omp parallel num_threads(threads_)
    {
      for (int t = thread_id(); t < ranges; t += team_size()) {
        const SweepPlan& plan = sweep_plans_[static_cast<std::size_t>(t)];
        for (std::size_t s = 0; s < plan.order.size(); ++s) {
          const std::int64_t r = plan.order[s];
          const Segment* first = segments + lattice_.row_segment_begin(r);
          const Segment* last = segments + lattice_.row_segment_begin(r + 1);
          if (parity == 0) {
            if (first != last) {
              const std::int64_t begin = lattice_.row_storage_begin(r);
              even_sweep<T, K, kStokes>(base, stride, begin,
                                        lattice_.row_storage_begin(r + 1) - begin, p);
            }
          } else {
            odd_sweep<T, K, kStokes>(base, stride, masks, first, last, p, masked);
          }
          if (!links) continue;
          for (std::int64_t k = plan.ready_begin[s]; k < plan.ready_begin[s + 1]; ++k) {
            link_row(t, plan.ready[static_cast<std::size_t>(k)], parity, update, forces,
                     correction);
          }
        }
      }
      if (links) {
        // Every post-collision value of this step must be in place before the remaining links
        // read it.
#pragma omp barrier
        for (int t = thread_id(); t < ranges; t += team_size()) {
          for (std::int64_t r : sweep_plans_[static_cast<std::size_t>(t)].after_barrier) {
            link_row(t, r, parity, update, forces, correction);
          }
        }
      }
    }
    finish_step(parity, update, body_force);
  }

  /// Clears the link pass's partial sums for a step and returns the mass correction it applies:
  /// the net mass the interpolation added in the previous step, returned evenly through the
  /// rest populations of the boundary nodes (c_0 = 0: no momentum change). Only the net leak is
  /// corrected (local defects largely cancel, exactly so for a symmetric body in Stokes flow,
  /// and correcting them locally would perturb the second-order wall), so the total mass stays
  /// constant to within one step's leak.
  double begin_step(std::vector<double>* body_force) {
    if (body_force != nullptr) {
      for (auto& partial : partial_force_) partial.assign(3 * links_.num_bodies() + 1, 0.0);
    }
    for (auto& d : partial_defect_) d = 0.0;
    return settings_.mass_correction && settings_.interpolated
               ? pending_defect_ / static_cast<double>(boundary_nodes())
               : 0.0;
  }

  /// The link pass of this thread (inside a parallel region): the links of its work ranges.
  void link_ranges(int parity, bool update, bool forces, double correction) {
    const int ranges = lattice_.num_ranges();
    for (int t = thread_id(); t < ranges; t += team_size()) {
      const std::int64_t r0 = lattice_.range_row_begin(t), r1 = lattice_.range_row_begin(t + 1);
      for (std::int64_t r = r0; r < r1; ++r) link_row(t, r, parity, update, forces, correction);
    }
  }

  /// The sums of a step's link pass: the mass defect and the body forces, over the work ranges
  /// in a fixed order (the same result whatever the thread timing) and then over the ranks.
  void finish_step(int parity, bool update, std::vector<double>* body_force) {
    const std::size_t bodies = links_.num_bodies();
    if (update) {
      pending_defect_ = 0.0;
      for (double d : partial_defect_) pending_defect_ += d;
    }
    if (body_force == nullptr) {
      if (update) pending_defect_ = group_.sum(pending_defect_);
      return;
    }
    std::vector<double> sums(3 * bodies + 2, 0.0);
    for (const auto& partial : partial_force_) {
      for (std::size_t k = 0; k <= 3 * bodies; ++k) sums[k] += partial[k];
    }
    sums[3 * bodies + 1] = pending_defect_;
    group_.sum(&sums);  // one collective for the forces, their magnitude and the defect
    if (update) pending_defect_ = sums[3 * bodies + 1];
    body_force->assign(sums.begin(), sums.begin() + static_cast<std::ptrdiff_t>(3 * bodies));
    const double magnitude = sums[3 * bodies];
    force_magnitude_ = parity == 1 ? 0.5 * (force_magnitude_ + magnitude) : magnitude;
  }

  /// One step of a rank of a decomposed box: the sweep of the two boundary planes, then the
  /// interior sweep while the populations crossing the interfaces travel (see HaloPlan), then
  /// the link pass once they have arrived (links next to an interface read them).
  template <CollisionKernel K, bool kStokes>
  void step_decomposed(int parity, std::vector<double>* body_force) {
    T* base = populations_.data();
    const std::int64_t stride = populations_.stride();
    const KernelParams<T> p = params_;
    const Segment* segments = lattice_.segments().data();
    const std::uint32_t* masks = lattice_.solid_masks();
    const bool update = settings_.interpolated;
    const bool masked = !settings_.interpolated;
    const bool links = update || body_force != nullptr;
    const double correction = begin_step(body_force);
    const HaloPlan& plan = lattice_.halo();
    // Even step: the owned values go out, the halo's come in; odd step: the values this rank's
    // nodes wrote into the halo go back to their owners.
    const auto& send_down = parity == 0 ? plan.low_owned : plan.low_halo;
    const auto& send_up = parity == 0 ? plan.high_owned : plan.high_halo;
    const auto& receive_down = parity == 0 ? plan.low_halo : plan.low_owned;
    const auto& receive_up = parity == 0 ? plan.high_halo : plan.high_owned;
    auto sweep = [&](std::int64_t r) {
      const Segment* first = segments + lattice_.row_segment_begin(r);
      const Segment* last = segments + lattice_.row_segment_begin(r + 1);
      if (parity == 0) {
        if (first != last) {
          const std::int64_t begin = lattice_.row_storage_begin(r);
          even_sweep<T, K, kStokes>(base, stride, begin, lattice_.row_storage_begin(r + 1) - begin,
                                    p);
        }
      } else {
        odd_sweep<T, K, kStokes>(base, stride, masks, first, last, p, masked);
      }
    };
    const std::int64_t boundary_rows = static_cast<std::int64_t>(plan.boundary_rows.size());
    const std::int64_t interior_rows = static_cast<std::int64_t>(plan.interior_rows.size());
    std::exception_ptr failure;
#pragma omp parallel num_threads(threads_)
    {
#pragma omp for schedule(dynamic, 4)
      for (std::int64_t b = 0; b < boundary_rows; ++b) {
        sweep(plan.boundary_rows[static_cast<std::size_t>(b)]);
      }
#pragma omp master
      {
        try {
          for (std::size_t k = 0; k < send_down.size(); ++k) send_down_[k] = base[send_down[k]];
          for (std::size_t k = 0; k < send_up.size(); ++k) send_up_[k] = base[send_up[k]];
          exchange_.start(group_, send_down_.data(), send_down.size() * sizeof(T), send_up_.data(),
                          send_up.size() * sizeof(T), receive_down_.data(),
                          receive_down.size() * sizeof(T), receive_up_.data(),
                          receive_up.size() * sizeof(T));
        } catch (...) {
          failure = std::current_exception();
        }
      }
#pragma omp for schedule(dynamic, 16)
      for (std::int64_t b = 0; b < interior_rows; ++b) {
        sweep(plan.interior_rows[static_cast<std::size_t>(b)]);
        // MPI moves a large message only inside its calls: the master thread lets it progress
        // now and then while the interior is swept.
        if (thread_id() == 0 && b % kProgressRows == 0 && !failure) exchange_.progress();
      }
#pragma omp master
      {
        if (!failure) {
          try {
            exchange_.wait();
            for (std::size_t k = 0; k < receive_down.size(); ++k) {
              base[receive_down[k]] = receive_down_[k];
            }
            for (std::size_t k = 0; k < receive_up.size(); ++k)
              base[receive_up[k]] = receive_up_[k];
          } catch (...) {
            failure = std::current_exception();
          }
        }
      }
#pragma omp barrier
      if (links && !failure) link_ranges(parity, update, body_force != nullptr, correction);
    }
    if (failure) std::rethrow_exception(failure);
    finish_step(parity, update, body_force);
  }

  /// Every rank's work-range summaries, in rank order (nodes are dense indices already).
  std::vector<MomentSummary> gather_moments(const std::vector<MomentSummary>& mine) const {
    constexpr std::size_t kFields = 9;
    // The ranks may have different numbers of work ranges: gather one summary per rank.
    MomentSummary own;
    for (const MomentSummary& m : mine) {
      for (int c = 0; c < 3; ++c) own.sum_u[c] += m.sum_u[c];
      own.sum_drho += m.sum_drho;
      if (m.nonfinite_node >= 0 && own.nonfinite_node < 0) own.nonfinite_node = m.nonfinite_node;
      if (m.max_speed_node >= 0 && (own.max_speed_node < 0 || m.max_speed2 > own.max_speed2)) {
        own.max_speed2 = m.max_speed2;
        own.max_speed_node = m.max_speed_node;
      }
      if (m.min_rho_node >= 0 && (own.min_rho_node < 0 || m.min_rho < own.min_rho)) {
        own.min_rho = m.min_rho;
        own.min_rho_node = m.min_rho_node;
      }
    }
    const std::vector<double> one = {own.sum_u[0],
                                     own.sum_u[1],
                                     own.sum_u[2],
                                     own.sum_drho,
                                     own.max_speed2,
                                     static_cast<double>(own.max_speed_node),
                                     own.min_rho,
                                     static_cast<double>(own.min_rho_node),
                                     static_cast<double>(own.nonfinite_node)};
    const std::vector<double> all = group_.allgather(one);
    std::vector<MomentSummary> out(static_cast<std::size_t>(group_.size()));
    for (std::size_t r = 0; r < out.size(); ++r) {
      const double* v = all.data() + kFields * r;
      MomentSummary& m = out[r];
      m.sum_u[0] = v[0];
      m.sum_u[1] = v[1];
      m.sum_u[2] = v[2];
      m.sum_drho = v[3];
      m.max_speed2 = v[4];
      m.max_speed_node = static_cast<std::int64_t>(v[5]);
      m.min_rho = v[6];
      m.min_rho_node = static_cast<std::int64_t>(v[7]);
      m.nonfinite_node = static_cast<std::int64_t>(v[8]);
    }
    return out;
  }

  /// The links of x-row `row` (see solver.h): interpolated bounce-back with the mass
  /// correction when `update`, momentum exchange per body into range t's partial sums when
  /// `forces`. The reflected value is computed from the same post-collision values either way,
  /// so the force is that of the populations the fluid receives.
  /// (`update` is true exactly with interpolated walls; the pass is compiled for each
  /// combination of the switches, so that the per-link loop carries no test of them.)
  void link_row(int t, std::int64_t row, int parity, bool update, bool forces, double correction) {
    const bool correct = !wall_state_.empty();
    if (update) {
      if (correct) {
        forces ? link_row_with<true, true, true>(t, row, parity, correction)
               : link_row_with<true, true, false>(t, row, parity, correction);
      } else {
        forces ? link_row_with<true, false, true>(t, row, parity, correction)
               : link_row_with<true, false, false>(t, row, parity, correction);
      }
    } else if (forces) {
      link_row_with<false, false, true>(t, row, parity, correction);
    }
  }

  template <bool kInterpolated, bool kCorrect, bool kForces>
  void link_row_with(int t, std::int64_t row, int parity, double correction) {
    T* base = populations_.data();
    const LinkTable& L = links_;
    const std::int64_t begin = L.row_begin[static_cast<std::size_t>(row)];
    const std::int64_t end = L.row_begin[static_cast<std::size_t>(row) + 1];
    if (begin == end) return;
    constexpr bool interpolate = kInterpolated;
    constexpr bool update = kInterpolated;
    // Even parity: f*_i(r - c_i) at a, f*_ib(r) at b; odd parity: the other way round (the
    // weights follow the values, not the positions).
    const std::int64_t* first = parity == 0 ? L.a.data() : L.b.data();
    const std::int64_t* second = parity == 0 ? L.b.data() : L.a.data();
    // Halfway bounce-back in the kernels (masked sweeps): the value leaving r and the one coming
    // back share the slot row opp(i) at r. Interpolated walls (plain sweeps): the odd sweep
    // writes the leaving value into the solid neighbour's slot, row i at r + c_i, and reads the
    // one coming back from there; the pass moves each value to where the next step reads it.
    constexpr bool plain = kInterpolated;
    const std::int64_t* out = plain && parity == 1 ? L.ghost.data() : L.self.data();
    const std::int64_t* in = plain && parity == 0 ? L.ghost.data() : L.self.data();
    const std::int32_t* node = L.node.data();
    const double* weight_a = L.weight_a.data();
    const double* weight_b = L.weight_b.data();
    double* force = kForces ? partial_force_[static_cast<std::size_t>(t)].data() : nullptr;
    double defect = 0.0;
    for (std::int64_t l = begin; l < end; ++l) {
      if (l + kLinkPrefetch < end) {
        // The pass is bound by the latency of its scattered loads (last-level-cache hits on
        // this machine); prefetching a few links ahead keeps more of them in flight.
        __builtin_prefetch(base + out[l + kLinkPrefetch], 0);
        __builtin_prefetch(base + in[l + kLinkPrefetch], 1);
        __builtin_prefetch(base + first[l + kLinkPrefetch], 0);
        __builtin_prefetch(base + second[l + kLinkPrefetch], 0);
      }
      const double f = base[out[l]];
      double back = f;
      if constexpr (interpolate) {
        const double fa = base[first[l]], fb = base[second[l]];
        double reflected = f + weight_a[l] * (fa - f) + weight_b[l] * (fb - f);
        if constexpr (kCorrect)
          reflected += wall_correction(l, reflected, f, fa, fb, base, out, update);
        back = static_cast<T>(reflected);  // in float, rounded as the fluid receives it
      }
      if constexpr (update) {
        base[in[l]] = static_cast<T>(back);
        defect += back - f;
        if (l + 1 == end || node[l + 1] != node[l]) {
          base[node[l]] = static_cast<T>(base[node[l]] - correction);
        }
      }
      if constexpr (kForces) {
        // f = g + w. The rest part 2 w_i c_i (the reference pressure) sums to zero over the whole
        // fluid-solid interface (along every lattice line, as many fluid-to-solid links as
        // solid-to-fluid ones), but not over one body whose links in a sub-node gap were given to
        // the neighbour they cross first: it is left out of the bodies' forces, which it would
        // offset by a constant of order w / (nu U) each, and kept in the round-off scale.
        const int q = L.direction[l];
        const double sum = f + back;
        const auto& c = kC[q];
        double* fb = force + 3 * static_cast<std::size_t>(L.body[l]);
        force[3 * links_.num_bodies()] += std::abs((sum + 2.0 * d3q19::weight(q)) * c[0]);
        fb[0] += sum * c[0];
        fb[1] += sum * c[1];
        fb[2] += sum * c[2];
      }
    }
    partial_defect_[static_cast<std::size_t>(t)] += defect;
  }

  /// The regularized collision's wall correction of link l (lbm.h, Numerics), added to the plain
  /// closure's value k = f + a (f_a - f) + b (f_b - f): relaxed by wall_rate_ per step
  /// towards its implicit steady value, which damps its feedback through the wall node's moments
  /// and leaves the steady state as it is. `update` false (a force-only pass) keeps the state.
  /// The steady value, with c = (1 - b) c0: (k + c (h + g)) / (1 + c/2) - k = c (h + g - k/2) /
  /// (1 + c/2), h = (f_a - f + f_b)/2; on a link of a one-node gap (both links of the line
  /// halfway bounce-back, b = 0, solved together) c0 (f*_ib - f*_i + g) / (1 + c0).
  double wall_correction(std::int64_t l, double k, double f, double fa, double fb, const T* base,
                         const std::int64_t* out, bool update) {
    const LinkTable& L = links_;
    const auto link = static_cast<std::size_t>(l);
    const int q = L.direction[link];
    const double g = 3.0 * d3q19::weight(q) * kC[q][0] * settings_.force_x;
    const std::int64_t partner = L.partner[link];
    const double source =
        partner >= 0 ? base[out[partner]] - f + g : 0.5 * (fa - f + fb) + g - 0.5 * k;
    const double target = wall_gain_[link] * source;
    double& state = wall_state_[link];
    const double next = state + wall_rate_ * (target - state);
    if (update) state = next;
    return next;
  }

  const SparseLattice& lattice_;
  const LinkTable& links_;
  SolverSettings settings_;
  int threads_;
  mpi::Communicator group_;
  Populations<T> populations_;
  mpi::Communicator::RingExchange exchange_;
  std::vector<T> send_down_, send_up_, receive_down_, receive_up_;  ///< Halo message buffers.
  KernelParams<T> params_;
  std::vector<double> even_force_;
  std::vector<std::vector<double>> partial_force_;  ///< Per work range.
  std::vector<double> partial_defect_;              ///< Per work range.
  std::vector<double> wall_state_;  ///< Per link: rr's wall correction (empty: off).
  std::vector<double> wall_gain_;   ///< Per link: see wall_gains().
  double wall_rate_ = kWallCorrectionRate;
  std::vector<SweepPlan> sweep_plans_;  ///< Per work range (one rank's whole box only).
  double pending_defect_ = 0.0;         ///< Net mass added by the last interpolation pass.
  double force_magnitude_ = 0.0;        ///< See force_magnitude().
  std::int64_t boundary_nodes_ = 0;     ///< This rank's.
  std::int64_t global_boundary_nodes_ = -1;
};

}  // namespace

std::unique_ptr<SolverBase> make_solver(Precision precision, const SparseLattice& lattice,
                                        const LinkTable& links, const SolverSettings& settings,
                                        int threads, const mpi::Communicator& group) {
  if (precision == Precision::kFloat) {
    return std::make_unique<Solver<float>>(lattice, links, settings, threads, group);
  }
  return std::make_unique<Solver<double>>(lattice, links, settings, threads, group);
}

}  // namespace lbm
}  // namespace draglab
