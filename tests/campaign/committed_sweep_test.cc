// The committed convergence in d of dense packings at Re 100 (data/datasets/dense_d_sweep_8/,
// from the campaigns of data/campaigns/dense_d_sweep_8/: 8 spheres at phi 0.5 and 0.6, d 32, 48
// and 64, one realization each; and data/datasets/dense_d_sweep/, the 27-sphere packings of the
// same phi): each file is the run of the committed spec it names (the spec hash in its header is
// that spec's), and on 8 spheres the drag converges in d (each refinement moves it less than the
// one before). tests/lbm/committed_dense_sweep_test.cc checks the error model on both. Also the
// committed parts of the standard dataset (data/datasets/standard/): each the run of its spec at
// the rule's resolutions, the dataset built from them, and its Stokes points against a reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
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

namespace draglab {
namespace campaign {
namespace {

// The standard dataset's committed parts (data/campaigns/standard/NAME.toml, run into one
// database and exported to data/datasets/standard/NAME.csv) and the dataset built from them
// (data/datasets/standard/standard.csv; docs/campaigns.md, "A dataset in parts").
const std::vector<Part> kStandardParts = {{"standard", "standard_low"},
                                          {"standard", "standard_re100"},
                                          {"standard", "standard_re300_mid"},
                                          {"standard", "standard_re300_dense"}};
const std::string kStandardDataset = kDatasets + "standard/standard.csv";

TEST(CommittedStandard, EachPartIsTheRunOfItsCommittedSpecAtTheRulesResolutions) {
  for (const Part& part : kStandardParts) {
    SCOPED_TRACE(part.label());
    const CampaignSpec spec = parse_campaign_spec(part.spec());
    std::string hash;
    const std::vector<Unit> units = read_export(part.data(), &hash);
    EXPECT_EQ(hash, sha256_hex(spec.to_json()));
    EXPECT_EQ(static_cast<std::int64_t>(units.size()), spec.unit_count());
    // The resolution rule as coded today still gives each unit's d: a change of the rule would
    // make a resumed part run other units than these.
    for (const Unit& u : units) {
      const std::vector<double> d = spec.point_resolutions(u.phi, u.re);
      EXPECT_NE(std::find(d.begin(), d.end(), u.d), d.end()) << u.phi << " " << u.re << " " << u.d;
    }
  }
}

TEST(CommittedStandard, TheDatasetReimportsToItsIdWithAPointForEveryMeasuredOne) {
  std::ifstream in(kStandardDataset);
  ASSERT_TRUE(in.good()) << kStandardDataset;
  std::string id;
  const std::string key = "# draglab dataset ";
  for (std::string line; std::getline(in, line) && id.empty();) {
    if (line.rfind(key, 0) == 0) id = line.substr(key.size(), 12);
  }
  const Dataset d = read_dataset_csv(kStandardDataset);
  EXPECT_EQ(d.id, id);
  std::set<std::pair<double, double>> measured;
  for (const Part& part : kStandardParts) {
    std::string hash;
    for (const Unit& u : read_export(part.data(), &hash)) {
      if (u.status == "done") measured.insert({u.phi, u.re});
    }
  }
  EXPECT_EQ(d.points.size(), measured.size());
  for (const DatasetPoint& p : d.points) {
    EXPECT_TRUE(measured.count({p.phi, p.re_target})) << p.phi << " " << p.re_target;
    EXPECT_GT(p.F_uncertainty, 0.0);
  }
}

// Stokes flow against van der Hoef et al. (2005), F = 10 phi/(1 - phi)^2 + (1 - phi)^2 (1 +
// 1.5 sqrt(phi)): a fit to their own LB data on random arrays of 54 - 3000 spheres, phi 0.1 -
// 0.6, which it matches within about 3 %. Each point must lie within 3 combined standard
// uncertainties (its own and 3 % of the fit).
TEST(CommittedStandard, StokesPointsAgreeWithVanDerHoef2005) {
  const Dataset d = read_dataset_csv(kStandardDataset);
  int checked = 0;
  for (const DatasetPoint& p : d.points) {
    if (p.re_target != 0.0) continue;
    const double e = 1.0 - p.phi;
    const double reference = 10.0 * p.phi / (e * e) + e * e * (1.0 + 1.5 * std::sqrt(p.phi));
    const double sigma = std::hypot(p.F_uncertainty, 0.03 * reference);
    EXPECT_LT(std::fabs(p.F - reference), 3.0 * sigma)
        << "phi " << p.phi << ": F " << p.F << " +- " << p.F_uncertainty << ", vdH 2005 "
        << reference;
    ++checked;
  }
  EXPECT_EQ(checked, 6);
}

}  // namespace
}  // namespace campaign
}  // namespace draglab
