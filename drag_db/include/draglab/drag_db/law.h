// draglab/drag_db/law.h: a law version (record) and the loaded, immutable evaluator (Law).
//
// A LawRecord is what the database stores for `name@version`: the form key, the parameter values,
// the native convention, the validity box, the provenance and the content hash.
// A Law is a LawRecord bound to its registered form: load it once, then evaluate it from any
// number of threads without touching the database.
//
// Units: F, K, beta d^2/mu, C_d are dimensionless; beta() takes SI inputs and returns
// kg m^-3 s^-1. Conventions (which F, which Re, which velocity): conventions.h.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "draglab/drag_db/conventions.h"
#include "draglab/drag_db/law_form.h"

namespace draglab {

/// Life cycle of a law version. Published and retracted versions are immutable.
enum class LawStatus { kDraft, kPublished, kRetracted };
const char* to_string(LawStatus s);
LawStatus law_status_from_string(const std::string& s);

/// A parameter value of a law version.
struct LawParameter {
  std::string name;
  double value = 0.0;
  std::string unit = "1";
};

/// Where a law version comes from.
struct Provenance {
  std::string kind = "literature";  ///< "literature", "fitted" or "manual".
  std::string citation;             ///< Literature reference (literature laws).
  std::string dataset_id;           ///< Fitted laws: the dataset the fit used.
  std::string data_hash;            ///< Fitted laws: hash of the data points.
  std::string fitter_settings;      ///< Fitted laws: the fitter's options, JSON text.
  std::string code_version;         ///< draglab version (git describe) that wrote the record.
};

/// A law as users name it: NAME (its latest published version), NAME@latest, NAME@<version> or
/// NAME@<hash prefix>; one version is written "name@version" (Format, LawRecord::reference).
struct LawReference {
  std::string name;
  std::string selector = "latest";  ///< "latest", a version number or a content-hash prefix.

  /// Splits `text` at its first '@'. Throws Error(kInvalidArgument) naming the text and the
  /// forms it may take when the name or the selector is empty.
  static LawReference Parse(const std::string& text);
  /// The same without throwing: false when malformed (`out->name` still holds the part before
  /// the '@', for a message).
  static bool TryParse(const std::string& text, LawReference* out);
  /// "name@version".
  static std::string Format(const std::string& name, int version);
  /// The selector as a version number when it is one (decimal digits, at most 9), else -1.
  int version_number() const;
};

/// One stored law version. Content hash: SHA-256 over form, parameters, convention and validity
/// (content_hash_of); name, version, status, provenance and notes are not part of it.
struct LawRecord {
  std::string name;
  int version = 0;
  std::string form;
  std::vector<LawParameter> parameters;
  std::vector<double> covariance;  ///< Row-major n x n (n = parameters.size()) or empty.
  NativeConvention convention;
  ValidityBox validity;
  Provenance provenance;
  std::string content_hash;  ///< 64 hex digits.
  LawStatus status = LawStatus::kDraft;
  std::string created_at;  ///< ISO 8601 UTC.
  std::string notes;
  std::string retraction_reason;  ///< Set when status == kRetracted.

  /// "name@version".
  std::string reference() const { return LawReference::Format(name, version); }
  std::vector<double> parameter_values() const;
};

/// SHA-256 (hex) of the canonical JSON of form, parameters (name, value as %.17g, unit),
/// convention and validity box.
std::string content_hash_of(const LawRecord& record);

/// A record for `form` with its published default parameters, convention and validity box
/// (name = form key, provenance = the form's citation). Version and status are left to the caller.
LawRecord literature_record(const LawForm& form);

/// What to do with inputs outside the law's validity box (inputs that are physically impossible,
/// such as eps outside (0, 1], Re < 0, NaN or inf, are always an error).
enum class RangePolicy {
  kError,        ///< Throw / return an error status (default).
  kClamp,        ///< Clamp phi, Re and extra inputs into the box and count the event.
  kExtrapolate,  ///< Evaluate the formula as is and count the event.
};
const char* to_string(RangePolicy p);
RangePolicy range_policy_from_string(const std::string& s);

/// One evaluation with the point the formula actually saw (differs from the request only under
/// RangePolicy::kClamp).
struct LawEvaluation {
  double phi = 0.0;              ///< phi evaluated (clamped into the validity box if so asked).
  double re = 0.0;               ///< Re evaluated.
  double F = 0.0;                ///< Canonical drag-only F at (phi, re).
  bool out_of_validity = false;  ///< The requested point lay outside the validity box.
};

/// A loaded law version: immutable formula and parameters, thread-safe evaluation.
///
/// Under RangePolicy::kClamp only the closure F is evaluated at the clamped point; conversions
/// that count particles (beta = 18 mu phi eps F / d^2, beta d^2/mu) or normalise by the gas
/// fraction (K = F / eps) use the caller's actual phi, which is the physical state of the cell.
/// The range policy and the out-of-range counter are atomics; set the policy before sharing.
class Law {
 public:
  /// Binds `record` to its registered form; throws Error(kNotFound) for an unknown form and
  /// Error(kInvalidArgument) if the parameters do not match the form's.
  explicit Law(LawRecord record, RangePolicy policy = RangePolicy::kError);
  Law(const Law&) = delete;
  Law& operator=(const Law&) = delete;

  const LawRecord& record() const { return record_; }
  const LawForm& form() const { return *form_; }
  std::string reference() const { return record_.reference(); }
  int num_extra_inputs() const { return form_->num_extra_inputs; }

  void set_range_policy(RangePolicy p) { policy_.store(p); }
  RangePolicy range_policy() const { return policy_.load(); }
  /// Evaluations outside the validity box that were clamped or extrapolated since load.
  std::uint64_t out_of_range_count() const { return out_of_range_.load(); }

  /// Canonical drag-only F(phi, Re). `extra` holds num_extra_inputs() values (polydisperse
  /// forms: y_i = d_i/<d>), or may be null for forms without extra inputs.
  double F(double phi, double re, const double* extra = nullptr) const;
  /// F with the point actually evaluated (see LawEvaluation).
  LawEvaluation evaluate(double phi, double re, const double* extra = nullptr) const;
  /// Array path: out[i] = F(phi[i], re[i], extra + i*num_extra_inputs()). On error the contents
  /// of out are unspecified and an Error names the first bad index (a non-finite result, which
  /// only extrapolation far outside the validity box can produce, is an error too).
  void F(std::size_t n, const double* phi, const double* re, double* out,
         const double* extra = nullptr) const;
  /// beta d^2/mu = 18 phi (1-phi) F (actual phi; F possibly at the clamped point).
  double beta_d2_over_mu(double phi, double re, const double* extra = nullptr) const;
  /// K = F/(1-phi), the total force including the mean pressure gradient part.
  double K(double phi, double re, const double* extra = nullptr) const;
  /// C_d Re_p = 24 eps F (interstitial Re_p = Re/eps), finite at Re = 0.
  double drag_coefficient_times_re_p(double phi, double re, const double* extra = nullptr) const;
  /// C_d with the interstitial slip in the dynamic pressure; Re must be > 0.
  double drag_coefficient(double phi, double re, const double* extra = nullptr) const;
  /// MFiX's DRAG_USR output lDgA = beta / phi = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1]; same
  /// arguments and checks as beta(); finite at eps_g = 1.
  double dga(double eps_g, double mu_g, double rho_g, double slip, double d_p,
             const double* extra = nullptr) const;
  /// Friction coefficient beta [kg m^-3 s^-1] from dimensional inputs (argument order of MFiX's
  /// usr_drag): gas fraction eps_g, gas viscosity mu_g [Pa s], gas density rho_g [kg/m^3],
  /// interstitial slip |u_g - u_s| [m/s], particle diameter d_p [m].
  double beta(double eps_g, double mu_g, double rho_g, double slip, double d_p,
              const double* extra = nullptr) const;
  /// CFD-DEM per-particle drag coefficient gamma [kg/s] (drag on the particle = gamma times the
  /// interstitial slip vector; conventions::particle_drag_coefficient) of a particle of diameter
  /// d_i [m] at local voidage eps_g, fluid viscosity mu_g [Pa s] and density rho_g [kg/m^3],
  /// slip |u_f - u_p| [m/s]. Polydisperse forms (one extra input, y = d_i/<d>) take d_mean [m],
  /// the Sauter mean diameter of the particles around, and evaluate F at Re = rho_g eps_g d_mean
  /// slip / mu_g and y = d_i/d_mean; monodisperse forms ignore d_mean (Re with d_i). *re_out, if
  /// given, receives the Reynolds number used. Same checks as beta().
  double particle_drag(double eps_g, double mu_g, double rho_g, double slip, double d_i,
                       double d_mean, double* re_out = nullptr) const;

 private:
  /// Validates (phi, re, extra) and applies the range policy; returns the values to evaluate.
  void prepare(double& phi, double& re, double* extra_out, const double* extra_in,
               std::size_t index, bool array) const;

  LawRecord record_;
  const LawForm* form_;
  std::vector<double> params_;
  mutable std::atomic<RangePolicy> policy_;
  mutable std::atomic<std::uint64_t> out_of_range_{0};
};

}  // namespace draglab
