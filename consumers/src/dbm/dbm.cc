// The discrete bubble model (consumers/src/dbm/dbm.h): emulsion on the 3-D MAC grid, bubbles,
// injection, coalescence and the time averages.
#include "dbm/dbm.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "draglab/error.h"
#include "gas/mac_operators.h"
#include "gas/mac_pressure.h"
#include "gas/particle_kernel.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fmt;
using Vec = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;
/// The emulsion fraction the emulsion equations see is kept above this where bubbles crowd
/// (counted as clamps): 0.6 bubble fraction is about the random close packing of spheres, beyond
/// which bubbles pushed together (collisions resolved by position) no longer displace more.
constexpr double kMinEmulsionFraction = 0.4;
/// Sweeps of the overlap resolution per step (each removes most of the remaining overlap).
constexpr int kCollisionSweeps = 4;
/// Loops run on several threads only above these sizes: a parallel region costs more than a
/// small loop, and far more when another process holds a core (the threads wait on each other).
constexpr int kParallelCells = 20000;
constexpr long kParallelBubbles = 20000;
/// Size bins of the bubble-size histogram: 1 cm, up to 1 m (the last bin takes larger ones).
constexpr int kSizeBins = 100;

[[noreturn]] void Bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

double SphereVolume(double d) { return kPi / 6.0 * d * d * d; }
double SphereDiameter(double volume) { return std::cbrt(6.0 * volume / kPi); }

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

BubbleForceOptions ForceOptions(const DbmOptions& o) {
  BubbleForceOptions f;
  f.emulsion_density_kg_m3 = o.emulsion_density_kg_m3;
  f.bubble_density_kg_m3 = o.bubble_density_kg_m3;
  f.virtual_mass_coefficient = o.virtual_mass_coefficient;
  f.gravity = Vec(0.0, 0.0, -o.gravity_m_s2);
  return f;
}

/// Pairs (a < b) of touching bubbles, |x_a - x_b| < r_a + r_b, from cell lists of the largest
/// diameter over the box [0, hi] (O(N)).
std::vector<std::pair<int, int>> TouchingPairs(const std::vector<DbmBubble>& bubbles,
                                               const std::array<double, 3>& hi) {
  std::vector<std::pair<int, int>> pairs;
  double d_max = 0.0;
  for (const DbmBubble& b : bubbles) d_max = std::max(d_max, b.diameter_m);
  if (bubbles.size() < 2 || d_max <= 0.0) return pairs;
  const double L[3] = {hi[0], hi[1], hi[2] * 1.01};
  int nb[3];
  for (int c = 0; c < 3; ++c) nb[c] = std::max(1, std::min(512, static_cast<int>(L[c] / d_max)));
  auto bin_of = [&](const Vec& x, int c) {
    return std::clamp(static_cast<int>(x(c) / L[c] * nb[c]), 0, nb[c] - 1);
  };
  const int bins = nb[0] * nb[1] * nb[2];
  std::vector<int> start(static_cast<std::size_t>(bins) + 1, 0), order(bubbles.size());
  std::vector<int> bin(bubbles.size());
  for (std::size_t b = 0; b < bubbles.size(); ++b) {
    const Vec& x = bubbles[b].x;
    bin[b] = bin_of(x, 0) + nb[0] * (bin_of(x, 1) + nb[1] * bin_of(x, 2));
    ++start[static_cast<std::size_t>(bin[b]) + 1];
  }
  for (int q = 0; q < bins; ++q) start[q + 1] += start[q];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (std::size_t b = 0; b < bubbles.size(); ++b) order[fill[bin[b]]++] = static_cast<int>(b);
  }
  for (std::size_t a = 0; a < bubbles.size(); ++a) {
    const Vec& xa = bubbles[a].x;
    const int b0 = bin_of(xa, 0), b1 = bin_of(xa, 1), b2 = bin_of(xa, 2);
    for (int o2 = std::max(b2 - 1, 0); o2 <= std::min(b2 + 1, nb[2] - 1); ++o2) {
      for (int o1 = std::max(b1 - 1, 0); o1 <= std::min(b1 + 1, nb[1] - 1); ++o1) {
        for (int o0 = std::max(b0 - 1, 0); o0 <= std::min(b0 + 1, nb[0] - 1); ++o0) {
          const int q = o0 + nb[0] * (o1 + nb[1] * o2);
          for (int s = start[q]; s < start[q + 1]; ++s) {
            const int b = order[s];
            if (b <= static_cast<int>(a)) continue;
            const double reach = 0.5 * (bubbles[a].diameter_m + bubbles[b].diameter_m);
            if ((bubbles[b].x - xa).squaredNorm() < reach * reach)
              pairs.emplace_back(static_cast<int>(a), b);
          }
        }
      }
    }
  }
  return pairs;
}

}  // namespace

std::vector<DbmNozzle> square_nozzle_array(int nozzles_per_side, double pitch_m, double width_m,
                                           double depth_m) {
  std::vector<DbmNozzle> out;
  const double half = 0.5 * (nozzles_per_side - 1) * pitch_m;
  for (int b = 0; b < nozzles_per_side; ++b) {
    for (int a = 0; a < nozzles_per_side; ++a) {
      out.push_back({0.5 * width_m - half + a * pitch_m, 0.5 * depth_m - half + b * pitch_m});
    }
  }
  return out;
}

namespace {

/// Where a bubble's gas is mapped: its lobes (two while a merger relaxes), or its centre.
struct Blob {
  Vec x;
  double volume;
};

void AppendBlobs(const DbmBubble& b, std::vector<Blob>* blobs) {
  if (b.lobe_remaining > 0.0) {
    const double rest = b.volume_m3 - b.lobe_volume_m3;
    if (b.lobe_volume_m3 > 0.0)
      blobs->push_back({b.x + b.lobe_remaining * b.lobe_offset, b.lobe_volume_m3});
    if (rest > 0.0) blobs->push_back({b.x + b.lobe_remaining * b.rest_offset, rest});
  } else {
    blobs->push_back({b.x, b.volume_m3});
  }
}

}  // namespace

DbmBubble merge_bubbles(const DbmBubble& a, const DbmBubble& b) {
  DbmBubble m = a;
  const double v = a.volume_m3 + b.volume_m3;
  m.x = (a.volume_m3 * a.x + b.volume_m3 * b.x) / v;
  m.v = (a.volume_m3 * a.v + b.volume_m3 * b.v) / v;
  m.volume_m3 = v;
  m.diameter_m = SphereDiameter(v);
  // The merged gas stays where it was mapped: the parents' blobs (a parent still relaxing from a
  // merger has two), reduced to two lobes by joining, each time, the pair whose joining moves
  // the least gas (the smallest V_i V_j / (V_i + V_j) |x_i - x_j|^2). Joining keeps the centroid.
  std::vector<Blob> blobs;
  AppendBlobs(a, &blobs);
  AppendBlobs(b, &blobs);
  while (blobs.size() > 2) {
    std::size_t bi = 0, bj = 1;
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < blobs.size(); ++i)
      for (std::size_t j = i + 1; j < blobs.size(); ++j) {
        const double cost = blobs[i].volume * blobs[j].volume /
                            (blobs[i].volume + blobs[j].volume) *
                            (blobs[i].x - blobs[j].x).squaredNorm();
        if (cost < least) {
          least = cost;
          bi = i;
          bj = j;
        }
      }
    const double joined = blobs[bi].volume + blobs[bj].volume;
    blobs[bi].x = (blobs[bi].volume * blobs[bi].x + blobs[bj].volume * blobs[bj].x) / joined;
    blobs[bi].volume = joined;
    blobs.erase(blobs.begin() + static_cast<long>(bj));
  }
  m.lobe_volume_m3 = blobs[0].volume;
  m.lobe_offset = blobs[0].x - m.x;
  m.rest_offset = blobs.size() > 1 ? Vec(blobs[1].x - m.x) : Vec(-m.lobe_offset);
  m.lobe_remaining = 1.0;
  return m;
}

void move_bubble_centre(DbmBubble* b, const Eigen::Vector3d& delta) {
  if (delta.squaredNorm() == 0.0) return;
  b->x += delta;
  if (b->lobe_remaining > 0.0) {
    b->lobe_offset -= delta / b->lobe_remaining;
    b->rest_offset -= delta / b->lobe_remaining;
  } else {
    b->lobe_remaining = 1.0;
    b->lobe_volume_m3 = b->volume_m3;
    b->lobe_offset = b->rest_offset = -delta;
  }
}

bool DbmOptions::IsValid(std::string* error) const {
  auto positive = [&](double v, const char* name) {
    return std::isfinite(v) && v > 0.0
               ? true
               : fail(error, std::string(name) + " must be > 0, got " + fmt(v));
  };
  if (!positive(width_m, "width_m") || !positive(depth_m, "depth_m") ||
      !positive(height_m, "height_m") ||
      !positive(emulsion_density_kg_m3, "emulsion_density_kg_m3") ||
      !positive(emulsion_viscosity_pa_s, "emulsion_viscosity_pa_s") ||
      !positive(gravity_m_s2, "gravity_m_s2") ||
      !positive(bubble_density_kg_m3, "bubble_density_kg_m3") ||
      !positive(bubble_diameter_m, "bubble_diameter_m") || !positive(dt_s, "dt_s") ||
      !positive(sample_interval_s, "sample_interval_s") ||
      !positive(cg_tolerance, "cg_tolerance")) {
    return false;
  }
  if (nx < 2 || nz < 2 || ny < 1)
    return fail(error, "cells: nx and nz must be >= 2 and ny >= 1, got " + std::to_string(nx) +
                           ", " + std::to_string(nz) + ", " + std::to_string(ny));
  if (!(bubble_density_kg_m3 < emulsion_density_kg_m3))
    return fail(error, "bubble_density_kg_m3 = " + fmt(bubble_density_kg_m3) +
                           " must be below the emulsion density " + fmt(emulsion_density_kg_m3) +
                           " kg/m^3 (bubbles rise)");
  if (!(virtual_mass_coefficient >= 0.0 && virtual_mass_coefficient <= 10.0))
    return fail(
        error, "virtual_mass_coefficient must be in [0, 10], got " + fmt(virtual_mass_coefficient));
  if (lift && !(std::abs(lift_coefficient) <= 1.0))
    return fail(error, "lift_coefficient must be in [-1, 1], got " + fmt(lift_coefficient));
  if (!(bubble_gas_flow_m3_s >= 0.0 && std::isfinite(bubble_gas_flow_m3_s)))
    return fail(error, "bubble_gas_flow_m3_s must be >= 0, got " + fmt(bubble_gas_flow_m3_s));
  if (!(film_drainage_s >= 0.0 && film_drainage_s <= 10.0))
    return fail(error, "film_drainage_s must be in [0, 10] s, got " + fmt(film_drainage_s));
  if (!(average_from_s >= 0.0)) return fail(error, "average_from_s must be >= 0");
  if (!(cfl >= 0.0 && cfl <= 0.9))
    return fail(error, "cfl must be in [0, 0.9] (0: the fixed step dt_s), got " + fmt(cfl));
  if (!(injection_ramp_s >= 0.0 && injection_ramp_s <= 1e4))
    return fail(error, "injection_ramp_s must be in [0, 1e4] s, got " + fmt(injection_ramp_s));
  const double column = std::min(width_m, depth_m);
  if (!(coupling_width_m >= 0.0 && coupling_width_m <= column))
    return fail(error, "coupling_width_m must be in [0, " + fmt(column) +
                           "] m (0: " + fmt(kCouplingWidthInDiameters) +
                           " bubble diameters; at most the column's width and depth), got " +
                           fmt(coupling_width_m));
  if (!(bubble_diameter_m < column))
    return fail(error, "bubble_diameter_m = " + fmt(bubble_diameter_m) +
                           " m is not smaller than the column (" + fmt(column) +
                           " m across): such a bubble is a slug, which the DBM's spheres do "
                           "not represent");
  if (bubble_gas_flow_m3_s > 0.0 && nozzles.empty())
    return fail(error, "nozzles: a bubble gas flow needs at least one nozzle");
  const double r = 0.5 * bubble_diameter_m;
  for (std::size_t n = 0; n < nozzles.size(); ++n) {
    const DbmNozzle& a = nozzles[n];
    if (!(a.x_m >= r && a.x_m <= width_m - r && a.y_m >= r && a.y_m <= depth_m - r))
      return fail(error, "nozzle " + std::to_string(n) + " at (" + fmt(a.x_m) + ", " + fmt(a.y_m) +
                             ") m is closer than a bubble radius (" + fmt(r) + " m) to a wall");
    for (std::size_t m = 0; m < n; ++m) {
      const double gap = std::hypot(a.x_m - nozzles[m].x_m, a.y_m - nozzles[m].y_m);
      if (gap < bubble_diameter_m)
        return fail(error, "nozzles " + std::to_string(m) + " and " + std::to_string(n) + " are " +
                               fmt(gap) + " m apart, less than the bubble diameter " +
                               fmt(bubble_diameter_m) +
                               " m: their bubbles would overlap (widen the nozzle pitch)");
    }
  }
  return true;
}

double DbmOptions::CouplingWidth() const {
  return coupling_width_m > 0.0 ? coupling_width_m : kCouplingWidthInDiameters * bubble_diameter_m;
}

double DbmOptions::StableTimeStep() const {
  const double hx = width_m / nx, hy = depth_m / ny, hz = height_m / nz;
  double inv_h2 = 1.0 / (hx * hx) + 1.0 / (hz * hz);
  if (ny > 1) inv_h2 += 1.0 / (hy * hy);
  const double viscous = emulsion_density_kg_m3 / (2.0 * emulsion_viscosity_pa_s * inv_h2);
  const BubbleForceModel force(ForceOptions(*this));
  const double u_br = davies_taylor_rise_velocity(bubble_diameter_m, gravity_m_s2);
  const double relaxation = force.inertia_density() * bubble_diameter_m /
                            (0.75 * force.drag_coefficient() * emulsion_density_kg_m3 * u_br);
  return std::min(viscous, relaxation);
}

struct DbmSimulation::Impl {
  std::array<int, 3> n{};     // cells per axis (0 x, 1 z, 2 y)
  std::array<double, 3> h{};  // cell size per axis
  int cells = 0;
  double cell_volume = 0.0;
  std::array<Eigen::VectorXd, 3> vel, vel_star;  // face velocities normal to each axis
  Eigen::VectorXd eps_e, eps_e_new, eps_b, pressure, mobility;
  // Cell-centred emulsion quantities the bubbles see, by physical component (x, y, z).
  std::array<Eigen::VectorXd, 3> uc, uc_prev, grad_p, accel, curl, reaction;
  bool have_prev = false;
  double previous_dt = 0.0;
  std::unique_ptr<MacPressureSolver> solver;
  std::vector<double> forming;  // gas in the bubble forming at each nozzle [m^3]
  double nozzle_flow = 0.0;     // per nozzle [m^3/s]
  std::uint64_t next_id = 1;
  std::map<std::pair<std::uint64_t, std::uint64_t>, double> contact_since;
  double next_sample = 0.0;
  double top_outflow = 0.0;
  int size_bins = kSizeBins;
  int fastest_cell = 0;  // of the last step, for the diagnosis

  /// What a step changes, to take it again from its start.
  struct State {
    double time = 0.0;
    std::vector<DbmBubble> bubbles;
    DbmDiagnostics diag;
    std::array<Eigen::VectorXd, 3> vel, uc_prev;
    Eigen::VectorXd eps_e, eps_b, pressure;
    bool have_prev = false;
    double previous_dt = 0.0, top_outflow = 0.0;
    std::vector<double> forming;
    std::uint64_t next_id = 1;
    std::map<std::pair<std::uint64_t, std::uint64_t>, double> contact_since;
  };
  State Save(double t, const std::vector<DbmBubble>& b, const DbmDiagnostics& d) const {
    return State{t,        b,         d,           vel,         uc_prev, eps_e,   eps_b,
                 pressure, have_prev, previous_dt, top_outflow, forming, next_id, contact_since};
  }
  void Restore(const State& s, double* t, std::vector<DbmBubble>* b, DbmDiagnostics* d) {
    *t = s.time;
    *b = s.bubbles;
    *d = s.diag;
    vel = s.vel;
    uc_prev = s.uc_prev;
    eps_e = s.eps_e;
    eps_b = s.eps_b;
    pressure = s.pressure;
    have_prev = s.have_prev;
    previous_dt = s.previous_dt;
    top_outflow = s.top_outflow;
    forming = s.forming;
    next_id = s.next_id;
    contact_since = s.contact_since;
  }
  double kernel_radius = 0.0;  // half the coupling width [m]

  static int AxisOf(int component) { return component == 0 ? 0 : (component == 1 ? 2 : 1); }
  int Cell(int i, int j, int k) const { return i + n[0] * (j + n[1] * k); }
  /// A cell-centred field at (i, j, k) clamped into the grid.
  double Clamped(const Eigen::VectorXd& f, int i, int j, int k) const {
    return f(
        Cell(std::clamp(i, 0, n[0] - 1), std::clamp(j, 0, n[1] - 1), std::clamp(k, 0, n[2] - 1)));
  }
  /// Index of face p of axis a (faces normal to a: n[a] + 1 of them along a).
  int FaceIndex(int a, int i, int j, int k) const {
    std::array<int, 3> f = n;
    ++f[a];
    return i + f[0] * (j + f[1] * k);
  }
  /// The cells on the two sides of the face (a, p): p - e_a and p (clamped at the top face).
  int CellBelow(int a, std::array<int, 3> p) const {
    --p[a];
    return Cell(p[0], p[1], p[2]);
  }
  int CellAbove(int a, std::array<int, 3> p) const {
    p[a] = std::min(p[a], n[a] - 1);
    return Cell(p[0], p[1], p[2]);
  }
  double FaceFraction(const Eigen::VectorXd& e, int a, const std::array<int, 3>& p) const {
    return 0.5 * (e(CellBelow(a, p)) + e(CellAbove(a, p)));
  }
  internal::Tent3 TentOf(const Vec& x) const {
    return internal::TentAt3(x(0), x(1), x(2), h[0], h[2], h[1], n[0], n[2], n[1]);
  }
  /// The cells a bubble of diameter d at x is mapped to: the smooth kernel of the coupling
  /// width, or, for a bubble wider than half of it, of twice the bubble's own diameter, so a
  /// large bubble displaces and pushes the emulsion over its own volume and alone never fills
  /// a cell past about half (pi / 6 at the kernel's centre).
  internal::Smooth3 StencilOf(const Vec& x, double d) const {
    return internal::SmoothAt3(x(0), x(1), x(2), std::max(kernel_radius, d), h[0], h[2], h[1], n[0],
                               n[2], n[1]);
  }
};

DbmSimulation::DbmSimulation(const DbmOptions& options)
    : opt_(options),
      force_((
          [&] {
            std::string why;
            if (!options.IsValid(&why)) Bad("dbm: " + why);
          }(),
          ForceOptions(options))),
      impl_(std::make_unique<Impl>()) {
  const double stable = opt_.StableTimeStep();
  if (opt_.dt_s > stable * (1.0 + 1e-12))
    Bad("dbm: dt_s = " + fmt(opt_.dt_s) + " s is above the stability limit " + fmt(stable) +
        " s (the emulsion's explicit viscous limit and the bubbles' slip relaxation time); "
        "remedy: dt_s <= " +
        fmt(stable) + " s");
  Impl& m = *impl_;
  m.n = {opt_.nx, opt_.nz, opt_.ny};
  m.h = {opt_.width_m / opt_.nx, opt_.height_m / opt_.nz, opt_.depth_m / opt_.ny};
  m.cells = opt_.nx * opt_.ny * opt_.nz;
  m.cell_volume = m.h[0] * m.h[1] * m.h[2];
  m.kernel_radius = 0.5 * opt_.CouplingWidth();
  for (int a = 0; a < 3; ++a) {
    std::array<int, 3> f = m.n;
    ++f[a];
    m.vel[a] = Eigen::VectorXd::Zero(static_cast<long>(f[0]) * f[1] * f[2]);
    m.vel_star[a] = m.vel[a];
  }
  for (auto* field : {&m.eps_e, &m.eps_e_new}) *field = Eigen::VectorXd::Ones(m.cells);
  m.eps_b = Eigen::VectorXd::Zero(m.cells);
  m.mobility = Eigen::VectorXd::Zero(m.cells);
  m.pressure = Eigen::VectorXd::Zero(m.cells);
  for (auto* group : {&m.uc, &m.uc_prev, &m.grad_p, &m.accel, &m.curl, &m.reaction}) {
    for (auto& field : *group) field = Eigen::VectorXd::Zero(m.cells);
  }
  MacPressureOptions po;
  po.nx = opt_.nx;
  po.nz = opt_.nz;
  po.ny = opt_.ny;
  po.dx = m.h[0];
  po.dz = m.h[1];
  po.dy = m.h[2];
  po.solver = opt_.solver;
  po.cg_tolerance = opt_.cg_tolerance;
  po.cg_max_iterations = 20000;
  m.solver = std::make_unique<MacPressureSolver>(po);

  // Injection: a bubble forms at each nozzle from its share of the flow and is released when it
  // holds V_b; the forming bubbles start from seeded random volumes (the nozzles' phases), gas
  // counted as injected at t = 0.
  if (opt_.bubble_gas_flow_m3_s > 0.0) {
    m.nozzle_flow = opt_.bubble_gas_flow_m3_s / static_cast<double>(opt_.nozzles.size());
    std::mt19937_64 rng(opt_.seed);
    std::uniform_real_distribution<double> phase(0.0, SphereVolume(opt_.bubble_diameter_m));
    for (std::size_t k = 0; k < opt_.nozzles.size(); ++k) {
      m.forming.push_back(phase(rng));
      diag_.gas_injected_m3 += m.forming.back();
    }
  }
  m.next_sample = opt_.average_from_s;
  avg_.w_cell = avg_.u_cell = avg_.v_cell = Eigen::VectorXd::Zero(m.cells);
  avg_.bubble_fraction = Eigen::VectorXd::Zero(m.cells);
  avg_.holdup_by_height = Eigen::VectorXd::Zero(opt_.nz);
  avg_.diameter_sum_by_height = Eigen::VectorXd::Zero(opt_.nz);
  avg_.count_by_height = Eigen::VectorXd::Zero(opt_.nz);
  avg_.size_histogram = Eigen::MatrixXd::Zero(opt_.nz, m.size_bins);
}

DbmSimulation::~DbmSimulation() = default;

std::uint64_t DbmSimulation::AddBubble(const Vec& x, const Vec& v, double diameter_m) {
  if (!(diameter_m > 0.0 && diameter_m < std::min(opt_.width_m, opt_.depth_m)))
    Bad("dbm: a bubble's diameter must be in (0, column width), got " + fmt(diameter_m));
  DbmBubble b;
  b.x = x;
  b.v = v;
  b.diameter_m = diameter_m;
  b.volume_m3 = SphereVolume(diameter_m);
  b.id = impl_->next_id++;
  bubbles_.push_back(b);
  diag_.max_bubble_diameter_m = std::max(diag_.max_bubble_diameter_m, diameter_m);
  return b.id;
}

double DbmSimulation::gas_in_bubbles_m3() const {
  double v = 0.0;
  for (const DbmBubble& b : bubbles_) v += b.volume_m3;
  return v;
}

double DbmSimulation::gas_forming_m3() const {
  double v = 0.0;
  for (double f : impl_->forming) v += f;
  return v;
}

const Eigen::VectorXd& DbmSimulation::bubble_fraction() const { return impl_->eps_b; }
const Eigen::VectorXd& DbmSimulation::dynamic_pressure() const { return impl_->pressure; }
double DbmSimulation::top_outflow_m3_s() const { return impl_->top_outflow; }

Eigen::VectorXd DbmSimulation::emulsion_velocity(int component) const {
  const Impl& m = *impl_;
  const int a = Impl::AxisOf(component);
  Eigen::VectorXd out(m.cells);
  for (int k = 0; k < m.n[2]; ++k) {
    for (int j = 0; j < m.n[1]; ++j) {
      for (int i = 0; i < m.n[0]; ++i) {
        std::array<int, 3> p{i, j, k}, q{i, j, k};
        ++q[a];
        std::array<int, 3> f = m.n;
        ++f[a];
        auto face = [&](const std::array<int, 3>& r) { return r[0] + f[0] * (r[1] + f[1] * r[2]); };
        out(m.Cell(i, j, k)) = 0.5 * (m.vel[a](face(p)) + m.vel[a](face(q)));
      }
    }
  }
  return out;
}

Eigen::Vector3d DbmSimulation::EmulsionVelocityAt(const Vec& x) const {
  const Impl& m = *impl_;
  const internal::Tent3 t = m.TentOf(x);
  Vec u;
  for (int c = 0; c < 3; ++c) {
    const Eigen::VectorXd field = emulsion_velocity(c);
    u(c) = internal::Interpolate3(field, t, m.n[0], m.n[1]);
  }
  return u;
}

void DbmSimulation::AdvanceTo(double t_s) {
  while (time_ < t_s - 1e-9 * opt_.dt_s) Step();
  // (With cfl > 0 the last step may end past t_s by less than one step.)
}

void DbmSimulation::Step() {
  Impl& m = *impl_;
  // The step: dt_s, or less where the emulsion would move more than `cfl` cells per step.
  double dt = opt_.dt_s;
  if (opt_.cfl > 0.0) {
    double rate = 0.0;  // max over faces of |u| / h
    for (int a = 0; a < 3; ++a) rate = std::max(rate, m.vel[a].cwiseAbs().maxCoeff() / m.h[a]);
    if (rate > 0.0) dt = std::min(dt, opt_.cfl / rate);
  }
  // The step is chosen from the velocity at its start; a sudden displacement within it (a large
  // bubble breaking through the surface) can still pass the convective limit. With the adaptive
  // step, such a step is taken again from its start, shortened to the CFL number it reached.
  Impl::State saved;
  if (opt_.cfl > 0.0) saved = m.Save(time_, bubbles_, diag_);
  for (int attempt = 0;; ++attempt) {
    const double cfl = TakeStep(dt);
    if (cfl <= 1.0) break;
    // A sudden displacement passes the limit by a little; a run that passes it many times over
    // is diverging, and a step shortened as much would only overflow.
    if (opt_.cfl > 0.0 && attempt < kMaxStepRetakes && cfl < kRetakeAtMost) {
      m.Restore(saved, &time_, &bubbles_, &diag_);
      diag_.retaken_steps += 1;
      dt *= opt_.cfl / cfl;
      continue;
    }
    const int nx = m.n[0], nz = m.n[1];
    const int c = m.fastest_cell, i = c % nx, j = (c / nx) % nz, k = c / (nx * nz);
    double largest = 0.0;
    for (const DbmBubble& b : bubbles_) largest = std::max(largest, b.diameter_m);
    throw std::runtime_error(
        "dbm: at t = " + fmt(time_) + " s the emulsion moves " + fmt(cfl) +
        " cells per step (above 1, the limit of its explicit advection) at (" +
        fmt((i + 0.5) * m.h[0]) + ", " + fmt((k + 0.5) * m.h[2]) + ", " + fmt((j + 0.5) * m.h[1]) +
        ") m, bubble fraction " + fmt(m.eps_b(c)) + ", largest bubble " + fmt(largest) +
        " m: the run is diverging" +
        (attempt > 0 ? " (" + std::to_string(attempt) + " shorter steps did not hold it)"
                     : std::string()) +
        (opt_.cfl > 0.0 ? "; remedy: the bubbles crowd beyond what the emulsion equations hold "
                          "(max bubble fraction " +
                              fmt(diag_.max_bubble_fraction) +
                              "): a coarser grid, [dbm] collisions = true, or a lower gas flow"
                        : "; remedy: [dbm] cfl (an adaptive step) or dt_s below " +
                              fmt(dt / std::max(cfl, 1e-300)) + " s"));
  }
  Accumulate(dt);
}

/// The projection's face coefficients: eps_e u = eps_e u* - eps_e a (dt / rho_e) grad p',
/// a = eps_e / (eps_e + C_VM eps_b), continuity with storage. The bubbles' response to the
/// pressure change enters the pressure equation (semi-implicit):
/// -div((C_e + M) grad p_new) = -residual - div(M grad p_old), M the face mobility.
struct DbmSimulation::Projection {
  std::array<Eigen::VectorXd, 3> coeff, eps_face, coeff_total;
  Eigen::VectorXd mobility_flux;  ///< div(M grad p_old) V
};

double DbmSimulation::TakeStep(double dt) {
  DbmStepStages stages(*this, dt);
  const auto bubbles_start = std::chrono::steady_clock::now();
  stages.SampleEmulsion();
  stages.InjectBubbles();
  stages.MoveBubbles();
  stages.RemoveLeavingBubbles();
  stages.BubbleInteractions();
  diag_.bubble_wall_s += Seconds(bubbles_start);

  const auto emulsion_start = std::chrono::steady_clock::now();
  stages.DepositFractions();
  stages.BubbleMobility();
  stages.PredictEmulsion();
  stages.SolveEmulsionPressure();
  stages.CorrectEmulsionVelocities();
  stages.FollowPressureChange();
  diag_.emulsion_wall_s += Seconds(emulsion_start);
  stages.Finish();
  return stages.cfl();
}

struct DbmStepStages::State {
  std::vector<double> bubble_mobility;
  DbmSimulation::Projection projection;
  Eigen::VectorXd pressure_old;
};

DbmStepStages::DbmStepStages(DbmSimulation& simulation, double dt)
    : sim_(simulation), dt_(dt), t1_(simulation.time_ + dt), state_(std::make_unique<State>()) {
  DbmDiagnostics& diag = sim_.diag_;
  diag.min_dt_s = diag.steps == 0 ? dt : std::min(diag.min_dt_s, dt);
  if (diag.steps == 0) {
    sim_.DepositFractions(false);
    sim_.impl_->eps_e = sim_.impl_->eps_e_new;
  }
}
DbmStepStages::~DbmStepStages() = default;

void DbmStepStages::SampleEmulsion() { sim_.SampleEmulsion(dt_); }
void DbmStepStages::InjectBubbles() { sim_.InjectBubbles(dt_); }
void DbmStepStages::MoveBubbles() { sim_.MoveBubbles(dt_); }
void DbmStepStages::RemoveLeavingBubbles() { sim_.RemoveLeavingBubbles(); }
void DbmStepStages::BubbleInteractions() {
  const DbmOptions& o = sim_.opt_;
  if (o.collisions && !o.coalescence && sim_.bubbles_.size() > 1) sim_.CollideBubbles();
  if (o.coalescence && sim_.bubbles_.size() > 1) sim_.CoalesceBubbles(t1_);
}
void DbmStepStages::DepositFractions() { sim_.DepositFractions(true); }
void DbmStepStages::BubbleMobility() { state_->bubble_mobility = sim_.BubbleMobility(dt_); }
void DbmStepStages::PredictEmulsion() { sim_.PredictEmulsion(dt_); }
void DbmStepStages::SolveEmulsionPressure() {
  state_->projection = sim_.ProjectionCoefficients(dt_);
  state_->pressure_old = sim_.impl_->pressure;
  sim_.SolveEmulsionPressure(dt_, t1_, state_->projection);
}
double DbmStepStages::CorrectEmulsionVelocities() {
  cfl_ = sim_.CorrectEmulsionVelocities(dt_, state_->projection, &fastest_cell_);
  return cfl_;
}
void DbmStepStages::FollowPressureChange() {
  if (sim_.opt_.implicit_bubble_pressure && !sim_.bubbles_.empty()) {
    sim_.FollowPressureChange(dt_, sim_.impl_->pressure - state_->pressure_old,
                              state_->bubble_mobility);
    sim_.DepositFractions(false);
  }
}
void DbmStepStages::Finish() {
  DbmSimulation::Impl& m = *sim_.impl_;
  m.eps_e = m.eps_e_new;
  sim_.diag_.max_cfl = std::max(sim_.diag_.max_cfl, cfl_);
  sim_.time_ = t1_;
  sim_.diag_.steps += 1;
  m.fastest_cell = fastest_cell_;
}

/// The bubble and emulsion fractions from the bubbles' mapped volumes (fraction clamps and the
/// largest bubble fraction counted when `count`).
void DbmSimulation::DepositFractions(bool count) {
  Impl& m = *impl_;
  const int nx = m.n[0], nz = m.n[1];
  std::vector<Blob> blobs;
  m.eps_b.setZero();
  for (const DbmBubble& b : bubbles_) {
    // Gas breaking through the surface displaces less emulsion as it leaves, each lobe by
    // its own height (by the bubble's, a merger with a bubble below would bring back gas
    // that had left).
    blobs.clear();
    AppendBlobs(b, &blobs);
    for (const Blob& blob : blobs) {
      const double d = SphereDiameter(blob.volume);
      const double inside = std::clamp((opt_.height_m - blob.x(2)) / (0.5 * d), 0.0, 1.0);
      internal::Deposit3(m.eps_b, m.StencilOf(blob.x, d), inside * blob.volume / m.cell_volume, nx,
                         nz);
    }
  }
  for (std::size_t k = 0; k < m.forming.size(); ++k) {
    const Vec at(opt_.nozzles[k].x_m, opt_.nozzles[k].y_m, 0.5 * SphereDiameter(m.forming[k]));
    internal::Deposit3(m.eps_b, m.StencilOf(at, opt_.bubble_diameter_m),
                       m.forming[k] / m.cell_volume, nx, nz);
  }
  for (int c = 0; c < m.cells; ++c) {
    if (count) diag_.max_bubble_fraction = std::max(diag_.max_bubble_fraction, m.eps_b(c));
    double e = 1.0 - m.eps_b(c);
    if (e < kMinEmulsionFraction) {
      e = kMinEmulsionFraction;
      if (count) diag_.fraction_clamps += 1;
    }
    m.eps_e_new(c) = e;
  }
}

/// What the bubbles see: cell-centred emulsion velocity, pressure gradient (less the hydrostatic
/// head), material acceleration and (for lift) vorticity, by physical component.
void DbmSimulation::SampleEmulsion(double dt) {
  Impl& m = *impl_;
  const int nx = m.n[0], nz = m.n[1], ny = m.n[2];
  for (int c = 0; c < 3; ++c) m.uc[c] = emulsion_velocity(c);
#pragma omp parallel for schedule(static) if (m.cells >= kParallelCells)
  for (int k = 0; k < ny; ++k) {
    for (int j = 0; j < nz; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int cell = m.Cell(i, j, k);
        const double p = m.pressure(cell);
        // Face gradients (zero through walls, the outlet p = 0 half a cell above the top row),
        // averaged to the centre.
        auto face_grad = [&](int di, int dj, int dk, double hh, bool wall) {
          if (wall) return 0.0;
          return (m.Clamped(m.pressure, i + di, j + dj, k + dk) - p) / hh;
        };
        const double gx =
            0.5 * (face_grad(1, 0, 0, m.h[0], i == nx - 1) - face_grad(-1, 0, 0, m.h[0], i == 0));
        const double gy =
            0.5 * (face_grad(0, 0, 1, m.h[2], k == ny - 1) - face_grad(0, 0, -1, m.h[2], k == 0));
        const double g_top =
            j == nz - 1 ? (0.0 - p) / (0.5 * m.h[1]) : face_grad(0, 1, 0, m.h[1], false);
        const double gz = 0.5 * (g_top - face_grad(0, -1, 0, m.h[1], j == 0));
        m.grad_p[0](cell) = gx;
        m.grad_p[1](cell) = gy;
        m.grad_p[2](cell) = gz;
        // Velocity gradients, central differences (one-sided at the boundaries).
        auto d_dx = [&](const Eigen::VectorXd& f) {
          const int a = std::max(i - 1, 0), b = std::min(i + 1, nx - 1);
          return b > a ? (m.Clamped(f, b, j, k) - m.Clamped(f, a, j, k)) / ((b - a) * m.h[0]) : 0.0;
        };
        auto d_dy = [&](const Eigen::VectorXd& f) {
          const int a = std::max(k - 1, 0), b = std::min(k + 1, ny - 1);
          return b > a ? (m.Clamped(f, i, j, b) - m.Clamped(f, i, j, a)) / ((b - a) * m.h[2]) : 0.0;
        };
        auto d_dz = [&](const Eigen::VectorXd& f) {
          const int a = std::max(j - 1, 0), b = std::min(j + 1, nz - 1);
          return b > a ? (m.Clamped(f, i, b, k) - m.Clamped(f, i, a, k)) / ((b - a) * m.h[1]) : 0.0;
        };
        const Vec u(m.uc[0](cell), m.uc[1](cell), m.uc[2](cell));
        for (int c = 0; c < 3; ++c) {
          const double dudt =
              m.have_prev ? (m.uc[c](cell) - m.uc_prev[c](cell)) / m.previous_dt : 0.0;
          m.accel[c](cell) =
              dudt + u(0) * d_dx(m.uc[c]) + u(1) * d_dy(m.uc[c]) + u(2) * d_dz(m.uc[c]);
        }
        if (opt_.lift) {
          m.curl[0](cell) = d_dy(m.uc[2]) - d_dz(m.uc[1]);
          m.curl[1](cell) = d_dz(m.uc[0]) - d_dx(m.uc[2]);
          m.curl[2](cell) = d_dx(m.uc[1]) - d_dy(m.uc[0]);
        }
      }
    }
  }
  for (int c = 0; c < 3; ++c) m.uc_prev[c] = m.uc[c];
  m.have_prev = true;
  m.previous_dt = dt;
}

/// Injection: the forming bubbles grow by the nozzle flow; a full one is released, leaving the
/// nozzle at its rise velocity. The emulsion sees them grow (no impulsive displacement).
void DbmSimulation::InjectBubbles(double dt) {
  Impl& m = *impl_;
  if (!(m.nozzle_flow > 0.0)) return;
  const double d = opt_.bubble_diameter_m;
  const double v_b = SphereVolume(d);
  const double u_br = davies_taylor_rise_velocity(d, opt_.gravity_m_s2);
  // The start-up ramp: the flow rises linearly over injection_ramp_s (its mean over the step).
  const double ramp =
      opt_.injection_ramp_s > 0.0 ? std::min(1.0, (time_ + 0.5 * dt) / opt_.injection_ramp_s) : 1.0;
  for (std::size_t k = 0; k < opt_.nozzles.size(); ++k) {
    m.forming[k] += ramp * m.nozzle_flow * dt;
    diag_.gas_injected_m3 += ramp * m.nozzle_flow * dt;
    while (m.forming[k] >= v_b) {
      AddBubble(Vec(opt_.nozzles[k].x_m, opt_.nozzles[k].y_m, 0.5 * d), Vec(0.0, 0.0, u_br), d);
      diag_.bubbles_injected += 1;
      m.forming[k] -= v_b;
    }
  }
}

/// Walls: a bubble's centre stays a radius away; its velocity into a wall is dropped. A merged
/// bubble can grow into a wall: its centre then jumps off it, and its gas follows as after a
/// merger (move_bubble_centre), not within the step.
void DbmSimulation::KeepInside(DbmBubble& bub) const {
  const double r = 0.5 * bub.diameter_m;
  const double lo[3] = {r, r, r};
  const double hi[3] = {opt_.width_m - r, opt_.depth_m - r, 1e300};
  Vec delta = Vec::Zero();
  for (int c = 0; c < 3; ++c) {
    if (bub.x(c) < lo[c]) {
      delta(c) = lo[c] - bub.x(c);
      bub.v(c) = std::max(bub.v(c), 0.0);
    } else if (bub.x(c) > hi[c]) {
      delta(c) = hi[c] - bub.x(c);
      bub.v(c) = std::min(bub.v(c), 0.0);
    }
  }
  move_bubble_centre(&bub, delta);
}

/// Bubble motion (drag implicit) and the force each exerts on the emulsion (Impl::reaction).
void DbmSimulation::MoveBubbles(double dt) {
  Impl& m = *impl_;
  const int nx = m.n[0], nz = m.n[1];
  const double rho_e = opt_.emulsion_density_kg_m3;
  const double g = opt_.gravity_m_s2;
  const long nb = static_cast<long>(bubbles_.size());
  std::vector<Vec> reaction(static_cast<std::size_t>(nb));
  const Vec gravity(0.0, 0.0, -g);
  const double rho_b = opt_.bubble_density_kg_m3;
  const double c_vm = opt_.virtual_mass_coefficient;
#pragma omp parallel for schedule(static) if (nb >= kParallelBubbles)
  for (long b = 0; b < nb; ++b) {
    DbmBubble& bub = bubbles_[static_cast<std::size_t>(b)];
    const internal::Smooth3 s = m.StencilOf(bub.x, bub.diameter_m);
    Vec u = Vec::Zero(), gp = Vec::Zero(), acc = Vec::Zero(), w = Vec::Zero();
    for (int c = 0; c < 3; ++c) {
      u(c) = internal::Interpolate3(m.uc[c], s, nx, nz);
      gp(c) = internal::Interpolate3(m.grad_p[c], s, nx, nz);
      acc(c) = internal::Interpolate3(m.accel[c], s, nx, nz);
      if (opt_.lift) w(c) = internal::Interpolate3(m.curl[c], s, nx, nz);
    }
    gp(2) -= rho_e * g;  // the hydrostatic head: grad p = grad p' + rho_e g_vec
    Vec gp_and_lift = gp;
    if (opt_.lift) {
      // F_L / V = -C_L rho_e (v - u) x curl u, folded into the pressure-gradient argument.
      const Vec slip = bub.v - u;
      gp_and_lift += opt_.lift_coefficient * rho_e * slip.cross(w);
    }
    const Vec v_new = force_.Step(bub.v, u, gp_and_lift, acc, bub.diameter_m, dt);
    // What the emulsion exerted besides the pressure and gravity: drag, virtual mass, lift,
    // less the virtual mass's emulsion-acceleration part C_VM rho_e V Du/Dt, which the emulsion
    // carries as added inertia instead (explicitly it feeds the emulsion's own acceleration
    // back with gain C_VM eps_b / eps_e, unstable in crowded cells).
    reaction[static_cast<std::size_t>(b)] =
        bub.volume_m3 * (rho_b * (v_new - bub.v) / dt - rho_b * gravity + gp - c_vm * rho_e * acc);
    bub.v = v_new;
    bub.x += dt * v_new;
    if (bub.lobe_remaining > 0.0) {
      const double rise = davies_taylor_rise_velocity(bub.diameter_m, g);
      bub.lobe_remaining = std::max(0.0, bub.lobe_remaining - dt * rise / bub.diameter_m);
    }
    KeepInside(bub);
  }
  diag_.bubble_steps += nb;
  for (auto& f : m.reaction) f.setZero();
  for (long b = 0; b < nb; ++b) {
    const DbmBubble& bub = bubbles_[static_cast<std::size_t>(b)];
    const internal::Smooth3 s = m.StencilOf(bub.x, bub.diameter_m);
    for (int c = 0; c < 3; ++c)
      internal::Deposit3(m.reaction[c], s,
                         -reaction[static_cast<std::size_t>(b)](c) / m.cell_volume, nx, nz);
  }
}

/// Bubbles leave at the bed surface: when their centre, and the gas still relaxing to it after
/// a jump (its lobes), have reached it.
void DbmSimulation::RemoveLeavingBubbles() {
  std::size_t kept = 0;
  std::vector<Blob> blobs;
  auto left = [&](const DbmBubble& b) {
    blobs.clear();
    AppendBlobs(b, &blobs);
    bool all = b.x(2) >= opt_.height_m;
    for (const Blob& blob : blobs) all = all && blob.x(2) >= opt_.height_m;
    return all;
  };
  for (std::size_t b = 0; b < bubbles_.size(); ++b) {
    if (left(bubbles_[b])) {
      diag_.bubbles_left += 1;
      diag_.gas_left_m3 += bubbles_[b].volume_m3;
    } else {
      bubbles_[kept++] = bubbles_[b];
    }
  }
  bubbles_.resize(kept);
}

/// Bubble-bubble contacts without coalescence: overlapping bubbles are pushed apart and their
/// approach along the line of centres is removed (a perfectly inelastic hard-sphere collision,
/// volume-weighted, so momentum is kept).
void DbmSimulation::CollideBubbles() {
  const std::array<double, 3> domain_hi{opt_.width_m, opt_.depth_m, opt_.height_m};
  for (int sweep = 0; sweep < kCollisionSweeps; ++sweep) {
    bool any = false;
    for (const auto& [a, b] : TouchingPairs(bubbles_, domain_hi)) {
      DbmBubble& A = bubbles_[static_cast<std::size_t>(a)];
      DbmBubble& B = bubbles_[static_cast<std::size_t>(b)];
      Vec n = B.x - A.x;
      const double dist = n.norm();
      const double overlap = 0.5 * (A.diameter_m + B.diameter_m) - dist;
      if (overlap <= 0.0) continue;
      n = dist > 1e-12 ? Vec(n / dist) : Vec(0.0, 0.0, 1.0);  // coincident: stack them
      const double wa = B.volume_m3 / (A.volume_m3 + B.volume_m3), wb = 1.0 - wa;
      A.x -= wa * overlap * n;
      B.x += wb * overlap * n;
      const double approach = (B.v - A.v).dot(n);
      if (approach < 0.0) {
        A.v += wa * approach * n;
        B.v -= wb * approach * n;
      }
      any = true;
    }
    for (DbmBubble& b : bubbles_) KeepInside(b);
    if (!any) break;
    diag_.collision_sweeps += 1;
  }
}

/// Coalescence: touching bubbles merge after the film-drainage time (t1: the end of the step).
void DbmSimulation::CoalesceBubbles(double t1) {
  Impl& m = *impl_;
  const std::array<double, 3> domain_hi{opt_.width_m, opt_.depth_m, opt_.height_m};
  std::map<std::pair<std::uint64_t, std::uint64_t>, double> touching;
  std::vector<std::pair<int, int>> ready;
  for (const auto& [a, b] : TouchingPairs(bubbles_, domain_hi)) {
    const auto key = std::minmax(bubbles_[a].id, bubbles_[b].id);
    const auto found = m.contact_since.find(key);
    const double since = found == m.contact_since.end() ? t1 : found->second;
    touching[key] = since;
    if (t1 - since >= opt_.film_drainage_s - 1e-12) ready.emplace_back(a, b);
  }
  m.contact_since = std::move(touching);
  std::vector<char> gone(bubbles_.size(), 0), merged(bubbles_.size(), 0);
  for (const auto& [a, b] : ready) {
    if (merged[a] || merged[b]) continue;  // each bubble merges at most once per step
    DbmBubble& A = bubbles_[a];
    A = merge_bubbles(A, bubbles_[b]);
    gone[b] = merged[a] = merged[b] = 1;
    // The merged bubble keeps A's id; its pending contacts restart.
    diag_.coalescences += 1;
    diag_.max_bubble_diameter_m = std::max(diag_.max_bubble_diameter_m, A.diameter_m);
    if (A.diameter_m >= std::min(opt_.width_m, opt_.depth_m)) {
      throw std::runtime_error(
          "dbm: at t = " + fmt(t1) + " s coalescence made a bubble of " + fmt(A.diameter_m) +
          " m, as wide as the column: the bed slugs, which spherical bubbles do not represent; "
          "remedy: a wider column, a lower superficial velocity, or a film-drainage time");
    }
  }
  std::size_t kept = 0;
  for (std::size_t b = 0; b < bubbles_.size(); ++b) {
    if (!gone[b]) bubbles_[kept++] = bubbles_[b];
  }
  bubbles_.resize(kept);
}

/// The bubbles' mobility under a pressure-gradient change (Impl::mobility, per cell: sum of
/// V dt / (m + k dt), m the inertia density, k the drag linearised at the bubble's slip, over
/// the cell volume); returns each bubble's dt / (m + k dt) (empty without the implicit
/// bubble pressure).
std::vector<double> DbmSimulation::BubbleMobility(double dt) {
  Impl& m = *impl_;
  const int nx = m.n[0], nz = m.n[1];
  m.mobility.setZero();
  std::vector<double> bubble_mobility(bubbles_.size(), 0.0);
  if (!opt_.implicit_bubble_pressure) return bubble_mobility;
  const double inertia = force_.inertia_density();
  for (std::size_t b = 0; b < bubbles_.size(); ++b) {
    const DbmBubble& bub = bubbles_[b];
    const internal::Smooth3 s = m.StencilOf(bub.x, bub.diameter_m);
    Vec u;
    for (int c = 0; c < 3; ++c) u(c) = internal::Interpolate3(m.uc[c], s, nx, nz);
    const double k = 0.75 * force_.drag_coefficient() * opt_.emulsion_density_kg_m3 *
                     (bub.v - u).norm() / bub.diameter_m;
    bubble_mobility[b] = dt / (inertia + k * dt);
    internal::Deposit3(m.mobility, s, bub.volume_m3 * bubble_mobility[b] / m.cell_volume, nx, nz);
  }
  return bubble_mobility;
}

/// Emulsion predictor (Impl::vel_star): advection and viscosity explicit, the bubbles' reaction
/// as a source, the inertia (eps_e + C_VM eps_b) rho_e with the bubbles' added mass.
void DbmSimulation::PredictEmulsion(double dt) {
  Impl& m = *impl_;
  const double rho_e = opt_.emulsion_density_kg_m3;
  const double c_vm = opt_.virtual_mass_coefficient;
  const std::array<const Eigen::VectorXd*, 3> vel{&m.vel[0], &m.vel[1], &m.vel[2]};
  const internal::MacOperators3D ops(vel, m.eps_e, m.n, m.h, opt_.emulsion_viscosity_pa_s,
                                     opt_.walls == WallSlip::kNoSlip,
                                     opt_.depth_walls == WallSlip::kNoSlip);
  for (int a = 0; a < 3; ++a) {
    const int component = Impl::AxisOf(a);  // the involution maps axes to components too
    std::array<int, 3> f = m.n;
    ++f[a];
    Eigen::VectorXd& star = m.vel_star[a];
    star.setZero();
    // Evaluated faces: interior ones, and the top face for the vertical axis.
    const int last = a == 1 ? f[a] - 1 : f[a] - 2;
#pragma omp parallel for schedule(static) if (m.cells >= kParallelCells)
    for (int k = 0; k < f[2]; ++k) {
      for (int j = 0; j < f[1]; ++j) {
        for (int i = 0; i < f[0]; ++i) {
          const std::array<int, 3> p{i, j, k};
          if (p[a] < 1 || p[a] > last) continue;
          const internal::FaceMomentumTerms terms = ops.Face(a, p);
          const double e_f = m.FaceFraction(m.eps_e_new, a, p);
          const double inertia = (e_f + c_vm * (1.0 - e_f)) * rho_e;
          const double source = 0.5 * (m.reaction[component](m.CellBelow(a, p)) +
                                       m.reaction[component](m.CellAbove(a, p)));
          const int fi = m.FaceIndex(a, i, j, k);
          star(fi) = m.vel[a](fi) + dt * (-terms.advection + (terms.viscous + source) / inertia);
        }
      }
    }
  }
}

DbmSimulation::Projection DbmSimulation::ProjectionCoefficients(double dt) const {
  const Impl& m = *impl_;
  const double rho_e = opt_.emulsion_density_kg_m3;
  const double c_vm = opt_.virtual_mass_coefficient;
  Projection pr;
  for (int a = 0; a < 3; ++a) {
    std::array<int, 3> f = m.n;
    ++f[a];
    pr.coeff[a] = Eigen::VectorXd::Zero(m.vel[a].size());
    pr.eps_face[a] = Eigen::VectorXd::Zero(m.vel[a].size());
    for (int k = 0; k < f[2]; ++k) {
      for (int j = 0; j < f[1]; ++j) {
        for (int i = 0; i < f[0]; ++i) {
          const std::array<int, 3> p{i, j, k};
          const bool wall = p[a] == 0 || (p[a] == f[a] - 1 && a != 1);
          if (wall) continue;
          const double e_f = m.FaceFraction(m.eps_e_new, a, p);
          const int fi = m.FaceIndex(a, i, j, k);
          pr.eps_face[a](fi) = e_f;
          pr.coeff[a](fi) = e_f * e_f / (e_f + c_vm * (1.0 - e_f)) * dt / rho_e;
        }
      }
    }
    pr.coeff_total[a] = pr.coeff[a];
  }
  pr.mobility_flux = Eigen::VectorXd::Zero(m.cells);
  if (!opt_.implicit_bubble_pressure) return pr;
  for (int a = 0; a < 3; ++a) {
    std::array<int, 3> f = m.n;
    ++f[a];
    const double face_area =
        a == 0 ? m.h[1] * m.h[2] : (a == 1 ? m.h[0] * m.h[2] : m.h[0] * m.h[1]);
    for (int k = 0; k < f[2]; ++k)
      for (int j = 0; j < f[1]; ++j)
        for (int i = 0; i < f[0]; ++i) {
          const std::array<int, 3> p{i, j, k};
          const int fi = m.FaceIndex(a, i, j, k);
          if (pr.coeff[a](fi) == 0.0) continue;  // walls
          const int below = m.CellBelow(a, p);
          const bool top = p[a] == m.n[a];
          const double mf =
              top ? m.mobility(below) : 0.5 * (m.mobility(below) + m.mobility(m.CellAbove(a, p)));
          pr.coeff_total[a](fi) += mf;
          const double hh = top ? 0.5 * m.h[a] : m.h[a];
          const double p_up = top ? 0.0 : m.pressure(m.CellAbove(a, p));
          const double flux = mf * face_area * (m.pressure(below) - p_up) / hh;  // out of below
          pr.mobility_flux(below) += flux;
          if (!top) pr.mobility_flux(m.CellAbove(a, p)) -= flux;
        }
  }
  return pr;
}

/// The emulsion pressure from the continuity residual of the predicted velocities.
void DbmSimulation::SolveEmulsionPressure(double dt, double t1, const Projection& pr) {
  Impl& m = *impl_;
  const int nx = m.n[0], nz = m.n[1], ny = m.n[2];
  const double area[3] = {m.h[1] * m.h[2], m.h[0] * m.h[2], m.h[0] * m.h[1]};
  Eigen::VectorXd residual(m.cells);
  for (int k = 0; k < ny; ++k) {
    for (int j = 0; j < nz; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int cell = m.Cell(i, j, k);
        double net = m.cell_volume * (m.eps_e_new(cell) - m.eps_e(cell)) / dt;
        for (int a = 0; a < 3; ++a) {
          std::array<int, 3> lo{i, j, k}, hi{i, j, k};
          ++hi[a];
          const int flo = m.FaceIndex(a, lo[0], lo[1], lo[2]);
          const int fhi = m.FaceIndex(a, hi[0], hi[1], hi[2]);
          net += area[a] * (pr.eps_face[a](fhi) * m.vel_star[a](fhi) -
                            pr.eps_face[a](flo) * m.vel_star[a](flo));
        }
        residual(cell) = net - pr.mobility_flux(cell);
      }
    }
  }
  try {
    m.pressure = m.solver->Solve(pr.coeff_total[0], pr.coeff_total[2], pr.coeff_total[1], residual,
                                 0.0, m.pressure);
  } catch (const Error& e) {
    // A run-time failure (exit 1), with what the bubbles did to the pressure equation.
    throw std::runtime_error("dbm: at t = " + fmt(t1) + " s " + e.what() +
                             "; the bubble fraction reaches " + fmt(m.eps_b.maxCoeff()) +
                             " (crowded bubbles make the equation ill-conditioned; remedy: "
                             "[dbm] collisions = true, no film drainage, a coarser grid, or a "
                             "lower gas flow)");
  }
  diag_.max_continuity_residual =
      std::max(diag_.max_continuity_residual, m.solver->diagnostics().relative_residual);
  diag_.max_cg_iterations = std::max(diag_.max_cg_iterations, m.solver->diagnostics().iterations);
}

/// The emulsion's face velocities from the new pressure, and its outflow through the surface;
/// returns the largest face CFL number (and the cell below that face).
double DbmSimulation::CorrectEmulsionVelocities(double dt, const Projection& pr,
                                                int* fastest_cell) {
  Impl& m = *impl_;
  double cfl = 0.0;
  for (int a = 0; a < 3; ++a) {
    std::array<int, 3> f = m.n;
    ++f[a];
    for (int k = 0; k < f[2]; ++k) {
      for (int j = 0; j < f[1]; ++j) {
        for (int i = 0; i < f[0]; ++i) {
          const std::array<int, 3> p{i, j, k};
          const int fi = m.FaceIndex(a, i, j, k);
          if (pr.coeff[a](fi) == 0.0) {
            m.vel[a](fi) = 0.0;
            continue;
          }
          const double p_up = p[a] < m.n[a] ? m.pressure(m.CellAbove(a, p)) : 0.0;
          const double hh = p[a] < m.n[a] ? m.h[a] : 0.5 * m.h[a];
          const double grad = (p_up - m.pressure(m.CellBelow(a, p))) / hh;
          m.vel[a](fi) = m.vel_star[a](fi) - pr.coeff[a](fi) / pr.eps_face[a](fi) * grad;
          const double face_cfl = std::abs(m.vel[a](fi)) * dt / m.h[a];
          if (face_cfl > cfl) {
            cfl = face_cfl;
            *fastest_cell = m.CellBelow(a, p);
          }
        }
      }
    }
  }
  const double top_area = m.h[0] * m.h[2];
  double out = 0.0;
  for (int k = 0; k < m.n[2]; ++k)
    for (int i = 0; i < m.n[0]; ++i) {
      const int fi = m.FaceIndex(1, i, m.n[1], k);
      out += top_area * pr.eps_face[1](fi) * m.vel[1](fi);
    }
  m.top_outflow = out;
  return cfl;
}

/// The bubbles follow the pressure change dp: dv = -dt / (m + k dt) grad dp.
void DbmSimulation::FollowPressureChange(double dt, const Eigen::VectorXd& dp,
                                         const std::vector<double>& bubble_mobility) {
  Impl& m = *impl_;
  const int nx = m.n[0], nz = m.n[1], ny = m.n[2];
  std::array<Eigen::VectorXd, 3> grad_dp;
  for (auto& g : grad_dp) g = Eigen::VectorXd::Zero(m.cells);
  for (int k = 0; k < ny; ++k)
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < nx; ++i) {
        const int cell = m.Cell(i, j, k);
        auto face_grad = [&](int di, int dj, int dk, double hh, bool wall) {
          return wall ? 0.0 : (m.Clamped(dp, i + di, j + dj, k + dk) - dp(cell)) / hh;
        };
        grad_dp[0](cell) =
            0.5 * (face_grad(1, 0, 0, m.h[0], i == nx - 1) - face_grad(-1, 0, 0, m.h[0], i == 0));
        grad_dp[1](cell) =
            0.5 * (face_grad(0, 0, 1, m.h[2], k == ny - 1) - face_grad(0, 0, -1, m.h[2], k == 0));
        const double g_top =
            j == nz - 1 ? -dp(cell) / (0.5 * m.h[1]) : face_grad(0, 1, 0, m.h[1], false);
        grad_dp[2](cell) = 0.5 * (g_top - face_grad(0, -1, 0, m.h[1], j == 0));
      }
#pragma omp parallel for schedule(static) if (static_cast <long>(bubbles_.size()) >= \
                                              kParallelBubbles)
  for (long b = 0; b < static_cast<long>(bubbles_.size()); ++b) {
    DbmBubble& bub = bubbles_[static_cast<std::size_t>(b)];
    const internal::Smooth3 s = m.StencilOf(bub.x, bub.diameter_m);
    Vec g;
    for (int c = 0; c < 3; ++c) g(c) = internal::Interpolate3(grad_dp[c], s, nx, nz);
    const Vec dv = -bubble_mobility[static_cast<std::size_t>(b)] * g;
    bub.v += dv;
    bub.x += dt * dv;
    KeepInside(bub);
  }
}

void DbmSimulation::Accumulate(double dt) {
  Impl& m = *impl_;
  const int nz = m.n[1];
  // 9. Time averages and the bubble samples.
  if (time_ > opt_.average_from_s + 1e-12) {
    const double w = std::min(dt, time_ - opt_.average_from_s);
    avg_.time_s += w;
    avg_.u_cell += w * m.uc[0];
    avg_.v_cell += w * m.uc[1];
    avg_.w_cell += w * m.uc[2];
    avg_.bubble_fraction += w * m.eps_b;
  }
  if (time_ >= m.next_sample - 1e-12 && time_ > opt_.average_from_s) {
    m.next_sample += opt_.sample_interval_s;
    avg_.samples += 1;
    const double row_volume = opt_.width_m * opt_.depth_m * m.h[1];
    for (const DbmBubble& b : bubbles_) {
      const int row = std::clamp(static_cast<int>(b.x(2) / m.h[1]), 0, nz - 1);
      avg_.holdup_by_height(row) += b.volume_m3 / row_volume;
      avg_.diameter_sum_by_height(row) += b.diameter_m;
      avg_.count_by_height(row) += 1.0;
      const int s = std::min(static_cast<int>(b.diameter_m / avg_.size_bin_m), m.size_bins - 1);
      avg_.size_histogram(row, s) += 1.0;
    }
  }
}

}  // namespace consumers
}  // namespace draglab
