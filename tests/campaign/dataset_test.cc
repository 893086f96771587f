// Resolution extrapolation on synthetic F(d) with known limits, and build_dataset on unit rows
// with known values (realization mean, standard error, pairing, skipped points, stable hash).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "campaign_internal.h"
#include "campaign_test_util.h"
#include "db/sqlite_util.h"
#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"

namespace draglab {
namespace campaign {
namespace {

using internal::extrapolate_inverse_d;
using internal::extrapolate_richardson;

TEST(Extrapolation, RichardsonRecoversSecondOrderOnUnevenResolutions) {
  // F(d) = F_inf (1 + c/d^2): the interpolated bounce-back's asymptotic form. The three finest
  // resolutions (12, 16, 24: ratios 4/3 and 3/2) determine p exactly, so p and F_inf must come
  // back to bisection precision (1e-12 in p), far below 1e-9.
  const double F_inf = 7.25, c = -3.0;
  std::vector<double> d = {24, 8, 16, 12}, F;  // unsorted on purpose
  for (double x : d) F.push_back(F_inf * (1.0 + c / (x * x)));
  const auto e = extrapolate_richardson(d, F);
  EXPECT_EQ(e.method, "richardson");
  EXPECT_NEAR(e.order, 2.0, 1e-9);
  EXPECT_NEAR(e.F_inf, F_inf, 1e-9 * F_inf);
  EXPECT_NEAR(e.discretisation_error, std::fabs(F_inf * c / (24.0 * 24.0)), 1e-9);
  EXPECT_TRUE(e.note.empty());
}

TEST(Extrapolation, RichardsonRecoversFirstOrder) {
  std::vector<double> d = {10, 14, 20}, F;
  for (double x : d) F.push_back(4.0 + 6.0 / x);
  const auto e = extrapolate_richardson(d, F);
  EXPECT_NEAR(e.order, 1.0, 1e-9);
  EXPECT_NEAR(e.F_inf, 4.0, 1e-9);
}

TEST(Extrapolation, InverseDIsExactForItsModelAndLeastSquaresOtherwise) {
  std::vector<double> d = {8, 12, 16}, F;
  for (double x : d) F.push_back(3.5 + 2.0 / x);
  auto e = extrapolate_inverse_d(d, F);
  EXPECT_EQ(e.method, "inverse_d");
  EXPECT_NEAR(e.F_inf, 3.5, 1e-12);
  EXPECT_DOUBLE_EQ(e.order, 1.0);
  EXPECT_NEAR(e.discretisation_error, 2.0 / 16.0, 1e-12);
  // Two points: the line through them (hand calculation: F_inf = (16*F16 - 8*F8)/8).
  e = extrapolate_inverse_d({8, 16}, {4.0, 3.0});
  EXPECT_NEAR(e.F_inf, (16 * 3.0 - 8 * 4.0) / 8.0, 1e-12);
}

TEST(Extrapolation, RichardsonFallsBackWithANote) {
  // Two resolutions: inverse_d.
  auto e = extrapolate_richardson({8, 16}, {4.0, 3.0});
  EXPECT_EQ(e.method, "inverse_d");
  EXPECT_NE(e.note.find("2 resolutions"), std::string::npos);
  // Non-monotone (noise larger than the discretisation error): inverse_d, said so.
  e = extrapolate_richardson({8, 12, 16}, {4.0, 3.0, 3.5});
  EXPECT_EQ(e.method, "inverse_d");
  EXPECT_NE(e.note.find("not monotone"), std::string::npos) << e.note;
  // One resolution: the value itself.
  e = extrapolate_inverse_d({8}, {4.0});
  EXPECT_EQ(e.method, "finest");
  EXPECT_DOUBLE_EQ(e.F_inf, 4.0);
}

/// A database with a campaign whose unit rows are written by hand (no LBM): F known exactly.
class SyntheticCampaign : public ::testing::Test {
 protected:
  void SetUp() override {
    db_path_ = dir_.file("synthetic.db");
    DatabaseOptions o;
    o.seed_literature = false;
    db_ = std::make_unique<Database>(db_path_, o);
    spec_.name = "synthetic";
    spec_.phi = {0.1, 0.2};
    spec_.re = {0.0};
    spec_.realizations = 2;
    spec_.resolutions = {8, 12, 16};
    spec_.extrapolation = "richardson";
    db::Statement c(db_->handle(),
                    "INSERT INTO campaigns (name, spec_json, spec_hash, created_at, code_version) "
                    "VALUES (?, ?, 'h', 't', 'v')");
    c.bind(1, spec_.name).bind(2, spec_.to_json()).run();
    campaign_id_ = sqlite3_last_insert_rowid(db_->handle());
  }
  /// Inserts a unit and finishes it as done (F) or failed (F NaN).
  void unit(int phi_index, int realization, int resolution_index, double F) {
    db::Statement s(db_->handle(),
                    "INSERT INTO campaign_units (campaign_id, phi_index, re_index, realization, "
                    "resolution_index, phi, re_target, resolution, seed, status, F, re, "
                    "error_estimate, wall_s, converged, diagnosis, result_json) VALUES (?, ?, 0, "
                    "?, ?, ?, 0, ?, 1, ?, ?, 0, 0.01, 1.0, ?, ?, ?)");
    const bool done = std::isfinite(F);
    s.bind(1, campaign_id_).bind(2, phi_index).bind(3, realization).bind(4, resolution_index);
    s.bind(5, spec_.phi[phi_index]).bind(6, spec_.resolutions[resolution_index]);
    s.bind(7, done ? "done" : "failed");
    if (done) {
      s.bind(8, F);
    } else {
      s.bind_null(8);
    }
    s.bind(9, done ? 1 : 0).bind(10, done ? "" : "Mach number above the limit");
    s.bind(11, "{\"F_standard_error\": 0.05}");
    s.run();
  }
  campaign_test::TempDir dir_;
  std::string db_path_;
  std::unique_ptr<Database> db_;
  CampaignSpec spec_;
  std::int64_t campaign_id_ = 0;
};

TEST_F(SyntheticCampaign, MeansStandardErrorsAndRichardson) {
  // phi index 0: realizations with F_inf 5.0 and 5.4, both with F(d) = F_inf (1 + 2/d^2).
  const double F_inf[2] = {5.0, 5.4};
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < 3; ++k) {
      const double d = spec_.resolutions[k];
      unit(0, r, k, F_inf[r] * (1.0 + 2.0 / (d * d)));
    }
  }
  // phi index 1: every unit failed -> skipped, named.
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < 3; ++k) unit(1, r, k, NAN);
  }
  std::vector<std::string> skipped;
  const Dataset d = build_dataset(*db_, campaign_id_, &skipped);
  ASSERT_EQ(d.points.size(), 1u);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("phi = 0.2"), std::string::npos) << skipped[0];
  EXPECT_NE(skipped[0].find("Mach"), std::string::npos) << skipped[0];
  const DatasetPoint& p = d.points[0];
  EXPECT_EQ(p.extrapolation, "richardson");
  EXPECT_NEAR(p.order, 2.0, 1e-8);
  EXPECT_NEAR(p.F, 5.2, 1e-9);  // mean of the limits: the extrapolation is linear in F
  EXPECT_EQ(p.realizations, 2);
  // Standard error over 2 realizations at d = 16: |F1 - F2|/2, scaled by F_inf/F(16).
  const double scale = 1.0 + 2.0 / 256.0;
  const double se_finest = std::fabs(5.4 - 5.0) * scale / 2.0;
  EXPECT_NEAR(p.F_standard_error, se_finest / scale, 1e-12);
  EXPECT_NEAR(p.F_discretisation_error, 5.2 * 2.0 / 256.0, 1e-9);
  EXPECT_NEAR(p.F_uncertainty, std::hypot(p.F_standard_error, p.F_discretisation_error), 1e-12);
  EXPECT_EQ(p.F_at_resolution.size(), 3u);
  EXPECT_DOUBLE_EQ(p.wall_s, 6.0);
  // The same campaign built twice is the same dataset (content hash identity).
  const Dataset again = build_dataset(*db_, campaign_id_);
  EXPECT_EQ(again.id, d.id);
  EXPECT_EQ(again.hash, d.hash);
  EXPECT_EQ(dataset_hash(again.points), d.hash);
  campaign_test::RawDb raw(db_path_);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM datasets"), 1);
}

TEST_F(SyntheticCampaign, UnpairedRealizationsDropTheCoarseResolution) {
  // Realization 1 failed at d = 8 only: pairing keeps d = 12, 16 for both realizations, and
  // with 2 resolutions richardson falls back to inverse_d.
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < 3; ++k) {
      const double d = spec_.resolutions[k];
      unit(0, r, k, (r == 1 && k == 0) ? NAN : 4.0 + 1.0 / d);
    }
  }
  const Dataset d = build_dataset(*db_, campaign_id_);
  ASSERT_EQ(d.points.size(), 1u);
  EXPECT_EQ(d.points[0].resolutions, (std::vector<double>{12, 16}));
  EXPECT_EQ(d.points[0].extrapolation, "inverse_d");
  EXPECT_NEAR(d.points[0].F, 4.0, 1e-12);
  EXPECT_NE(d.method.find("resolution(s) left out"), std::string::npos) << d.method;
}

TEST_F(SyntheticCampaign, NoConvergedUnitIsAnError) {
  unit(0, 0, 0, NAN);
  try {
    build_dataset(*db_, campaign_id_);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("no (phi, Re) point with a converged unit"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace campaign
}  // namespace draglab

namespace draglab {
namespace campaign {
namespace {

/// export_units: every column of every unit, ordered by (phi, Re, realization, resolution);
/// CSV numbers read back to the same double; a failed unit's F is null.
TEST_F(SyntheticCampaign, ExportHoldsEveryUnitInOrderAtFullPrecision) {
  const double F = 1.0 / 3.0;
  unit(1, 0, 0, F);
  unit(0, 1, 2, std::nan(""));  // failed
  unit(0, 0, 1, 2.0 * F);
  const UnitsExport e = export_units(*db_, campaign_id_);
  EXPECT_EQ(e.count, 3u);
  const nlohmann::json units = nlohmann::json::parse(e.json);
  ASSERT_EQ(units.size(), 3u);
  EXPECT_EQ(units[0]["phi_index"], 0);
  EXPECT_EQ(units[0]["realization"], 0);
  EXPECT_EQ(units[1]["realization"], 1);
  EXPECT_EQ(units[2]["phi_index"], 1);
  EXPECT_EQ(units[0]["F"].get<double>(), 2.0 * F);
  EXPECT_TRUE(units[1]["F"].is_null());
  EXPECT_DOUBLE_EQ(units[0]["result_json"]["F_standard_error"].get<double>(), 0.05);
  std::istringstream csv(e.csv);
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_NE(header.find("phi_index"), std::string::npos);
  EXPECT_NE(header.find(",F,"), std::string::npos);
  int lines = 0;
  for (std::string l; std::getline(csv, l);) ++lines;
  EXPECT_EQ(lines, 2);
  char full[32];
  std::snprintf(full, sizeof full, "%.17g", 2.0 * F);
  EXPECT_NE(first.find(full), std::string::npos) << first;
  EXPECT_EQ(std::strtod(full, nullptr), 2.0 * F);
  EXPECT_EQ(export_units(*db_, campaign_id_ + 1).count, 0u);  // another campaign: nothing
}

}  // namespace
}  // namespace campaign
}  // namespace draglab

namespace draglab {
namespace campaign {
namespace {

/// Campaigns that are parts of one grid (slices of phi), with unit rows written by hand.
class DatasetParts : public ::testing::Test {
 protected:
  void SetUp() override {
    db_path_ = dir_.file("parts.db");
    DatabaseOptions o;
    o.seed_literature = false;
    db_ = std::make_unique<Database>(db_path_, o);
  }
  static CampaignSpec slice(const std::string& name, std::vector<double> phi) {
    CampaignSpec s;
    s.name = name;
    s.phi = std::move(phi);
    s.re = {0.0};
    s.realizations = 2;
    s.resolutions = {8, 16};
    s.extrapolation = "inverse_d";
    return s;
  }
  std::int64_t add(const CampaignSpec& spec) {
    db::Statement c(db_->handle(),
                    "INSERT INTO campaigns (name, spec_json, spec_hash, created_at, code_version) "
                    "VALUES (?, ?, ?, 't', 'v')");
    c.bind(1, spec.name).bind(2, spec.to_json()).bind(3, "hash-" + spec.name).run();
    return sqlite3_last_insert_rowid(db_->handle());
  }
  /// Every unit of `spec` done, F(d) = F_inf(phi) (1 + 1/d) + 0.1 realization, by `version`.
  void finish(std::int64_t id, const CampaignSpec& spec, const std::string& version) {
    for (std::size_t i = 0; i < spec.phi.size(); ++i) {
      for (int r = 0; r < spec.realizations; ++r) {
        for (std::size_t k = 0; k < spec.resolutions.size(); ++k) {
          const double d = spec.resolutions[k];
          db::Statement s(
              db_->handle(),
              "INSERT INTO campaign_units (campaign_id, phi_index, re_index, "
              "realization, resolution_index, phi, re_target, resolution, seed, status, "
              "F, re, error_estimate, wall_s, converged, code_version, claimed_by) "
              "VALUES (?, ?, 0, ?, ?, ?, 0, ?, 1, 'done', ?, 0, 0.01, 2.0, 1, ?, "
              "'host-a:12:0')");
          s.bind(1, id).bind(2, static_cast<int>(i)).bind(3, r).bind(4, static_cast<int>(k));
          s.bind(5, spec.phi[i]).bind(6, d);
          s.bind(7, (10.0 * spec.phi[i] + 0.1 * r) * (1.0 + 1.0 / d));
          s.bind(8, version);
          s.run();
        }
      }
    }
  }
  /// The message of the Error(kInvalidArgument) that building from `ids` throws ("" if none).
  std::string refusal(const std::vector<std::int64_t>& ids, const BuildDatasetOptions& o) {
    try {
      build_dataset(*db_, ids, o);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
      return e.what();
    }
    return "";
  }
  campaign_test::TempDir dir_;
  std::string db_path_;
  std::unique_ptr<Database> db_;
};

TEST_F(DatasetParts, PartsMakeTheDatasetOneCampaignOfTheWholeGridMakes) {
  const CampaignSpec whole = slice("whole", {0.1, 0.2, 0.3});
  const CampaignSpec low = slice("low", {0.1, 0.2}), high = slice("high", {0.3});
  const std::int64_t w = add(whole), a = add(low), b = add(high);
  finish(w, whole, "1.0 (abc)");
  finish(a, low, "1.0 (abc)");
  finish(b, high, "1.0 (abc)");
  BuildDatasetOptions o;
  o.name = "standard";
  const Dataset parts = build_dataset(*db_, {b, a}, o);
  // Parts in either order, or the whole grid in one campaign: the same points, so the same
  // dataset (its hash covers the points; the stored one is returned).
  EXPECT_EQ(build_dataset(*db_, {a, b}, o).hash, parts.hash);
  EXPECT_EQ(build_dataset(*db_, w).id, parts.id);
  ASSERT_EQ(parts.points.size(), 3u);
  EXPECT_EQ(parts.points[0].phi, 0.1);
  EXPECT_EQ(parts.points[2].phi, 0.3);
  // inverse_d through F_inf (1 + 1/d) at d 8, 16: the mean limit 10 phi + 0.05.
  EXPECT_NEAR(parts.points[1].F, 2.05, 1e-12);
  // The provenance of each part: campaign, spec hash, versions, hosts, time, units.
  const nlohmann::json method = nlohmann::json::parse(parts.method);
  ASSERT_EQ(method.at("parts").size(), 2u);
  EXPECT_EQ(method["parts"][0]["campaign"], "high");
  EXPECT_EQ(method["parts"][0]["spec_hash"], "hash-high");
  EXPECT_EQ(method["parts"][1]["code_versions"], nlohmann::json::array({"1.0 (abc)"}));
  EXPECT_EQ(method["parts"][1]["hosts"], nlohmann::json::array({"host-a"}));
  EXPECT_DOUBLE_EQ(method["parts"][1]["unit_seconds"].get<double>(), 2 * 2 * 2 * 2.0);
  EXPECT_EQ(method.at("units_done"), 12);
  EXPECT_FALSE(method.contains("mixed_code_versions"));
}

TEST_F(DatasetParts, APointInTwoPartsAnotherSpecOrAnotherCodeVersionIsNamed) {
  BuildDatasetOptions o;
  o.name = "standard";
  const CampaignSpec low = slice("low", {0.1, 0.2}), again = slice("again", {0.2, 0.3});
  const std::int64_t a = add(low), b = add(again);
  finish(a, low, "1.0 (abc)");
  finish(b, again, "1.0 (abc)");
  std::string m = refusal({a, b}, o);
  EXPECT_NE(m.find("phi = 0.2, Re = 0 is in two parts, campaigns 'low' and 'again'"),
            std::string::npos)
      << m;
  // Other packings (another seed) or another operator: not the same grid, the key named.
  CampaignSpec reseeded = slice("reseeded", {0.3});
  reseeded.seed = 27;
  const std::int64_t c = add(reseeded);
  finish(c, reseeded, "1.0 (abc)");
  m = refusal({a, c}, o);
  EXPECT_NE(m.find("'reseeded' is not a part of the same grid as 'low': [grid] seed is 27"),
            std::string::npos)
      << m;
  CampaignSpec other_operator = slice("bgk", {0.35});
  other_operator.collision = "bgk";
  const std::int64_t g = add(other_operator);
  finish(g, other_operator, "1.0 (abc)");
  m = refusal({a, g}, o);
  EXPECT_NE(m.find("[lbm] collision is \"bgk\" there and \"auto\" in 'low'"), std::string::npos)
      << m;
  // Another resolution budget, box, realizations or step limit is a slice's own choice (each
  // part's box is recorded).
  CampaignSpec finer = slice("finer", {0.4});
  finer.resolutions = {12, 24};
  finer.realizations = 3;
  finer.max_steps = 7;
  finer.spheres = 27;
  const std::int64_t f = add(finer);
  finish(f, finer, "1.0 (abc)");
  EXPECT_EQ(refusal({a, f}, o), "");
  const nlohmann::json boxes = nlohmann::json::parse(build_dataset(*db_, {a, f}, o).method);
  EXPECT_EQ(boxes["parts"][0]["spheres"], 16);
  EXPECT_EQ(boxes["parts"][1]["spheres"], 27);
  // Units of another code version: named, unless the mix is allowed (and then recorded).
  const CampaignSpec later = slice("later", {0.5});
  const std::int64_t l = add(later);
  finish(l, later, "1.1 (def)");
  m = refusal({a, l}, o);
  EXPECT_NE(m.find("2 code versions ('low': 1.0 (abc); 'later': 1.1 (def))"), std::string::npos)
      << m;
  o.allow_mixed_code = true;
  const Dataset mixed = build_dataset(*db_, {a, l}, o);
  EXPECT_EQ(nlohmann::json::parse(mixed.method).at("mixed_code_versions"),
            nlohmann::json::array({"1.0 (abc)", "1.1 (def)"}));
  // Several campaigns need a name; none is not a dataset.
  EXPECT_NE(refusal({a, f}, BuildDatasetOptions()).find("needs a name"), std::string::npos);
  EXPECT_NE(refusal({}, o).find("no campaign"), std::string::npos);
  EXPECT_NE(refusal({a, a}, o).find("named twice"), std::string::npos);
}

}  // namespace
}  // namespace campaign
}  // namespace draglab
