// The committed convergence in d of dense packings at Re 100 (data/datasets/dense_d_sweep_8/,
// from the campaigns of data/campaigns/dense_d_sweep_8/: 8 spheres at phi 0.5 and 0.6, d 32, 48
// and 64, one realization each; and data/datasets/dense_d_sweep/, the 27-sphere packings of the
// same phi): each file is the run of the committed spec it names (the spec hash in its header is
// that spec's), and on 8 spheres the drag converges in d (each refinement moves it less than the
// one before). tests/lbm/committed_dense_sweep_test.cc checks the error model on both.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/lbm/lbm.h"
#include "draglab/lbm/resolution.h"

namespace draglab {
namespace campaign {
namespace {

const std::string kCampaigns = std::string(DRAGLAB_DATA_DIR) + "/campaigns/";
const std::string kDatasets = std::string(DRAGLAB_DATA_DIR) + "/datasets/";

struct Unit {
  double phi = 0, re = 0, d = 0, F = NAN, estimate = NAN, steps = NAN;
  std::string status;
};

/// Splits one CSV line; quoted fields (result_json) may hold commas and doubled quotes.
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

/// The units of an exported campaign file and the spec hash its header names.
std::vector<Unit> read_export(const std::string& path, std::string* spec_hash) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<Unit> units;
  std::vector<std::string> columns;
  const std::string hash_key = "# Spec hash (SHA-256 of the canonical spec): ";
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(hash_key, 0) == 0) *spec_hash = line.substr(hash_key.size());
    if (line.empty() || line[0] == '#') continue;
    if (columns.empty()) {
      columns = split_csv(line);
      continue;
    }
    const std::vector<std::string> f = split_csv(line);
    EXPECT_EQ(f.size(), columns.size()) << path;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < columns.size() && i < f.size(); ++i) row[columns[i]] = f[i];
    Unit u;
    u.phi = std::stod(row["phi"]);
    u.re = std::stod(row["re_target"]);
    u.d = std::stod(row["resolution"]);
    u.status = row["status"];
    if (u.status == "done") {
      u.F = std::stod(row["F"]);
      u.estimate = std::stod(row["error_estimate"]);
      u.steps = std::stod(row["steps"]);
    }
    units.push_back(u);
  }
  return units;
}

/// One committed part: folder (under data/campaigns/ and data/datasets/) and name.
struct Part {
  std::string folder, name;
  std::string spec() const { return kCampaigns + folder + "/" + name + ".toml"; }
  std::string data() const { return kDatasets + folder + "/" + name + ".csv"; }
  std::string label() const { return folder + "/" + name; }
};
const std::vector<Part> kParts8 = {{"dense_d_sweep_8", "d32"},
                                   {"dense_d_sweep_8", "d48_re100"},
                                   {"dense_d_sweep_8", "d48_re300"},
                                   {"dense_d_sweep_8", "d64"},
                                   {"dense_d_sweep_8", "d64_re300"}};
const std::vector<Part> kParts27 = {{"dense_d_sweep", "d32"}, {"dense_d_sweep", "d48_re100"}};

std::vector<Part> all_parts() {
  std::vector<Part> parts = kParts8;
  parts.insert(parts.end(), kParts27.begin(), kParts27.end());
  return parts;
}

TEST(CommittedDenseSweep, EachFileIsTheRunOfItsCommittedSpec) {
  for (const Part& part : all_parts()) {
    SCOPED_TRACE(part.label());
    const CampaignSpec spec = parse_campaign_spec(part.spec());
    std::string hash;
    const std::vector<Unit> units = read_export(part.data(), &hash);
    EXPECT_EQ(hash, sha256_hex(spec.to_json()));
    EXPECT_EQ(units.size(), spec.phi.size() * spec.re.size() * spec.resolutions.size());
    for (const Unit& u : units) {
      EXPECT_EQ(u.d, spec.resolutions.front());
      if (u.status == "done") {
        EXPECT_TRUE(std::isfinite(u.F) && u.F > 0.0);
        EXPECT_TRUE(std::isfinite(u.estimate) && u.estimate > 0.0);
      }
    }
  }
}

TEST(CommittedDenseSweep, EachRefinementMovesTheDragLessThanTheOneBefore) {
  std::map<double, std::vector<Unit>> at_re100;  // phi -> runs
  for (const Part& part : kParts8) {
    std::string hash;
    for (const Unit& u : read_export(part.data(), &hash)) {
      if (u.status == "done" && u.re == 100.0) at_re100[u.phi].push_back(u);
    }
  }
  ASSERT_EQ(at_re100.size(), 2u);
  for (auto& [phi, runs] : at_re100) {
    SCOPED_TRACE("phi " + std::to_string(phi));
    ASSERT_EQ(runs.size(), 3u) << "d 32, 48 and 64";
    std::sort(runs.begin(), runs.end(), [](const Unit& a, const Unit& b) { return a.d < b.d; });
    EXPECT_LT(std::fabs(runs[2].F - runs[1].F), std::fabs(runs[1].F - runs[0].F));
  }
}

// `campaign plan`'s step model (lbm::predicted_steps) against what these runs took: steady at
// Re 100, time-averaged at Re 300 (expects_unsteady_flow). Without the average in the model the
// Re 300 units took 6 - 9 times the prediction. The factor 3 is the model's stated reach (the
// 60 calibration units at Re <= 25 lay within 2.6).
TEST(CommittedDenseSweep, ThePlansStepModelPredictsEveryRunWithinAFactorThree) {
  for (const Part& part : all_parts()) {
    const CampaignSpec spec = parse_campaign_spec(part.spec());
    std::string hash;
    for (const Unit& u : read_export(part.data(), &hash)) {
      if (u.status != "done") continue;
      SCOPED_TRACE(part.label() + ": phi " + std::to_string(u.phi) + ", Re " +
                   std::to_string(u.re));
      EXPECT_EQ(lbm::expects_unsteady_flow(u.phi, u.re), u.re == 300.0);
      const double predicted =
          lbm::predicted_steps(u.phi, u.re, u.d, lbm::collision_from_string(spec.collision));
      EXPECT_LT(u.steps / predicted, 3.0) << u.steps << " steps, predicted " << predicted;
      EXPECT_GT(u.steps / predicted, 1.0 / 3.0) << u.steps << " steps, predicted " << predicted;
    }
  }
}

}  // namespace
}  // namespace campaign
}  // namespace draglab
