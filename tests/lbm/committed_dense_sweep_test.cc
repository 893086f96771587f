// The error model against the committed convergence in d of dense packings at Re 100 and 300
// (data/datasets/dense_d_sweep_8/: random phi 0.5 and 0.6, 8 spheres, d 32, 48 and 64, the
// engine's automatic operator; measured by the campaigns of data/campaigns/dense_d_sweep_8/), and
// at Re 100 on the 27-sphere packings of the same phi (data/datasets/dense_d_sweep/).
// Reference per packing: the Richardson value of the two finest d at order 2 (the interpolated
// wall's) where F is monotone in d, and also the value at the order the three d give (the
// extrapolation's spread); the finest run where F is not monotone. Every run that meets the
// resolution rule must have |F / reference - 1| within the discretisation estimate the current
// model gives it (error_model.h), recomputed from the run's record; this sweep is what set the
// model's growth with Re (error_model.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "error_model.h"

namespace draglab {
namespace lbm {
namespace {

const std::string kData8 = std::string(DRAGLAB_DATA_DIR) + "/datasets/dense_d_sweep_8/";
const std::string kData27 = std::string(DRAGLAB_DATA_DIR) + "/datasets/dense_d_sweep/";

/// The result_json of every finished unit of an exported campaign CSV (its last column, quoted
/// with doubled quotes).
std::vector<nlohmann::json> finished_runs(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<nlohmann::json> runs;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line.find(",done,") == std::string::npos) continue;
    const std::size_t open = line.find(",\"{");
    if (open == std::string::npos) continue;
    std::string text = line.substr(open + 2, line.size() - open - 3);
    for (std::size_t at = 0; (at = text.find("\"\"", at)) != std::string::npos; ++at) {
      text.erase(at, 1);
    }
    runs.push_back(nlohmann::json::parse(text));
  }
  return runs;
}

/// Richardson value from resolutions d1 < d2 at order p.
double richardson(double d1, double F1, double d2, double F2, double p) {
  const double r = std::pow(d2 / d1, p);
  return (r * F2 - F1) / (r - 1.0);
}

/// The order p with F(d) = F_inf + C d^-p through three resolutions (ascending), by bisection.
double observed_order(const double d[3], const double F[3]) {
  const double target = (F[0] - F[1]) / (F[1] - F[2]);
  auto ratio = [&](double p) {
    return (std::pow(d[0], -p) - std::pow(d[1], -p)) / (std::pow(d[1], -p) - std::pow(d[2], -p));
  };
  double lo = 0.25, hi = 6.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    ((ratio(lo) - target) * (ratio(mid) - target) <= 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

/// The current model's discretisation estimate for a recorded run (driver.cc builds the same).
double model_estimate(const nlohmann::json& r) {
  ErrorModelInput em;
  em.boundary = Boundary::kInterpolated;
  em.collision = collision_from_string(r.at("collision").get<std::string>());
  em.tau = r.at("tau").get<double>();
  em.wall_corrected = r.at("wall_corrected").get<bool>();
  em.magic = 3.0 / 16.0;  // TRT's, which rr with TRT's wall keeps
  em.d = r.at("d").get<double>();
  em.phi = r.at("phi").get<double>();
  em.re = r.at("re").get<double>();
  em.precision = precision_from_string(r.at("precision").get<std::string>());
  return discretisation_error_estimate(em);
}

/// Checks every resolved run at `re` of the exported `parts` (in folder `data`) against the
/// references of its packing (the file comment); `runs_per_phi` is how many finished runs each
/// packing has. Returns how many (run, reference) pairs were checked.
int check_error_model(const std::string& data, const std::vector<std::string>& parts, double re,
                      const std::map<double, std::size_t>& runs_per_phi) {
  std::map<double, std::vector<nlohmann::json>> by_phi;
  for (const std::string& part : parts) {
    for (const auto& r : finished_runs(data + part + ".csv")) {
      if (std::abs(r.at("re").get<double>() / re - 1.0) < 0.02)
        by_phi[r.at("phi").get<double>()].push_back(r);
    }
  }
  EXPECT_EQ(by_phi.size(), runs_per_phi.size());
  int checked = 0;
  for (auto& [phi, runs] : by_phi) {
    SCOPED_TRACE("phi " + std::to_string(phi) + ", Re " + std::to_string(re));
    const auto expected = runs_per_phi.lower_bound(phi - 1e-9);
    EXPECT_TRUE(expected != runs_per_phi.end() && std::abs(expected->first - phi) < 1e-9);
    if (expected == runs_per_phi.end()) continue;
    EXPECT_EQ(runs.size(), expected->second);
    if (runs.size() != expected->second || runs.size() < 2) continue;  // no reference
    std::sort(runs.begin(), runs.end(),
              [](const auto& a, const auto& b) { return a.at("d") < b.at("d"); });
    // The finest three resolutions (or two).
    std::vector<double> d, F;
    for (std::size_t k = runs.size() >= 3 ? runs.size() - 3 : 0; k < runs.size(); ++k) {
      d.push_back(runs[k].at("d"));
      F.push_back(runs[k].at("F"));
    }
    std::vector<double> references;
    if (d.size() == 2) {
      references.push_back(richardson(d[0], F[0], d[1], F[1], 2.0));
    } else if ((F[0] - F[1]) * (F[1] - F[2]) > 0.0) {
      references.push_back(richardson(d[1], F[1], d[2], F[2], 2.0));
      references.push_back(richardson(d[1], F[1], d[2], F[2], observed_order(d.data(), F.data())));
    } else {
      references.push_back(F[2]);
    }
    for (const auto& r : runs) {
      const double estimate = model_estimate(r);
      // The record's own estimate came from the model of its day (growth 1 + Re/10 before the
      // 8-sphere Re 100 sweep, 1 + Re/7 since); recomputed from the record, a resolved TRT run's
      // is the recorded one or differs only by that growth: a check of the inputs read here.
      const bool resolved = r.at("d").get<double>() >= r.at("resolution_needed").get<double>();
      if (r.at("collision") == "trt" && resolved) {
        const double run_re = r.at("re").get<double>();
        const double floor = r.at("precision") == "float" ? 1e-5 : 0.0;
        const double recorded = r.at("discretisation_error").get<double>();
        const double regrown =
            floor + (recorded - floor) * (1.0 + run_re / 7.0) / (1.0 + run_re / 10.0);
        EXPECT_LT(std::min(std::abs(estimate - recorded), std::abs(estimate - regrown)), 1e-9);
      }
      if (!resolved) continue;
      for (double reference : references) {
        const double error = std::abs(r.at("F").get<double>() / reference - 1.0);
        EXPECT_LE(error, estimate)
            << "d " << r.at("d") << ": F " << r.at("F") << " against " << reference;
        ++checked;
      }
    }
  }
  return checked;
}

TEST(CommittedDenseSweep, TheErrorModelBoundsEveryResolvedRunAtRe100) {
  EXPECT_GE(check_error_model(kData8, {"d32", "d48_re100", "d64"}, 100.0, {{0.5, 3}, {0.6, 3}}), 6);
}

// Re 300: unsteady flow, each F a time mean (its standard error, about 0.1 %, is small beside
// the estimates). phi 0.5 has d 32 (below the boundary-layer bound: not checked), 48 and 64;
// phi 0.6 diverged at d 32, so its reference is the order-2 Richardson value of d 48 and 64 (its
// d 48 run lies below the boundary-layer bound: only d 64 is checked).
TEST(CommittedDenseSweep, TheErrorModelBoundsEveryResolvedRunAtRe300) {
  EXPECT_GE(
      check_error_model(kData8, {"d32", "d48_re300", "d64_re300"}, 300.0, {{0.5, 3}, {0.6, 2}}), 5);
}

// The 27-sphere packings of the same phi at Re 100 (d 32: rr with TRT's wall; d 48: TRT at phi 0.5,
// rr with TRT's wall at phi 0.6): two resolutions, so the reference is their order-2 Richardson
// value; both runs meet the resolution rule at phi 0.5, only d 48 at phi 0.6 (d 32 lies below
// the cell-Reynolds bound of 35.5).
TEST(CommittedDenseSweep, TheErrorModelBoundsEveryResolvedRunOf27SpheresAtRe100) {
  EXPECT_GE(check_error_model(kData27, {"d32", "d48_re100"}, 100.0, {{0.5, 2}, {0.6, 2}}), 3);
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
