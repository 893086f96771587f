// case_run.h: the one way from a packing to a drag record, shared by `draglab lbm run` and every
// campaign unit:
//   packing -> hydrodynamic-diameter calibration (optional) -> voxelization -> run -> record
// (the run's result, the lattice, the exact answer where one is known, the field file).
// Callers check their own input first (the command line names its options, a campaign its spec
// keys); run_case checks again what only the engine can (the run's size, the operator against the
// cell Reynolds number) and prints nothing.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/lbm/calibration.h"
#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {

struct CaseOptions {
  RunOptions run;
  double resolution =
      0.0;  ///< d, lattice units per sphere diameter ([kMinResolution, kMaxResolution]).
  /// Normalise with a hydrodynamic diameter: calibrated first on a dilute SC array at the same d,
  /// scheme and tau (needs run.tau > 0 at finite Re, d <= 128) ...
  bool calibrate = false;
  /// ... or given, in lattice units, within [0.5 d, 1.5 d] (0 = none; not with calibrate).
  double hydrodynamic_diameter = 0.0;
  std::string fields;       ///< Write the final fields here (HDF5 and XDMF; "" = none).
  std::string description;  ///< One line naming the geometry, recorded as "case" ("" = none).
  /// True if valid; otherwise *error names the field and its allowed range.
  bool IsValid(std::string* error) const;
};

/// The drag on one size class of a packing with a few distinct diameters (bidisperse, ...), in
/// the polydisperse convention of van der Hoef et al. (2005): each sphere's drag force over
/// 3 pi mu d_i U, with its own diameter d_i and the superficial velocity U; the mixture's F and
/// Re use the Sauter mean diameter <d> (the packing's d_ref), and F = sum over classes of
/// x_i F_i / y_i^2 (RunResult::F).
struct SpeciesDrag {
  double diameter = 0.0;         ///< y_i = d_i/<d>.
  double volume_fraction = 0.0;  ///< x_i: the class's share of the solids volume.
  std::int64_t spheres = 0;
  double F = 0.0;  ///< Mean over the class's spheres (time means for unsteady flow).
  /// Standard error of that mean over the spheres (0 with one sphere): the spread of the
  /// sphere-to-sphere drag in one packing, not the discretisation error.
  double F_standard_error = 0.0;
};

/// At most this many distinct diameters make size classes (a lognormal packing, whose every
/// sphere differs, reports none).
constexpr int kMaxSpecies = 8;

struct CaseResult {
  RunResult run;
  std::array<std::int64_t, 3> dims{0, 0, 0};
  double resolution = 0.0;  ///< d as realised on the lattice.
  std::int64_t spheres = 0;
  /// The hydrodynamic diameter the drag is normalised with (lattice units of the realised d),
  /// 0 = none; phi_hydrodynamic = (d_h/d)^3 phi.
  double hydrodynamic_diameter = 0.0;
  double phi_hydrodynamic = 0.0;
  std::optional<CalibrationResult> calibration;
  /// Per size class, smallest first, when the packing has 2 to kMaxSpecies distinct diameters
  /// and the run converged; empty otherwise.
  std::vector<SpeciesDrag> species;
  /// The exact F where one is known (Stokes flow through an SC array: the Sangani-Acrivos series,
  /// at phi_hydrodynamic with a hydrodynamic diameter), NaN otherwise; `reference` names it.
  double reference_F = 0.0;
  std::string reference;
  /// The field file could not be written (the drag is complete all the same); "" = written or
  /// not asked for.
  std::string fields_error;
  /// The run's JSON record (RunResult::ToJson) with the case's: re_target, resolution, dims,
  /// spheres, case, calibration, species, phi_hydrodynamic, reference_F and error, fields.
  std::string ToJson(const CaseOptions& options) const;
};

/// Runs `packing` as `options` say. `progress` gets each stage's fraction with the stage's name
/// ("lbm calibrate", the voxelizer's stages, "lbm run"). Bad options or a run the operator
/// cannot hold: Error(kInvalidArgument) before any work. A calibration that fails throws
/// std::runtime_error (a run-time failure); a run that fails is returned with its diagnosis
/// (run.converged false) when options.run.throw_on_failure is false. Decomposed over
/// options.run.ranks: collective, the field file written by the first rank.
CaseResult run_case(const arrays::Packing& packing, const CaseOptions& options,
                    const ProgressCallback& progress = nullptr);

}  // namespace lbm
}  // namespace draglab
