// The progress line's ETA (cli/progress.h): a job reported as one fraction of the whole with a
// changing stage text (the DPM scene: "settle: KE = ...", then "flow: ...") must extrapolate from
// the job's start; a job reported per stage (fraction back to 0) restarts the extrapolation.
// Reference: a job that runs at a constant rate r finishes (1 - f) / r after the report at f; a
// job whose rate drops finishes at its new rate.
#include <gtest/gtest.h>

#include "cli/progress.h"

namespace draglab {
namespace cli {
namespace {

TEST(EtaEstimate, ConstantRateOverTheWholeJobIsExtrapolatedExactly) {
  EtaEstimate eta;
  const double rate = 0.01;               // fraction per second: a 100 s job
  EXPECT_LT(eta.Observe(0.0, 0.0), 0.0);  // nothing done yet: unknown
  for (double t : {10.0, 40.0, 75.0}) {
    EXPECT_NEAR(eta.Observe(rate * t, t), 100.0 - t, 1e-9) << "at t = " << t;
  }
  EXPECT_LT(eta.Observe(1.0, 100.0), 0.0);  // finished
}

TEST(EtaEstimate, JobThatStartsPartlyDoneCountsOnlyTheWorkSinceItsFirstReport) {
  EtaEstimate eta;
  eta.Observe(0.5, 0.0);  // e.g. a resumed campaign
  EXPECT_NEAR(eta.Observe(0.6, 10.0), 40.0, 1e-9);
}

TEST(EtaEstimate, FractionThatDropsStartsANewPass) {
  EtaEstimate eta;
  eta.Observe(0.0, 0.0);
  EXPECT_NEAR(eta.Observe(0.9, 90.0), 10.0, 1e-9);  // stage 1 at 0.01 per s
  eta.Observe(0.0, 100.0);                          // stage 2 starts from 0, 4x slower
  EXPECT_NEAR(eta.Observe(0.1, 140.0), 360.0, 1e-9);
}

TEST(EtaEstimate, JobThatSlowsDownIsEstimatedAtItsRecentRateAndSaysSo) {
  // 0.01 per s for 80 s, then 0.001 per s: at t = 100 (f = 0.82) the job needs 180 s more; the
  // average rate (0.0082 per s) would promise 22 s.
  EtaEstimate eta;
  for (int t = 0; t <= 80; ++t) eta.Observe(0.01 * t, t);
  double last = -1.0;
  for (int t = 81; t <= 100; ++t) last = eta.Observe(0.8 + 0.001 * (t - 80), t);
  EXPECT_NEAR(last, 180.0, 1e-6);
  EXPECT_EQ(eta.trend(), EtaEstimate::Trend::kSlowing);
}

TEST(EtaEstimate, JobWithoutRecentProgressHasNoEstimate) {
  EtaEstimate eta;
  for (int t = 0; t <= 50; ++t) eta.Observe(0.01 * t, t);
  double last = 0.0;
  for (int t = 51; t <= 70; ++t) last = eta.Observe(0.5, t);
  EXPECT_LT(last, 0.0);
  EXPECT_EQ(eta.trend(), EtaEstimate::Trend::kStalled);
}

TEST(EtaEstimate, TooLittleProgressGivesNoEstimate) {
  EtaEstimate eta;
  eta.Observe(0.0, 0.0);
  EXPECT_LT(eta.Observe(0.004, 30.0), 0.0);
  EXPECT_GT(eta.Observe(0.02, 60.0), 0.0);
}

}  // namespace
}  // namespace cli
}  // namespace draglab
