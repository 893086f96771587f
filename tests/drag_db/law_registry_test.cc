// Generic properties every registered drag-law form must have, one value-parameterised test per
// form (all_law_forms()):
//   - a complete description (key, title, citation, parameters, validity box with min < max);
//   - finite, positive F on a grid over the validity box, its edges and Re = 0;
//   - automatic derivatives (ceres::Jet<double, 4>, inputs seeded four at a time) equal to central
//     finite differences at interior points away from regime switches, and finite parameter
//     gradients at Re = 0 (the fitter fits Stokes data there);
//   - the isolated-sphere Stokes limit F(phi -> 0, Re -> 0) = single_sphere_stokes_F;
//   - continuity of F as Re -> 0;
//   - across every declared regime switch, a jump that vanishes as the offset shrinks (continuous
//     switches) or equals the documented jump of the published law (e.g. gidaspow at eps = 0.8);
//   - the symbolic (code export) instantiation builds.
// Tolerances are justified where they are used.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "ceres/jet.h"
#include "codegen/expr.h"
#include "draglab/drag_db/conventions.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"

namespace draglab {
namespace {

using Jet = AutoDiffScalar;

class LawFormTest : public ::testing::TestWithParam<const LawForm*> {
 protected:
  const LawForm& form() const { return *GetParam(); }
  const LawFormDescription& desc() const { return GetParam()->description; }
  std::vector<double> params() const { return form().default_parameters(); }

  /// Representative extra inputs: 1 (y = d_i/<d> of a monodisperse system) when inside the box.
  std::vector<double> representative_extra() const {
    std::vector<double> extra;
    for (const ExtraInputSpec& e : desc().validity.extra) {
      extra.push_back(e.range.contains(1.0) ? 1.0 : 0.5 * (e.range.min + e.range.max));
    }
    return extra;
  }

  double F(double phi, double re, const std::vector<double>& extra,
           const std::vector<double>& p) const {
    return form().F(phi, re, extra.empty() ? nullptr : extra.data(), p.data());
  }
  double F(double phi, double re) const { return F(phi, re, representative_extra(), params()); }

  /// Points inside (and on the edges of) the validity range [min, max].
  static std::vector<double> grid(const InputRange& r, bool log_spaced) {
    std::vector<double> g = {r.min, r.max};
    for (double f : {0.01, 0.25, 0.5, 0.75, 0.99}) g.push_back(r.min + f * (r.max - r.min));
    if (log_spaced) {
      for (double x = 1e-8; x < r.max; x *= 10.0) {
        if (x > r.min) g.push_back(x);
      }
    }
    return g;
  }
};

// ---- Description -----------------------------------------------------------------------------

TEST_P(LawFormTest, DescriptionIsComplete) {
  const LawFormDescription& d = desc();
  EXPECT_EQ(&find_law_form(d.key), &form());
  EXPECT_FALSE(d.title.empty());
  EXPECT_FALSE(d.form_notes.empty());
  if (d.literature) {
    EXPECT_FALSE(d.citation.empty());
  }
  // Keys are identifiers usable in C, Fortran and file names.
  for (char c : d.key) {
    const bool ok = std::islower(static_cast<unsigned char>(c)) ||
                    std::isdigit(static_cast<unsigned char>(c)) || c == '_';
    EXPECT_TRUE(ok) << d.key;
  }

  EXPECT_EQ(static_cast<int>(d.parameters.size()), form().num_parameters);
  std::set<std::string> names;
  for (const ParameterSpec& p : d.parameters) {
    EXPECT_FALSE(p.name.empty());
    EXPECT_FALSE(p.description.empty()) << p.name;
    EXPECT_TRUE(std::isfinite(p.value)) << p.name;
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate parameter " << p.name;
  }

  const ValidityBox& v = d.validity;
  EXPECT_LT(v.phi.min, v.phi.max);
  EXPECT_GE(v.phi.min, 0.0);
  EXPECT_LT(v.phi.max, 1.0);
  EXPECT_LT(v.re.min, v.re.max);
  EXPECT_GE(v.re.min, 0.0);
  EXPECT_EQ(v.re.min, 0.0) << "Re = 0 (the Stokes limit) must be inside every box";
  if (!d.has_inertia) {
    EXPECT_LE(v.re.max, 1.0) << "a Stokes-limit law has a small Re range";
  }
  EXPECT_EQ(static_cast<int>(v.extra.size()), form().num_extra_inputs);
  for (const ExtraInputSpec& e : v.extra) {
    EXPECT_FALSE(e.name.empty());
    EXPECT_LT(e.range.min, e.range.max) << e.name;
  }
  for (const RegimeSwitch& s : d.switches) {
    EXPECT_FALSE(s.description.empty());
    EXPECT_NE(s.location, nullptr) << s.description;
    EXPECT_GE(s.documented_relative_jump, 0.0) << s.description;
  }
  EXPECT_TRUE(std::isfinite(d.single_sphere_stokes_F));
  EXPECT_NE(form().F, nullptr);
  EXPECT_NE(form().F_autodiff, nullptr);
  EXPECT_NE(form().F_symbolic, nullptr);
  EXPECT_NE(form().F_array, nullptr);
}

// ---- Values over the box ---------------------------------------------------------------------

TEST_P(LawFormTest, FiniteAndPositiveOverTheValidityBox) {
  const ValidityBox& v = desc().validity;
  std::vector<std::vector<double>> extras = {representative_extra()};
  for (std::size_t k = 0; k < v.extra.size(); ++k) {
    for (double x : {v.extra[k].range.min, v.extra[k].range.max}) {
      std::vector<double> e = representative_extra();
      e[k] = x;
      extras.push_back(e);
    }
  }
  std::vector<double> res = grid(v.re, true);
  res.push_back(0.0);
  res.push_back(std::numeric_limits<double>::denorm_min());
  for (double phi : grid(v.phi, false)) {
    for (double re : res) {
      for (const auto& extra : extras) {
        const double f = F(phi, re, extra, params());
        EXPECT_TRUE(std::isfinite(f)) << "phi=" << phi << " Re=" << re;
        EXPECT_GT(f, 0.0) << "phi=" << phi << " Re=" << re;
      }
    }
  }
  // The physical corners outside the box must still be finite (extrapolation policy).
  for (double phi : {0.0, 1e-300, 0.7}) {
    for (double re : {0.0, 1e-300, 1.0, 1e4}) {
      EXPECT_TRUE(std::isfinite(F(phi, re))) << "phi=" << phi << " Re=" << re;
    }
  }
}

TEST_P(LawFormTest, SingleSphereStokesLimit) {
  const double expected = desc().single_sphere_stokes_F;
  // At the corner every form reduces to a few exact operations (e.g. 0.75 * 4.8^2 / 18): rounding.
  EXPECT_NEAR(F(0.0, 0.0), expected, 1e-14 * std::max(1.0, expected));
  // Approaching the corner: the slowest terms are 0.48 phi^(1/3) (tenneti2011: 5e-5 at 1e-12) and
  // sqrt(Re), sqrt(phi) terms (< 2e-6); 1e-4 separates a limit from a different constant.
  EXPECT_NEAR(F(1e-12, 1e-12), expected, 1e-4 * std::max(1.0, expected));
}

TEST_P(LawFormTest, ReZeroLimitIsContinuous) {
  for (double phi : grid(desc().validity.phi, false)) {
    const double f0 = F(phi, 0.0);
    // The slowest approach is a sqrt(Re) term (Dalla Valle C_d): 2*0.63*4.8/24 sqrt(Re/V_r), at
    // most ~3e-5 relative for Re = 1e-10 even with Syamlal-O'Brien's V_r = eps^4.14 at phi = 0.6.
    EXPECT_NEAR(F(phi, 1e-10), f0, 1e-4 * f0) << "phi=" << phi;
    EXPECT_LE(std::fabs(F(phi, 1e-14) - f0), std::fabs(F(phi, 1e-10) - f0) + 1e-15 * f0)
        << "phi=" << phi;
  }
}

// ---- Derivatives -----------------------------------------------------------------------------

/// Inputs of F in one vector: phi, Re, extra inputs, parameters.
struct Inputs {
  std::vector<double> values;
  int num_extra = 0;
};

std::vector<Jet> jet_gradient_inputs(const Inputs& in, std::size_t first_seeded) {
  std::vector<Jet> jets;
  for (std::size_t i = 0; i < in.values.size(); ++i) {
    Jet j(in.values[i]);
    if (i >= first_seeded && i < first_seeded + 4) j.v[i - first_seeded] = 1.0;
    jets.push_back(j);
  }
  return jets;
}

double eval_inputs(const LawForm& form, const std::vector<double>& x, int num_extra) {
  return form.F(x[0], x[1], num_extra > 0 ? &x[2] : nullptr, x.data() + 2 + num_extra);
}

/// dF/dx_i for every input by automatic differentiation, seeding four inputs per evaluation.
std::vector<double> autodiff_gradient(const LawForm& form, const Inputs& in, double* value) {
  std::vector<double> grad(in.values.size());
  for (std::size_t first = 0; first < in.values.size(); first += 4) {
    const std::vector<Jet> x = jet_gradient_inputs(in, first);
    const Jet f = form.F_autodiff(x[0], x[1], in.num_extra > 0 ? &x[2] : nullptr,
                                  x.data() + 2 + in.num_extra);
    *value = f.a;
    for (std::size_t k = 0; k < 4 && first + k < in.values.size(); ++k) grad[first + k] = f.v[k];
  }
  return grad;
}

/// Distance (relative to the coordinate scale) of (phi, re) from every declared switch.
bool near_a_switch(const LawFormDescription& d, const std::vector<double>& p, double phi, double re,
                   double margin) {
  for (const RegimeSwitch& s : d.switches) {
    if (s.axis == RegimeSwitch::Axis::kPhi) {
      const double at = s.location(re, p.data());
      if (std::fabs(phi - at) < margin * std::max(at, 0.01)) return true;
    } else {
      const double at = s.location(phi, p.data());
      if (std::isfinite(at) && std::fabs(re - at) < margin * std::max(at, 1e-3)) return true;
    }
  }
  return false;
}

TEST_P(LawFormTest, AutodiffMatchesCentralDifferences) {
  const ValidityBox& v = desc().validity;
  const std::vector<double> p = params();
  const std::vector<double> extra = representative_extra();
  std::vector<double> res;
  for (double re : {0.05, 0.37, 7.3, 180.0, 777.0, 0.3 * v.re.max, 0.6 * v.re.max}) {
    if (re > v.re.min && re < v.re.max) res.push_back(re);
  }
  int checked = 0;
  for (double fphi : {0.3, 0.55, 0.8}) {
    const double phi = v.phi.min + fphi * (v.phi.max - v.phi.min);
    for (double re : res) {
      if (near_a_switch(desc(), p, phi, re, 1e-3)) continue;
      Inputs in;
      in.num_extra = form().num_extra_inputs;
      in.values = {phi, re};
      in.values.insert(in.values.end(), extra.begin(), extra.end());
      in.values.insert(in.values.end(), p.begin(), p.end());
      double value = 0.0;
      const std::vector<double> grad = autodiff_gradient(form(), in, &value);
      const double f = eval_inputs(form(), in.values, in.num_extra);
      // The Jet's value part runs nearly the same double operations; ceres divides by
      // multiplying with the reciprocal (1 ulp apart), so allow a few tens of ulps.
      EXPECT_NEAR(value, f, 1e-14 * std::fabs(f));
      for (std::size_t i = 0; i < in.values.size(); ++i) {
        const double x = in.values[i];
        const double h = 1e-6 * std::max(std::fabs(x), 1e-2);
        std::vector<double> xp = in.values, xm = in.values;
        xp[i] += h;
        xm[i] -= h;
        const double fd =
            (eval_inputs(form(), xp, in.num_extra) - eval_inputs(form(), xm, in.num_extra)) /
            (2.0 * h);
        // Central differences with h = 1e-6 |x| err by ~2e-16 |F|/h (rounding) plus h^2 F'''/6
        // (~1e-12 |F|/|x| for these smooth laws): < 1e-9 (|F|/|x| + |dF/dx|); 1e-7 leaves a
        // margin of 100 and still catches any wrong derivative (errors of order 1).
        const double scale = std::fabs(grad[i]) + std::fabs(f) / std::max(std::fabs(x), 1e-2);
        EXPECT_NEAR(grad[i], fd, 1e-7 * scale)
            << "d F/d input " << i << " at phi=" << phi << " Re=" << re;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 0);
}

TEST_P(LawFormTest, GradientIsFiniteAtReZero) {
  // The fitter fits Stokes-limit data (Re = 0): derivatives must not be 0 * inf = NaN there.
  const ValidityBox& v = desc().validity;
  const std::vector<double> p = params();
  const std::vector<double> extra = representative_extra();
  for (double fphi : {0.3, 0.8}) {
    Inputs in;
    in.num_extra = form().num_extra_inputs;
    in.values = {v.phi.min + fphi * (v.phi.max - v.phi.min), 0.0};
    in.values.insert(in.values.end(), extra.begin(), extra.end());
    in.values.insert(in.values.end(), p.begin(), p.end());
    double value = 0.0;
    const std::vector<double> grad = autodiff_gradient(form(), in, &value);
    EXPECT_TRUE(std::isfinite(value));
    for (std::size_t i = 0; i < grad.size(); ++i) {
      EXPECT_TRUE(std::isfinite(grad[i])) << "input " << i << " at phi=" << in.values[0];
    }
  }
}

// ---- Regime switches -------------------------------------------------------------------------

/// |F+ - F-| / |F-| across the switch at offset delta (absolute in phi, relative in Re).
double measured_jump(const LawForm& form, const RegimeSwitch& s, double other, double delta) {
  const std::vector<double> p = form.default_parameters();
  const double at = s.location(other, p.data());
  double below, above;
  auto eval = [&](double phi, double re) {
    std::vector<double> extra(form.num_extra_inputs, 1.0);
    return form.F(phi, re, extra.empty() ? nullptr : extra.data(), p.data());
  };
  if (s.axis == RegimeSwitch::Axis::kPhi) {
    below = eval(at - delta, other);
    above = eval(at + delta, other);
  } else {
    below = eval(other, at * (1.0 - delta));
    above = eval(other, at * (1.0 + delta));
  }
  return std::fabs(above - below) / std::fabs(below);
}

TEST_P(LawFormTest, JumpsAcrossSwitchesAreTheDocumentedOnes) {
  const ValidityBox& v = desc().validity;
  const std::vector<double> p = params();
  for (const RegimeSwitch& s : desc().switches) {
    SCOPED_TRACE(s.description);
    const double jump = measured_jump(form(), s, s.documented_at_other, 1e-9);
    if (s.documented_relative_jump == 0.0) {
      // A continuous switch: only the slope contributes, |dlnF/dlnx| * 2e-9 < 1e-7 here.
      EXPECT_LT(jump, 1e-6);
      EXPECT_LE(measured_jump(form(), s, s.documented_at_other, 1e-12), 1e-9);
      // ... and it is continuous wherever it applies on the other axis.
      const InputRange& other_range = s.axis == RegimeSwitch::Axis::kPhi ? v.re : v.phi;
      for (double f : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        const double other = other_range.min + f * (other_range.max - other_range.min);
        const double at = s.location(other, p.data());
        const bool usable =
            std::isfinite(at) && at > 0.0 && (s.axis == RegimeSwitch::Axis::kRe || at < 1.0);
        if (!usable) continue;
        EXPECT_LT(measured_jump(form(), s, other, 1e-9), 1e-6) << "other=" << other;
      }
    } else {
      // The documented value is printed to 4 significant figures (5e-4 relative); the finite
      // offset adds < 1e-7.
      EXPECT_NEAR(jump, s.documented_relative_jump, 1e-3 * s.documented_relative_jump + 1e-7);
    }
  }
}

// ---- Symbolic instantiation ------------------------------------------------------------------

TEST_P(LawFormTest, SymbolicTraceBuilds) {
  using codegen::Expr;
  std::vector<Expr> extra, parameters;
  for (int k = 0; k < form().num_extra_inputs; ++k) {
    extra.push_back(Expr::input(desc().validity.extra[k].name, 2 + k));
  }
  for (int i = 0; i < form().num_parameters; ++i) {
    parameters.push_back(Expr::parameter(desc().parameters[i].name, i));
  }
  Expr f;
  ASSERT_NO_THROW(f = form().F_symbolic(Expr::input("phi", 0), Expr::input("re", 1),
                                        extra.empty() ? nullptr : extra.data(),
                                        parameters.empty() ? nullptr : parameters.data()));
  ASSERT_NE(f.node(), nullptr);
  EXPECT_NE(f.node()->op, codegen::Op::kConstant) << "F must depend on its inputs";
}

std::string form_name(const ::testing::TestParamInfo<const LawForm*>& info) {
  return info.param->key();
}

INSTANTIATE_TEST_SUITE_P(LawForms, LawFormTest, ::testing::ValuesIn(all_law_forms()), form_name);

// ---- The registry itself ---------------------------------------------------------------------

TEST(LawRegistry, HoldsTheLiteratureLibrary) {
  for (const char* key :
       {"bvk2007", "bvk2007_poly", "di_felice", "ergun", "gidaspow", "gidaspow_blend",
        "hill_koch_ladd", "hys2010", "rong2013", "schiller_naumann", "syamlal_obrien", "tang2015",
        "tenneti2011", "vdh2004", "vdh2005", "vdh2005_poly", "wen_yu"}) {
    EXPECT_NO_THROW(find_law_form(key)) << key;
  }
  const std::vector<const LawForm*> forms = all_law_forms();
  EXPECT_TRUE(std::is_sorted(forms.begin(), forms.end(), [](const LawForm* a, const LawForm* b) {
    return a->key() < b->key();
  }));
}

TEST(LawRegistry, NativeConventionsAreTheDocumentedOnes) {
  // Total-force laws and their Reynolds numbers (drag_laws.md 0.2, 1.8, 1.12).
  EXPECT_EQ(find_law_form("hill_koch_ladd").convention.force, ForceKind::kTotal);
  EXPECT_EQ(find_law_form("hill_koch_ladd").convention.reynolds,
            ReynoldsDefinition::kSuperficialRadius);
  EXPECT_EQ(find_law_form("tenneti2011").convention.force, ForceKind::kTotal);
  EXPECT_EQ(find_law_form("syamlal_obrien").convention.reynolds,
            ReynoldsDefinition::kInterstitialDiameter);
  for (const char* tfm : {"ergun", "wen_yu", "gidaspow", "gidaspow_blend", "syamlal_obrien"}) {
    EXPECT_EQ(find_law_form(tfm).convention.normalisation, Normalisation::kBetaD2OverMuPhi) << tfm;
    EXPECT_EQ(find_law_form(tfm).convention.tfm_model, TfmModel::kModelA) << tfm;
  }
  EXPECT_FALSE(find_law_form("vdh2005").description.has_inertia);
}

TEST(LawRegistry, UnknownKeyListsTheValidOnes) {
  try {
    find_law_form("no_such_law");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
    EXPECT_NE(std::string(e.what()).find("gidaspow_blend"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace draglab
