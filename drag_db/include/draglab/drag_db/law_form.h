// draglab/drag_db/law_form.h: the registry of drag-law formulas ("forms").
//
// A law form is one published formula, e.g. "bvk2007" (Beetstra, van der Hoef & Kuipers 2007),
// written once in drag_db/src/laws/<key>.h as a template on the scalar type and registered by
// key in <key>.cc. The registry instantiates it three times from that one source:
//   double                  evaluation inside solvers (scalar and array paths),
//   ceres::Jet<double, 4>   automatic derivatives for the fitter and the derivative tests,
//   codegen::Expr           a symbolic trace from which `draglab law export` writes C/Fortran.
//
// A *form* has no identity in the database; a *law version* (law.h, database.h) is a form plus
// parameter values, conventions, validity box and provenance.
//
// Every form returns the canonical drag-only F(phi, Re) of conventions.h after converting from
// its native convention; `convention` records the native one.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "draglab/drag_db/conventions.h"

namespace ceres {
template <typename T, int N>
struct Jet;
}  // namespace ceres

namespace draglab {
namespace codegen {
class Expr;
}  // namespace codegen

/// Scalar type used for automatic derivatives; stride 4 matches
/// ceres::DynamicAutoDiffCostFunction's default, so the fitter can use F_autodiff directly.
using AutoDiffScalar = ceres::Jet<double, 4>;

/// Closed interval [min, max] of an input.
struct InputRange {
  double min = 0.0;
  double max = 0.0;
  bool contains(double x) const { return x >= min && x <= max; }
};

/// A named parameter (coefficient) of a form, with its published default value.
struct ParameterSpec {
  std::string name;
  double value = 0.0;
  std::string unit = "1";
  std::string description;
};

/// An input beyond (phi, Re), e.g. the size ratio y_i = d_i/<d> of polydisperse laws.
struct ExtraInputSpec {
  std::string name;
  std::string description;
  InputRange range;
};

/// Where the law was fitted / claimed valid. Evaluation outside it is handled by RangePolicy.
struct ValidityBox {
  InputRange phi;
  InputRange re;
  std::vector<ExtraInputSpec> extra;
};

/// An internal regime switch (a branch in the formula), for the continuity tests and docs.
struct RegimeSwitch {
  enum class Axis { kPhi, kRe };
  std::string description;
  Axis axis = Axis::kPhi;
  /// Location of the switch on `axis` given the other coordinate and the parameters.
  double (*location)(double other, const double* params) = nullptr;
  /// Relative jump |F+ - F-|/F- across the switch as published (0 for continuous switches);
  /// the continuity test measures it and checks it against this documented value.
  double documented_relative_jump = 0.0;
  /// Where on the other axis the jump above was measured (for documentation and tests).
  double documented_at_other = 0.0;
};

/// Everything about a form except its function pointers.
struct LawFormDescription {
  std::string key;         ///< Registry key, e.g. "bvk2007".
  std::string title;       ///< One line: authors, year, what it is.
  std::string citation;    ///< Full literature citation (DOI where known).
  std::string form_notes;  ///< Which variant was implemented and why (known disagreements).
  std::vector<ParameterSpec> parameters;
  ValidityBox validity;
  std::vector<RegimeSwitch> switches;
  /// F at phi -> 0, Re -> 0 (1 for laws that recover Stokes drag; 0.96 with Dalla Valle's C_d).
  double single_sphere_stokes_F = 1.0;
  /// False for laws valid only in the Stokes limit (their Re range is [0, small]).
  bool has_inertia = true;
  /// Seeded as a published literature version in every new database.
  bool literature = true;
};

/// A registered form: description, native convention and the three instantiations.
struct LawForm {
  LawFormDescription description;
  NativeConvention convention;
  int num_parameters = 0;
  int num_extra_inputs = 0;
  /// Canonical F. `extra` has num_extra_inputs values (may be null if 0); `params` has
  /// num_parameters values in the order of description.parameters.
  double (*F)(double phi, double re, const double* extra, const double* params) = nullptr;
  AutoDiffScalar (*F_autodiff)(const AutoDiffScalar& phi, const AutoDiffScalar& re,
                               const AutoDiffScalar* extra,
                               const AutoDiffScalar* params) = nullptr;
  codegen::Expr (*F_symbolic)(const codegen::Expr& phi, const codegen::Expr& re,
                              const codegen::Expr* extra, const codegen::Expr* params) = nullptr;
  /// out[i] = F(phi[i], re[i], extra + i*num_extra_inputs, params) with the formula inlined.
  void (*F_array)(std::size_t n, const double* phi, const double* re, const double* extra,
                  const double* params, double* out) = nullptr;

  const std::string& key() const { return description.key; }
  std::vector<double> default_parameters() const;
};

/// Adds a form to the registry (called by DRAGLAB_REGISTER_LAW_FORM at load time).
void register_law_form(const LawForm& form);
/// The form registered under `key`; throws Error(kNotFound) listing the valid keys.
const LawForm& find_law_form(const std::string& key);
/// All registered forms, sorted by key.
std::vector<const LawForm*> all_law_forms();
/// Comma-separated list of registered keys (for error messages and --help).
std::string law_form_keys();

}  // namespace draglab
