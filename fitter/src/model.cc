// The fit model: evaluation, automatic derivatives, cost and physical-constraint checks.
#include <algorithm>
#include <cmath>
#include <limits>

#include <ceres/jet.h>
#include <fmt/core.h>

#include "fit_internal.h"

namespace draglab {
namespace fitter {
namespace internal {

std::vector<double> Model::z_of_params() const {
  std::vector<double> z(free_index.size());
  for (std::size_t j = 0; j < free_index.size(); ++j) z[j] = params[free_index[j]] / scale[j];
  return z;
}

std::vector<double> Model::params_at(const double* z) const {
  std::vector<double> p = params;
  for (std::size_t j = 0; j < free_index.size(); ++j) p[free_index[j]] = scale[j] * z[j];
  return p;
}

namespace {

/// The extra inputs as constants of the automatic derivatives.
std::vector<AutoDiffScalar> extra_jets(const LawForm& form, const double* extra) {
  std::vector<AutoDiffScalar> jets;
  for (int k = 0; k < form.num_extra_inputs; ++k) jets.emplace_back(extra[k]);
  return jets;
}

const AutoDiffScalar* data_or_null(const std::vector<AutoDiffScalar>& v) {
  return v.empty() ? nullptr : v.data();
}

}  // namespace

double model_F(const Model& m, const double* z, double phi, double re, const double* extra) {
  const std::vector<double> p = m.params_at(z);
  return m.form->F(phi, re, extra, p.data());
}

double model_F_gradient(const Model& m, const double* z, double phi, double re, const double* extra,
                        double* grad) {
  constexpr int kStride = 4;  // AutoDiffScalar = ceres::Jet<double, 4>
  const int n = m.num_free();
  std::vector<AutoDiffScalar> p(m.params.size());
  const std::vector<double> values = m.params_at(z);
  const AutoDiffScalar phi_jet(phi), re_jet(re);
  const std::vector<AutoDiffScalar> extra_jet = extra_jets(*m.form, extra);
  double F = m.form->F(phi, re, extra, values.data());
  for (int first = 0; first < n; first += kStride) {
    for (std::size_t k = 0; k < values.size(); ++k) p[k] = AutoDiffScalar(values[k]);
    const int count = std::min(kStride, n - first);
    for (int c = 0; c < count; ++c) {
      p[m.free_index[first + c]] = AutoDiffScalar(values[m.free_index[first + c]], c);
    }
    const AutoDiffScalar f = m.form->F_autodiff(phi_jet, re_jet, data_or_null(extra_jet), p.data());
    F = f.a;
    // dF/dz = dF/dx * scale.
    for (int c = 0; c < count; ++c) grad[first + c] = f.v[c] * m.scale[first + c];
  }
  return F;
}

double dF_dRe(const LawForm& form, const double* params, double phi, double re,
              const double* extra) {
  std::vector<AutoDiffScalar> p(form.num_parameters);
  for (int k = 0; k < form.num_parameters; ++k) p[k] = AutoDiffScalar(params[k]);
  const std::vector<AutoDiffScalar> extra_jet = extra_jets(form, extra);
  const AutoDiffScalar f = form.F_autodiff(AutoDiffScalar(phi), AutoDiffScalar(re, 0),
                                           data_or_null(extra_jet), p.data());
  return f.v[0];
}

double robust_rho(RobustLoss loss, double scale, double s, double* drho) {
  const double a2 = scale * scale;
  switch (loss) {
    case RobustLoss::kHuber:  // Ceres HuberLoss(a): s for s <= a^2, else 2 a sqrt(s) - a^2
      if (s <= a2) {
        *drho = 1.0;
        return s;
      } else {
        const double r = std::sqrt(s);
        *drho = scale / r;
        return 2.0 * scale * r - a2;
      }
    case RobustLoss::kCauchy:  // Ceres CauchyLoss(a): a^2 log(1 + s/a^2)
      *drho = 1.0 / (1.0 + s / a2);
      return a2 * std::log1p(s / a2);
    case RobustLoss::kNone:
      break;
  }
  *drho = 1.0;
  return s;
}

double lsq_cost(const Model& m, const std::vector<FitPoint>& points, RobustLoss loss,
                double loss_scale, const double* z, double* grad) {
  const int n = m.num_free();
  std::vector<double> g(n);
  if (grad) std::fill(grad, grad + n, 0.0);
  double cost = 0.0;
  for (const FitPoint& pt : points) {
    const double F = grad ? model_F_gradient(m, z, pt.phi, pt.re, pt.extra_data(), g.data())
                          : model_F(m, z, pt.phi, pt.re, pt.extra_data());
    const double r = (F - pt.F) / pt.sigma;
    double drho = 1.0;
    cost += 0.5 * robust_rho(loss, loss_scale, r * r, &drho);
    if (grad) {
      for (int j = 0; j < n; ++j) grad[j] += drho * r * g[j] / pt.sigma;
    }
  }
  if (!std::isfinite(cost)) return std::numeric_limits<double>::max();
  return cost;
}

ConstraintGrid constraint_grid(const LawForm& form, const std::vector<FitPoint>& points) {
  constexpr int kNodes = 12;
  double phi_lo = 1.0, phi_hi = 0.0, re_lo = std::numeric_limits<double>::max(), re_hi = 0.0;
  for (const FitPoint& p : points) {
    phi_lo = std::min(phi_lo, p.phi);
    phi_hi = std::max(phi_hi, p.phi);
    re_lo = std::min(re_lo, p.re);
    re_hi = std::max(re_hi, p.re);
  }
  const ValidityBox& box = form.description.validity;
  const double phi_pad = 0.1 * (phi_hi - phi_lo), re_pad = 0.1 * (re_hi - re_lo);
  double lo = std::max(box.phi.min, phi_lo - phi_pad), hi = std::min(box.phi.max, phi_hi + phi_pad);
  if (lo > hi) {  // data outside the form's box: check over the data range itself
    lo = std::max(1e-6, phi_lo - phi_pad);
    hi = std::min(0.74, phi_hi + phi_pad);
  }
  ConstraintGrid grid;
  for (int i = 0; i < kNodes; ++i) grid.phi.push_back(lo + (hi - lo) * i / (kNodes - 1.0));
  if (form.num_extra_inputs > 0 && !points.empty()) {
    std::vector<double> smallest = points.front().extra, largest = points.front().extra;
    for (const FitPoint& p : points) {
      for (std::size_t k = 0; k < p.extra.size() && k < smallest.size(); ++k) {
        smallest[k] = std::min(smallest[k], p.extra[k]);
        largest[k] = std::max(largest[k], p.extra[k]);
      }
    }
    grid.extra_sets = {smallest, largest};
  }
  double rlo = std::max({box.re.min, re_lo - re_pad, 0.0}),
         rhi = std::min(box.re.max, re_hi + re_pad);
  if (rlo > rhi) {
    rlo = std::max(0.0, re_lo - re_pad);
    rhi = re_hi + re_pad;
  }
  if (rhi <= 0.0) {
    grid.re.push_back(0.0);
    return grid;
  }
  int log_nodes = kNodes;
  if (rlo <= 0.0) {
    grid.re.push_back(0.0);
    --log_nodes;
    rlo = 1e-3 * rhi;  // log-spaced from three decades below the top
  }
  for (int i = 0; i < log_nodes; ++i) {
    grid.re.push_back(rlo * std::pow(rhi / rlo, log_nodes == 1 ? 1.0 : i / (log_nodes - 1.0)));
  }
  return grid;
}

std::string check_constraints(const LawForm& form, const double* params,
                              const ConstraintGrid& grid) {
  int negative_F = 0, decreasing = 0;
  std::string first_negative, first_decreasing;
  for (const std::vector<double>& extra_set : grid.extra_sets) {
    const double* extra = extra_set.empty() ? nullptr : extra_set.data();
    const std::string at_extra =
        extra_set.empty() ? std::string() : fmt::format(", y = {:.3g}", extra_set[0]);
    for (double phi : grid.phi) {
      for (double re : grid.re) {
        const double F = form.F(phi, re, extra, params);
        if (!(F > 0.0)) {
          if (negative_F++ == 0) {
            first_negative =
                fmt::format("phi = {:.3g}, Re = {:.3g}{} (F = {:.4g})", phi, re, at_extra, F);
          }
        }
        const double slope = dF_dRe(form, params, phi, re, extra);
        // Tolerance: rounding of the automatic derivative (relative 1e-12 of F per unit Re).
        if (!(slope >= -1e-12 * std::fabs(F))) {
          if (decreasing++ == 0) {
            first_decreasing = fmt::format("phi = {:.3g}, Re = {:.3g}{} (dF/dRe = {:.4g})", phi, re,
                                           at_extra, slope);
          }
        }
      }
    }
  }
  const std::size_t nodes = grid.nodes();
  std::string report;
  if (negative_F > 0) {
    report +=
        fmt::format("F <= 0 at {} of {} grid nodes, e.g. {}", negative_F, nodes, first_negative);
  }
  if (decreasing > 0) {
    if (!report.empty()) report += "; ";
    report += fmt::format("dF/dRe < 0 at {} of {} grid nodes, e.g. {}", decreasing, nodes,
                          first_decreasing);
  }
  return report;
}

}  // namespace internal
}  // namespace fitter
}  // namespace draglab
