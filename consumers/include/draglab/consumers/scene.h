// draglab/consumers/scene.h: fluidized-bed scenes (TOML files, docs/scenes.md), the minimum
// fluidization velocity of a loaded drag law, and the numbers derived from a scene.
//
// A Scene is what a scene file declares: a pseudo-2D box (width x height x depth), monodisperse
// particles, the gas, the distributor (background) flow, a central jet that injects one bubble,
// the times, the gas grid, the bubble criterion, the outputs and the drag law(s) by reference
// "name@version". Units are SI throughout (m, s, kg/m^3, Pa s, m/s). Parsing checks types and
// unknown keys; Scene::IsValid checks every range and names the field and its allowed range.
//
// Minimum fluidization (minimum_fluidization): at U_mf the drag on the particles of a bed at
// eps_mf carries their buoyant weight. With the canonical drag-only F (drag per particle
// F_d = 3 pi mu d U F, U superficial) and the mean pressure gradient of the bed acting on the
// particles' volume, the particle and mixture momentum balances give
//     n F_d = phi eps (rho_p - rho_g) g      (n = phi / V_p particles per volume)
//  <=> 18 Re F(phi, Re) = eps Ar,  Re = rho_g U d / mu (superficial), Ar = rho_g (rho_p - rho_g)
//      g d^3 / mu^2,
// which for Ergun's F = (150 phi + 1.75 Re)/(18 eps^2) is the Kunii-Levenspiel quadratic
// 1.75 Re^2/eps^3 + 150 phi Re/eps^3 = Ar. It is solved for Re by bracketing inside the law's
// validity range of Re and Brent's method.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "draglab/drag_db/law.h"

namespace draglab {
namespace consumers {

/// Standard gravity [m/s^2], the default of SceneGas::gravity_m_s2.
constexpr double kStandardGravity = 9.81;

/// Box of the pseudo-2D bed [m]: x across the width, y up, z across the (thin) depth.
struct SceneGeometry {
  double width_m = 0.0;
  double height_m = 0.0;
  double depth_m = 0.0;
};

/// Spheres of one size (diameter_m) or of 2 to 8 size classes (diameters_m with their
/// volume_fractions, for the models that run them: the DPM). Give exactly one of count and
/// bed_height_mf_m. (The DPM's contact model is its own table, [dem].)
struct SceneParticles {
  /// One size; with size classes, their Sauter mean 1/sum(x_i/d_i) (set by the parser), the
  /// diameter of the bed's monodisperse quantities (U_mf, grid checks).
  double diameter_m = 0.0;
  std::vector<double> diameters_m;       ///< Size classes [m]; empty: one size.
  std::vector<double> volume_fractions;  ///< Their shares of the solids volume, summing to 1.
  double density_kg_m3 = 0.0;
  double restitution = 0.97;     ///< Normal restitution coefficient, (0, 1] (the TFM's default).
  std::int64_t count = 0;        ///< Number of particles, or 0: from bed_height_mf_m.
  double bed_height_mf_m = 0.0;  ///< Bed height at eps_mf, or 0: from count.
};

/// The gas (incompressible in the consumers: Mach << 0.1 at the jet velocities used).
struct SceneGas {
  double density_kg_m3 = 0.0;
  double viscosity_pa_s = 0.0;
  double gravity_m_s2 = kStandardGravity;
};

/// How the background velocity through the porous plate is set.
enum class BackgroundMode {
  kUmf,    ///< umf_factor times the loaded law's own U_mf (each law at its own incipient state).
  kFixed,  ///< velocity_m_s for every law (as the experiment did with one measured U_mf).
  /// umf_factor times the law's U_mf at the SETTLED packing's own mean gas fraction (from the
  /// settled bed height) instead of eps_mf: a DEM packing in a thin box settles looser than
  /// eps_mf, and at the eps_mf U_mf it is not yet fluidized (docs/dpm.md).
  kUmfPacking,
};
const char* to_string(BackgroundMode mode);

/// Distributor (porous plate) flow, superficial.
struct SceneDistributor {
  BackgroundMode mode = BackgroundMode::kUmf;
  double umf_factor = 1.0;    ///< kUmf: multiple of the law's U_mf, (0, 10].
  double velocity_m_s = 0.0;  ///< kFixed: superficial velocity [m/s], > 0.
};

/// Central slot jet through the bottom that injects one bubble (superficial velocity in the
/// slot; the slot replaces the porous plate over its width while the jet is on).
struct SceneJet {
  double slot_width_m = 0.0;
  double velocity_m_s = 0.0;
  double center_m = -1.0;  ///< Slot centre from the left wall; < 0 in the file: width / 2.
  double start_s = 0.0;    ///< Jet start, after the settled bed has been fluidized from t = 0.
  double duration_s = 0.0;
  /// Valve opening time [s] of the jet and the distributor (linear ramps, gas_phase.h
  /// inflow_ramp_s), [0, duration_s]; 0 switches instantly.
  double ramp_s = 0.0;
};

/// Times [s]. t = 0 is when the background flow starts through the settled bed.
struct SceneTime {
  double duration_s = 0.0;  ///< Simulated time after t = 0.
  double t_ref_s = 0.3;     ///< Snapshot time after jet start (the seed's 0.3 s).
  double gas_dt_s = 0.0;    ///< Gas step, or 0: recommended_gas_dt_s (SceneDerived).
};

/// Gas grid: cells across the width and the height, and across the depth (1 for the pseudo-2D
/// models; the DBM's emulsion grid is 3-D).
struct SceneGrid {
  int cells_x = 0;
  int cells_y = 0;
  int cells_z = 1;
};

/// Bubble criterion: cells with eps_g above the threshold that are connected to the jet's bubble.
struct SceneBubble {
  double eps_threshold = 0.8;       ///< (eps_mf, 1).
  double sample_interval_s = 0.01;  ///< Time-series spacing, (0, duration].
};

/// What is written besides the JSON result (nothing unless asked for).
struct SceneOutputs {
  std::string directory;    ///< Where files go; empty: next to the working directory as out/<name>.
  bool fields = false;      ///< Gas fields to HDF5 + XDMF.
  bool particles = false;   ///< Particles to HDF5 + XDMF (Polyvertex).
  double interval_s = 0.0;  ///< Output spacing; 0: only the snapshot at t_ref.
};

/// A bed model's own table of a scene file ([dem], [tfm], [dbm]): the model defines its fields in
/// its folder and reads and checks them through BedModel::scene_table (bed_model.h).
class SceneSection {
 public:
  virtual ~SceneSection() = default;
  virtual std::unique_ptr<SceneSection> Clone() const = 0;
  bool present = false;  ///< The file has the table.
};

/// The model tables of a scene by table name; copied with the scene (each section cloned).
class SceneSections {
 public:
  SceneSections() = default;
  SceneSections(const SceneSections& other);
  SceneSections& operator=(const SceneSections& other);
  SceneSections(SceneSections&&) = default;
  SceneSections& operator=(SceneSections&&) = default;

  /// The section of `table`, made with `make` (the model's defaults) when the scene has none.
  SceneSection& Get(const std::string& table,
                    const std::function<std::unique_ptr<SceneSection>()>& make);
  /// The section of `table`, or null.
  const SceneSection* Find(const std::string& table) const;
  /// The section of `table` as its model's type T (T's defaults when the scene has none).
  template <typename T>
  const T& As(const std::string& table) const {
    static const T defaults;
    const SceneSection* s = Find(table);
    return s != nullptr ? static_cast<const T&>(*s) : defaults;
  }
  template <typename T>
  T& As(const std::string& table) {
    return static_cast<T&>(Get(table, [] { return std::make_unique<T>(); }));
  }

 private:
  std::map<std::string, std::unique_ptr<SceneSection>> sections_;
};

/// A value of a scene file as a model's key reader gets it: typed reads whose errors name the
/// key and where it stands.
class SceneValue {
 public:
  /// `node` is the TOML node (toml++'s toml::node) of `field` at `at` (file:line).
  SceneValue(const void* node, std::string field, std::string at)
      : node_(node), field_(std::move(field)), at_(std::move(at)) {}
  double number() const;
  /// A number that must be >= 0 (its absence selects a default, held as -1).
  double number_or_default() const;
  std::int64_t integer() const;
  /// A whole number in [lo, hi] (`what`, if given, says what it counts in the message).
  int integer_in(int lo, int hi, const std::string& what = "") const;
  std::string text() const;
  bool boolean() const;
  /// An array of numbers ("<what> in m" names its elements in the message).
  std::vector<double> numbers(const std::string& what) const;
  const std::string& field() const { return field_; }
  const std::string& at() const { return at_; }

 private:
  const void* node_;
  std::string field_, at_;
};

/// A scene file, parsed. Built by parse_scene / load_scene; IsValid checks every range.
struct Scene {
  std::string name;
  std::string description;
  std::string solver = "dpm";  ///< A registered bed model: "dpm", "tfm", "dbm" (bed_model.h).
  std::uint64_t seed = 1;      ///< Initial packing realization.
  SceneGeometry geometry;
  SceneParticles particles;
  SceneGas gas;
  SceneDistributor distributor;
  SceneJet jet;
  SceneTime time;
  SceneGrid grid;
  SceneBubble bubble;
  SceneOutputs outputs;
  /// The tables of the bed models (BedModel::scene_table), by table name.
  SceneSections sections;
  /// The tables the file has (the DBM refuses those of the jet-driven models).
  std::vector<std::string> tables;
  std::vector<std::string> laws;  ///< "name@version" references, at least one.
  double eps_mf = 0.42;           ///< Gas fraction of the bed at minimum fluidization.
  /// Range policy the solver uses for drag evaluations outside a law's validity box during a
  /// run (void fractions near 1 in the bubble): "clamp" (default), "extrapolate" or "error".
  std::string range_policy = "clamp";
  std::string origin;       ///< File (or label) it was read from, for messages.
  std::string source_text;  ///< The TOML text, for the scene hash.

  /// Checks every field; on failure *error names the field and the allowed range.
  bool IsValid(std::string* error) const;
  /// Throws Error(kInvalidArgument) with IsValid's message.
  void Validate() const;

  /// Mean particle volume [m^3] (pi d^3/6 for one size; with size classes the number-weighted
  /// mean, (pi/6)/sum(x_i/d_i^3)) and mean particle mass [kg].
  double particle_volume_m3() const;
  double particle_mass_kg() const;
  /// Whether the bed has size classes ([particles] diameters_m).
  bool polydisperse() const { return !particles.diameters_m.empty(); }
  /// The number fraction of each size class (x_i/d_i^3 normalised); {1} for one size.
  std::vector<double> number_fractions() const;
  /// The lightest particle's mass [kg] (the DEM's contact time is shortest for it).
  double smallest_particle_mass_kg() const;
  /// Particle count: `count`, or (1 - eps_mf) W D H_mf / V_p rounded.
  std::int64_t particle_count() const;
  /// Bed height at eps_mf: `bed_height_mf_m`, or N V_p / ((1 - eps_mf) W D); the DBM's bed
  /// fills the column (height_m).
  double bed_height_mf_m() const;
  /// Slot centre [m] (jet.center_m, or width/2).
  double jet_center_m() const;
  /// SHA-256 (hex) of the scene text: identifies the scene in stored consumer results.
  std::string hash() const;
};

/// Parses TOML text (origin names it in messages). Throws Error(kInvalidArgument) for invalid
/// TOML, an unknown section or key (named, with the valid ones), a wrong type, or a range error
/// (Scene::IsValid).
Scene parse_scene(const std::string& toml_text, const std::string& origin = "<scene>");
/// Reads and parses a scene file; a missing file is Error(kNotFound).
Scene load_scene(const std::string& path);

/// The largest Re_mf minimum_fluidization looks for beyond a law's box when asked to extrapolate
/// (a bed of 1 cm glass beads in air fluidizes near Re 2 000).
constexpr double kExtrapolatedReMax = 1e5;

/// Options of minimum_fluidization.
struct MinFluidizationOptions {
  double eps_mf = 0.42;               ///< Bed gas fraction at minimum fluidization, (0.2, 0.9).
  double relative_tolerance = 1e-12;  ///< On Re_mf, (0, 1e-3].
  int max_iterations = 200;           ///< Brent iterations, [10, 10000].
  bool IsValid(std::string* error) const;
};

/// U_mf of one law for one particle/gas pair.
struct MinFluidizationResult {
  std::string law;  ///< "name@version".
  double eps_mf = 0.0;
  double umf_m_s = 0.0;     ///< Superficial U_mf [m/s].
  double re_mf = 0.0;       ///< rho_g U_mf d / mu (= canonical Re at U_mf).
  double archimedes = 0.0;  ///< Ar = rho_g (rho_p - rho_g) g d^3 / mu^2.
  double F_mf = 0.0;        ///< Canonical F at (1 - eps_mf, Re_mf).
  double beta_mf = 0.0;     ///< beta at U_mf [kg m^-3 s^-1].
  double residual = 0.0;    ///< (18 Re F - eps Ar) / (eps Ar) at the solution.
  int iterations = 0;       ///< Brent iterations (bracketing excluded).
  /// Empty inside the law's validity box; otherwise (only under RangePolicy::kExtrapolate) the
  /// box the solution lies outside.
  std::string extrapolation;
  std::string BriefReport() const;
};

/// Solves 18 Re F(1 - eps_mf, Re) = eps_mf Ar for Re inside the law's validity range of Re.
/// Throws Error(kInvalidArgument) for bad particle/gas values or options, Error(kOutOfValidity)
/// when 1 - eps_mf is outside the law's phi range or no root lies inside its Re range (the
/// message names the law, the range and a remedy), Error(kInternal) if Brent does not converge.
/// A law loaded with RangePolicy::kExtrapolate is solved beyond its box instead (Re up to
/// kExtrapolatedReMax), and the result's `extrapolation` says so.
MinFluidizationResult minimum_fluidization(const Law& law, const SceneParticles& particles,
                                           const SceneGas& gas,
                                           const MinFluidizationOptions& options);

/// Numbers derived from a scene and one law (draglab scene check).
struct SceneDerived {
  std::int64_t particle_count = 0;
  double bed_height_mf_m = 0.0;
  double archimedes = 0.0;
  MinFluidizationResult umf;
  double background_m_s = 0.0;             ///< Background velocity used with this law.
  double stokes_number = 0.0;              ///< Collision Stokes number rho_p U_mf d / (9 mu).
  double particle_response_s = 0.0;        ///< Stokes response time rho_p d^2 / (18 mu).
  double gas_drag_relaxation_s = 0.0;      ///< eps_mf rho_g / beta at U_mf: gas side.
  double solids_drag_relaxation_s = 0.0;   ///< (1 - eps_mf) rho_p / beta at U_mf.
  double recommended_gas_dt_s = 0.0;       ///< Convective limit 0.5 min(dx, dy) / u_max, u_max the
                                           ///< interstitial jet velocity (or background if larger).
  double jet_area_rate_m2_s = 0.0;         ///< q = v_jet w_slot.
  double leakage_bubble_diameter_m = 0.0;  ///< Davidson-Harrison D* = q / (pi U_mf).
  std::string BriefReport() const;
};

/// Derives SceneDerived for `law`; throws as minimum_fluidization does, and Error
/// (kInvalidArgument) if the scene's explicit time steps exceed their stability limits.
SceneDerived derive_scene(const Scene& scene, const Law& law);

}  // namespace consumers
}  // namespace draglab
