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
  // The record names the operator that ran (RunResult::collision), whatever was asked.
  r.collision = Collision::kRegularized;
  const nlohmann::json rr = nlohmann::json::parse(r.ToJson(o));
  EXPECT_EQ(rr["collision"], "rr");
  EXPECT_FALSE(rr.contains("magic"));                // TRT only
  EXPECT_FALSE(rr.contains("collision_requested"));  // named, not chosen
  o.collision = Collision::kAuto;
  r.collision_reason = "kappa Re / d = 30 > 23";
  const nlohmann::json chosen = nlohmann::json::parse(r.ToJson(o));
  EXPECT_EQ(chosen["collision"], "rr");
  EXPECT_EQ(chosen["collision_requested"], "auto");
  EXPECT_EQ(chosen["collision_reason"], r.collision_reason);
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
