// The SQLite drag-law database through its C++ API (database.h).
//
// Set-up: every test works on a fresh database file in its own temporary directory. Records are
// built from the registered form "bvk2007" (Beetstra, van der Hoef & Kuipers 2007) with its
// published coefficients, renamed so that they do not collide with the seeded literature copy.
// What is checked: exact round trip of every stored field, version numbering, the reference
// syntax (name, name@latest, name@N, name@<hash prefix>), the draft -> published -> retracted
// life cycle and its refusals, validation with nothing half-written, check(), the history
// written by schema-2 triggers, options and the default path.
// Doubles are compared exactly: SQLite stores REAL as IEEE-754 binary64, so a round trip through
// the database must not change a single bit (the content hash depends on it).
#include "draglab/drag_db/database.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <stdlib.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

namespace fs = std::filesystem;

// A fresh temporary directory, removed with everything in it at the end of the test.
using TempDir = test::TempDir;

ErrorCode code_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::kOk;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// bvk2007 with its published coefficients under a new name; `scale_a` changes parameter a so
// that versions differ in content.
LawRecord bvk_record(const std::string& name, double scale_a = 1.0) {
  LawRecord r = literature_record(find_law_form("bvk2007"));
  r.name = name;
  r.provenance.kind = "manual";
  r.parameters[0].value *= scale_a;
  r.notes = "test record";
  return r;
}

DatabaseOptions unseeded() {
  DatabaseOptions o;
  o.seed_literature = false;
  return o;
}

void expect_same_content(const LawRecord& a, const LawRecord& b) {
  EXPECT_EQ(a.form, b.form);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (std::size_t i = 0; i < a.parameters.size(); ++i) {
    EXPECT_EQ(a.parameters[i].name, b.parameters[i].name);
    EXPECT_EQ(a.parameters[i].value, b.parameters[i].value);  // exact: binary64 round trip
    EXPECT_EQ(a.parameters[i].unit, b.parameters[i].unit);
  }
  EXPECT_EQ(a.covariance, b.covariance);
  EXPECT_EQ(a.convention.force, b.convention.force);
  EXPECT_EQ(a.convention.normalisation, b.convention.normalisation);
  EXPECT_EQ(a.convention.reynolds, b.convention.reynolds);
  EXPECT_EQ(a.convention.tfm_model, b.convention.tfm_model);
  EXPECT_EQ(a.validity.phi.min, b.validity.phi.min);
  EXPECT_EQ(a.validity.phi.max, b.validity.phi.max);
  EXPECT_EQ(a.validity.re.min, b.validity.re.min);
  EXPECT_EQ(a.validity.re.max, b.validity.re.max);
  ASSERT_EQ(a.validity.extra.size(), b.validity.extra.size());
  for (std::size_t k = 0; k < a.validity.extra.size(); ++k) {
    EXPECT_EQ(a.validity.extra[k].name, b.validity.extra[k].name);
    EXPECT_EQ(a.validity.extra[k].description, b.validity.extra[k].description);
    EXPECT_EQ(a.validity.extra[k].range.min, b.validity.extra[k].range.min);
    EXPECT_EQ(a.validity.extra[k].range.max, b.validity.extra[k].range.max);
  }
  EXPECT_EQ(a.provenance.kind, b.provenance.kind);
  EXPECT_EQ(a.provenance.citation, b.provenance.citation);
  EXPECT_EQ(a.provenance.dataset_id, b.provenance.dataset_id);
  EXPECT_EQ(a.provenance.data_hash, b.provenance.data_hash);
  EXPECT_EQ(a.provenance.fitter_settings, b.provenance.fitter_settings);
  EXPECT_EQ(a.notes, b.notes);
}

bool is_iso8601_utc(const std::string& s) {
  // YYYY-MM-DDTHH:MM:SSZ
  if (s.size() != 20 || s[4] != '-' || s[7] != '-' || s[10] != 'T' || s[13] != ':' ||
      s[16] != ':' || s[19] != 'Z') {
    return false;
  }
  for (int i : {0, 1, 2, 3, 5, 6, 8, 9, 11, 12, 14, 15, 17, 18}) {
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
  }
  return true;
}

TEST(DatabaseBasics, NewFileIsWalAtCurrentSchemaAndSeededWithEveryLiteratureForm) {
  TempDir dir;
  Database db(dir.file("new.db"));
  EXPECT_EQ(db.schema_version(), Database::current_schema_version());
  EXPECT_GE(Database::current_schema_version(), 2);

  sqlite3_stmt* stmt = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db.handle(), "PRAGMA journal_mode", -1, &stmt, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0)), "wal");
  sqlite3_finalize(stmt);

  std::vector<const LawForm*> literature;
  for (const LawForm* f : all_law_forms()) {
    if (f->description.literature) literature.push_back(f);
  }
  ASSERT_FALSE(literature.empty());  // bvk2007 at least
  const std::vector<LawRecord> laws = db.list();
  ASSERT_EQ(laws.size(), literature.size());
  for (const LawForm* f : literature) {
    const LawRecord r = db.resolve(f->key());
    EXPECT_EQ(r.version, 1);
    EXPECT_EQ(r.status, LawStatus::kPublished);
    EXPECT_EQ(r.provenance.kind, "literature");
    EXPECT_EQ(r.provenance.citation, f->description.citation);
    // The stored record reproduces the form's defaults exactly, hence the same content hash.
    EXPECT_EQ(r.content_hash, content_hash_of(literature_record(*f))) << f->key();
    EXPECT_TRUE(is_iso8601_utc(r.created_at)) << r.created_at;
  }
  // Seeding again adds nothing: every literature form is present.
  EXPECT_EQ(db.seed_literature(), 0);
  EXPECT_EQ(db.list().size(), literature.size());
}

TEST(DatabaseBasics, RoundTripOfEveryFieldIsExact) {
  TempDir dir;
  Database db(dir.file("roundtrip.db"), unseeded());
  LawRecord in = bvk_record("fitted_bvk");
  // Values that do not survive a decimal round trip with fewer than 17 digits.
  in.parameters[1].value = 1.0 / 3.0;
  in.parameters[2].value = std::nextafter(0.413, 1.0);
  in.provenance.kind = "fitted";
  in.provenance.dataset_id = "campaign-7/run-3";
  in.provenance.data_hash = std::string(64, 'a');
  in.provenance.fitter_settings = R"({"loss":"cauchy","scale":0.1})";
  in.provenance.code_version = "0.1.0 (test)";
  in.validity.phi = {0.2, 0.5};
  in.validity.re = {0.0, std::numeric_limits<double>::infinity()};
  const std::size_t n = in.parameters.size();
  in.covariance.assign(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      in.covariance[i * n + j] = (i == j) ? 0.1 * (i + 1) : 1e-3 / (1.0 + i + j);
    }
  }
  in.notes = "multi-line\nnotes with 'quotes' and ; semicolons";

  const LawRecord stored = db.add_draft(in);
  EXPECT_EQ(stored.name, "fitted_bvk");
  EXPECT_EQ(stored.version, 1);
  EXPECT_EQ(stored.status, LawStatus::kDraft);
  EXPECT_EQ(stored.provenance.code_version, "0.1.0 (test)");
  expect_same_content(in, stored);
  EXPECT_EQ(stored.content_hash, content_hash_of(in));

  const LawRecord again = db.resolve("fitted_bvk@1");
  expect_same_content(in, again);
  EXPECT_EQ(again.content_hash, stored.content_hash);
  EXPECT_EQ(again.created_at, stored.created_at);
}

TEST(DatabaseBasics, ExtraInputsOfPolydisperseFormsRoundTrip) {
  const LawForm* form = nullptr;
  for (const LawForm* f : all_law_forms()) {
    if (f->num_extra_inputs > 0) form = f;
  }
  if (!form) GTEST_SKIP() << "no registered form has extra inputs yet";
  TempDir dir;
  Database db(dir.file("extra.db"), unseeded());
  LawRecord in = literature_record(*form);
  in.name = "poly";
  in.validity.extra[0].range.max =
      in.validity.extra[0].range.min +
      0.5 * (in.validity.extra[0].range.max - in.validity.extra[0].range.min);
  const LawRecord stored = db.add_published(in);
  expect_same_content(in, stored);
  EXPECT_EQ(stored.content_hash, content_hash_of(in));
}

TEST(DatabaseBasics, VersionsCountUpAndListIsOrdered) {
  TempDir dir;
  Database db(dir.file("versions.db"), unseeded());
  EXPECT_EQ(db.add_published(bvk_record("zeta")).version, 1);
  EXPECT_EQ(db.add_published(bvk_record("alpha")).version, 1);
  EXPECT_EQ(db.add_published(bvk_record("zeta", 1.1)).version, 2);
  EXPECT_EQ(db.add_draft(bvk_record("zeta", 1.2)).version, 3);

  const std::vector<LawRecord> all = db.list();
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].reference(), "alpha@1");
  EXPECT_EQ(all[1].reference(), "zeta@1");
  EXPECT_EQ(all[2].reference(), "zeta@2");
  EXPECT_EQ(all[3].reference(), "zeta@3");
  EXPECT_EQ(db.list("zeta").size(), 3u);
  EXPECT_EQ(db.list("zeta", /*include_drafts=*/false).size(), 2u);
  EXPECT_TRUE(db.list("nobody").empty());
}

TEST(DatabaseBasics, ContentHashFollowsContentNotMetadata) {
  TempDir dir;
  Database db(dir.file("hash.db"), unseeded());
  const LawRecord v1 = db.add_published(bvk_record("h"));
  LawRecord same = bvk_record("h");
  same.notes = "different notes, same formula";
  same.provenance.citation = "someone else";
  const LawRecord v2 = db.add_published(same);
  const LawRecord v3 = db.add_published(bvk_record("h", 1.0000001));
  EXPECT_EQ(v1.content_hash, v2.content_hash);  // notes/provenance are not content
  EXPECT_NE(v1.content_hash, v3.content_hash);  // a parameter is
  EXPECT_EQ(v1.content_hash.size(), 64u);
}

// LawReference: the one parser and writer of "name@version" (Database::resolve, the command
// line's publish and retract, every result that names the law it ran).
TEST(LawReference, ParsesEveryFormAndWritesOneVersion) {
  const LawReference plain = LawReference::Parse("bvk2007");
  EXPECT_EQ(plain.name, "bvk2007");
  EXPECT_EQ(plain.selector, "latest");
  EXPECT_EQ(plain.version_number(), -1);
  const LawReference numbered = LawReference::Parse("eq6_quick@12");
  EXPECT_EQ(numbered.name, "eq6_quick");
  EXPECT_EQ(numbered.version_number(), 12);
  EXPECT_EQ(LawReference::Parse("r@latest").version_number(), -1);
  EXPECT_EQ(LawReference::Parse("r@0a1b2c").version_number(), -1);      // a hash prefix
  EXPECT_EQ(LawReference::Parse("r@1234567890").version_number(), -1);  // too long
  EXPECT_EQ(LawReference::Parse("r@2@3").selector, "2@3");              // split at the first
  for (const char* bad : {"", "@1", "r@", "@"}) {
    EXPECT_EQ(code_of([&] { LawReference::Parse(bad); }), ErrorCode::kInvalidArgument) << bad;
    LawReference out;
    EXPECT_FALSE(LawReference::TryParse(bad, &out)) << bad;
  }
  EXPECT_NE(message_of([] { LawReference::Parse("r@"); }).find("name@<version>"),
            std::string::npos);
  EXPECT_EQ(LawReference::Format("eq6_standard", 1), "eq6_standard@1");
  LawRecord record;
  record.name = "x";
  record.version = 7;
  EXPECT_EQ(record.reference(), "x@7");
  EXPECT_EQ(LawReference::Parse(record.reference()).version_number(), 7);
}

TEST(DatabaseResolve, NameLatestNumberAndHashPrefix) {
  TempDir dir;
  Database db(dir.file("resolve.db"), unseeded());
  const LawRecord v1 = db.add_published(bvk_record("r"));
  const LawRecord v2 = db.add_published(bvk_record("r", 1.5));
  const LawRecord v3 = db.add_draft(bvk_record("r", 2.0));

  EXPECT_EQ(db.resolve("r").version, 2);  // latest *published*, not the newer draft
  EXPECT_EQ(db.resolve("r@latest").version, 2);
  EXPECT_EQ(db.resolve("r@1").version, 1);
  EXPECT_EQ(db.resolve("r@3").version, 3);
  EXPECT_EQ(db.resolve("r@" + v1.content_hash.substr(0, 8)).version, 1);
  EXPECT_EQ(db.resolve("r@" + v3.content_hash).version, 3);  // the full hash works too
  std::string upper = v2.content_hash.substr(0, 6);
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(db.resolve("r@" + upper).version, 2);

  // Too short a hash prefix (3 hex digits), not hex, malformed.
  EXPECT_EQ(code_of([&] { db.resolve("r@abc"); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { db.resolve("r@xyz1"); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { db.resolve("@1"); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { db.resolve("r@"); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { db.resolve(""); }), ErrorCode::kInvalidArgument);

  // Unknown version: names the versions that exist.
  const std::string no_version = message_of([&] { db.resolve("r@9"); });
  EXPECT_NE(no_version.find("no version 9"), std::string::npos) << no_version;
  EXPECT_NE(no_version.find("3 draft"), std::string::npos) << no_version;
  EXPECT_EQ(code_of([&] { db.resolve("r@9"); }), ErrorCode::kNotFound);
  // A hash prefix that matches nothing.
  std::string other = v1.content_hash.substr(0, 8);
  other[0] = other[0] == 'f' ? '0' : 'f';
  bool matches_any = false;
  for (const LawRecord& v : {v1, v2, v3}) matches_any |= v.content_hash.rfind(other, 0) == 0;
  if (!matches_any) {
    EXPECT_EQ(code_of([&] { db.resolve("r@" + other); }), ErrorCode::kNotFound);
  }
}

TEST(DatabaseResolve, UnknownNameListsKnownNames) {
  TempDir dir;
  Database db(dir.file("unknown.db"), unseeded());
  db.add_published(bvk_record("known_one"));
  db.add_published(bvk_record("known_two"));
  const std::string message = message_of([&] { db.resolve("unknown"); });
  EXPECT_NE(message.find("'unknown'"), std::string::npos) << message;
  EXPECT_NE(message.find("known_one, known_two"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { db.resolve("unknown@2"); }), ErrorCode::kNotFound);
}

TEST(DatabaseResolve, AmbiguousHashPrefixListsCandidates) {
  TempDir dir;
  Database db(dir.file("ambiguous.db"), unseeded());
  // Identical content published twice (e.g. re-published after a retraction): same hash.
  const LawRecord v1 = db.add_published(bvk_record("dup"));
  const LawRecord v2 = db.add_published(bvk_record("dup"));
  ASSERT_EQ(v1.content_hash, v2.content_hash);
  const std::string ref = "dup@" + v1.content_hash.substr(0, 10);
  const std::string message = message_of([&] { db.resolve(ref); });
  EXPECT_NE(message.find("ambiguous"), std::string::npos) << message;
  EXPECT_NE(message.find("dup@1"), std::string::npos) << message;
  EXPECT_NE(message.find("dup@2"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { db.resolve(ref); }), ErrorCode::kInvalidArgument);
}

TEST(DatabaseResolve, LatestSkipsRetractedAndSaysWhenNothingIsPublished) {
  TempDir dir;
  Database db(dir.file("latest.db"), unseeded());
  db.add_published(bvk_record("l"));
  db.add_published(bvk_record("l", 1.2));
  db.retract("l", 2, "coefficient typo");
  EXPECT_EQ(db.resolve("l").version, 1);
  db.retract("l", 1, "superseded");
  db.add_draft(bvk_record("l", 1.3));
  const std::string message = message_of([&] { db.resolve("l"); });
  EXPECT_NE(message.find("no published version"), std::string::npos) << message;
  EXPECT_NE(message.find("2 retracted"), std::string::npos) << message;
  EXPECT_NE(message.find("3 draft"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { db.resolve("l@latest"); }), ErrorCode::kNotFound);
}

TEST(DatabaseLifeCycle, PublishedVersionsRefuseEveryChangeThroughTheApi) {
  TempDir dir;
  Database db(dir.file("life.db"), unseeded());
  const LawRecord published = db.add_published(bvk_record("p"));
  EXPECT_EQ(published.status, LawStatus::kPublished);

  LawRecord changed = published;
  changed.parameters[0].value = 11.0;
  const std::string message = message_of([&] { db.update_draft(changed); });
  EXPECT_NE(message.find("p@1"), std::string::npos) << message;
  EXPECT_NE(message.find("create a new version instead"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { db.update_draft(changed); }), ErrorCode::kImmutable);
  EXPECT_EQ(code_of([&] { db.delete_draft("p", 1); }), ErrorCode::kImmutable);
  EXPECT_EQ(code_of([&] { db.publish("p", 1); }), ErrorCode::kImmutable);
  EXPECT_EQ(code_of([&] { db.retract("p", 1, "  "); }), ErrorCode::kInvalidArgument);

  db.retract("p", 1, "wrong exponent");
  EXPECT_EQ(code_of([&] { db.retract("p", 1, "again"); }), ErrorCode::kImmutable);
  EXPECT_EQ(code_of([&] { db.delete_draft("p", 1); }), ErrorCode::kImmutable);
  EXPECT_EQ(code_of([&] { db.update_draft(changed); }), ErrorCode::kImmutable);

  const LawRecord after = db.resolve("p@1");
  EXPECT_EQ(after.status, LawStatus::kRetracted);
  EXPECT_EQ(after.retraction_reason, "wrong exponent");
  expect_same_content(published, after);
  EXPECT_EQ(after.content_hash, published.content_hash);
}

TEST(DatabaseLifeCycle, DraftsChangeThenPublishAndCanBeDeleted) {
  TempDir dir;
  Database db(dir.file("drafts.db"), unseeded());
  LawRecord draft = db.add_draft(bvk_record("d"));
  const std::string first_hash = draft.content_hash;
  draft.parameters[3].value = 8.5;
  draft.notes = "refit";
  const LawRecord updated = db.update_draft(draft);
  EXPECT_EQ(updated.version, 1);
  EXPECT_EQ(updated.parameters[3].value, 8.5);
  EXPECT_EQ(updated.notes, "refit");
  EXPECT_NE(updated.content_hash, first_hash);
  EXPECT_EQ(updated.content_hash, content_hash_of(updated));
  EXPECT_EQ(updated.created_at, draft.created_at);

  // Retracting a draft makes no sense: drafts are deleted.
  EXPECT_EQ(code_of([&] { db.retract("d", 1, "x"); }), ErrorCode::kInvalidArgument);

  const LawRecord published = db.publish("d", 1);
  EXPECT_EQ(published.status, LawStatus::kPublished);
  EXPECT_EQ(published.content_hash, updated.content_hash);

  db.add_draft(bvk_record("d", 3.0));
  db.delete_draft("d", 2);
  EXPECT_EQ(db.list("d").size(), 1u);
  EXPECT_EQ(code_of([&] { db.delete_draft("d", 2); }), ErrorCode::kNotFound);
}

TEST(DatabaseLifeCycle, LoadWarnsForRetractedAndDraftVersions) {
  TempDir dir;
  Database db(dir.file("load.db"), unseeded());
  db.add_published(bvk_record("w"));
  db.add_published(bvk_record("w", 1.1));
  db.add_draft(bvk_record("w", 1.2));
  db.retract("w", 1, "fitted to a biased campaign");

  std::string warning = "stale";
  auto latest = db.load("w", RangePolicy::kError, &warning);
  EXPECT_EQ(latest->reference(), "w@2");
  EXPECT_TRUE(warning.empty()) << warning;

  auto retracted = db.load("w@1", RangePolicy::kError, &warning);
  EXPECT_NE(warning.find("retracted"), std::string::npos) << warning;
  EXPECT_NE(warning.find("fitted to a biased campaign"), std::string::npos) << warning;
  EXPECT_NE(warning.find("w@2"), std::string::npos) << warning;
  // The retracted law still evaluates: same formula as loading its record directly.
  const LawRecord r1 = db.resolve("w@1");
  Law direct(r1);
  EXPECT_EQ(retracted->F(0.3, 10.0), direct.F(0.3, 10.0));

  db.load("w@3", RangePolicy::kClamp, &warning);
  EXPECT_NE(warning.find("draft"), std::string::npos) << warning;
  EXPECT_EQ(db.load("w@3", RangePolicy::kClamp)->range_policy(), RangePolicy::kClamp);
}

TEST(DatabaseValidation, BadRecordsAreRefusedAndNothingIsWritten) {
  TempDir dir;
  Database db(dir.file("validation.db"), unseeded());
  db.add_published(bvk_record("ok"));

  struct Case {
    const char* what;
    std::function<void(LawRecord&)> spoil;
    ErrorCode code;
  };
  const std::vector<Case> cases = {
      {"name with @", [](LawRecord& r) { r.name = "bad@name"; }, ErrorCode::kInvalidArgument},
      {"name with space", [](LawRecord& r) { r.name = "bad name"; }, ErrorCode::kInvalidArgument},
      {"empty name", [](LawRecord& r) { r.name = ""; }, ErrorCode::kInvalidArgument},
      {"unknown form", [](LawRecord& r) { r.form = "no_such_form"; }, ErrorCode::kNotFound},
      {"missing parameter", [](LawRecord& r) { r.parameters.pop_back(); },
       ErrorCode::kInvalidArgument},
      {"renamed parameter", [](LawRecord& r) { r.parameters[0].name = "z"; },
       ErrorCode::kInvalidArgument},
      {"NaN parameter",
       [](LawRecord& r) { r.parameters[0].value = std::numeric_limits<double>::quiet_NaN(); },
       ErrorCode::kInvalidArgument},
      {"covariance size",
       [](LawRecord& r) {
         r.covariance = {1.0, 0.0, 0.0};
       },
       ErrorCode::kInvalidArgument},
      {"phi range reversed",
       [](LawRecord& r) {
         r.validity.phi = {0.5, 0.2};
       },
       ErrorCode::kInvalidArgument},
      {"phi range reaching 1",
       [](LawRecord& r) {
         r.validity.phi = {0.1, 1.0};
       },
       ErrorCode::kInvalidArgument},
      {"negative Re",
       [](LawRecord& r) {
         r.validity.re = {-1.0, 10.0};
       },
       ErrorCode::kInvalidArgument},
      {"convention of another form", [](LawRecord& r) { r.convention.force = ForceKind::kTotal; },
       ErrorCode::kInvalidArgument},
      {"fitted without dataset",
       [](LawRecord& r) {
         r.provenance.kind = "fitted";
         r.provenance.data_hash = "abc";
       },
       ErrorCode::kInvalidArgument},
      {"literature without citation",
       [](LawRecord& r) {
         r.provenance.kind = "literature";
         r.provenance.citation.clear();
       },
       ErrorCode::kInvalidArgument},
      {"unknown provenance kind", [](LawRecord& r) { r.provenance.kind = "guess"; },
       ErrorCode::kInvalidArgument},
      {"fitter settings not JSON", [](LawRecord& r) { r.provenance.fitter_settings = "{oops"; },
       ErrorCode::kInvalidArgument},
  };
  for (const Case& c : cases) {
    LawRecord r = bvk_record("ok", 1.7);
    c.spoil(r);
    EXPECT_EQ(code_of([&] { db.add_draft(r); }), c.code) << c.what;
    EXPECT_EQ(code_of([&] { db.add_published(r); }), c.code) << c.what;
  }
  const std::vector<LawRecord> laws = db.list();
  ASSERT_EQ(laws.size(), 1u);
  EXPECT_EQ(laws[0].reference(), "ok@1");
}

TEST(DatabaseValidation, FailureInsideAWriteRollsBackTheWholeVersion) {
  TempDir dir;
  Database db(dir.file("atomic.db"), unseeded());
  // A temporary trigger on this connection makes the *parameter* insert fail after the laws row
  // has been written: the transaction must take the laws row back with it.
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db.handle(),
                         "CREATE TEMP TRIGGER fail_params BEFORE INSERT ON main.law_parameters "
                         "WHEN NEW.name = 'd' BEGIN SELECT RAISE(ABORT, 'injected failure'); END;",
                         nullptr, nullptr, &err),
            SQLITE_OK)
      << (err ? err : "");
  const std::string message = message_of([&] { db.add_published(bvk_record("half")); });
  EXPECT_NE(message.find("injected failure"), std::string::npos) << message;
  EXPECT_TRUE(db.list().empty());
  EXPECT_TRUE(db.history("half").empty());  // not even a 'created' event survived
  ASSERT_EQ(sqlite3_exec(db.handle(), "DROP TRIGGER temp.fail_params", nullptr, nullptr, &err),
            SQLITE_OK);
  EXPECT_EQ(db.add_published(bvk_record("half")).version, 1);
}

TEST(DatabaseCheck, CleanDatabasePassesAndTamperingIsFound) {
  TempDir dir;
  Database db(dir.file("check.db"), unseeded());
  db.add_published(bvk_record("c"));
  db.add_draft(bvk_record("c", 1.4));

  DatabaseCheckReport clean = db.check();
  EXPECT_TRUE(clean.ok) << clean.FullReport();
  EXPECT_EQ(clean.schema_version, Database::current_schema_version());
  EXPECT_EQ(clean.laws_checked, 2);
  EXPECT_EQ(clean.BriefReport().find('\n'), std::string::npos);
  EXPECT_NE(clean.BriefReport().find("OK"), std::string::npos);

  // Change a draft's parameter behind draglab's back (allowed in SQL for drafts) without its
  // hash, and drop one guard trigger.
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db.handle(),
                         "UPDATE law_parameters SET value = 12.5 WHERE position = 0 AND law_id = "
                         "(SELECT id FROM laws WHERE name = 'c' AND version = 2);"
                         "DROP TRIGGER laws_immutable_delete;",
                         nullptr, nullptr, &err),
            SQLITE_OK)
      << (err ? err : "");
  DatabaseCheckReport tampered = db.check();
  EXPECT_FALSE(tampered.ok);
  ASSERT_EQ(tampered.problems.size(), 2u) << tampered.FullReport();
  const std::string full = tampered.FullReport();
  EXPECT_NE(full.find("c@2"), std::string::npos) << full;
  EXPECT_NE(full.find("laws_immutable_delete"), std::string::npos) << full;
  EXPECT_EQ(tampered.BriefReport().find('\n'), std::string::npos);
  EXPECT_NE(tampered.BriefReport().find("2 problems"), std::string::npos);
  // Loading the altered version is refused rather than silently evaluating other numbers.
  EXPECT_EQ(code_of([&] { db.load("c@2"); }), ErrorCode::kDatabase);
  EXPECT_NO_THROW(db.load("c@1"));
}

TEST(DatabaseHistory, TriggersRecordTheLifeCycle) {
  TempDir dir;
  Database db(dir.file("history.db"), unseeded());
  LawRecord draft = db.add_draft(bvk_record("e"));
  draft.parameters[0].value = 9.0;
  db.update_draft(draft);
  db.publish("e", 1);
  db.retract("e", 1, "bad data");
  db.add_draft(bvk_record("e", 2.0));
  db.delete_draft("e", 2);

  const std::vector<LawEvent> all = db.history("e");
  std::vector<std::string> kinds;
  for (const LawEvent& ev : all) kinds.push_back(ev.event + "@" + std::to_string(ev.version));
  EXPECT_EQ(kinds, (std::vector<std::string>{"created@1", "updated@1", "published@1", "retracted@1",
                                             "created@2", "deleted@2"}));
  EXPECT_EQ(all[3].detail, "bad data");
  for (const LawEvent& ev : all) EXPECT_TRUE(is_iso8601_utc(ev.at)) << ev.at;
  EXPECT_EQ(db.history("e", 2).size(), 2u);

  // The history itself is append-only.
  char* err = nullptr;
  EXPECT_NE(sqlite3_exec(db.handle(), "DELETE FROM law_events", nullptr, nullptr, &err), SQLITE_OK);
  sqlite3_free(err);
  EXPECT_EQ(db.history("e").size(), all.size());
}

TEST(DatabaseOptionsAndPaths, IsValidAndDefaultPath) {
  DatabaseOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error));
  o.busy_timeout_ms = -1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("busy_timeout_ms"), std::string::npos);
  TempDir dir;
  EXPECT_EQ(code_of([&] { Database db(dir.file("x.db"), o); }), ErrorCode::kInvalidArgument);

  const char* saved = std::getenv("DRAGLAB_DB");
  const std::string saved_value = saved ? saved : "";
  setenv("DRAGLAB_DB", "/some/where/laws.db", 1);
  EXPECT_EQ(Database::default_path(), "/some/where/laws.db");
  setenv("DRAGLAB_DB", "", 1);
  EXPECT_EQ(Database::default_path(), "./draglab.db");
  unsetenv("DRAGLAB_DB");
  EXPECT_EQ(Database::default_path(), "./draglab.db");
  if (saved) setenv("DRAGLAB_DB", saved_value.c_str(), 1);
}

TEST(DatabaseOptionsAndPaths, ReadOnlyOpenReadsButRefusesWrites) {
  TempDir dir;
  const std::string path = dir.file("ro.db");
  {
    Database writer(path, unseeded());
    writer.add_published(bvk_record("ro"));
  }
  DatabaseOptions ro;
  ro.read_only = true;
  Database db(path, ro);
  EXPECT_EQ(db.resolve("ro").version, 1);
  EXPECT_NO_THROW(db.load("ro@1"));
  // A change on a read-only open is bad input, and the message says what gives write access.
  EXPECT_EQ(code_of([&] { db.add_draft(bvk_record("ro")); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { db.migrate(); }), ErrorCode::kInvalidArgument);
  try {
    db.add_draft(bvk_record("ro"));
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("write permission on the file and on its directory"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(code_of([&] { Database missing(dir.file("missing.db"), ro); }), ErrorCode::kNotFound);
  EXPECT_FALSE(fs::exists(dir.file("missing.db")));
}

TEST(LawNames, OneRuleForEveryCaller) {
  for (const char* ok : {"vdh2004", "eq6_quick", "a", "Law-2.b", "9lives"}) {
    EXPECT_NO_THROW(check_law_name(ok)) << ok;
  }
  for (const std::string bad :
       {std::string(""), std::string("_x"), std::string("a b"), std::string("a@1"),
        std::string(".hidden"), std::string(101, 'a'), std::string("caf\xC3\xA9")}) {
    try {
      check_law_name(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find("A-Z a-z 0-9"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace draglab
