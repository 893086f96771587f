// NLopt: the multi-start global check of the least-squares optimum and the minimax fit.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <fmt/core.h>
#include <nlopt.h>

#include "fit_internal.h"

namespace draglab {
namespace fitter {
namespace internal {
namespace {

struct CostData {
  const Model* model;
  const std::vector<FitPoint>* points;
  RobustLoss loss;
  double loss_scale;
};

double nlopt_cost(unsigned n, const double* z, double* grad, void* data) {
  const auto* d = static_cast<const CostData*>(data);
  const double cost = lsq_cost(*d->model, *d->points, d->loss, d->loss_scale, z, grad);
  if (grad) {
    for (unsigned j = 0; j < n; ++j) {
      if (!std::isfinite(grad[j])) grad[j] = 0.0;
    }
  }
  return cost;
}

/// Radical inverse in base `base` (Halton sequence component).
double radical_inverse(unsigned index, unsigned base) {
  double result = 0.0, f = 1.0 / base;
  for (; index > 0; index /= base, f /= base) result += f * (index % base);
  return result;
}

}  // namespace

GlobalSearchResult global_search(const Model& m, const std::vector<FitPoint>& points,
                                 RobustLoss loss, double loss_scale,
                                 const std::vector<double>& z_center,
                                 const std::vector<double>& z_halfwidth, unsigned seed,
                                 int starts) {
  static const unsigned kPrimes[] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53};
  const unsigned n = static_cast<unsigned>(m.num_free());
  GlobalSearchResult result;
  result.best_cost = std::numeric_limits<double>::max();
  result.best_z = z_center;
  // Halton points with a seeded random shift (Cranley-Patterson rotation): evenly spread starts
  // that differ between seeds but are reproducible for a given one.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> shift(n);
  for (unsigned j = 0; j < n; ++j) shift[j] = unit(rng);
  CostData data{&m, &points, loss, loss_scale};
  nlopt_opt opt = nlopt_create(NLOPT_LD_LBFGS, n);
  nlopt_set_min_objective(opt, nlopt_cost, &data);
  nlopt_set_ftol_rel(opt, 1e-15);
  nlopt_set_xtol_rel(opt, 1e-12);
  nlopt_set_maxeval(opt, 3000);
  std::vector<double> z(n);
  for (int s = 0; s < starts; ++s) {
    for (unsigned j = 0; j < n; ++j) {
      const double u = std::fmod(radical_inverse(s + 1, kPrimes[j % 16]) + shift[j], 1.0);
      z[j] = z_center[j] + (2.0 * u - 1.0) * z_halfwidth[j];
    }
    double cost = 0.0;
    const nlopt_result status = nlopt_optimize(opt, z.data(), &cost);
    ++result.starts;
    if (status < 0 && status != NLOPT_ROUNDOFF_LIMITED) continue;
    cost = lsq_cost(m, points, loss, loss_scale, z.data(), nullptr);
    if (!std::isfinite(cost)) continue;
    ++result.successful_starts;
    if (cost < result.best_cost) {
      result.best_cost = cost;
      result.best_z = z;
    }
  }
  nlopt_destroy(opt);
  return result;
}

namespace {

struct MinimaxData {
  const Model* model;
  const std::vector<FitPoint>* points;
  const ConstraintGrid* grid;
};

double minimax_objective(unsigned n, const double* y, double* grad, void*) {
  if (grad) {
    std::fill(grad, grad + n, 0.0);
    grad[n - 1] = 1.0;
  }
  return y[n - 1];  // t
}

// c_{2i} = F_i(z)/F_i - 1 - t <= 0, c_{2i+1} = 1 - F_i(z)/F_i - t <= 0.
void data_constraints(unsigned m, double* c, unsigned n, const double* y, double* grad,
                      void* data) {
  const auto* d = static_cast<const MinimaxData*>(data);
  const unsigned nz = n - 1;
  const double t = y[nz];
  std::vector<double> g(nz);
  for (unsigned i = 0; i < m / 2; ++i) {
    const FitPoint& pt = (*d->points)[i];
    const double F = model_F_gradient(*d->model, y, pt.phi, pt.re, pt.extra_data(), g.data());
    const double rel = F / pt.F - 1.0;
    c[2 * i] = rel - t;
    c[2 * i + 1] = -rel - t;
    if (grad) {
      double* g0 = grad + (2 * i) * n;
      double* g1 = grad + (2 * i + 1) * n;
      for (unsigned j = 0; j < nz; ++j) {
        g0[j] = g[j] / pt.F;
        g1[j] = -g[j] / pt.F;
      }
      g0[nz] = -1.0;
      g1[nz] = -1.0;
    }
  }
}

// Per grid node: -F <= 0 and -dF/dRe <= 0. The gradient of dF/dRe in z is a central difference
// of the automatic dF/dRe (Jets of one level only).
void grid_constraints(unsigned m, double* c, unsigned n, const double* y, double* grad,
                      void* data) {
  const auto* d = static_cast<const MinimaxData*>(data);
  const Model& model = *d->model;
  const unsigned nz = n - 1;
  std::vector<double> g(nz), zp(y, y + nz), zm(y, y + nz);
  const std::vector<double> params = model.params_at(y);
  unsigned k = 0;
  for (const std::vector<double>& extra_set : d->grid->extra_sets) {
    const double* extra = extra_set.empty() ? nullptr : extra_set.data();
    for (double phi : d->grid->phi) {
      for (double re : d->grid->re) {
        const double F = model_F_gradient(model, y, phi, re, extra, g.data());
        c[k] = -F;
        const double slope = dF_dRe(*model.form, params.data(), phi, re, extra);
        c[k + 1] = -slope;
        if (grad) {
          double* gF = grad + k * n;
          double* gS = grad + (k + 1) * n;
          for (unsigned j = 0; j < nz; ++j) {
            gF[j] = -g[j];
            const double h = 1e-6 * std::max(1.0, std::fabs(y[j]));
            zp[j] = y[j] + h;
            zm[j] = y[j] - h;
            const std::vector<double> pp = model.params_at(zp.data()),
                                      pm = model.params_at(zm.data());
            gS[j] = -(dF_dRe(*model.form, pp.data(), phi, re, extra) -
                      dF_dRe(*model.form, pm.data(), phi, re, extra)) /
                    (2.0 * h);
            zp[j] = zm[j] = y[j];
          }
          gF[nz] = gS[nz] = 0.0;
        }
        k += 2;
      }
    }
  }
  (void)m;
}

double max_relative_error(const Model& m, const std::vector<FitPoint>& points, const double* z) {
  double worst = 0.0;
  for (const FitPoint& pt : points) {
    worst = std::max(worst, std::fabs(model_F(m, z, pt.phi, pt.re, pt.extra_data()) / pt.F - 1.0));
  }
  return worst;
}

}  // namespace

bool minimax_fit(const Model& m, const std::vector<FitPoint>& points, const ConstraintGrid* grid,
                 const std::vector<double>& z_start, std::vector<double>* z_out,
                 double* max_rel_err, std::string* message) {
  const unsigned nz = static_cast<unsigned>(m.num_free());
  const unsigned n = nz + 1;
  MinimaxData data{&m, &points, grid};
  const double start_err = max_relative_error(m, points, z_start.data());
  std::vector<double> y(z_start);
  y.push_back(start_err);  // feasible start for the data constraints
  nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, n);
  nlopt_set_min_objective(opt, minimax_objective, nullptr);
  const unsigned m_data = 2 * static_cast<unsigned>(points.size());
  std::vector<double> tol_data(m_data, 1e-12);
  nlopt_add_inequality_mconstraint(opt, m_data, data_constraints, &data, tol_data.data());
  std::vector<double> tol_grid;
  if (grid) {
    const unsigned m_grid = 2 * static_cast<unsigned>(grid->nodes());
    tol_grid.assign(m_grid, 1e-12);
    nlopt_add_inequality_mconstraint(opt, m_grid, grid_constraints, &data, tol_grid.data());
  }
  nlopt_set_xtol_rel(opt, 1e-9);
  nlopt_set_maxeval(opt, 3000);
  double t = 0.0;
  const nlopt_result status = nlopt_optimize(opt, y.data(), &t);
  nlopt_destroy(opt);
  y.pop_back();
  const double err = max_relative_error(m, points, y.data());
  const std::vector<double> params = m.params_at(y.data());
  const std::string violated = grid ? check_constraints(*m.form, params.data(), *grid) : "";
  if (!std::isfinite(err) || !violated.empty() ||
      (status < 0 && status != NLOPT_ROUNDOFF_LIMITED)) {
    *message = fmt::format("NLopt SLSQP minimax fit failed (status {}){}{}",
                           static_cast<int>(status), violated.empty() ? "" : ": ", violated);
    return false;
  }
  *z_out = y;
  *max_rel_err = err;
  *message = fmt::format(
      "NLopt SLSQP minimax: max relative error {:.4g} (least squares: {:.4g}), status {}", err,
      start_err, static_cast<int>(status));
  return true;
}

}  // namespace internal
}  // namespace fitter
}  // namespace draglab
