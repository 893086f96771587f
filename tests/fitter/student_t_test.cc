// Student t quantile of the fitter's 95 % intervals against tabulated values (NIST e-Handbook,
// data/fitter_student_t.csv) and the closed form of dof = 1 and 2.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "draglab/error.h"
#include "student_t.h"

namespace draglab {
namespace fitter {
namespace {

TEST(StudentT, MatchesNistTable) {
  std::ifstream in(std::string(DRAGLAB_DATA_DIR) + "/fitter_student_t.csv");
  ASSERT_TRUE(in) << "data/fitter_student_t.csv missing";
  std::string line;
  int rows = 0;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::istringstream row(line);
    double p = 0, dof = 0, t = 0;
    char comma;
    row >> p >> comma >> dof >> comma >> t;
    // The table is rounded to three decimals: half a unit in the last place.
    EXPECT_NEAR(student_t_quantile(p, dof), t, 5e-4 + 1e-12) << "p = " << p << ", dof = " << dof;
    ++rows;
  }
  EXPECT_EQ(rows, 13);
}

TEST(StudentT, ClosedFormsForOneAndTwoDof) {
  // dof = 1 (Cauchy): t_p = tan(pi (p - 1/2)); dof = 2: t_p = (2p - 1) sqrt(2 / (4 p (1-p))).
  for (double p : {0.6, 0.9, 0.975, 0.999}) {
    const double pi = std::acos(-1.0);
    EXPECT_NEAR(student_t_quantile(p, 1.0), std::tan(pi * (p - 0.5)),
                1e-9 * std::tan(pi * (p - 0.5)));
    const double t2 = (2 * p - 1) * std::sqrt(2.0 / (4 * p * (1 - p)));
    EXPECT_NEAR(student_t_quantile(p, 2.0), t2, 1e-10 * t2);
    EXPECT_NEAR(student_t_quantile(1.0 - p, 2.0), -t2, 1e-10 * t2);
  }
  // Large dof tends to the normal quantile 1.959964.
  EXPECT_NEAR(student_t_quantile(0.975, 1e6), 1.959964, 1e-5);
}

TEST(StudentT, RejectsBadArguments) {
  EXPECT_THROW(student_t_quantile(0.0, 3), Error);
  EXPECT_THROW(student_t_quantile(1.0, 3), Error);
  EXPECT_THROW(student_t_quantile(0.9, 0), Error);
  EXPECT_THROW(student_t_quantile(0.9, std::nan("")), Error);
}

}  // namespace
}  // namespace fitter
}  // namespace draglab
