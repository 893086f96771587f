// draglab/consumers/dem.h: the soft-sphere discrete element method (DEM) of the DPM consumer.
//
// Spheres (diameter and density per particle) in a box whose six faces are flat walls, or
// periodic along chosen axes. Contacts (particle-particle and particle-wall) use the linear
// spring-dashpot normal force, with the damping set in closed form from the restitution
// coefficient e, and a tangential spring with Coulomb friction (the spring is truncated to the
// slip limit mu_f |F_n|); tangential forces produce torques (rotational degrees of freedom).
// Gravity and an external force per particle supplied by the caller (gas drag and pressure force
// of the coupling) act on every particle. Integration: velocity Verlet (kick-drift-kick); the
// contact damping and the tangential-spring increment use the half-step velocity (as LAMMPS).
// Neighbour search: a half Verlet list (pairs i < j closer than R_i + R_j + skin), built from
// linked cells and rebuilt only when a particle has moved more than skin/2 since the last build
// (or after sort_particles() / reset_contacts()). Each pair is evaluated once and applies equal
// and opposite forces. OpenMP: the particles are split into contiguous ranges of equal work
// (pairs + particles); threads accumulate into their own force buffers, added in thread order, so
// the results are deterministic for a fixed thread count (they differ in rounding between counts).
//
// Units: SI (m, kg, s, N). Axes: x width, y height (gravity along -y by default), z depth.
// Contact model, parameters, time step and limits: docs/dem.md.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace draglab {
namespace consumers {

/// Particles as a structure of arrays (SI units). All arrays have size(); index i is one sphere.
/// The external force (fx_ext, ...) is set by the caller and held constant over each DEM step.
struct Particles {
  std::vector<double> x, y, z;                 ///< Centre position [m].
  std::vector<double> vx, vy, vz;              ///< Velocity [m/s].
  std::vector<double> wx, wy, wz;              ///< Angular velocity [rad/s].
  std::vector<double> fx_ext, fy_ext, fz_ext;  ///< External force [N] (drag, pressure force).
  std::vector<double> diameter;                ///< [m], > 0.
  std::vector<double> density;                 ///< [kg/m^3], > 0.
  std::vector<std::int64_t> id;  ///< Stable identity (insertion order), kept on reorder.

  std::size_t size() const { return x.size(); }
  /// Appends a sphere at rest (no spin, no external force); id = previous size().
  void add(double px, double py, double pz, double d, double rho, double pvx = 0.0,
           double pvy = 0.0, double pvz = 0.0);
  double radius(std::size_t i) const { return 0.5 * diameter[i]; }
  double volume(std::size_t i) const;             ///< pi d^3 / 6 [m^3].
  double mass(std::size_t i) const;               ///< rho pi d^3 / 6 [kg].
  double moment_of_inertia(std::size_t i) const;  ///< Solid sphere m d^2 / 10 [kg m^2].
  /// True if all arrays have the same size and every diameter, density is finite and > 0.
  bool IsValid(std::string* error) const;
};

/// DEM settings: box, walls, contact parameters, time step.
struct DemOptions {
  std::array<double, 3> box_min{0.0, 0.0, 0.0};       ///< Lower corner [m].
  std::array<double, 3> box_max{0.15, 0.45, 0.015};   ///< Upper corner [m] (the seed's bed).
  std::array<bool, 3> periodic{false, false, false};  ///< Periodic axes (no walls there).
  std::array<double, 3> gravity{0.0, -9.81, 0.0};     ///< [m/s^2].
  double normal_stiffness = 7000.0;  ///< k_n [N/m], > 0 (consumers.md 3.5: 7000 N/m).
  double restitution = 0.97;         ///< Particle-particle e, (0, 1].
  double friction = 0.1;             ///< Particle-particle Coulomb mu_f, >= 0.
  double wall_restitution = 0.97;    ///< Particle-wall e, (0, 1].
  double wall_friction = 0.1;        ///< Particle-wall mu_f, >= 0.
  /// k_t / k_n, (0, 1]. 2/7 makes the tangential and normal oscillation periods equal for solid
  /// spheres (MFiX's KT_FAC default).
  double tangential_stiffness_ratio = 2.0 / 7.0;
  /// eta_t / eta_n, [0, 1] (MFiX's DES_ETAT_FAC default 0.5).
  double tangential_damping_ratio = 0.5;
  /// Time step [s]: 0 = automatic t_c / min_steps_per_contact; else must be > 0 and at most that.
  double dt = 0.0;
  /// Steps per contact time at the largest allowed step, [4, 10000]. Default 20 (t_c/20).
  double min_steps_per_contact = 20.0;
  /// Divergence guard: stop when an overlap exceeds this fraction of the smaller diameter,
  /// (0, 0.5].
  double max_overlap_fraction = 0.2;
  /// Verlet-list skin as a fraction of the largest diameter, [0, 1]. A larger skin means fewer
  /// list rebuilds but more candidate pairs per step; 0 rebuilds the list every step. Reduced
  /// automatically where a periodic axis is shorter than 3 (d_max + skin).
  double neighbor_skin_fraction = 0.2;
  /// True if valid; otherwise *error names the field and its allowed range.
  bool IsValid(std::string* error) const;
};

/// Mechanical energy of the particles [J].
struct DemEnergy {
  double kinetic_translational = 0.0;
  double kinetic_rotational = 0.0;
  double elastic = 0.0;        ///< Normal and tangential springs of all contacts.
  double gravitational = 0.0;  ///< -sum m g.x (zero at the origin).
  double kinetic() const { return kinetic_translational + kinetic_rotational; }
  double total() const { return kinetic() + elastic + gravitational; }
};

/// Box faces, in the order of DemSystem::wall_force(): 2*axis + (0 lower, 1 upper).
enum class Wall { kXMin = 0, kXMax, kYMin, kYMax, kZMin, kZMax };

/// The DEM solver. Not copyable; one instance per simulation. Throws draglab::Error
/// (kInvalidArgument) for invalid options or particles (message names the field and range), for
/// a step above the stability limit, and when it detects divergence (non-finite state, overlap
/// above max_overlap_fraction, a particle moving more than a quarter diameter per step, a particle
/// outside the box, too many contacts on one particle); the message names the limit and a remedy.
class DemSystem {
 public:
  DemSystem(const DemOptions& options, Particles particles);
  DemSystem(const DemSystem&) = delete;
  DemSystem& operator=(const DemSystem&) = delete;

  const DemOptions& options() const { return options_; }
  const Particles& particles() const { return p_; }
  /// Mutable access for the caller's external forces and velocities. After changing positions,
  /// diameters or densities call reset_contacts().
  Particles& mutable_particles() { return p_; }
  /// Forgets the tangential contact history and recomputes the forces (after an edit).
  void reset_contacts();

  /// Smallest contact time t_c = pi / sqrt(k_n/m_eff - gamma^2), gamma = eta_n / (2 m_eff), over
  /// the lightest particle pair and the lightest particle on a wall [s].
  double contact_time() const { return contact_time_; }
  /// Largest accepted step t_c / min_steps_per_contact [s].
  double max_time_step() const { return contact_time_ / options_.min_steps_per_contact; }
  /// The step that step() and advance() use: options.dt, or max_time_step() if that is 0 [s].
  double time_step() const { return dt_; }

  /// One velocity-Verlet step of dt [s]; dt above max_time_step() is refused.
  void step(double dt);
  void step() { step(dt_); }
  /// Advances by `duration` [s] in equal steps no longer than time_step(); returns the steps.
  std::int64_t advance(double duration);

  double time() const { return time_; }  ///< Simulated time [s].
  std::int64_t steps() const { return steps_; }
  DemEnergy energy() const;
  double kinetic_energy() const { return energy().kinetic(); }
  std::int64_t contact_count() const { return contacts_; }  ///< Particle-particle contacts.
  std::int64_t wall_contact_count() const { return wall_contacts_; }
  /// Force that the particles exert on a wall at the last force evaluation [N].
  std::array<double, 3> wall_force(Wall w) const;
  /// Largest overlap / smaller diameter at the last force evaluation.
  double max_overlap_fraction() const { return max_overlap_; }
  /// Neighbour-list builds so far (constructor, reset_contacts, sort_particles included).
  std::int64_t neighbor_list_builds() const { return list_builds_; }
  /// Skin of the neighbour list [m]: neighbor_skin_fraction * d_max, or less (periodic axes).
  double neighbor_skin() const { return skin_; }
  /// Reorders particles by linked cell (memory locality, faster steps); ids follow the
  /// particles. Indices change: call only between steps, before caller-side per-index data.
  void sort_particles();

  /// The complete state (particles, forces, contact history, neighbour list, time and counters)
  /// as bytes, so that a system restored from them continues bit for bit as this one would with
  /// the same options and thread count: a checkpoint for the machine and build that wrote it
  /// (native byte order), not an exchange format.
  std::string SaveState() const;
  /// The system SaveState wrote, with `options` (the saved system's; the caller keys its
  /// checkpoints so). Throws Error(kInvalidArgument) for bytes that are not such a state.
  static std::unique_ptr<DemSystem> LoadState(const DemOptions& options, const std::string& bytes);

 private:
  void build_cells();
  void build_neighbor_list();
  void pack_state();
  void compute_forces(double dt);
  void check_state(double dt) const;

  DemOptions options_;
  Particles p_;
  double contact_time_ = 0.0;
  double dt_ = 0.0;
  double time_ = 0.0;
  std::int64_t steps_ = 0;
  double d_max_ = 0.0, d_min_ = 0.0;
  // Per-particle derived data; contact force and torque, 6 per particle (fx fy fz tx ty tz).
  std::vector<double> inv_mass_, inv_inertia_, mass_;
  std::vector<double> force_, elastic_;
  // Per-particle state read by the pair loop, packed (kStateStride per particle) so that a
  // neighbour costs two cache lines instead of eleven: x y z vx vy vz wx wy wz r m.
  std::vector<double> state_;
  // Force buffers of OpenMP threads 1.. (thread 0 writes force_), each over the index range its
  // thread writes, added in thread order.
  std::vector<std::vector<double>> thread_force_;
  // Linked cells (edge >= d_max + skin), used to build the neighbour list.
  std::array<int, 3> ncell_{1, 1, 1};
  std::array<double, 3> cell_size_{1.0, 1.0, 1.0};
  std::vector<int> cell_of_, cell_start_, cell_particles_;
  // Half Verlet list: neighbours j > i of particle i are nbr_[nbr_start_[i] .. nbr_start_[i+1]),
  // ascending; positions at the last build decide the next one.
  double skin_ = 0.0;
  std::vector<int> nbr_start_, nbr_;
  std::vector<double> x_built_, y_built_, z_built_;
  std::int64_t list_builds_ = 0;
  // Tangential contact history, double-buffered, kMaxContacts slots per particle. A pair's spring
  // is kept by its lower index (the list owner) as seen from that particle; walls by the particle.
  std::vector<int> hist_count_[2], hist_partner_[2];
  std::vector<double> hist_xi_[2];
  int hist_cur_ = 0;
  // Diagnostics of the last force evaluation.
  std::int64_t contacts_ = 0, wall_contacts_ = 0;
  double max_overlap_ = 0.0;
  std::array<double, 18> wall_force_{};
  int overflow_particle_ = -1;
};

/// Options of settle_particles().
struct SettleOptions {
  int n = 1000;              ///< Number of spheres, >= 1.
  double diameter = 2.5e-3;  ///< [m], > 0.
  /// Each particle's diameter [m] (n values, > 0), for beds of several sizes; empty: all
  /// `diameter`. The order is the insertion order (shuffle it for a mixed bed).
  std::vector<double> diameters;
  double density = 2526.0;  ///< [kg/m^3], > 0.
  std::uint64_t seed = 1;   ///< Random insertion seed (same seed, same packing).
  /// Solids fraction of the random insertion cloud above the floor, (0, 0.35].
  double insertion_solids_fraction = 0.25;
  /// Stop when the mean kinetic energy per particle is below this fraction of m g d, (0, 1e-2].
  double kinetic_energy_tolerance = 1e-8;
  double max_time = 5.0;  ///< Simulated time limit [s], > 0.
  /// A checkpoint file of the settling, so that one stopped part-way (a kill, a session's end)
  /// goes on from where it was, bit for bit: written atomically every checkpoint_interval_s of
  /// wall time, read at the start when present and made with the same options and particles,
  /// removed once the bed is at rest. Empty: none.
  std::string checkpoint_path;
  /// Wall seconds between checkpoints, [0, 1e6]; 0 writes one at every kinetic-energy check.
  double checkpoint_interval_s = 600.0;
  bool IsValid(std::string* error) const;
};

/// A settled packing and how it was made.
struct SettleResult {
  Particles particles;  ///< At rest, sorted by cell; velocities set to zero.
  double simulated_time_s = 0.0;
  std::int64_t steps = 0;
  double bed_height_m = 0.0;          ///< Highest sphere top above the floor.
  double kinetic_energy_ratio = 0.0;  ///< Final mean KE per particle / (m g d).
  double floor_force_n = 0.0;         ///< Force on the floor along gravity [N].
  double weight_n = 0.0;              ///< Total weight N m |g| [N].
  double wall_s = 0.0;
  double resumed_at_s = 0.0;  ///< Simulated time of the checkpoint it went on from; 0: none.
  std::string BriefReport() const;
};

/// Progress: fraction in [0, 1] and a short stage text.
using DemProgress = std::function<void(double fraction, const std::string& stage)>;

/// Settles `settle.n` equal spheres under gravity onto the floor of `options`' box (gravity
/// must be along -y): random sequential insertion (deterministic seed) in a column above the
/// floor that may extend above the box top, then DEM until the kinetic energy is small. Throws
/// Error(kInvalidArgument) if the options are invalid, if the settled bed does not fit below the
/// box top, or if it is not at rest after max_time.
SettleResult settle_particles(const DemOptions& options, const SettleOptions& settle,
                              const DemProgress& progress = nullptr);

}  // namespace consumers
}  // namespace draglab
