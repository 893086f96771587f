// draglab/consumers/dpm.h: the coupled DPM (CFD-DEM) run of a scene with one loaded drag law.
//
// DpmSimulation joins the soft-sphere DEM (dem.h, x width, y height, z depth) and the
// volume-averaged gas (gas_phase.h, x width, z height): particles are settled with the gas off,
// then each gas step (1) maps the particles to the gas cells with a bilinear tent kernel (the
// depth integrated): eps = 1 - sum V_p W / (dx dz depth), clamped to min_void_fraction with a
// counter; (2) evaluates per particle beta_p = Law::beta(eps_p, mu, rho_g, |slip|, d) at the
// interstitial slip and the drag coefficient c_p = beta_p V_p / (1 - eps_p) [kg/s] (computed as
// Law::dga V_p, finite at eps = 1), so that the drag on ONE particle is F_d = c_p (u_g - u_p) =
// 3 pi mu d eps F (u_g - u_p); (3) gives the gas the cell fields beta_c = sum c_p W / V_cell and
// the c-weighted solids velocity, so the gas solves the drag implicitly; (4) gives the particles
// drag (with the new gas velocity interpolated with the same kernel: the transpose of the
// mapping, so the momentum the gas receives equals the one the particles lose to round-off)
// plus the pressure-gradient force -V_p grad p, held constant over the DEM substeps of the gas
// step. Units SI. Limits: one gas cell across the depth; monodisperse particles; the momentum
// exchange is first order in the gas step (eps lags one gas step in continuity). See docs/dpm.md.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "draglab/consumers/bubble.h"
#include "draglab/consumers/dem.h"
#include "draglab/consumers/gas_phase.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/consumer_results.h"
#include "draglab/drag_db/law.h"

namespace draglab {
namespace consumers {

/// The DEM's linear spring-dashpot normal contact time between two of the scene's particles
/// (reduced mass m/2; [dem] spring_stiffness_n_m and restitution): t_c = pi / sqrt(k/m_eff -
/// eta^2/(4 m_eff^2)), eta = 2 sqrt(k m_eff) |ln e| / sqrt(pi^2 + ln^2 e).
double contact_time_s(const Scene& scene);

/// Run controls on top of the scene (tests and the CLI override a few scene values).
struct DpmOptions {
  double duration_s = 0.0;  ///< Simulated time after t = 0; 0: the scene's duration, else > 0.
  /// Background superficial velocity [m/s]; < 0: from the scene (U_mf factor or fixed value).
  double background_override_m_s = -1.0;
  bool jet = true;  ///< false: no jet (fixed-bed and plateau tests).
  /// Particles held fixed (no DEM steps): a fixed bed, for pressure-drop checks.
  bool freeze_particles = false;
  /// Lower clamp of the mapped void fraction, (0, 0.5); each clamp is counted.
  double min_void_fraction = 0.2;
  /// Settling: mean kinetic energy per particle below this fraction of m g d, (0, 1e-2].
  double settle_kinetic_tolerance = 1e-4;
  double settle_max_time_s = 3.0;  ///< Settling time limit [s], > 0.
  /// A checkpoint of the settling (SettleOptions::checkpoint_path): a settling stopped part-way
  /// goes on from it, bit for bit. Empty: none.
  std::string settle_checkpoint_path;
  double settle_checkpoint_interval_s = 600.0;  ///< Wall seconds between checkpoints, [0, 1e6].
  /// Gas step [s]; 0: the scene's gas_dt_s, else SceneDerived::recommended_gas_dt_s. >= 0.
  double gas_dt_s = 0.0;
  /// Output directory for fields/particles files (scene [outputs]); empty: the scene's
  /// outputs.directory, else out/<scene name>. Files are written only if the scene asks.
  std::string output_directory;
  bool IsValid(std::string* error) const;
};

/// One sample of the time series: the sample every bed model takes (bubble.h).
using DpmSample = BedSample;

/// Number of initial layers the particles are coloured by (equal-height bands of the settled
/// bed, bottom = 0), as the experiment colours them so that mixing shows.
constexpr int kInitialLayers = 6;

/// The particles and the mapped void fraction at one instant (figures and files).
using DpmSnapshot = BedSnapshot;

/// Per gas step coupling diagnostics (the last step).
struct DpmStepDiagnostics {
  /// Sum over particles of the drag force [N] (x width, z height).
  double drag_on_particles_x = 0.0, drag_on_particles_z = 0.0;
  /// Sum over cells of beta_c V_c (u_p,c - u_g,c): the drag the cell fields put on the gas [N].
  double drag_on_gas_x = 0.0, drag_on_gas_z = 0.0;
  double min_void_fraction = 1.0;  ///< Smallest mapped eps before clamping.
};

/// Result of a coupled run.
struct DpmResult {
  std::string law;    ///< name@version.
  std::string scene;  ///< Scene name.
  std::string scene_hash;
  double umf_m_s = 0.0;         ///< The loaded law's U_mf (scene particles, gas, eps_mf).
  double background_m_s = 0.0;  ///< Superficial background velocity used.
  std::string background_mode;  ///< "umf", "umf_packing", "fixed" or "override".
  double eps_mf = 0.0;
  /// Mean gas fraction of the settled packing (column-averaged surface height) and the law's
  /// U_mf at it (background "umf_packing" uses the latter).
  double eps_packing = 0.0;
  double umf_packing_m_s = 0.0;
  /// Empty when the law's U_mf lies inside its validity box; otherwise (range_policy =
  /// "extrapolate") the box it lies outside (MinFluidizationResult::extrapolation).
  std::string umf_extrapolation;
  double t_ref_s = 0.0;            ///< After jet start.
  double bubble_diameter_m = 0.0;  ///< At t_ref (nearest sample); 0 if none found.
  bool bubble_at_t_ref = false;    ///< A sample at t_ref existed and held a bubble.
  std::vector<DpmSample> series;
  std::int64_t particles = 0;
  double settled_bed_height_m = 0.0;
  double settle_wall_s = 0.0;
  double wall_s = 0.0;  ///< Whole run including settling.
  /// OpenMP threads of the run. Trajectories are bitwise reproducible at a fixed thread count;
  /// another count changes the summation order, hence round-off, and a chaotic bed then drifts
  /// (measured on the quick scene, 1 vs 2 threads: D 5.50 vs 5.59 cm; docs/scenes.md).
  int threads = 1;
  long gas_steps = 0;
  std::int64_t dem_steps = 0;
  double gas_dt_s = 0.0, dem_dt_s = 0.0;
  std::int64_t void_fraction_clamps = 0;     ///< Cell values raised to min_void_fraction.
  double max_relative_mass_imbalance = 0.0;  ///< max |in - out - storage| / mass in.
  /// Vertical momentum balance of gas + particles over the run after the jet start (or the
  /// whole run): |dP - impulse of the external forces| / (weight * time) (see docs/dpm.md).
  double momentum_mismatch = 0.0;
  double max_action_reaction_mismatch_n = 0.0;  ///< max |sum F_p + sum F_gas| per step [N].
  std::uint64_t law_out_of_range = 0;           ///< Clamped/extrapolated drag evaluations.
  /// Snapshot at the sample nearest to t_ref (has_snapshot false if the run ended before).
  bool has_snapshot = false;
  DpmSnapshot snapshot;
  std::vector<std::string> output_files;  ///< HDF5/XDMF files written (only when asked).
  std::string BriefReport() const;
};

/// Progress: fraction in [0, 1] and a stage text.
using DpmProgress = std::function<void(double fraction, const std::string& stage)>;

/// The coupled run. Throws draglab::Error(kInvalidArgument) for an invalid scene or options,
/// and with a diagnosis (limit and remedy) when the gas or DEM solver reports instability, the
/// void fraction leaves (0, 1], or a particle leaves the box.
class DpmSimulation {
 public:
  DpmSimulation(const Scene& scene, std::shared_ptr<const Law> law, const DpmOptions& options);
  ~DpmSimulation();

  /// Settles the particles (gas off), then Start(); called by Run if not done.
  void Settle(const DpmProgress& progress = nullptr);
  /// Starts from a given packing (at rest, inside the box; e.g. dem().particles() of another
  /// simulation of the same scene, so that several laws start from the same packing) and builds
  /// the gas. Throws Error(kInvalidArgument) if the particles are invalid or outside the box.
  void Start(Particles settled);
  /// Runs to the duration and returns the result.
  DpmResult Run(const DpmProgress& progress = nullptr);
  /// One coupled gas step (after Settle); returns its diagnostics.
  const DpmStepDiagnostics& Step();

  const GasPhase& gas() const;
  const DemSystem& dem() const;
  /// Each particle's drag coefficient c_p [kg/s] of the last step (drag = c_p (u_g - u_p)),
  /// in the order of dem().particles().
  const std::vector<double>& drag_coefficients() const;
  double time() const;  ///< Since the background flow started [s].
  double gas_dt() const { return gas_dt_; }
  double bed_weight_n() const;  ///< N m_p g (1 - rho_g/rho_p): buoyant weight [N].
  double settled_bed_height_m() const { return settled_height_; }
  /// The mapped void fraction as a GridField2D (x, height) for bubble.h.
  GridField2D VoidFractionField() const;
  /// Initial layer of each particle by its stable id (Particles::id), set by Start().
  const std::vector<int>& initial_layer_by_id() const { return layer_by_id_; }
  /// Snapshot of the current state (t_s = time after jet start).
  DpmSnapshot Snapshot() const;

 private:
  DemOptions MakeDemOptions() const;
  struct Impl;
  Scene scene_;
  std::shared_ptr<const Law> law_;
  DpmOptions opt_;
  DpmResult result_;
  double gas_dt_ = 0.0;
  double settled_height_ = 0.0;
  std::vector<int> layer_by_id_;
  std::unique_ptr<Impl> impl_;
};

// The DPM's result in the forms its bed model stores (src/dpm/dpm_bed_model.cc).
/// What a regression compares, from a DPM result: U_mf, background, the bubble at t_ref (its
/// diameter and centroid height), the highest bed surface over the samples, wall time.
ConsumerMetrics consumer_metrics_of(const DpmResult& result);
/// The full DPM result as JSON text (the fields of `draglab scene run --json`, without the
/// snapshot's particle arrays).
std::string dpm_result_json(const DpmResult& result);

}  // namespace consumers
}  // namespace draglab
