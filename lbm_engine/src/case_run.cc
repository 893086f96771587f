// case_run.cc: packing -> calibration -> voxelization -> run -> record (case_run.h).
#include "draglab/lbm/case_run.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "draglab/arrays/voxelization.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/lbm/convergence.h"
#include "draglab/lbm/fields_io.h"
#include "draglab/lbm/resolution.h"

namespace draglab {
namespace lbm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// The largest d a calibration box holds (CalibrationOptions::diameter).
constexpr double kMaxCalibrationResolution = 128.0;

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

/// Before the calibration's runs: the operator must hold the run's cell Reynolds number
/// (resolution.h; the run checks it again on the lattice's own d and phi).
void check_operator_holds(double phi, const CaseOptions& options) {
  const RunOptions& run = options.run;
  if (run.re == 0.0) return;
  const VelocityPlan plan = plan_velocity(phi, run.re, options.resolution, run.collision,
                                          run.mach_target, 0.0, false, run.tau);
  const std::string refusal =
      cell_reynolds_refusal(plan, run.re, options.resolution, run.collision);
  if (!refusal.empty()) throw Error(ErrorCode::kInvalidArgument, "lbm run: " + refusal);
}

/// The calibration runs of case `options`, on the run's ranks and with the run's own operator
/// (auto chooses it from the run's phi, Re and d). A calibration that does not converge is a
/// run-time failure, as a run is; bad options stay bad input.
CalibrationResult calibrate(double phi, const CaseOptions& options,
                            const ProgressCallback& progress) {
  CalibrationOptions co;
  co.diameter = options.resolution;
  co.run = options.run;
  co.run.checkpoint.clear();       // the run itself keeps it
  co.run.throw_on_failure = true;  // no drag is derived from a run that failed
  co.run.collision =
      choose_collision(phi, options.run.re, options.resolution, options.run.collision).collision;
  try {
    return calibrate_hydrodynamic_diameter(co, [&progress](double f, const std::string&) {
      if (progress) progress(f, "lbm calibrate");
    });
  } catch (const Error& e) {
    if (e.code() == ErrorCode::kOutOfValidity) throw std::runtime_error(e.what());
    throw;
  }
}

/// The exact F of the case where one is known. With a hydrodynamic diameter the spheres are
/// taken to be of diameter d_h, so the array's solids fraction is (d_h/d)^3 phi and the series
/// is evaluated there (drag_laws: vdH 2005 procedure).
void set_reference(const arrays::Packing& packing, const CaseOptions& options, CaseResult* r) {
  r->reference_F = analytical_reference_F(packing, options.run.re);
  if (r->hydrodynamic_diameter > 0.0) {
    const double ratio = r->hydrodynamic_diameter / r->resolution;
    r->phi_hydrodynamic = r->run.phi * ratio * ratio * ratio;
    if (std::isfinite(r->reference_F)) {
      r->reference_F = r->phi_hydrodynamic <= kSanganiAcrivosMaxPhi
                           ? sangani_acrivos_sc_F(r->phi_hydrodynamic)
                           : kNaN;
    }
  }
  if (!std::isfinite(r->reference_F)) return;
  r->reference = r->hydrodynamic_diameter > 0.0
                     ? "Sangani-Acrivos series (SC, Stokes) at phi_hydrodynamic"
                     : "Sangani-Acrivos series (SC, Stokes)";
}

/// The size classes of `packing` (distinct diameters, within a relative 1e-9) and each one's drag
/// from the run's per-sphere drag (normalised with the packing's d_ref, the Sauter mean).
std::vector<SpeciesDrag> species_drag(const arrays::Packing& packing, const RunResult& run) {
  std::vector<SpeciesDrag> classes;
  std::vector<int> class_of(packing.size());
  for (std::size_t s = 0; s < packing.size(); ++s) {
    const double y = 2.0 * packing.radii[s];
    int c = 0;
    while (c < static_cast<int>(classes.size()) &&
           std::abs(classes[static_cast<std::size_t>(c)].diameter - y) > 1e-9 * y) {
      ++c;
    }
    if (c == static_cast<int>(classes.size())) {
      if (classes.size() == kMaxSpecies) return {};
      SpeciesDrag sd;
      sd.diameter = y;
      classes.push_back(sd);
    }
    class_of[s] = c;
  }
  if (classes.size() < 2 || !run.converged || run.body_F.size() != packing.size()) return {};
  double solids = 0.0;
  for (double r : packing.radii) solids += r * r * r;
  std::vector<double> sum(classes.size(), 0.0), sum2(classes.size(), 0.0);
  for (std::size_t s = 0; s < packing.size(); ++s) {
    SpeciesDrag& sd = classes[static_cast<std::size_t>(class_of[s])];
    const double F_i = run.body_F[s] / sd.diameter;
    ++sd.spheres;
    sd.volume_fraction += packing.radii[s] * packing.radii[s] * packing.radii[s] / solids;
    sum[static_cast<std::size_t>(class_of[s])] += F_i;
    sum2[static_cast<std::size_t>(class_of[s])] += F_i * F_i;
  }
  for (std::size_t c = 0; c < classes.size(); ++c) {
    SpeciesDrag& sd = classes[c];
    const double n = static_cast<double>(sd.spheres);
    sd.F = sum[c] / n;
    const double var = n > 1.0 ? std::max(0.0, (sum2[c] - n * sd.F * sd.F) / (n - 1.0)) : 0.0;
    sd.F_standard_error = std::sqrt(var / n);
  }
  std::sort(classes.begin(), classes.end(),
            [](const SpeciesDrag& a, const SpeciesDrag& b) { return a.diameter < b.diameter; });
  return classes;
}

/// The record without the field file's entries (it is stored in the field file itself).
nlohmann::json record(const CaseResult& r, const CaseOptions& options) {
  RunOptions used = options.run;  // as run: with the hydrodynamic diameter it normalised with
  used.use_hydrodynamic_diameter = r.hydrodynamic_diameter > 0.0;
  used.hydrodynamic_diameter = r.hydrodynamic_diameter;
  nlohmann::json j = nlohmann::json::parse(r.run.ToJson(used));
  j["re_target"] = options.run.re;
  j["resolution"] = r.resolution;
  j["dims"] = r.dims;
  j["spheres"] = r.spheres;
  if (!options.description.empty()) j["case"] = options.description;
  if (r.calibration) {
    const CalibrationResult& cal = *r.calibration;
    j["calibration"] = {{"d_h_over_d", cal.ratio},
                        {"phi", cal.calibration.phi},
                        {"F_input", cal.calibration.F_input},
                        {"F_series", cal.calibration.F_reference},
                        {"positions", cal.calibration.positions},
                        {"wall_s", cal.wall_s}};
  }
  if (!r.species.empty()) {
    nlohmann::json species = nlohmann::json::array();
    for (const SpeciesDrag& sd : r.species) {
      species.push_back({{"diameter_over_sauter", sd.diameter},
                         {"volume_fraction", sd.volume_fraction},
                         {"spheres", sd.spheres},
                         {"F", sd.F},
                         {"F_standard_error", sd.F_standard_error}});
    }
    j["species"] = species;
  }
  if (r.hydrodynamic_diameter > 0.0) j["phi_hydrodynamic"] = r.phi_hydrodynamic;
  if (std::isfinite(r.reference_F)) {
    j["reference_F"] = r.reference_F;
    j["reference"] = r.reference;
    j["error"] = number_or_null(r.run.F / r.reference_F - 1.0);
  }
  return j;
}

/// Writes the field file on the first rank; a failure is kept in r->fields_error (the drag it
/// would cost is complete).
void write_field_file(const Fields& fields, const arrays::VoxelGrid& grid,
                      const CaseOptions& options, CaseResult* r) {
  if (!options.run.ranks.is_root()) return;
  FieldsWriteOptions fo;
  fo.dx = grid.dx;
  fo.run_json = record(*r, options).dump();
  try {
    write_fields(options.fields, fields, fo);
  } catch (const std::exception& e) {
    r->fields_error = e.what();
  }
}

}  // namespace

bool CaseOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (!run.IsValid(error)) return false;
  if (!std::isfinite(resolution) || resolution < kMinResolution || resolution > kMaxResolution) {
    return fail("resolution = " + core::format_number(resolution) + " is outside [" +
                core::format_number(kMinResolution) + ", " + core::format_number(kMaxResolution) +
                "] lattice units per diameter");
  }
  if (calibrate && hydrodynamic_diameter != 0.0) {
    return fail("give calibrate or hydrodynamic_diameter, not both");
  }
  if (hydrodynamic_diameter != 0.0 &&
      !(hydrodynamic_diameter >= 0.5 * resolution && hydrodynamic_diameter <= 1.5 * resolution)) {
    return fail("hydrodynamic_diameter = " + core::format_number(hydrodynamic_diameter) +
                " is outside [0.5 d, 1.5 d] = [" + core::format_number(0.5 * resolution) + ", " +
                core::format_number(1.5 * resolution) + "] (0 = none)");
  }
  if (calibrate && run.re > 0.0 && run.tau == 0.0) {
    return fail(
        "calibrate at re > 0 needs tau: d_h depends on tau and the calibration runs in Stokes "
        "flow");
  }
  if (calibrate && resolution > kMaxCalibrationResolution) {
    return fail("calibrate works for resolution up to " +
                core::format_number(kMaxCalibrationResolution));
  }
  return true;
}

std::string CaseResult::ToJson(const CaseOptions& options) const {
  nlohmann::json j = record(*this, options);
  if (!options.fields.empty()) {
    if (fields_error.empty()) {
      j["fields"] = options.fields;
      j["fields_xdmf"] = xdmf_path_for(options.fields);
    } else {
      j["fields"] = nullptr;
      j["fields_error"] = fields_error;
    }
  }
  return j.dump();
}

CaseResult run_case(const arrays::Packing& packing, const CaseOptions& options,
                    const ProgressCallback& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, "lbm run: " + error);
  check_run_size(packing, options.resolution, options.run, "lbm run: resolution");

  CaseResult r;
  RunOptions run = options.run;
  if (options.calibrate) {
    check_operator_holds(packing.phi(), options);
    r.calibration = calibrate(packing.phi(), options, progress);
    run.use_hydrodynamic_diameter = true;
    run.hydrodynamic_diameter = r.calibration->ratio * options.resolution;
  } else if (options.hydrodynamic_diameter > 0.0) {
    run.use_hydrodynamic_diameter = true;
    run.hydrodynamic_diameter = options.hydrodynamic_diameter;
  }

  arrays::VoxelizationOptions vo;
  vo.resolution = options.resolution;
  const arrays::VoxelGrid grid = arrays::voxelize(packing, vo, progress);
  if (options.calibrate) run.hydrodynamic_diameter *= grid.resolution() / options.resolution;

  const ProgressCallback run_progress = [&progress](double f, const std::string&) {
    if (progress) progress(f, "lbm run");
  };
  Fields fields;
  r.run = options.fields.empty() ? lbm::run(grid, packing.phi(), run, run_progress)
                                 : run_with_fields(grid, packing.phi(), run, &fields, run_progress);
  r.dims = grid.dims;
  r.resolution = grid.resolution();
  r.spheres = static_cast<std::int64_t>(packing.size());
  r.hydrodynamic_diameter = run.use_hydrodynamic_diameter ? run.hydrodynamic_diameter : 0.0;
  set_reference(packing, options, &r);
  r.species = species_drag(packing, r.run);
  if (!options.fields.empty()) write_field_file(fields, grid, options, &r);
  return r;
}

}  // namespace lbm
}  // namespace draglab
