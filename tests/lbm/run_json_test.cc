// RunResult::ToJson: the one record of an LBM run (`draglab lbm run --json`, a campaign unit's
// stored result). A run that did not converge has no drag to report: its non-finite values are
// null (JSON has no NaN), never a number.
#include <gtest/gtest.h>

#include <limits>

#include <nlohmann/json.hpp>

#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {
namespace {

TEST(RunResultJson, ScalarsSchemeAndNullForWhatWasNotMeasured) {
  RunResult r;
  r.converged = false;
  r.diagnosis = "Mach number above the limit";
  r.F = std::numeric_limits<double>::quiet_NaN();
  r.re = 4.5;
  r.steps = 1200;
  RunOptions o;
  o.collision = Collision::kTrt;
  o.magic = 3.0 / 16.0;
  const nlohmann::json j = nlohmann::json::parse(r.ToJson(o));
  EXPECT_TRUE(j["F"].is_null());
  EXPECT_FALSE(j["converged"].get<bool>());
  EXPECT_EQ(j["diagnosis"], "Mach number above the limit");
  EXPECT_DOUBLE_EQ(j["re"].get<double>(), 4.5);
  EXPECT_EQ(j["steps"], 1200);
  EXPECT_EQ(j["collision"], to_string(Collision::kTrt));
  EXPECT_DOUBLE_EQ(j["magic"].get<double>(), 3.0 / 16.0);
  EXPECT_TRUE(j["d_hydrodynamic"].is_null());
  o.collision = Collision::kRegularized;
  EXPECT_FALSE(nlohmann::json::parse(r.ToJson(o)).contains("magic"));  // TRT only
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
