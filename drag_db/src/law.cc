// Law: a law version bound to its registered form; input checks and range policies.
#include "draglab/drag_db/law.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "draglab/error.h"

namespace draglab {
namespace {

std::string fmt_double(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

std::string at_index(std::size_t index, bool array) {
  return array ? " at index " + std::to_string(index) : std::string();
}

}  // namespace

const char* to_string(RangePolicy p) {
  switch (p) {
    case RangePolicy::kClamp:
      return "clamp";
    case RangePolicy::kExtrapolate:
      return "extrapolate";
    case RangePolicy::kError:
    default:
      return "error";
  }
}

RangePolicy range_policy_from_string(const std::string& s) {
  if (s == "error") return RangePolicy::kError;
  if (s == "clamp") return RangePolicy::kClamp;
  if (s == "extrapolate") return RangePolicy::kExtrapolate;
  throw Error(ErrorCode::kInvalidArgument,
              "range policy '" + s + "' is not one of: error, clamp, extrapolate");
}

std::vector<double> LawRecord::parameter_values() const {
  std::vector<double> v;
  v.reserve(parameters.size());
  for (const LawParameter& p : parameters) v.push_back(p.value);
  return v;
}

Law::Law(LawRecord record, RangePolicy policy)
    : record_(std::move(record)), form_(&find_law_form(record_.form)), policy_(policy) {
  const auto& specs = form_->description.parameters;
  if (record_.parameters.size() != specs.size()) {
    throw Error(ErrorCode::kInvalidArgument, record_.reference() + ": form '" + record_.form +
                                                 "' takes " + std::to_string(specs.size()) +
                                                 " parameters, the record has " +
                                                 std::to_string(record_.parameters.size()));
  }
  for (std::size_t i = 0; i < specs.size(); ++i) {
    if (record_.parameters[i].name != specs[i].name) {
      throw Error(ErrorCode::kInvalidArgument,
                  record_.reference() + ": parameter " + std::to_string(i) + " is '" +
                      record_.parameters[i].name + "', form '" + record_.form + "' expects '" +
                      specs[i].name + "'");
    }
    if (!std::isfinite(record_.parameters[i].value)) {
      throw Error(ErrorCode::kInvalidArgument,
                  record_.reference() + ": parameter '" + specs[i].name + "' is not finite");
    }
  }
  if (record_.validity.extra.size() != static_cast<std::size_t>(form_->num_extra_inputs)) {
    throw Error(ErrorCode::kInvalidArgument,
                record_.reference() + ": validity box declares " +
                    std::to_string(record_.validity.extra.size()) + " extra inputs, form '" +
                    record_.form + "' takes " + std::to_string(form_->num_extra_inputs));
  }
  params_ = record_.parameter_values();
}

void Law::prepare(double& phi, double& re, double* extra_out, const double* extra_in,
                  std::size_t index, bool array) const {
  // Physically impossible inputs: always an error, whatever the policy.
  if (!std::isfinite(phi) || phi < 0.0 || phi >= 1.0) {
    throw Error(ErrorCode::kInvalidArgument,
                reference() + ": phi = " + fmt_double(phi) + at_index(index, array) +
                    " is outside [0, 1) (eps = 1 - phi must lie in (0, 1])");
  }
  if (!std::isfinite(re) || re < 0.0) {
    throw Error(ErrorCode::kInvalidArgument, reference() + ": Re = " + fmt_double(re) +
                                                 at_index(index, array) +
                                                 " must be finite and >= 0");
  }
  const int n_extra = form_->num_extra_inputs;
  if (n_extra > 0 && extra_in == nullptr) {
    throw Error(ErrorCode::kInvalidArgument,
                reference() + ": form '" + record_.form + "' needs " + std::to_string(n_extra) +
                    " extra input(s): " + record_.validity.extra[0].name);
  }
  for (int k = 0; k < n_extra; ++k) {
    if (!std::isfinite(extra_in[k])) {
      throw Error(ErrorCode::kInvalidArgument, reference() + ": extra input '" +
                                                   record_.validity.extra[k].name +
                                                   "' is not finite" + at_index(index, array));
    }
    extra_out[k] = extra_in[k];
  }

  const ValidityBox& box = record_.validity;
  bool outside = !box.phi.contains(phi) || !box.re.contains(re);
  for (int k = 0; k < n_extra; ++k) outside = outside || !box.extra[k].range.contains(extra_out[k]);
  if (!outside) return;

  switch (policy_.load(std::memory_order_relaxed)) {
    case RangePolicy::kError: {
      std::string what;
      if (!box.phi.contains(phi)) {
        what = "phi = " + fmt_double(phi) + " is outside the validity range [" +
               fmt_double(box.phi.min) + ", " + fmt_double(box.phi.max) + "]";
      } else if (!box.re.contains(re)) {
        what = "Re = " + fmt_double(re) + " is outside the validity range [" +
               fmt_double(box.re.min) + ", " + fmt_double(box.re.max) + "]";
      } else {
        for (int k = 0; k < n_extra; ++k) {
          if (!box.extra[k].range.contains(extra_out[k])) {
            what = box.extra[k].name + " = " + fmt_double(extra_out[k]) +
                   " is outside the validity range [" + fmt_double(box.extra[k].range.min) + ", " +
                   fmt_double(box.extra[k].range.max) + "]";
          }
        }
      }
      throw Error(ErrorCode::kOutOfValidity,
                  reference() + ": " + what + at_index(index, array) +
                      " (choose the range policy 'clamp' or 'extrapolate' to evaluate anyway)");
    }
    case RangePolicy::kClamp:
      phi = std::clamp(phi, box.phi.min, box.phi.max);
      re = std::clamp(re, box.re.min, box.re.max);
      for (int k = 0; k < n_extra; ++k) {
        extra_out[k] = std::clamp(extra_out[k], box.extra[k].range.min, box.extra[k].range.max);
      }
      out_of_range_.fetch_add(1, std::memory_order_relaxed);
      return;
    case RangePolicy::kExtrapolate:
      out_of_range_.fetch_add(1, std::memory_order_relaxed);
      return;
  }
}

namespace {
constexpr int kMaxExtraInputs = 8;
}

LawEvaluation Law::evaluate(double phi, double re, const double* extra) const {
  double extra_buf[kMaxExtraInputs];
  LawEvaluation e;
  e.phi = phi;
  e.re = re;
  const std::uint64_t before = out_of_range_.load(std::memory_order_relaxed);
  prepare(e.phi, e.re, extra_buf, extra, 0, false);
  e.out_of_validity = out_of_range_.load(std::memory_order_relaxed) != before ||
                      !record_.validity.phi.contains(phi) || !record_.validity.re.contains(re);
  e.F = form_->F(e.phi, e.re, extra_buf, params_.data());
  if (!std::isfinite(e.F)) {
    throw Error(ErrorCode::kOutOfValidity,
                reference() + ": the formula gives a non-finite F at phi = " + fmt_double(e.phi) +
                    ", Re = " + fmt_double(e.re) + " (far outside its validity box)");
  }
  return e;
}

double Law::F(double phi, double re, const double* extra) const {
  return evaluate(phi, re, extra).F;
}

void Law::F(std::size_t n, const double* phi, const double* re, double* out,
            const double* extra) const {
  if (n == 0) return;
  if (phi == nullptr || re == nullptr || out == nullptr) {
    throw Error(ErrorCode::kInvalidArgument, reference() + ": null array passed to F");
  }
  const int n_extra = form_->num_extra_inputs;
  const ValidityBox& box = record_.validity;
  // Fast path: one branch-free scan says whether every point is plainly inside the box; then the
  // inlined formula runs over the caller's arrays directly.
  bool all_inside = true;
  for (std::size_t i = 0; i < n; ++i) {
    all_inside &= (phi[i] >= box.phi.min) & (phi[i] <= box.phi.max) & (re[i] >= box.re.min) &
                  (re[i] <= box.re.max) & (phi[i] < 1.0) & (re[i] >= 0.0);
  }
  if (all_inside && n_extra == 0) {
    form_->F_array(n, phi, re, nullptr, params_.data(), out);
    return;  // inside the validity box every form is finite (tested over each box)
  }
  // General path, in blocks: validate, apply the policy, evaluate.
  constexpr std::size_t kBlock = 256;
  double phi_buf[kBlock], re_buf[kBlock];
  std::vector<double> extra_buf(kBlock * static_cast<std::size_t>(std::max(n_extra, 1)));
  for (std::size_t start = 0; start < n; start += kBlock) {
    const std::size_t m = std::min(kBlock, n - start);
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t i = start + j;
      phi_buf[j] = phi[i];
      re_buf[j] = re[i];
      prepare(phi_buf[j], re_buf[j], extra_buf.data() + j * n_extra,
              n_extra > 0 ? extra + i * n_extra : nullptr, i, true);
    }
    form_->F_array(m, phi_buf, re_buf, n_extra > 0 ? extra_buf.data() : nullptr, params_.data(),
                   out + start);
    for (std::size_t j = 0; j < m; ++j) {
      if (!std::isfinite(out[start + j])) {
        throw Error(ErrorCode::kOutOfValidity,
                    reference() + ": the formula gives a non-finite F at index " +
                        std::to_string(start + j) + " (phi = " + fmt_double(phi_buf[j]) +
                        ", Re = " + fmt_double(re_buf[j]) + ", far outside its validity box)");
      }
    }
  }
}

double Law::beta_d2_over_mu(double phi, double re, const double* extra) const {
  return conventions::beta_d2_over_mu(phi, F(phi, re, extra));
}

double Law::K(double phi, double re, const double* extra) const {
  return conventions::total_force_K(phi, F(phi, re, extra));
}

double Law::drag_coefficient_times_re_p(double phi, double re, const double* extra) const {
  return conventions::drag_coefficient_times_re_p(phi, F(phi, re, extra));
}

double Law::drag_coefficient(double phi, double re, const double* extra) const {
  if (!(re > 0.0)) {
    throw Error(
        ErrorCode::kInvalidArgument,
        reference() + ": C_d needs Re > 0 (use C_d Re_p at Re = 0), got Re = " + fmt_double(re));
  }
  return conventions::drag_coefficient(phi, re, F(phi, re, extra));
}

namespace {

/// Checks the dimensional inputs of beta() and dga(); returns the canonical Re.
double checked_reynolds(const std::string& ref, double eps_g, double mu_g, double rho_g,
                        double slip, double d_p) {
  auto positive = [&](double v, const char* name) {
    if (!std::isfinite(v) || !(v > 0.0)) {
      throw Error(ErrorCode::kInvalidArgument,
                  ref + ": " + name + " = " + fmt_double(v) + " must be finite and > 0");
    }
  };
  if (!std::isfinite(eps_g) || !(eps_g > 0.0) || eps_g > 1.0) {
    throw Error(ErrorCode::kInvalidArgument,
                ref + ": eps_g = " + fmt_double(eps_g) + " is outside (0, 1]");
  }
  positive(mu_g, "mu_g");
  positive(rho_g, "rho_g");
  positive(d_p, "d_p");
  if (!std::isfinite(slip) || slip < 0.0) {
    throw Error(ErrorCode::kInvalidArgument,
                ref + ": slip = " + fmt_double(slip) + " must be finite and >= 0");
  }
  return conventions::reynolds(eps_g, mu_g, rho_g, slip, d_p);
}

}  // namespace

double Law::beta(double eps_g, double mu_g, double rho_g, double slip, double d_p,
                 const double* extra) const {
  const double re = checked_reynolds(reference(), eps_g, mu_g, rho_g, slip, d_p);
  const double phi = 1.0 - eps_g;
  return conventions::beta(phi, F(phi, re, extra), mu_g, d_p);
}

double Law::particle_drag(double eps_g, double mu_g, double rho_g, double slip, double d_i,
                          double d_mean, double* re_out) const {
  const int n_extra = form_->num_extra_inputs;
  if (n_extra > 1) {
    throw Error(ErrorCode::kInvalidArgument,
                reference() + ": particle_drag supports forms with at most one extra input (y)");
  }
  const bool poly = n_extra == 1;
  // The diameter of the Reynolds number: the mixture's for polydisperse forms.
  const double d_ref = poly ? d_mean : d_i;
  const double re = checked_reynolds(reference(), eps_g, mu_g, rho_g, slip, d_ref);
  if (poly && (!std::isfinite(d_i) || !(d_i > 0.0))) {
    throw Error(ErrorCode::kInvalidArgument,
                reference() + ": d_i = " + fmt_double(d_i) + " must be finite and > 0");
  }
  const double y = poly ? d_i / d_mean : 1.0;
  const double phi = 1.0 - eps_g;
  if (re_out != nullptr) *re_out = re;
  return conventions::particle_drag_coefficient(phi, F(phi, re, poly ? &y : nullptr), mu_g, d_i);
}

double Law::dga(double eps_g, double mu_g, double rho_g, double slip, double d_p,
                const double* extra) const {
  const double re = checked_reynolds(reference(), eps_g, mu_g, rho_g, slip, d_p);
  const double phi = 1.0 - eps_g;
  // Same operations, in the same order, as the exported _dga functions (codegen/export.cc).
  return eps_g * F(phi, re, extra) * 18.0 * (mu_g / (d_p * d_p));
}

}  // namespace draglab
