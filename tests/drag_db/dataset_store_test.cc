// Datasets in the drag-law database (dataset.h, schema version 4).
//
// Set-up: a fresh database file per test; datasets made of a few hand-written points.
// What is checked: the content hash is a function of the points only (stable, order-sensitive,
// changed by any value), a store/load round trip is bit-exact, storing the same points twice
// returns the existing dataset, prefixes resolve (and ambiguous or unknown ones are refused),
// the rows are immutable from the sqlite3 C API too (UPDATE, DELETE, INSERT OR REPLACE), the
// CSV form round-trips and refuses malformed files naming line and column, and a dataset extended
// beyond its grid's box takes exactly the other dataset's points outside it (counted by hand).
#include "draglab/drag_db/dataset.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "draglab/drag_db/database.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

namespace fs = std::filesystem;

using TempDir = test::TempDir;

Dataset sample(double scale = 1.0) {
  Dataset d;
  d.name = "sample";
  for (double phi : {0.2, 0.3, 0.4}) {
    for (double re : {0.0, 10.0}) {
      DatasetPoint p;
      p.phi = phi;
      p.re_target = re;
      p.re = re * 1.001;
      p.F = scale * (1.0 + 10.0 * phi + 0.1 * re) + 1e-13;  // not a short decimal
      p.F_standard_error = 0.01 * p.F;
      p.F_discretisation_error = 0.02 * p.F;
      p.F_uncertainty = 0.0223606797749979 * p.F;
      p.realizations = 3;
      p.resolutions = {8.0, 12.0};
      p.F_at_resolution = {p.F * 0.97, p.F * 0.99};
      p.order = 1.0;
      p.extrapolation = "inverse_d";
      p.wall_s = 1.5;
      d.points.push_back(p);
    }
  }
  return d;
}

TEST(DatasetStore, HashDependsOnPointsOnly) {
  const Dataset a = sample(), b = sample();
  EXPECT_EQ(dataset_hash(a.points), dataset_hash(b.points));
  EXPECT_EQ(dataset_hash(a.points).size(), 64u);
  Dataset c = sample();
  c.points[3].F = std::nextafter(c.points[3].F, 1e9);  // one ulp
  EXPECT_NE(dataset_hash(a.points), dataset_hash(c.points));
  Dataset slower = sample();
  slower.points[2].wall_s *= 3.0;  // the machine's speed is not part of the identity
  EXPECT_EQ(dataset_hash(a.points), dataset_hash(slower.points));
  Dataset swapped = sample();
  std::swap(swapped.points[0], swapped.points[1]);
  EXPECT_NE(dataset_hash(a.points), dataset_hash(swapped.points));
}

TEST(DatasetStore, RoundTripIsExactAndStoringTwiceReturnsTheSameDataset) {
  TempDir dir;
  Database db(dir.file("d.db"));
  EXPECT_GE(db.schema_version(), 4);
  const Dataset stored = store_dataset(db, sample());
  EXPECT_EQ(stored.id, stored.hash.substr(0, 12));
  EXPECT_EQ(stored.hash, dataset_hash(sample().points));
  const Dataset loaded = load_dataset(db, stored.id);
  ASSERT_EQ(loaded.points.size(), 6u);
  const Dataset original = sample();
  for (std::size_t i = 0; i < 6; ++i) {
    const DatasetPoint& p = loaded.points[i];
    const DatasetPoint& q = original.points[i];
    EXPECT_EQ(p.F, q.F);  // bit-exact
    EXPECT_EQ(p.F_uncertainty, q.F_uncertainty);
    EXPECT_EQ(p.re, q.re);
    EXPECT_EQ(p.F_at_resolution, q.F_at_resolution);
    EXPECT_EQ(p.extrapolation, q.extrapolation);
  }
  const Dataset again = store_dataset(db, sample());
  EXPECT_EQ(again.id, stored.id);
  EXPECT_EQ(again.created_at, stored.created_at);
  EXPECT_EQ(list_datasets(db).size(), 1u);
  EXPECT_EQ(load_dataset(db, stored.hash.substr(0, 4)).id, stored.id);
  store_dataset(db, sample(2.0));
  EXPECT_EQ(list_datasets(db).size(), 2u);
  try {
    load_dataset(db, "zz");
    FAIL() << "bad id accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  }
  EXPECT_THROW(load_dataset(db, "0000000"), Error);
}

TEST(DatasetStore, PerSpeciesPointsCarryTheirSizeRatio) {
  // Points of a polydisperse campaign's size classes share (phi, Re) and differ in y; y is part
  // of the identity, and a dataset without y keeps the hash it had before y existed (y is written
  // only where it is set).
  Dataset species = sample();
  const std::string without_y = dataset_hash(species.points);
  for (std::size_t i = 0; i < species.points.size(); ++i) species.points[i].y = 0.75 + 0.1 * i;
  EXPECT_NE(dataset_hash(species.points), without_y);
  species.points[1].phi = species.points[0].phi;
  species.points[1].re_target = species.points[0].re_target;  // same point, another size class
  TempDir dir;
  Database db(dir.file("d.db"));
  const Dataset stored = store_dataset(db, species);
  const Dataset loaded = load_dataset(db, stored.id);
  for (std::size_t i = 0; i < species.points.size(); ++i) {
    EXPECT_EQ(loaded.points[i].y, species.points[i].y);
  }
  Dataset copy = species;
  copy.hash = dataset_hash(copy.points);
  copy.id = copy.hash.substr(0, 12);
  write_dataset_csv(copy, dir.file("species.csv"));
  const Dataset back = read_dataset_csv(dir.file("species.csv"));
  EXPECT_EQ(back.hash, copy.hash);
  // The same size class twice is refused, naming y; y must be positive in every row.
  species.points[1].y = species.points[0].y;
  EXPECT_THROW(store_dataset(db, species), Error);
  std::ofstream(dir.file("bad.csv")) << "phi,re,F,F_uncertainty,y\n0.3,0,5,0.1,0.8\n0.3,0,6,0.1,\n";
  try {
    read_dataset_csv(dir.file("bad.csv"));
    ADD_FAILURE() << "a row without y accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("column 'y'"), std::string::npos) << e.what();
  }
}

TEST(DatasetStore, RowsAreImmutableForEveryClient) {
  TempDir dir;
  const std::string path = dir.file("d.db");
  std::string id;
  {
    Database db(path);
    id = store_dataset(db, sample()).id;
  }
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  for (const std::string sql :
       {"UPDATE datasets SET name = 'x'", "DELETE FROM datasets",
        "INSERT OR REPLACE INTO datasets SELECT id, hash, campaign_id, 'x', method, created_at, "
        "code_version, points_json FROM datasets"}) {
    char* message = nullptr;
    EXPECT_NE(sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, &message), SQLITE_OK) << sql;
    ASSERT_NE(message, nullptr);
    EXPECT_NE(std::string(message).find("immutable"), std::string::npos) << message;
    sqlite3_free(message);
  }
  sqlite3_close(raw);
  Database db(path);
  EXPECT_EQ(load_dataset(db, id).name, "sample");
}

TEST(DatasetStore, RefusesInvalidPointsAndWritesNothing) {
  TempDir dir;
  Database db(dir.file("d.db"));
  Dataset bad = sample();
  bad.points[2].F_uncertainty = 0.0;
  try {
    store_dataset(db, bad);
    FAIL() << "zero uncertainty accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("F_uncertainty"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(list_datasets(db).empty());
}

TEST(DatasetStore, CsvRoundTripAndMalformedFiles) {
  TempDir dir;
  Dataset d = sample();
  d.hash = dataset_hash(d.points);
  d.id = d.hash.substr(0, 12);
  write_dataset_csv(d, dir.file("out.csv"));
  const Dataset back = read_dataset_csv(dir.file("out.csv"));
  EXPECT_EQ(back.hash, d.hash);  // %.17g text round-trips every double
  EXPECT_EQ(back.name, "out");

  auto write = [&](const std::string& text) {
    std::ofstream(dir.file("x.csv")) << text;
    return dir.file("x.csv");
  };
  // Minimal columns.
  const Dataset minimal =
      read_dataset_csv(write("# comment\nphi,re,F,F_uncertainty\n0.3,0,5.1,0.1\n"));
  ASSERT_EQ(minimal.points.size(), 1u);
  EXPECT_EQ(minimal.points[0].re_target, 0.0);
  struct Case {
    const char* text;
    const char* expect;
  };
  for (const Case& c :
       {Case{"phi,re,F\n0.3,0,5\n", "F_uncertainty"},
        Case{"phi,re,F,F_uncertainty\n0.3,0,abc,0.1\n", "column 'F'"},
        Case{"phi,re,F,F_uncertainty\n0.9,0,5,0.1\n", "phi"},
        Case{"phi,re,F,F_uncertainty\n0.3,-1,5,0.1\n", "re"},
        Case{"phi,re,F,F_uncertainty\n0.3,0,5\n", "columns"},
        Case{"phi,re,F,F_uncertainty\n", "no data rows"},
        // Values an immutable dataset must never store (each once stored wrong).
        Case{"phi,re,F,F_uncertainty,realizations\n0.3,0,5,0.1,1e20\n", "realizations"},
        Case{"phi,re,F,F_uncertainty,realizations\n0.3,0,5,0.1,-4\n", "realizations"},
        Case{"phi,re,F,F_uncertainty,realizations\n0.3,0,5,0.1,2.7\n", "realizations"},
        Case{"phi,re,F,F_uncertainty,F_standard_error\n0.3,0,5,0.1,-1\n", "F_standard_error"},
        Case{"phi,re,F,F_uncertainty\n0.3,0,5,0.1\n0.3,0,6,0.1\n", "already given at"},
        Case{"phi,re,F,F,F_uncertainty\n0.3,0,5,5,0.1\n", "twice"},
        Case{"phi,re,F,F_uncertainty,resolutions,F_at_resolution\n"
             "0.3,0,5,0.1,10;20,5\n",
             "one F per resolution"},
        Case{"phi,re,F,F_uncertainty\n0.3,0,1e300,0.1\n", "F = "},
        Case{"phi,re,F,F_uncertainty\n0.3,1e300,5,0.1\n", "re = "},
        // Stored without complaint before the hardening: a misspelt optional column was dropped,
        // an order or extrapolation outside what the builder writes was kept forever.
        Case{"phi,re,F,F_uncertainty,realisations\n0.3,0,5,0.1,3\n", "unknown column"},
        Case{"phi,re,F,F_uncertainty,order\n0.3,0,5,0.1,-1\n", "order = "},
        Case{"phi,re,F,F_uncertainty,extrapolation\n0.3,0,5,0.1,magic\n", "extrapolation = "},
        // fuzz/fuzz_dataset_csv: a byte that is not UTF-8 in the free-text extrapolation column
        // reached the hash's JSON dump and left read_dataset_csv as nlohmann's type_error.
        Case{"phi,re,F,F_uncertainty,extrapolation\n0.3,0,5,0.1,\xDEinverse_d\n",
             "extrapolation = "},
        Case{"phi,(e_target,re,F,F_uncertainty\n0.3,0,0,5,0.1\n", "unknown column '(e_target'"}}) {
    try {
      read_dataset_csv(write(c.text));
      FAIL() << "accepted: " << c.text;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_dataset_csv(dir.file("missing.csv")), Error);
  // A file name that is not UTF-8 still imports (its name is kept with the bad byte replaced).
  std::ofstream(dir.file("bad\xDEname.csv")) << "phi,re,F,F_uncertainty\n0.3,0,5.1,0.1\n";
  EXPECT_NO_THROW(read_dataset_csv(dir.file("bad\xDEname.csv")));
}

// sample() covers phi 0.2-0.4 x Re 0-10. The extension has 3 points inside that box (left to the
// base) and 3 outside it: phi 0.5 (beyond phi), Re 30 (beyond Re), phi 0.1 (below phi).
Dataset extension_sample() {
  Dataset e = sample(2.0);
  e.name = "wider";
  for (auto [phi, re] : {std::pair{0.5, 0.0}, std::pair{0.3, 30.0}, std::pair{0.1, 10.0}}) {
    DatasetPoint p = e.points.front();
    p.phi = phi;
    p.re_target = re;
    p.re = re;
    e.points.push_back(p);
  }
  e.points.erase(e.points.begin(), e.points.begin() + 3);  // keep 3 of sample's 6 inside points
  e.hash = dataset_hash(e.points);
  e.id = e.hash.substr(0, 12);
  return e;
}

TEST(DatasetExtend, TakesTheOtherDatasetsPointsOutsideTheBoxOnly) {
  TempDir dir;
  Database db(dir.file("x.db"));
  Dataset base = sample();
  base.method = R"({"source":"campaign","extrapolation":"inverse_d"})";
  base = store_dataset(db, base);
  const Dataset extension = extension_sample();
  const DatasetBox box{0.2, 0.4, 0.0, 10.0};
  const Dataset extended = extend_dataset(base, box, extension, "wider.csv");
  ASSERT_EQ(extended.points.size(), 9u);  // 6 of the base's and the 3 outside the box
  for (std::size_t i = 1; i < extended.points.size(); ++i) {
    const DatasetPoint &a = extended.points[i - 1], &b = extended.points[i];
    EXPECT_TRUE(a.phi < b.phi || (a.phi == b.phi && a.re_target < b.re_target)) << i;
  }
  // Inside the box the base's values stand (the extension's F there is twice theirs).
  int from_base = 0;
  for (const DatasetPoint& p : extended.points)
    for (const DatasetPoint& q : base.points)
      if (p.phi == q.phi && p.re_target == q.re_target && p.F == q.F) ++from_base;
  EXPECT_EQ(from_base, 6);
  EXPECT_EQ(extended.name, base.name);
  const nlohmann::json method = nlohmann::json::parse(extended.method);
  EXPECT_EQ(method.at("extrapolation"), "inverse_d");  // the base's method is kept
  const nlohmann::json& with = method.at("extended_with");
  EXPECT_EQ(with.at("base_dataset"), base.id);
  EXPECT_EQ(with.at("dataset"), extension.id);
  EXPECT_EQ(with.at("source"), "wider.csv");
  EXPECT_EQ(with.at("points").size(), 3u);
  const Dataset stored = store_dataset(db, extended);
  EXPECT_NE(stored.id, base.id);
  EXPECT_EQ(load_dataset(db, stored.id).points.size(), 9u);
}

TEST(DatasetExtend, RefusesWhatWouldNotExtendTheBase) {
  const Dataset base = sample(), extension = extension_sample();
  // An extension all inside the box adds nothing.
  Dataset inside = base;
  try {
    extend_dataset(base, {0.2, 0.4, 0.0, 10.0}, inside, "same.csv");
    FAIL() << "an extension inside the box must be refused";
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input());
    EXPECT_NE(std::string(e.what()).find("adds nothing"), std::string::npos) << e.what();
  }
  // A base point outside the box it claims to cover.
  EXPECT_THROW(extend_dataset(base, {0.2, 0.3, 0.0, 10.0}, extension, "w.csv"), Error);
  // Size-class points: their F is per species, not a mixture's.
  Dataset classes = extension;
  classes.points.back().y = 1.5;
  EXPECT_THROW(extend_dataset(base, {0.2, 0.4, 0.0, 10.0}, classes, "c.csv"), Error);
}

}  // namespace
}  // namespace draglab
