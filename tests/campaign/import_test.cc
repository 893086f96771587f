// A campaign restored from its spec and the CSV of its units (campaign::import_campaign,
// `draglab campaign import`). The reference is the committed standard dataset
// (data/datasets/standard/): its parts' unit files were exported from the database the campaigns
// ran in, and its dataset file was built there. Importing the parts into a new database must
// give back every unit to the bit (the export of the import is the committed file, row for row)
// and the dataset built from them must have the committed dataset's id. Every malformed variant
// of a committed file is refused naming the file, line and column, with nothing stored.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "campaign_test_util.h"
#include "db/sqlite_util.h"
#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"

namespace draglab {
namespace campaign {
namespace {

const std::string kStandard = std::string(DRAGLAB_DATA_DIR) + "/datasets/standard/";
const std::string kSpecs = std::string(DRAGLAB_DATA_DIR) + "/campaigns/standard/";

std::string spec_of(const std::string& part) { return kSpecs + part + ".toml"; }
std::string units_of(const std::string& part) { return kStandard + part + ".csv"; }

/// The data lines of a units file (comments left out), without their first two columns (the
/// unit's and campaign's ids, which belong to the database), sorted.
std::vector<std::string> rows_without_ids(const std::string& csv_text) {
  std::vector<std::string> rows;
  std::istringstream in(csv_text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t second_comma = line.find(',', line.find(',') + 1);
    rows.push_back(line.substr(second_comma + 1));
  }
  std::sort(rows.begin() + 1, rows.end());  // the header stays first
  return rows;
}

std::string committed_dataset_id() {
  std::ifstream in(kStandard + "standard.csv");
  const std::string key = "# draglab dataset ";
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) == 0) return line.substr(key.size(), 12);
  }
  return "";
}

class CampaignImport : public ::testing::Test {
 protected:
  void SetUp() override {
    db_path_ = dir_.file("import.db");
    DatabaseOptions o;
    o.seed_literature = false;
    db_ = std::make_unique<Database>(db_path_, o);
  }
  std::int64_t campaigns() {
    db::Statement s(db_->handle(), "SELECT count(*) FROM campaigns");
    s.step();
    return s.integer(0);
  }
  /// A committed file with `edit` applied to its text, written to the temporary folder.
  std::string variant(const std::string& part, const std::string& name,
                      const std::function<std::string(std::string)>& edit) {
    const std::string path = dir_.file(name + ".csv");
    campaign_test::write_file(path, edit(campaign_test::read_file(units_of(part))));
    return path;
  }
  /// The refusal of importing `path` as a run of `part`'s spec (""" if it was accepted); the
  /// database must be as before.
  std::string refusal(const std::string& part, const std::string& path) {
    const std::int64_t before = campaigns();
    std::string message;
    try {
      import_campaign(*db_, parse_campaign_spec(spec_of(part)), path);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
      message = e.what();
    }
    EXPECT_EQ(campaigns(), before) << "nothing is stored from a refused file";
    return message;
  }
  campaign_test::TempDir dir_;
  std::string db_path_;
  std::unique_ptr<Database> db_;
};

TEST_F(CampaignImport, TheFileListsTheColumnsOfTheSchema) {
  std::vector<std::string> schema;
  db::Statement s(db_->handle(), "PRAGMA table_info(campaign_units)");
  while (s.step()) schema.push_back(s.text(1) + " " + s.text(2));
  EXPECT_EQ(units_file_columns(), schema);
}

TEST_F(CampaignImport, TheCommittedPartsComeBackToTheBitAndRebuildTheCommittedDataset) {
  std::vector<std::int64_t> ids;
  for (const std::string part :
       {"standard_low", "standard_re100", "standard_re300_mid", "standard_re300_dense"}) {
    SCOPED_TRACE(part);
    const ImportSummary summary =
        import_campaign(*db_, parse_campaign_spec(spec_of(part)), units_of(part));
    EXPECT_EQ(summary.units, summary.done + summary.failed + summary.pending);
    EXPECT_GT(summary.done, 0);
    // Every column of every unit as the file has it, apart from the database's own ids; units
    // not finished come back pending with nothing but their attempts.
    std::vector<std::string> expected = rows_without_ids(campaign_test::read_file(units_of(part)));
    for (std::string& row : expected) {
      for (const char* status : {",running,", ",pending,"}) {
        const std::size_t at = row.find(status);
        if (at == std::string::npos) continue;
        const std::size_t attempts_end = row.find(',', at + std::strlen(status));
        row = row.substr(0, at) + ",pending," +
              row.substr(at + std::strlen(status), attempts_end - at - std::strlen(status)) +
              std::string(15, ',');
      }
    }
    std::sort(expected.begin() + 1, expected.end());
    EXPECT_EQ(rows_without_ids(export_units(*db_, summary.campaign_id).csv), expected);
    ids.push_back(summary.campaign_id);
  }
  BuildDatasetOptions o;
  o.name = "standard";
  // The dense Re 300 part ran on a later build than the others (its engine computes the same
  // F; the build also keeps a unit's time through its checkpoint): the committed dataset was
  // built with --allow-mixed-code, which its method records.
  o.allow_mixed_code = true;
  EXPECT_EQ(build_dataset(*db_, ids, o).id, committed_dataset_id());
}

TEST_F(CampaignImport, APartNotFinishedComesBackWithItsRestPendingForResume) {
  const ImportSummary s = import_campaign(*db_, parse_campaign_spec(spec_of("standard_re100")),
                                          units_of("standard_re100"));
  const CampaignStatus st = campaign_status(*db_, "standard_re100");
  EXPECT_EQ(st.units_pending, s.pending);
  EXPECT_EQ(st.units_running, 0);
  EXPECT_EQ(st.units_done, s.done);
  EXPECT_EQ(st.units_failed, s.failed);
  EXPECT_EQ(st.spec_hash, s.spec_hash);
}

TEST_F(CampaignImport, AnExportWithItsProvenanceImportsAgain) {
  const CampaignSpec spec = parse_campaign_spec(spec_of("standard_re100"));
  const ImportSummary first = import_campaign(*db_, spec, units_of("standard_re100"));
  const std::string header =
      units_provenance(*db_, first.campaign_id, {"Command: draglab campaign run ..."});
  EXPECT_NE(header.find("# Spec hash (SHA-256 of the canonical spec): " + first.spec_hash + "\n"),
            std::string::npos)
      << header;
  EXPECT_NE(header.find("# Units: " + std::to_string(first.units) + ", done " +
                        std::to_string(first.done) + ", failed " + std::to_string(first.failed) +
                        ", not run " + std::to_string(first.pending)),
            std::string::npos)
      << header;
  EXPECT_NE(header.find("# Command: draglab campaign run ...\n"), std::string::npos) << header;
  for (const std::string& version : first.code_versions) {
    EXPECT_NE(header.find(version), std::string::npos) << header;
  }
  const std::string file = dir_.file("exported.csv");
  campaign_test::write_file(file, header + export_units(*db_, first.campaign_id).csv);
  DatabaseOptions o;
  o.seed_literature = false;
  Database other(dir_.file("other.db"), o);
  const ImportSummary again = import_campaign(other, spec, file);
  EXPECT_EQ(again.done, first.done);
  EXPECT_EQ(again.pending, first.pending);
  EXPECT_EQ(rows_without_ids(export_units(other, again.campaign_id).csv),
            rows_without_ids(export_units(*db_, first.campaign_id).csv));
}

TEST_F(CampaignImport, EveryMalformedFileIsRefusedNamingFileLineAndColumn) {
  const std::string part = "standard_re100";
  struct Case {
    std::string name;
    std::function<std::string(std::string)> edit;
    std::vector<std::string> said;
  };
  const auto replace_first = [](std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  // The first done unit's row: its line and its F column (the 16th).
  const std::string text = campaign_test::read_file(units_of(part));
  std::istringstream in(text);
  int line_number = 0, done_line = 0;
  std::string done_row;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    if (done_line == 0 && line.find(",done,") != std::string::npos) {
      done_line = line_number;
      done_row = line;
    }
  }
  ASSERT_GT(done_line, 0);
  // The lines of the header and of the spec-hash comment.
  int header_line = 0, hash_line = 0;
  {
    std::istringstream lines(text);
    int n = 0;
    for (std::string l; std::getline(lines, l);) {
      ++n;
      if (hash_line == 0 && l.rfind("# Spec hash", 0) == 0) hash_line = n;
      if (header_line == 0 && l.rfind("id,", 0) == 0) header_line = n;
    }
  }
  ASSERT_GT(header_line, 0);
  ASSERT_GT(hash_line, 0);
  const auto with_F = [&](const std::string& value) {
    std::vector<std::size_t> commas;
    for (std::size_t i = 0; i < done_row.size() && commas.size() < 16; ++i) {
      if (done_row[i] == ',') commas.push_back(i);
    }
    return done_row.substr(0, commas[14] + 1) + value + done_row.substr(commas[15]);
  };
  const std::string line = " line " + std::to_string(done_line);
  const std::vector<Case> cases = {
      {"renamed_column",
       [&](std::string t) { return replace_first(t, ",F,beta", ",Fd,beta"); },
       {"unknown column 'Fd'"}},
      {"missing_column",
       [&](std::string t) { return replace_first(t, ",mflups,", ","); },
       {"line " + std::to_string(header_line) + ": column 'mflups' is missing"}},
      {"extra_field",
       [&](std::string t) { return replace_first(t, done_row, done_row + ",1"); },
       {line, "28 fields, the header has 27"}},
      {"nan_drag",
       [&](std::string t) { return replace_first(t, done_row, with_F("nan")); },
       {line, "column 'F'", "not a finite number"}},
      {"text_drag",
       [&](std::string t) { return replace_first(t, done_row, with_F("abc")); },
       {line, "column 'F'", "not a number"}},
      {"empty_drag",
       [&](std::string t) { return replace_first(t, done_row, with_F("")); },
       {line, "column 'F'", "a done unit needs a positive number"}},
      {"duplicate_unit",
       [&](std::string t) { return t + done_row + "\n"; },
       {"appears twice", line}},
      {"missing_unit",
       [&](std::string t) { return replace_first(t, done_row + "\n", ""); },
       {"is missing"}},
      {"other_spec_hash",
       [&](std::string t) { return replace_first(t, "canonical spec): 8", "canonical spec): 9"); },
       {"line " + std::to_string(hash_line) + ": the file names spec hash",
        "the file is a run of another spec"}},
      {"unknown_status",
       [&](std::string t) { return replace_first(t, ",done,", ",finished,"); },
       {line, "column 'status'"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = variant(part, c.name, c.edit);
    const std::string message = refusal(part, path);
    EXPECT_NE(message.find(path), std::string::npos) << message;
    for (const std::string& s : c.said) EXPECT_NE(message.find(s), std::string::npos) << message;
  }
  // Another part's file under this spec (without the spec-hash comment): its rows are not units
  // of this spec.
  const std::string low = variant("standard_low", "low_as_re100", [](std::string t) {
    std::istringstream lines(t);
    std::string out;
    for (std::string l; std::getline(lines, l);) {
      if (l.rfind("# Spec hash", 0) != 0) out += l + "\n";
    }
    return out;
  });
  const std::string message = refusal(part, low);
  EXPECT_NE(message.find("the file is not a run of this spec"), std::string::npos) << message;
  // A campaign of the same name is already in the database.
  import_campaign(*db_, parse_campaign_spec(spec_of(part)), units_of(part));
  EXPECT_NE(refusal(part, units_of(part)).find("already in the database"), std::string::npos);
}

TEST_F(CampaignImport, TheCommandLineRefusesBadInputWithExit2BeforeCreatingADatabase) {
  const std::string fresh = dir_.file("fresh.db");
  const std::string bad = variant("standard_re100", "bad", [](std::string t) {
    return t.replace(t.find(",F,beta"), 7, ",Fd,beta");
  });
  std::string out, err;
  EXPECT_EQ(
      campaign_test::run_cli({"--db", fresh, "campaign", "import", spec_of("standard_re100"), bad},
                             dir_.path(), &out, &err),
      2)
      << err;
  EXPECT_NE(err.find("unknown column 'Fd'"), std::string::npos) << err;
  EXPECT_FALSE(campaign_test::exists(fresh)) << "no database is created for a refused file";
  EXPECT_EQ(campaign_test::run_cli({"--db", fresh, "campaign", "import", spec_of("standard_re100"),
                                    units_of("standard_re100")},
                                   dir_.path(), &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("imported campaign 'standard_re100'"), std::string::npos) << out;
  // A part with units not finished says how to run them.
  const std::string with_pending = variant("standard_re100", "pending", [](std::string t) {
    const std::size_t at = t.find(",failed,");
    const std::size_t row = t.rfind('\n', at) + 1;
    const std::size_t end = t.find('\n', at);
    std::vector<std::string> f;
    std::string cell;
    std::istringstream fields(t.substr(row, end - row));
    for (int i = 0; i < 12 && std::getline(fields, cell, ','); ++i) f.push_back(cell);
    f[10] = "pending";
    std::string pending;
    for (const std::string& c : f) pending += c + ",";
    return t.substr(0, row) + pending + std::string(14, ',') + t.substr(end);
  });
  const std::string other = dir_.file("other.db");
  EXPECT_EQ(campaign_test::run_cli(
                {"--db", other, "campaign", "import", spec_of("standard_re100"), with_pending},
                dir_.path(), &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("1 to run"), std::string::npos) << out;
  EXPECT_NE(out.find("campaign run " + spec_of("standard_re100") + " --resume"), std::string::npos)
      << out;
}

}  // namespace
}  // namespace campaign
}  // namespace draglab
