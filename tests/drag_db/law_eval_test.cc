// Law (law.h) behaviour for every literature form loaded as its published version:
//   - range policies: 'error' throws kOutOfValidity outside the box, 'clamp' evaluates at the
//     clamped point and 'extrapolate' at the point itself, both counting the event;
//   - physically impossible inputs (NaN, +-inf, phi >= 1, phi < 0, Re < 0, non-finite extra
//     inputs) are an error under every policy and never produce a number;
//   - the array path equals the scalar path bit for bit (fast in-box path and the block path);
//   - the derived quantities (beta, K, C_d) follow the conventions.h identities.
// All comparisons between two evaluations of the same formula are exact (same operations).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"

namespace draglab {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

class LawEvalTest : public ::testing::TestWithParam<const LawForm*> {
 protected:
  const LawForm& form() const { return *GetParam(); }
  const ValidityBox& box() const { return form().description.validity; }
  std::vector<double> extra_inside() const {
    std::vector<double> e;
    for (const ExtraInputSpec& s : box().extra) {
      e.push_back(s.range.contains(1.0) ? 1.0 : 0.5 * (s.range.min + s.range.max));
    }
    return e;
  }
  const double* extra_ptr(const std::vector<double>& e) const {
    return e.empty() ? nullptr : e.data();
  }
  double raw_F(double phi, double re, const std::vector<double>& extra) const {
    const std::vector<double> p = form().default_parameters();
    return form().F(phi, re, extra_ptr(extra), p.data());
  }
  double mid_phi() const { return 0.5 * (box().phi.min + box().phi.max); }
  double mid_re() const { return 0.5 * (box().re.min + box().re.max); }
};

ErrorCode error_code_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::kOk;
}

TEST_P(LawEvalTest, LiteratureRecordLoads) {
  const LawRecord record = literature_record(form());
  EXPECT_EQ(record.form, form().key());
  EXPECT_EQ(record.content_hash.size(), 64u);
  Law law(record);
  EXPECT_EQ(law.range_policy(), RangePolicy::kError);
  const std::vector<double> e = extra_inside();
  EXPECT_EQ(law.F(mid_phi(), mid_re(), extra_ptr(e)), raw_F(mid_phi(), mid_re(), e));
  EXPECT_EQ(law.out_of_range_count(), 0u);
}

TEST_P(LawEvalTest, RangePolicies) {
  Law law(literature_record(form()));
  const std::vector<double> e = extra_inside();
  // A point above the box in Re and (where possible) below it in phi.
  const double re_out = box().re.max * 2.0 + 1.0;
  const double phi_out = box().phi.min > 0.0 ? 0.5 * box().phi.min : box().phi.max + 0.01;
  const double phi_in = mid_phi();

  EXPECT_EQ(error_code_of([&] { law.F(phi_in, re_out, extra_ptr(e)); }), ErrorCode::kOutOfValidity);
  EXPECT_EQ(error_code_of([&] { law.F(phi_out, mid_re(), extra_ptr(e)); }),
            ErrorCode::kOutOfValidity);
  EXPECT_EQ(law.out_of_range_count(), 0u);

  law.set_range_policy(RangePolicy::kClamp);
  EXPECT_EQ(law.F(phi_in, re_out, extra_ptr(e)), raw_F(phi_in, box().re.max, e));
  const double phi_clamped = std::clamp(phi_out, box().phi.min, box().phi.max);
  EXPECT_EQ(law.F(phi_out, mid_re(), extra_ptr(e)), raw_F(phi_clamped, mid_re(), e));
  EXPECT_EQ(law.out_of_range_count(), 2u);

  law.set_range_policy(RangePolicy::kExtrapolate);
  EXPECT_EQ(law.F(phi_in, re_out, extra_ptr(e)), raw_F(phi_in, re_out, e));
  EXPECT_EQ(law.F(phi_out, mid_re(), extra_ptr(e)), raw_F(phi_out, mid_re(), e));
  EXPECT_EQ(law.out_of_range_count(), 4u);

  // Inside the box nothing is counted.
  EXPECT_EQ(law.F(phi_in, mid_re(), extra_ptr(e)), raw_F(phi_in, mid_re(), e));
  EXPECT_EQ(law.out_of_range_count(), 4u);

  // Extra inputs are range-checked too.
  for (std::size_t k = 0; k < e.size(); ++k) {
    std::vector<double> outside = e;
    outside[k] = box().extra[k].range.max * 2.0;
    law.set_range_policy(RangePolicy::kError);
    EXPECT_EQ(error_code_of([&] { law.F(phi_in, mid_re(), outside.data()); }),
              ErrorCode::kOutOfValidity);
    law.set_range_policy(RangePolicy::kClamp);
    std::vector<double> clamped = outside;
    clamped[k] = box().extra[k].range.max;
    EXPECT_EQ(law.F(phi_in, mid_re(), outside.data()), raw_F(phi_in, mid_re(), clamped));
  }
}

TEST_P(LawEvalTest, ImpossibleInputsAreAlwaysAnError) {
  const std::vector<double> e = extra_inside();
  for (RangePolicy policy : {RangePolicy::kError, RangePolicy::kClamp, RangePolicy::kExtrapolate}) {
    Law law(literature_record(form()), policy);
    const double re = mid_re(), phi = mid_phi();
    for (double bad_phi : {kNaN, kInf, -kInf, 1.0, 1.5, -0.1, -1e-300}) {
      EXPECT_EQ(error_code_of([&] { law.F(bad_phi, re, extra_ptr(e)); }),
                ErrorCode::kInvalidArgument)
          << "phi=" << bad_phi << " policy " << to_string(policy);
    }
    for (double bad_re : {kNaN, kInf, -kInf, -1.0, -1e-300}) {
      EXPECT_EQ(error_code_of([&] { law.F(phi, bad_re, extra_ptr(e)); }),
                ErrorCode::kInvalidArgument)
          << "Re=" << bad_re << " policy " << to_string(policy);
    }
    for (std::size_t k = 0; k < e.size(); ++k) {
      for (double bad : {kNaN, kInf}) {
        std::vector<double> x = e;
        x[k] = bad;
        EXPECT_EQ(error_code_of([&] { law.F(phi, re, x.data()); }), ErrorCode::kInvalidArgument);
      }
    }
    if (!e.empty()) {
      EXPECT_EQ(error_code_of([&] { law.F(phi, re, nullptr); }), ErrorCode::kInvalidArgument);
    }
    // Array path: the first bad index is reported and nothing is returned as a number.
    std::vector<double> phis = {phi, phi, kNaN, phi};
    std::vector<double> res = {re, re, re, re};
    std::vector<double> extras;
    for (int i = 0; i < 4; ++i) extras.insert(extras.end(), e.begin(), e.end());
    std::vector<double> out(4);
    try {
      law.F(4, phis.data(), res.data(), out.data(), extra_ptr(extras));
      ADD_FAILURE() << "NaN in an array was accepted";
    } catch (const Error& error) {
      EXPECT_EQ(error.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(error.what()).find("index 2"), std::string::npos) << error.what();
    }
  }
}

TEST_P(LawEvalTest, ArrayPathEqualsScalarPathBitForBit) {
  const std::vector<double> e = extra_inside();
  for (RangePolicy policy : {RangePolicy::kError, RangePolicy::kClamp, RangePolicy::kExtrapolate}) {
    Law law(literature_record(form()), policy);
    std::vector<double> phis, res, extras;
    // Inside the box (fast path when the form has no extra inputs)...
    for (double fp : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      for (double fr : {0.0, 1e-6, 0.01, 0.4, 1.0}) {
        phis.push_back(box().phi.min + fp * (box().phi.max - box().phi.min));
        res.push_back(box().re.min + fr * (box().re.max - box().re.min));
        extras.insert(extras.end(), e.begin(), e.end());
      }
    }
    std::vector<double> out(phis.size());
    law.F(phis.size(), phis.data(), res.data(), out.data(), extra_ptr(extras));
    for (std::size_t i = 0; i < phis.size(); ++i) {
      EXPECT_EQ(out[i], law.F(phis[i], res[i], extra_ptr(e))) << i;
    }
    if (policy == RangePolicy::kError) continue;
    // ... and with points outside it (block path with the policy applied), over 300 points so
    // that more than one block is used.
    phis.clear();
    res.clear();
    extras.clear();
    for (int i = 0; i < 300; ++i) {
      phis.push_back(0.002 * i);                      // 0 .. 0.598
      res.push_back(i % 7 == 0 ? 0.0 : 3.1 * i * i);  // 0 .. 2.8e5
      extras.insert(extras.end(), e.begin(), e.end());
    }
    out.assign(phis.size(), 0.0);
    law.F(phis.size(), phis.data(), res.data(), out.data(), extra_ptr(extras));
    for (std::size_t i = 0; i < phis.size(); ++i) {
      EXPECT_EQ(out[i], law.F(phis[i], res[i], extra_ptr(e))) << i;
    }
  }
}

TEST_P(LawEvalTest, DerivedQuantitiesFollowTheConventions) {
  Law law(literature_record(form()));
  const std::vector<double> e = extra_inside();
  const double phi = mid_phi(), re = 0.75 * box().re.max;  // Re > 0 for C_d
  const double F = law.F(phi, re, extra_ptr(e));
  EXPECT_EQ(law.beta_d2_over_mu(phi, re, extra_ptr(e)), conventions::beta_d2_over_mu(phi, F));
  EXPECT_EQ(law.K(phi, re, extra_ptr(e)), conventions::total_force_K(phi, F));
  EXPECT_EQ(law.drag_coefficient(phi, re, extra_ptr(e)), conventions::drag_coefficient(phi, re, F));
  EXPECT_EQ(error_code_of([&] { law.drag_coefficient(phi, 0.0, extra_ptr(e)); }),
            ErrorCode::kInvalidArgument);
  // beta from dimensional inputs: air-like gas, 0.5 mm particles, slip chosen to give Re.
  const double mu = 1.8e-5, rho = 1.2, d = 5e-4, eps = 1.0 - phi;
  const double slip = re * mu / (rho * eps * d);
  const double beta = law.beta(eps, mu, rho, slip, d, extra_ptr(e));
  const double expected = 18.0 * mu * phi * eps *
                          law.F(phi, conventions::reynolds(eps, mu, rho, slip, d), extra_ptr(e)) /
                          (d * d);
  EXPECT_NEAR(beta, expected, 1e-14 * expected);
}

std::string form_name(const ::testing::TestParamInfo<const LawForm*>& info) {
  return info.param->key();
}

INSTANTIATE_TEST_SUITE_P(LawEval, LawEvalTest, ::testing::ValuesIn(all_law_forms()), form_name);

}  // namespace
}  // namespace draglab
