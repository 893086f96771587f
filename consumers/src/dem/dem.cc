// Soft-sphere DEM: contact forces, velocity-Verlet integration, Verlet neighbour list, settling.
#include "draglab/consumers/dem.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Slots of tangential history per particle: 12 touching equal spheres + 3 walls + margin (a
// particle keeps only the pairs it owns, so dense monodisperse packs use about half).
constexpr int kMaxContacts = 20;
// Packed per-particle state for the pair loop: x y z vx vy vz wx wy wz r m (+1 padding).
constexpr int kStateStride = 12;

std::string Num(double v) { return core::format_number(v, 4); }

[[noreturn]] void Fail(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

/// A run that went wrong from valid input (divergence, no rest): a run-time failure, not bad
/// input (the command line exits 1, not 2).
[[noreturn]] void Diverged(const std::string& message) { throw std::runtime_error(message); }

bool Finite(const std::array<double, 3>& a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}

// Damping factor c(e) with eta_n = c(e) sqrt(k_n m_eff): the closed form that makes the
// linear spring-dashpot rebound with exactly e, c = 2 |ln e| / sqrt(pi^2 + ln^2 e).
double DampingFactor(double e) {
  const double l = std::log(e);
  return 2.0 * std::fabs(l) / std::sqrt(kPi * kPi + l * l);
}

// Contact time pi / sqrt(k/m - gamma^2), gamma = eta / (2 m).
double ContactTime(double k, double m_eff, double e) {
  const double eta = DampingFactor(e) * std::sqrt(k * m_eff);
  const double gamma = eta / (2.0 * m_eff);
  return kPi / std::sqrt(k / m_eff - gamma * gamma);
}

// Nearest periodic image of a separation d along an axis of length L, half = L/2 (infinite on a
// walled axis). One shift suffices: list pairs are closer than L/2 + skin, and a particle's
// displacement since the list build is below L/2 unless the caller moved it.
inline double NearestImage(double d, double length, double half) {
  if (d > half) return d - length;
  if (d < -half) return d + length;
  return d;
}

}  // namespace

// ---- Particles ---------------------------------------------------------------------------------

void Particles::add(double px, double py, double pz, double d, double rho, double pvx, double pvy,
                    double pvz) {
  id.push_back(static_cast<std::int64_t>(x.size()));
  x.push_back(px);
  y.push_back(py);
  z.push_back(pz);
  vx.push_back(pvx);
  vy.push_back(pvy);
  vz.push_back(pvz);
  wx.push_back(0.0);
  wy.push_back(0.0);
  wz.push_back(0.0);
  fx_ext.push_back(0.0);
  fy_ext.push_back(0.0);
  fz_ext.push_back(0.0);
  diameter.push_back(d);
  density.push_back(rho);
}

double Particles::volume(std::size_t i) const {
  return kPi / 6.0 * diameter[i] * diameter[i] * diameter[i];
}
double Particles::mass(std::size_t i) const { return density[i] * volume(i); }
double Particles::moment_of_inertia(std::size_t i) const {
  return 0.1 * mass(i) * diameter[i] * diameter[i];
}

bool Particles::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error != nullptr) *error = m;
    return false;
  };
  const std::size_t n = x.size();
  for (const auto* v :
       {&y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx_ext, &fy_ext, &fz_ext, &diameter, &density}) {
    if (v->size() != n)
      return fail("Particles: all arrays must have the same size (" + std::to_string(n) +
                  " positions)");
  }
  if (id.size() != n) return fail("Particles.id: size must equal the number of particles");
  for (std::size_t i = 0; i < n; ++i) {
    if (!(diameter[i] > 0.0) || !std::isfinite(diameter[i])) {
      return fail("Particles.diameter[" + std::to_string(i) + "] = " + Num(diameter[i]) +
                  " m: must be finite and > 0");
    }
    if (!(density[i] > 0.0) || !std::isfinite(density[i])) {
      return fail("Particles.density[" + std::to_string(i) + "] = " + Num(density[i]) +
                  " kg/m^3: must be finite and > 0");
    }
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || !std::isfinite(z[i]) ||
        !std::isfinite(vx[i]) || !std::isfinite(vy[i]) || !std::isfinite(vz[i])) {
      return fail("Particles: position/velocity of particle " + std::to_string(i) +
                  " is not finite");
    }
  }
  return true;
}

// ---- Options -----------------------------------------------------------------------------------

bool DemOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error != nullptr) *error = "DemOptions." + m;
    return false;
  };
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(box_min[a]) || !std::isfinite(box_max[a]) || !(box_max[a] > box_min[a])) {
      return fail("box_max[" + std::to_string(a) + "] = " + Num(box_max[a]) +
                  " m must be finite and > box_min[" + std::to_string(a) +
                  "] = " + Num(box_min[a]) + " m");
    }
  }
  if (!Finite(gravity)) return fail("gravity: must be finite");
  if (!(normal_stiffness > 0.0) || !std::isfinite(normal_stiffness)) {
    return fail("normal_stiffness = " + Num(normal_stiffness) + " N/m: must be > 0");
  }
  if (!(restitution > 0.0 && restitution <= 1.0)) {
    return fail("restitution = " + Num(restitution) + ": must be in (0, 1]");
  }
  if (!(wall_restitution > 0.0 && wall_restitution <= 1.0)) {
    return fail("wall_restitution = " + Num(wall_restitution) + ": must be in (0, 1]");
  }
  if (!(friction >= 0.0) || !std::isfinite(friction)) {
    return fail("friction = " + Num(friction) + ": must be finite and >= 0");
  }
  if (!(wall_friction >= 0.0) || !std::isfinite(wall_friction)) {
    return fail("wall_friction = " + Num(wall_friction) + ": must be finite and >= 0");
  }
  if (!(tangential_stiffness_ratio > 0.0 && tangential_stiffness_ratio <= 1.0)) {
    return fail("tangential_stiffness_ratio = " + Num(tangential_stiffness_ratio) +
                ": must be in (0, 1]");
  }
  if (!(tangential_damping_ratio >= 0.0 && tangential_damping_ratio <= 1.0)) {
    return fail("tangential_damping_ratio = " + Num(tangential_damping_ratio) +
                ": must be in [0, 1]");
  }
  if (!(dt >= 0.0) || !std::isfinite(dt)) {
    return fail("dt = " + Num(dt) + " s: must be 0 (automatic) or > 0");
  }
  if (!(min_steps_per_contact >= 4.0 && min_steps_per_contact <= 1e4)) {
    return fail("min_steps_per_contact = " + Num(min_steps_per_contact) +
                ": must be in [4, 10000]");
  }
  if (!(max_overlap_fraction > 0.0 && max_overlap_fraction <= 0.5)) {
    return fail("max_overlap_fraction = " + Num(max_overlap_fraction) + ": must be in (0, 0.5]");
  }
  if (!(neighbor_skin_fraction >= 0.0 && neighbor_skin_fraction <= 1.0)) {
    return fail("neighbor_skin_fraction = " + Num(neighbor_skin_fraction) + ": must be in [0, 1]");
  }
  return true;
}

// ---- DemSystem ---------------------------------------------------------------------------------

DemSystem::DemSystem(const DemOptions& options, Particles particles)
    : options_(options), p_(std::move(particles)) {
  std::string error;
  if (!options_.IsValid(&error)) Fail(error);
  if (p_.id.empty() && !p_.x.empty()) {
    p_.id.resize(p_.x.size());
    std::iota(p_.id.begin(), p_.id.end(), std::int64_t{0});
  }
  if (!p_.IsValid(&error)) Fail(error);
  const std::size_t n = p_.size();
  if (n == 0) Fail("Particles: at least one particle is needed");
  d_max_ = *std::max_element(p_.diameter.begin(), p_.diameter.end());
  d_min_ = *std::min_element(p_.diameter.begin(), p_.diameter.end());
  double m_min = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) m_min = std::min(m_min, p_.mass(i));
  // The lightest pair (m_eff = m/2) and the lightest particle on a wall (m_eff = m) bound t_c.
  contact_time_ =
      std::min(ContactTime(options_.normal_stiffness, 0.5 * m_min, options_.restitution),
               ContactTime(options_.normal_stiffness, m_min, options_.wall_restitution));
  if (options_.dt > 0.0) {
    if (options_.dt > max_time_step() * (1.0 + 1e-12)) {
      Fail("DemOptions.dt = " + Num(options_.dt) + " s is above the stability limit t_c / " +
           Num(options_.min_steps_per_contact) + " = " + Num(max_time_step()) +
           " s (contact time t_c = " + Num(contact_time_) + " s for normal_stiffness " +
           Num(options_.normal_stiffness) + " N/m and the lightest particle); remedy: dt <= " +
           Num(max_time_step()) + " s, dt = 0 (automatic), or a softer normal_stiffness");
    }
    dt_ = options_.dt;
  } else {
    dt_ = max_time_step();
  }
  // Linked cells: edge >= d_max + skin, so every list pair is within the 27 neighbouring cells.
  // A periodic axis needs >= 3 cells (each neighbour cell distinct, a single image in contact);
  // where it is too short for the requested skin, the skin shrinks to fit.
  skin_ = options_.neighbor_skin_fraction * d_max_;
  for (int a = 0; a < 3; ++a) {
    const double length = options_.box_max[a] - options_.box_min[a];
    if (options_.periodic[a] && std::floor(length / d_max_) < 3) {
      Fail("DemOptions.box_max[" + std::to_string(a) + "]: a periodic axis must be at least 3 " +
           "largest diameters long (" + Num(3 * d_max_) + " m), got " + Num(length) + " m");
    }
    if (!options_.periodic[a] && length < d_max_) {
      Fail("DemOptions.box_max[" + std::to_string(a) + "]: the box (" + Num(length) +
           " m) is narrower than the largest particle (" + Num(d_max_) + " m)");
    }
    if (options_.periodic[a]) skin_ = std::max(0.0, std::min(skin_, length / 3.0 - d_max_));
  }
  for (int a = 0; a < 3; ++a) {
    const double length = options_.box_max[a] - options_.box_min[a];
    ncell_[a] = std::max(1, static_cast<int>(std::floor(length / (d_max_ + skin_))));
    if (options_.periodic[a]) ncell_[a] = std::max(ncell_[a], 3);
    cell_size_[a] = length / ncell_[a];
  }
  reset_contacts();
}

void DemSystem::reset_contacts() {
  const std::size_t n = p_.size();
  mass_.resize(n);
  inv_mass_.resize(n);
  inv_inertia_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    mass_[i] = p_.mass(i);
    inv_mass_[i] = 1.0 / mass_[i];
    inv_inertia_[i] = 1.0 / p_.moment_of_inertia(i);
  }
  force_.assign(6 * n, 0.0);
  elastic_.assign(n, 0.0);
  state_.assign(kStateStride * n, 0.0);
  for (int b = 0; b < 2; ++b) {
    hist_count_[b].assign(n, 0);
    hist_partner_[b].assign(n * kMaxContacts, 0);
    hist_xi_[b].assign(n * kMaxContacts * 3, 0.0);
  }
  pack_state();
  build_neighbor_list();
  compute_forces(0.0);
  check_state(0.0);
}

void DemSystem::pack_state() {
  const int n = static_cast<int>(p_.size());
  state_.resize(static_cast<std::size_t>(kStateStride) * n);
  for (int i = 0; i < n; ++i) {
    double* s = &state_[static_cast<std::size_t>(kStateStride) * i];
    s[0] = p_.x[i];
    s[1] = p_.y[i];
    s[2] = p_.z[i];
    s[3] = p_.vx[i];
    s[4] = p_.vy[i];
    s[5] = p_.vz[i];
    s[6] = p_.wx[i];
    s[7] = p_.wy[i];
    s[8] = p_.wz[i];
    s[9] = 0.5 * p_.diameter[i];
    s[10] = mass_[i];
    s[11] = 0.0;
  }
}

// Half list from the linked cells: for each i the j > i (ascending) with centre distance below
// R_i + R_j + skin, any periodic image. Serial and cheap next to the steps between rebuilds.
void DemSystem::build_neighbor_list() {
  build_cells();
  const int n = static_cast<int>(p_.size());
  const double* X = p_.x.data();
  const double* Y = p_.y.data();
  const double* Z = p_.z.data();
  const double* D = p_.diameter.data();
  nbr_start_.assign(n + 1, 0);
  nbr_.clear();
  auto neighbour = [this](int axis, int k, int* wrapped, double* shift) {
    *shift = 0.0;
    *wrapped = k;
    if (k >= 0 && k < ncell_[axis]) return true;
    if (!options_.periodic[axis]) return false;
    const double length = options_.box_max[axis] - options_.box_min[axis];
    *shift = k < 0 ? -length : length;
    *wrapped = (k + ncell_[axis]) % ncell_[axis];
    return true;
  };
  for (int i = 0; i < n; ++i) {
    nbr_start_[i] = static_cast<int>(nbr_.size());
    const double xi = X[i], yi = Y[i], zi = Z[i], ri = 0.5 * D[i];
    const int c = cell_of_[i];
    const int cx = c % ncell_[0], cy = (c / ncell_[0]) % ncell_[1],
              cz = c / (ncell_[0] * ncell_[1]);
    for (int oz = -1; oz <= 1; ++oz) {
      int kz;
      double shz;
      if (!neighbour(2, cz + oz, &kz, &shz)) continue;
      for (int oy = -1; oy <= 1; ++oy) {
        int ky;
        double shy;
        if (!neighbour(1, cy + oy, &ky, &shy)) continue;
        for (int ox = -1; ox <= 1; ++ox) {
          int kx;
          double shx;
          if (!neighbour(0, cx + ox, &kx, &shx)) continue;
          const int cell = (kz * ncell_[1] + ky) * ncell_[0] + kx;
          for (int s = cell_start_[cell]; s < cell_start_[cell + 1]; ++s) {
            const int j = cell_particles_[s];
            if (j <= i) continue;
            const double dx = X[j] + shx - xi, dy = Y[j] + shy - yi, dz = Z[j] + shz - zi;
            const double cut = ri + 0.5 * D[j] + skin_;
            if (dx * dx + dy * dy + dz * dz < cut * cut) nbr_.push_back(j);
          }
        }
      }
    }
    std::sort(nbr_.begin() + nbr_start_[i], nbr_.end());
  }
  nbr_start_[n] = static_cast<int>(nbr_.size());
  x_built_.assign(p_.x.begin(), p_.x.end());
  y_built_.assign(p_.y.begin(), p_.y.end());
  z_built_.assign(p_.z.begin(), p_.z.end());
  ++list_builds_;
}

void DemSystem::build_cells() {
  const int n = static_cast<int>(p_.size());
  const int ncells = ncell_[0] * ncell_[1] * ncell_[2];
  cell_of_.resize(n);
  cell_start_.assign(ncells + 1, 0);
  cell_particles_.resize(n);
  const double* pos[3] = {p_.x.data(), p_.y.data(), p_.z.data()};
  for (int i = 0; i < n; ++i) {
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const int k = static_cast<int>(std::floor((pos[a][i] - options_.box_min[a]) / cell_size_[a]));
      c[a] = std::min(std::max(k, 0), ncell_[a] - 1);  // particles touching a wall: edge cell
    }
    cell_of_[i] = (c[2] * ncell_[1] + c[1]) * ncell_[0] + c[0];
    ++cell_start_[cell_of_[i] + 1];
  }
  for (int c = 0; c < ncells; ++c) cell_start_[c + 1] += cell_start_[c];
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = 0; i < n; ++i) cell_particles_[fill[cell_of_[i]]++] = i;
}

// Contact forces, torques and elastic energy of every particle at the packed state_. The
// relative velocities are the current (half-step) velocities; the tangential spring grows by
// g_t dt. Each list pair is evaluated once by its owner i (the lower index), which applies equal
// and opposite forces and alone reads and writes the pair's spring. Threads take contiguous
// ranges of owners with equal pair counts; thread 0 accumulates into force_, thread t > 0 into
// its own buffer (a pair's j may lie in another thread's range), and the buffers are added in
// thread order: no races, no atomics, the same result on every run with the same thread count.
void DemSystem::compute_forces(double dt) {
  const int n = static_cast<int>(p_.size());
  const int prev = hist_cur_, next = 1 - hist_cur_;
  const double kn = options_.normal_stiffness;
  const double kt = kn * options_.tangential_stiffness_ratio;
  const double ce = DampingFactor(options_.restitution);
  const double ce_wall = DampingFactor(options_.wall_restitution);
  const double mu = options_.friction, mu_wall = options_.wall_friction;
  const double eta_t_ratio = options_.tangential_damping_ratio;
  const bool periodic_any = options_.periodic[0] || options_.periodic[1] || options_.periodic[2];
  double length[3], half_length[3];
  for (int a = 0; a < 3; ++a) {
    length[a] = options_.box_max[a] - options_.box_min[a];
    half_length[a] = options_.periodic[a] ? 0.5 * length[a] : std::numeric_limits<double>::max();
  }
  const double* S = state_.data();
  const int* start = nbr_start_.data();
  const int* nbr = nbr_.data();
  const int pairs = start[n];
  const bool parallel = n >= 512;
  const int max_threads = parallel ? std::max(1, omp_get_max_threads()) : 1;
  if (static_cast<int>(thread_force_.size()) < max_threads - 1) {
    thread_force_.resize(max_threads - 1);
  }
  struct Totals {
    std::int64_t contacts = 0, wall_contacts = 0;
    double max_overlap = 0.0;
    double wall_force[18] = {0.0};
    int overflow = -1;
  };
  std::vector<Totals> totals(max_threads);
  std::vector<int> range_begin(max_threads + 1, n), range_written_end(max_threads, 0);

#pragma omp parallel if (parallel)
  {
    const int num_threads = omp_get_num_threads(), t = omp_get_thread_num();
    // First owner of thread k: work = pairs + particles (walls, bookkeeping) split evenly.
    auto split = [&](int k) {
      if (k <= 0) return 0;
      if (k >= num_threads) return n;
      const double target = static_cast<double>(k) * (pairs + n) / num_threads;
      int lo = 0, hi = n;
      while (lo < hi) {
        const int mid = lo + (hi - lo) / 2;
        if (start[mid] + mid < target) {
          lo = mid + 1;
        } else {
          hi = mid;
        }
      }
      return lo;
    };
    const int begin = split(t), end = split(t + 1);
    // Highest index + 1 this thread writes: its owners and their (ascending) partners.
    int written_end = end;
    for (int i = begin; i < end; ++i) {
      if (start[i + 1] > start[i]) written_end = std::max(written_end, nbr[start[i + 1] - 1] + 1);
    }
    range_begin[t] = begin;
    range_written_end[t] = written_end;
    std::fill(force_.begin() + 6 * static_cast<std::size_t>(begin),
              force_.begin() + 6 * static_cast<std::size_t>(end), 0.0);
    // Where this thread accumulates: force_ for thread 0, else its buffer, which covers only the
    // indices [begin, written_end) (index j lives at j - base).
    double* F = force_.data();
    int base = 0;
    if (t > 0) {
      std::vector<double>& buffer = thread_force_[t - 1];
      const std::size_t size = 6 * static_cast<std::size_t>(written_end - begin);
      if (buffer.size() < size) buffer.resize(size);
      std::fill(buffer.begin(), buffer.begin() + size, 0.0);
      F = buffer.data();
      base = begin;
    }
#pragma omp barrier
    Totals tot;
    for (int i = begin; i < end; ++i) {
      const double* si = S + static_cast<std::size_t>(kStateStride) * i;
      const double xi = si[0], yi = si[1], zi = si[2];
      const double vxi = si[3], vyi = si[4], vzi = si[5];
      const double wxi = si[6], wyi = si[7], wzi = si[8];
      const double ri = si[9], mi = si[10];
      const int old_count = hist_count_[prev][i];
      const int* old_partner = &hist_partner_[prev][static_cast<std::size_t>(i) * kMaxContacts];
      const double* old_xi = &hist_xi_[prev][static_cast<std::size_t>(i) * kMaxContacts * 3];
      int* new_partner = &hist_partner_[next][static_cast<std::size_t>(i) * kMaxContacts];
      double* new_xi = &hist_xi_[next][static_cast<std::size_t>(i) * kMaxContacts * 3];
      int count = 0;
      double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0, energy = 0;

      // One contact of i with unit normal n (from i towards the partner), overlap delta, partner
      // velocity vj, angular velocity wj and lever rj (all 0 for walls). Returns the force on i
      // in fc and n x F_t in nft (the torque on i is r_i n x F_t; on a partner sphere j, whose
      // normal and force are both reversed, it is r_j n x F_t).
      auto contact = [&](int partner, double nx, double ny, double nz, double delta, double m_eff,
                         double c_e, double mu_f, double vjx, double vjy, double vjz, double rj,
                         double wjx, double wjy, double wjz, double* fc, double* nft) {
        const double eta_n = c_e * std::sqrt(kn * m_eff);
        const double eta_t = eta_t_ratio * eta_n;
        // Velocity of i's contact point relative to the partner's: g = v_i - v_j + (r_i w_i +
        // r_j w_j) x n.
        const double sx = ri * wxi + rj * wjx, sy = ri * wyi + rj * wjy, sz = ri * wzi + rj * wjz;
        const double gx = vxi - vjx + (sy * nz - sz * ny);
        const double gy = vyi - vjy + (sz * nx - sx * nz);
        const double gz = vzi - vjz + (sx * ny - sy * nx);
        const double gn = gx * nx + gy * ny + gz * nz;  // > 0: approaching
        // Normal force magnitude (repulsive > 0). Not clipped at zero: the small tensile force
        // at the end of a contact is what makes the rebound exactly e (closed-form damping).
        const double fn = kn * delta + eta_n * gn;
        const double gtx = gx - gn * nx, gty = gy - gn * ny, gtz = gz - gn * nz;
        // Tangential spring: previous value rotated into the current tangent plane, then grown.
        double xix = 0, xiy = 0, xiz = 0;
        for (int s = 0; s < old_count; ++s) {
          if (old_partner[s] == partner) {
            xix = old_xi[3 * s];
            xiy = old_xi[3 * s + 1];
            xiz = old_xi[3 * s + 2];
            const double along = xix * nx + xiy * ny + xiz * nz;
            xix -= along * nx;
            xiy -= along * ny;
            xiz -= along * nz;
            break;
          }
        }
        xix += gtx * dt;
        xiy += gty * dt;
        xiz += gtz * dt;
        double ftx = -kt * xix - eta_t * gtx;
        double fty = -kt * xiy - eta_t * gty;
        double ftz = -kt * xiz - eta_t * gtz;
        const double ft = std::sqrt(ftx * ftx + fty * fty + ftz * ftz);
        const double limit = mu_f * std::fabs(fn);
        if (ft > limit) {
          // Sliding: force on the Coulomb cone, spring truncated to be consistent with it.
          const double scale = ft > 0.0 ? limit / ft : 0.0;
          ftx *= scale;
          fty *= scale;
          ftz *= scale;
          xix = -(ftx + eta_t * gtx) / kt;
          xiy = -(fty + eta_t * gty) / kt;
          xiz = -(ftz + eta_t * gtz) / kt;
        }
        fc[0] = -fn * nx + ftx;
        fc[1] = -fn * ny + fty;
        fc[2] = -fn * nz + ftz;
        nft[0] = ny * ftz - nz * fty;
        nft[1] = nz * ftx - nx * ftz;
        nft[2] = nx * fty - ny * ftx;
        energy += 0.5 * (kn * delta * delta + kt * (xix * xix + xiy * xiy + xiz * xiz));
        if (count < kMaxContacts) {
          new_partner[count] = partner;
          new_xi[3 * count] = xix;
          new_xi[3 * count + 1] = xiy;
          new_xi[3 * count + 2] = xiz;
          ++count;
        } else {
          tot.overflow = std::max(tot.overflow, i);
        }
      };

      // Particle-particle contacts of the pairs that i owns.
      for (int k = start[i]; k < start[i + 1]; ++k) {
        const int j = nbr[k];
        const double* sj = S + static_cast<std::size_t>(kStateStride) * j;
        double dx = sj[0] - xi, dy = sj[1] - yi, dz = sj[2] - zi;
        if (periodic_any) {
          // Nearest image: a touching pair is closer than d_max <= L/3.
          dx = NearestImage(dx, length[0], half_length[0]);
          dy = NearestImage(dy, length[1], half_length[1]);
          dz = NearestImage(dz, length[2], half_length[2]);
        }
        const double rj = sj[9];
        const double rsum = ri + rj;
        const double dist2 = dx * dx + dy * dy + dz * dz;
        if (dist2 >= rsum * rsum || dist2 == 0.0) continue;
        const double dist = std::sqrt(dist2);
        const double inv = 1.0 / dist;
        const double delta = rsum - dist;
        const double mj = sj[10];
        double fc[3], nft[3];
        contact(j, dx * inv, dy * inv, dz * inv, delta, mi * mj / (mi + mj), ce, mu, sj[3], sj[4],
                sj[5], rj, sj[6], sj[7], sj[8], fc, nft);
        fx += fc[0];
        fy += fc[1];
        fz += fc[2];
        tx += ri * nft[0];
        ty += ri * nft[1];
        tz += ri * nft[2];
        double* fj = F + 6 * static_cast<std::size_t>(j - base);
        fj[0] -= fc[0];
        fj[1] -= fc[1];
        fj[2] -= fc[2];
        fj[3] += rj * nft[0];
        fj[4] += rj * nft[1];
        fj[5] += rj * nft[2];
        ++tot.contacts;
        tot.max_overlap = std::max(tot.max_overlap, delta / (2.0 * std::min(ri, rj)));
      }
      // Walls: planes of the box on non-periodic axes; static, so the partner velocity is zero.
      const double pos[3] = {xi, yi, zi};
      for (int a = 0; a < 3; ++a) {
        if (options_.periodic[a]) continue;
        for (int side = 0; side < 2; ++side) {
          const double delta =
              side == 0 ? ri - (pos[a] - options_.box_min[a]) : ri - (options_.box_max[a] - pos[a]);
          if (delta <= 0.0) continue;
          double nrm[3] = {0.0, 0.0, 0.0};
          nrm[a] = side == 0 ? -1.0 : 1.0;  // from the particle towards the wall
          double fc[3], nft[3];
          contact(-1 - (2 * a + side), nrm[0], nrm[1], nrm[2], delta, mi, ce_wall, mu_wall, 0.0,
                  0.0, 0.0, 0.0, 0.0, 0.0, 0.0, fc, nft);
          fx += fc[0];
          fy += fc[1];
          fz += fc[2];
          tx += ri * nft[0];
          ty += ri * nft[1];
          tz += ri * nft[2];
          double* wf = &tot.wall_force[3 * (2 * a + side)];
          wf[0] -= fc[0];
          wf[1] -= fc[1];
          wf[2] -= fc[2];
          ++tot.wall_contacts;
          tot.max_overlap = std::max(tot.max_overlap, delta / (2.0 * ri));
        }
      }
      hist_count_[next][i] = count;
      double* fi = F + 6 * static_cast<std::size_t>(i - base);
      fi[0] += fx;
      fi[1] += fy;
      fi[2] += fz;
      fi[3] += tx;
      fi[4] += ty;
      fi[5] += tz;
      elastic_[i] = energy;
    }
    totals[t] = tot;
#pragma omp barrier
    // Partner forces that other threads wrote into their buffers, added in thread order.
    for (int u = 1; u < num_threads && range_begin[u] < end; ++u) {
      const int lo = std::max(begin, range_begin[u]), hi = std::min(end, range_written_end[u]);
      const double* buffer = thread_force_[u - 1].data();
      for (int q = 6 * (lo - range_begin[u]), stop = 6 * (hi - range_begin[u]); q < stop; ++q) {
        force_[6 * static_cast<std::size_t>(range_begin[u]) + q] += buffer[q];
      }
    }
  }
  hist_cur_ = next;
  Totals sum;
  for (const Totals& tot : totals) {
    sum.contacts += tot.contacts;
    sum.wall_contacts += tot.wall_contacts;
    sum.max_overlap = std::max(sum.max_overlap, tot.max_overlap);
    for (int k = 0; k < 18; ++k) sum.wall_force[k] += tot.wall_force[k];
    sum.overflow = std::max(sum.overflow, tot.overflow);
  }
  contacts_ = sum.contacts;
  wall_contacts_ = sum.wall_contacts;
  max_overlap_ = sum.max_overlap;
  std::copy(sum.wall_force, sum.wall_force + 18, wall_force_.begin());
  overflow_particle_ = sum.overflow;
}

void DemSystem::check_state(double dt) const {
  if (overflow_particle_ >= 0) {
    Diverged("DEM: particle " + std::to_string(overflow_particle_) + " has more than " +
             std::to_string(kMaxContacts) +
             " contacts (limit of the contact history); overlaps are " +
             "too large or the size ratio too wide; remedy: raise normal_stiffness or narrow the " +
             "size distribution");
  }
  if (max_overlap_ > options_.max_overlap_fraction || !std::isfinite(max_overlap_)) {
    Diverged("DEM diverged at t = " + Num(time_) + " s: overlap " + Num(max_overlap_) +
             " of a diameter exceeds max_overlap_fraction = " + Num(options_.max_overlap_fraction) +
             "; remedy: raise normal_stiffness (k_n = " + Num(options_.normal_stiffness) +
             " N/m) or lower the impact velocities / external forces");
  }
  const int n = static_cast<int>(p_.size());
  const double tol = 0.5 * d_max_;
  double vmax2 = 0.0;
  int bad = -1;
  for (int i = 0; i < n; ++i) {
    const double v2 = p_.vx[i] * p_.vx[i] + p_.vy[i] * p_.vy[i] + p_.vz[i] * p_.vz[i];
    const double pos[3] = {p_.x[i], p_.y[i], p_.z[i]};
    bool ok =
        std::isfinite(v2) && std::isfinite(force_[6 * i] + force_[6 * i + 1] + force_[6 * i + 2]);
    for (int a = 0; a < 3 && ok; ++a) {
      ok = std::isfinite(pos[a]) && (options_.periodic[a] || (pos[a] > options_.box_min[a] - tol &&
                                                              pos[a] < options_.box_max[a] + tol));
    }
    if (!ok) {
      bad = i;
      break;
    }
    vmax2 = std::max(vmax2, v2);
  }
  if (bad >= 0) {
    Diverged("DEM diverged at t = " + Num(time_) + " s: particle " + std::to_string(bad) +
             " is non-finite or outside the box (limit: half a diameter beyond a wall); remedy: " +
             "lower dt (now " + Num(dt_) +
             " s), raise normal_stiffness, or check the external "
             "forces");
  }
  if (dt > 0.0 && std::sqrt(vmax2) * dt > 0.25 * d_min_) {
    Diverged("DEM diverged at t = " + Num(time_) + " s: a particle moves " +
             Num(std::sqrt(vmax2) * dt / d_min_) + " diameters per step (limit 0.25; contacts " +
             "would be missed); remedy: lower dt (now " + Num(dt) +
             " s) or check the external forces");
  }
}

void DemSystem::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    Fail("DemSystem::step: dt = " + Num(dt) + " s must be > 0");
  if (dt > max_time_step() * (1.0 + 1e-12)) {
    Fail("DemSystem::step: dt = " + Num(dt) + " s is above the stability limit t_c / " +
         Num(options_.min_steps_per_contact) + " = " + Num(max_time_step()) +
         " s (t_c = " + Num(contact_time_) +
         " s); remedy: sub-step with advance() or dt <= " + Num(max_time_step()) + " s");
  }
  const int n = static_cast<int>(p_.size());
  const double gx = options_.gravity[0], gy = options_.gravity[1], gz = options_.gravity[2];
  const double h = 0.5 * dt;
  double* pos[3] = {p_.x.data(), p_.y.data(), p_.z.data()};
  double* vel[3] = {p_.vx.data(), p_.vy.data(), p_.vz.data()};
  const double* built[3] = {x_built_.data(), y_built_.data(), z_built_.data()};
  double lo[3], length[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = options_.box_min[a];
    length[a] = options_.box_max[a] - options_.box_min[a];
  }
  // Kick (half), drift, wrap periodic axes into [min, max); pack the state for the pair loop and
  // track the largest displacement since the list was built (nearest image on periodic axes).
  double max_displacement2 = 0.0;
#pragma omp parallel for schedule(static) if (n >= 512) reduction(max : max_displacement2)
  for (int i = 0; i < n; ++i) {
    const double im = inv_mass_[i], ii = inv_inertia_[i];
    const double* f = &force_[6 * static_cast<std::size_t>(i)];
    const double* f_ext[3] = {&p_.fx_ext[i], &p_.fy_ext[i], &p_.fz_ext[i]};
    double* w[3] = {&p_.wx[i], &p_.wy[i], &p_.wz[i]};
    double* s = &state_[static_cast<std::size_t>(kStateStride) * i];
    double displacement2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double g = options_.gravity[a];
      double& v = vel[a][i];
      v += h * ((f[a] + *f_ext[a]) * im + g);
      *w[a] += h * f[3 + a] * ii;
      double& q = pos[a][i];
      q += dt * v;
      double moved = q - built[a][i];
      if (options_.periodic[a]) {
        if (q < lo[a] || q >= lo[a] + length[a]) {
          q -= length[a] * std::floor((q - lo[a]) / length[a]);
          if (q >= lo[a] + length[a]) q = lo[a];  // rounding
        }
        moved = NearestImage(q - built[a][i], length[a], 0.5 * length[a]);
      }
      displacement2 += moved * moved;
      s[a] = q;
      s[3 + a] = v;
      s[6 + a] = *w[a];
    }
    max_displacement2 = std::max(max_displacement2, displacement2);
  }
  // Rebuild when two particles may have closed the skin between them.
  if (max_displacement2 > 0.25 * skin_ * skin_) build_neighbor_list();
  compute_forces(dt);
  // Kick (half) with the new forces.
#pragma omp parallel for schedule(static) if (n >= 512)
  for (int i = 0; i < n; ++i) {
    const double im = inv_mass_[i], ii = inv_inertia_[i];
    const double* f = &force_[6 * static_cast<std::size_t>(i)];
    p_.vx[i] += h * ((f[0] + p_.fx_ext[i]) * im + gx);
    p_.vy[i] += h * ((f[1] + p_.fy_ext[i]) * im + gy);
    p_.vz[i] += h * ((f[2] + p_.fz_ext[i]) * im + gz);
    p_.wx[i] += h * f[3] * ii;
    p_.wy[i] += h * f[4] * ii;
    p_.wz[i] += h * f[5] * ii;
  }
  time_ += dt;
  ++steps_;
  check_state(dt);
}

std::int64_t DemSystem::advance(double duration) {
  if (!(duration >= 0.0) || !std::isfinite(duration)) {
    Fail("DemSystem::advance: duration = " + Num(duration) + " s must be >= 0");
  }
  if (duration == 0.0) return 0;
  const std::int64_t k = static_cast<std::int64_t>(std::ceil(duration / dt_ * (1.0 - 1e-12)));
  const double h = duration / static_cast<double>(std::max<std::int64_t>(k, 1));
  for (std::int64_t s = 0; s < k; ++s) step(h);
  return k;
}

DemEnergy DemSystem::energy() const {
  DemEnergy e;
  const std::size_t n = p_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double m = mass_[i];
    e.kinetic_translational +=
        0.5 * m * (p_.vx[i] * p_.vx[i] + p_.vy[i] * p_.vy[i] + p_.vz[i] * p_.vz[i]);
    e.kinetic_rotational +=
        0.5 / inv_inertia_[i] * (p_.wx[i] * p_.wx[i] + p_.wy[i] * p_.wy[i] + p_.wz[i] * p_.wz[i]);
    e.elastic += elastic_[i];
    e.gravitational -= m * (options_.gravity[0] * p_.x[i] + options_.gravity[1] * p_.y[i] +
                            options_.gravity[2] * p_.z[i]);
  }
  return e;
}

std::array<double, 3> DemSystem::wall_force(Wall w) const {
  const int k = static_cast<int>(w);
  return {wall_force_[3 * k], wall_force_[3 * k + 1], wall_force_[3 * k + 2]};
}

void DemSystem::sort_particles() {
  const int n = static_cast<int>(p_.size());
  build_cells();
  // order[new] = old, in cell order.
  std::vector<int> order(cell_particles_.begin(), cell_particles_.end());
  std::vector<int> new_index(n);
  for (int k = 0; k < n; ++k) new_index[order[k]] = k;
  // Contact history first (it may refuse): a pair's spring moves to the pair's new lower index,
  // negated when the owner changes side (the spring seen from the partner is -xi); walls stay.
  const int cur = hist_cur_;
  std::vector<int> count(n, 0), partner(static_cast<std::size_t>(n) * kMaxContacts);
  std::vector<double> xi(static_cast<std::size_t>(n) * kMaxContacts * 3);
  for (int k = 0; k < n; ++k) {
    const int o = order[k];
    for (int s = 0; s < hist_count_[cur][o]; ++s) {
      const std::size_t from = static_cast<std::size_t>(o) * kMaxContacts + s;
      const int q = hist_partner_[cur][from];
      int owner = k, other = q;
      double sign = 1.0;
      if (q >= 0) {
        other = new_index[q];
        if (other < k) {
          std::swap(owner, other);
          sign = -1.0;
        }
      }
      if (count[owner] >= kMaxContacts) {
        Diverged("DEM: particle " + std::to_string(owner) + " has more than " +
                 std::to_string(kMaxContacts) + " contacts (limit of the contact history); " +
                 "overlaps are too large or the size ratio too wide; remedy: raise " +
                 "normal_stiffness or narrow the size distribution");
      }
      const std::size_t to = static_cast<std::size_t>(owner) * kMaxContacts + count[owner]++;
      partner[to] = other;
      for (int c = 0; c < 3; ++c) xi[3 * to + c] = sign * hist_xi_[cur][3 * from + c];
    }
  }
  auto permute = [&](auto& v) {
    auto copy = v;
    for (int k = 0; k < n; ++k) v[k] = copy[order[k]];
  };
  for (auto* v :
       {&p_.x, &p_.y, &p_.z, &p_.vx, &p_.vy, &p_.vz, &p_.wx, &p_.wy, &p_.wz, &p_.fx_ext, &p_.fy_ext,
        &p_.fz_ext, &p_.diameter, &p_.density, &elastic_, &mass_, &inv_mass_, &inv_inertia_}) {
    permute(*v);
  }
  permute(p_.id);
  const std::vector<double> force = force_;
  for (int k = 0; k < n; ++k) {
    for (int c = 0; c < 6; ++c)
      force_[6 * static_cast<std::size_t>(k) + c] =
          force[6 * static_cast<std::size_t>(order[k]) + c];
  }
  hist_count_[cur] = std::move(count);
  hist_partner_[cur] = std::move(partner);
  hist_xi_[cur] = std::move(xi);
  pack_state();
  build_neighbor_list();
}

// ---- Settling ----------------------------------------------------------------------------------

bool SettleOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error != nullptr) *error = "SettleOptions." + m;
    return false;
  };
  if (n < 1) return fail("n = " + std::to_string(n) + ": must be >= 1");
  if (!(diameter > 0.0) || !std::isfinite(diameter)) {
    return fail("diameter = " + Num(diameter) + " m: must be > 0");
  }
  if (!diameters.empty() && diameters.size() != static_cast<std::size_t>(n)) {
    return fail("diameters has " + std::to_string(diameters.size()) +
                " values for n = " + std::to_string(n) + " particles");
  }
  for (std::size_t i = 0; i < diameters.size(); ++i) {
    if (!(diameters[i] > 0.0) || !std::isfinite(diameters[i])) {
      return fail("diameters[" + std::to_string(i) + "] = " + Num(diameters[i]) +
                  " m: must be > 0");
    }
  }
  if (!(density > 0.0) || !std::isfinite(density)) {
    return fail("density = " + Num(density) + " kg/m^3: must be > 0");
  }
  if (!(insertion_solids_fraction > 0.0 && insertion_solids_fraction <= 0.35)) {
    return fail("insertion_solids_fraction = " + Num(insertion_solids_fraction) +
                ": must be in (0, 0.35]");
  }
  if (!(kinetic_energy_tolerance > 0.0 && kinetic_energy_tolerance <= 1e-2)) {
    return fail("kinetic_energy_tolerance = " + Num(kinetic_energy_tolerance) +
                ": must be in (0, 1e-2]");
  }
  if (!(max_time > 0.0) || !std::isfinite(max_time)) {
    return fail("max_time = " + Num(max_time) + " s: must be > 0");
  }
  if (!(checkpoint_interval_s >= 0.0 && checkpoint_interval_s <= 1e6)) {
    return fail("checkpoint_interval_s = " + Num(checkpoint_interval_s) +
                " s: must be in [0, 1e6]");
  }
  return true;
}

std::string SettleResult::BriefReport() const {
  std::ostringstream s;
  s << "settled " << particles.size() << " particles in " << Num(simulated_time_s) << " s ("
    << steps << " steps, " << Num(wall_s) << " s wall): bed height " << Num(bed_height_m)
    << " m, KE/(m g d) " << Num(kinetic_energy_ratio) << ", floor force/weight "
    << Num(weight_n > 0 ? floor_force_n / weight_n : 0.0);
  return s.str();
}

namespace {

// A settling checkpoint: this magic line, the key line (what made the settling), the progress
// display's two numbers, then the DEM state (DemSystem::SaveState).
constexpr char kSettleMagic[] = "draglab settle checkpoint 1\n";

// FNV-1a over bytes: the key's digest of the per-particle diameters.
std::uint64_t Fnv1a(const void* data, std::size_t size, std::uint64_t h = 1469598103934665603ULL) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  return h;
}

// Every input of a settling, exactly (%a), on one line: a checkpoint made with other options or
// particles is not taken up.
std::string SettleKey(const DemOptions& o, const SettleOptions& s, int threads) {
  std::string key;
  const auto add = [&key](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%a ", v);
    key += buf;
  };
  for (int a = 0; a < 3; ++a) {
    add(o.box_min[a]);
    add(o.box_max[a]);
    add(o.periodic[a] ? 1.0 : 0.0);
    add(o.gravity[a]);
  }
  for (double v : {o.normal_stiffness, o.restitution, o.friction, o.wall_restitution,
                   o.wall_friction, o.tangential_stiffness_ratio, o.tangential_damping_ratio, o.dt,
                   o.min_steps_per_contact, o.max_overlap_fraction, o.neighbor_skin_fraction}) {
    add(v);
  }
  for (double v : {s.diameter, s.density, s.insertion_solids_fraction, s.kinetic_energy_tolerance,
                   s.max_time}) {
    add(v);
  }
  key += "n " + std::to_string(s.n) + " seed " + std::to_string(s.seed) + " diameters " +
         std::to_string(Fnv1a(s.diameters.data(), s.diameters.size() * sizeof(double))) +
         " threads " + std::to_string(threads);
  return key;
}

struct SettleCheckpoint {
  double peak_ratio = 0.0, reported = 0.0;
  std::unique_ptr<DemSystem> dem;
};

void WriteSettleCheckpoint(const std::string& path, const std::string& key, double peak_ratio,
                           double reported, const DemSystem& dem) {
  const std::string state = dem.SaveState();
  const std::string line = key + "\n";
  const double numbers[2] = {peak_ratio, reported};
  core::write_file_atomically(path,
                              {{kSettleMagic, sizeof(kSettleMagic) - 1},
                               {line.data(), line.size()},
                               {numbers, sizeof numbers},
                               {state.data(), state.size()}},
                              "SettleOptions.checkpoint_path");
}

// The checkpoint at `path` if there is one made with `key`; none (nothing to go on from) when the
// file is missing, another settling's, or not a checkpoint.
SettleCheckpoint ReadSettleCheckpoint(const std::string& path, const std::string& key,
                                      const DemOptions& run) {
  SettleCheckpoint c;
  std::ifstream in(path, std::ios::binary);
  if (!in) return c;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string head = std::string(kSettleMagic) + key + "\n";
  if (bytes.size() < head.size() + 2 * sizeof(double) || bytes.compare(0, head.size(), head) != 0)
    return c;
  double numbers[2];
  std::memcpy(numbers, bytes.data() + head.size(), sizeof numbers);
  try {
    c.dem = DemSystem::LoadState(run, bytes.substr(head.size() + sizeof numbers));
  } catch (const Error&) {
    return c;
  }
  c.peak_ratio = numbers[0];
  c.reported = numbers[1];
  return c;
}

}  // namespace

SettleResult settle_particles(const DemOptions& options, const SettleOptions& settle,
                              const DemProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  if (!options.IsValid(&error)) Fail(error);
  if (!settle.IsValid(&error)) Fail(error);
  const double g =
      std::sqrt(options.gravity[0] * options.gravity[0] + options.gravity[1] * options.gravity[1] +
                options.gravity[2] * options.gravity[2]);
  if (!(options.gravity[1] < 0.0) || std::fabs(options.gravity[0]) > 1e-12 * g ||
      std::fabs(options.gravity[2]) > 1e-12 * g) {
    Fail("DemOptions.gravity: settle_particles needs gravity along -y");
  }
  // Several sizes: the hash cell and the column margins take the largest, the insertion volume and
  // the kinetic-energy scale the mean particle.
  const bool sized = !settle.diameters.empty();
  const auto diameter_of = [&](std::size_t i) {
    return sized ? settle.diameters[i] : settle.diameter;
  };
  const double d =
      sized ? *std::max_element(settle.diameters.begin(), settle.diameters.end()) : settle.diameter;
  const double lx = options.box_max[0] - options.box_min[0];
  const double lz = options.box_max[2] - options.box_min[2];
  if (lx < d || lz < d) {
    Fail("SettleOptions.diameter = " + Num(d) + " m: wider than the box cross-section");
  }
  double solids = 0.0;
  for (int i = 0; sized && i < settle.n; ++i) solids += kPi / 6.0 * std::pow(diameter_of(i), 3);
  // Insertion column: cross-section of the box, height from the target insertion fraction; it
  // may extend above the box top (the real top wall applies after settling).
  const double vp = sized ? solids / settle.n : kPi / 6.0 * d * d * d;
  const double d_mean = sized ? std::cbrt(6.0 * vp / kPi) : d;
  const double cross = lx * lz;
  const double column = std::max(d, settle.n * vp / (settle.insertion_solids_fraction * cross));
  DemOptions run = options;
  run.box_max[1] = options.box_min[1] + column + 2.0 * d;
  // Random sequential insertion on a coarse hash grid (cell = d): reject overlaps.
  std::mt19937_64 rng(settle.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double gap = 0.01 * d;
  const double len[3] = {lx, 0.0, lz};
  const int hx = std::max(1, static_cast<int>(lx / d)), hz = std::max(1, static_cast<int>(lz / d));
  // Hash rows from the lowest centre of the largest particle (smaller ones start a little lower:
  // row 0).
  const double y0 = options.box_min[1] + 0.5 * d + gap;
  const int hy = std::max(1, static_cast<int>((column - gap) / d) + 1);
  const double cx = lx / hx, cz = lz / hz;
  std::vector<std::vector<int>> hash(static_cast<std::size_t>(hx) * hy * hz);
  Particles parts;
  const std::int64_t max_tries = 2000LL * settle.n + 100000;
  std::int64_t tries = 0;
  while (static_cast<int>(parts.size()) < settle.n) {
    if (++tries > max_tries) {
      Fail("SettleOptions.n = " + std::to_string(settle.n) + ": random insertion failed; the " +
           "particles do not fit at insertion_solids_fraction " +
           Num(settle.insertion_solids_fraction) + " in the box cross-section");
    }
    const double di = diameter_of(parts.size()), r = 0.5 * di;
    const double lo[3] = {options.box_min[0] + (options.periodic[0] ? 0.0 : r + gap),
                          options.box_min[1] + r + gap,
                          options.box_min[2] + (options.periodic[2] ? 0.0 : r + gap)};
    const double hi[3] = {options.box_max[0] - (options.periodic[0] ? 0.0 : r + gap),
                          options.box_min[1] + column + r,
                          options.box_max[2] - (options.periodic[2] ? 0.0 : r + gap)};
    const double q[3] = {lo[0] + (hi[0] - lo[0]) * u01(rng), lo[1] + (hi[1] - lo[1]) * u01(rng),
                         lo[2] + (hi[2] - lo[2]) * u01(rng)};
    const int ix = std::min(hx - 1, static_cast<int>((q[0] - options.box_min[0]) / cx));
    const int iy = std::clamp(static_cast<int>((q[1] - y0) / d), 0, hy - 1);
    const int iz = std::min(hz - 1, static_cast<int>((q[2] - options.box_min[2]) / cz));
    bool free = true;
    for (int oz = -1; oz <= 1 && free; ++oz) {
      for (int oy = -1; oy <= 1 && free; ++oy) {
        for (int ox = -1; ox <= 1 && free; ++ox) {
          int kx = ix + ox, ky = iy + oy, kz = iz + oz;
          if (ky < 0 || ky >= hy) continue;
          if (kx < 0 || kx >= hx) {
            if (!options.periodic[0] || hx < 3) continue;
            kx = (kx + hx) % hx;
          }
          if (kz < 0 || kz >= hz) {
            if (!options.periodic[2] || hz < 3) continue;
            kz = (kz + hz) % hz;
          }
          for (int j : hash[(static_cast<std::size_t>(kz) * hy + ky) * hx + kx]) {
            double dd[3] = {parts.x[j] - q[0], parts.y[j] - q[1], parts.z[j] - q[2]};
            for (int a : {0, 2}) {
              if (options.periodic[a]) dd[a] -= len[a] * std::round(dd[a] / len[a]);
            }
            const double reach = 0.5 * (di + parts.diameter[j]) + gap;
            if (dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2] < reach * reach) free = false;
          }
        }
      }
    }
    if (!free) continue;
    hash[(static_cast<std::size_t>(iz) * hy + iy) * hx + ix].push_back(
        static_cast<int>(parts.size()));
    parts.add(q[0], q[1], q[2], di, settle.density);
  }
  // A checkpoint of this settling, if one is there, takes the place of the inserted cloud.
  const std::string key = SettleKey(run, settle, omp_get_max_threads());
  SettleCheckpoint resumed;
  if (!settle.checkpoint_path.empty())
    resumed = ReadSettleCheckpoint(settle.checkpoint_path, key, run);
  std::unique_ptr<DemSystem> system = std::move(resumed.dem);
  if (!system) {
    system = std::make_unique<DemSystem>(run, std::move(parts));
    system->sort_particles();
  }
  DemSystem& dem = *system;
  const double resumed_at_s = dem.time();
  const double m = settle.density * vp;
  const double ke_scale = m * g * d_mean;
  // Fall time from the column top plus relaxation; check every ~1 ms of simulated time.
  const double check = std::max(dem.time_step(), 1e-3);
  // Progress (for the ETA; the stop criterion is the kinetic energy alone): 30 % for the free
  // fall of the column top onto a bed at solids fraction 0.6, 70 % for the decay of the kinetic
  // energy from its peak to the tolerance, on a log scale (the decay is roughly exponential).
  const double fall_height = std::max(d, column - settle.n * vp / (0.6 * cross));
  const double fall_time = std::sqrt(2.0 * fall_height / g);
  double peak_ratio = resumed.peak_ratio, reported = resumed.reported;
  double ratio = std::numeric_limits<double>::infinity();
  auto last_checkpoint = std::chrono::steady_clock::now();
  while (dem.time() < settle.max_time) {
    if (!settle.checkpoint_path.empty() &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint).count() >=
            settle.checkpoint_interval_s) {
      WriteSettleCheckpoint(settle.checkpoint_path, key, peak_ratio, reported, dem);
      last_checkpoint = std::chrono::steady_clock::now();
    }
    dem.advance(check);
    ratio = dem.kinetic_energy() / settle.n / ke_scale;
    if (progress) {
      peak_ratio = std::max(peak_ratio, ratio);
      double decay = 0.0;
      if (dem.time() > fall_time && peak_ratio > settle.kinetic_energy_tolerance && ratio > 0.0) {
        decay =
            std::log(peak_ratio / ratio) / std::log(peak_ratio / settle.kinetic_energy_tolerance);
      }
      const double f =
          0.3 * std::min(1.0, dem.time() / fall_time) + 0.7 * std::clamp(decay, 0.0, 1.0);
      reported = std::max(reported, std::min(f, 0.99));
      progress(reported, (resumed_at_s > 0.0 ? "settling (went on from a checkpoint at t = " +
                                                   Num(resumed_at_s) + " s): KE/(m g d) = "
                                             : std::string("settling: KE/(m g d) = ")) +
                             Num(ratio));
    }
    // At rest: small kinetic energy, and the top particle has landed (not still in free fall).
    if (ratio < settle.kinetic_energy_tolerance && dem.time() > 0.05) break;
  }
  if (!(ratio < settle.kinetic_energy_tolerance)) {
    Diverged("settle_particles: not at rest after SettleOptions.max_time = " +
             Num(settle.max_time) + " s (KE/(m g d) = " + Num(ratio) +
             " > kinetic_energy_tolerance = " + Num(settle.kinetic_energy_tolerance) +
             "); remedy: raise max_time or lower restitution");
  }
  SettleResult result;
  result.particles = dem.particles();
  const auto& p = result.particles;
  double top = options.box_min[1];
  for (std::size_t i = 0; i < p.size(); ++i) top = std::max(top, p.y[i] + 0.5 * p.diameter[i]);
  result.bed_height_m = top - options.box_min[1];
  if (top > options.box_max[1]) {
    Fail("SettleOptions.n = " + std::to_string(settle.n) + ": the settled bed (" +
         Num(result.bed_height_m) + " m) does not fit in the box (height " +
         Num(options.box_max[1] - options.box_min[1]) + " m)");
  }
  for (auto* v : {&result.particles.vx, &result.particles.vy, &result.particles.vz,
                  &result.particles.wx, &result.particles.wy, &result.particles.wz}) {
    std::fill(v->begin(), v->end(), 0.0);
  }
  result.simulated_time_s = dem.time();
  result.steps = dem.steps();
  result.kinetic_energy_ratio = ratio;
  result.floor_force_n = -dem.wall_force(Wall::kYMin)[1];
  result.weight_n = settle.n * m * g;
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.resumed_at_s = resumed_at_s;
  // At rest: the checkpoint has served (a failed settling keeps it, for a longer max_time).
  if (!settle.checkpoint_path.empty()) std::remove(settle.checkpoint_path.c_str());
  return result;
}

}  // namespace consumers
}  // namespace draglab
