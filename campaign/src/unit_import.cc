// campaign/src/unit_import.cc: a campaign restored from its spec and the CSV of its units
// (draglab campaign import), the inverse of unit_export.cc. A dataset computed in parts keeps
// each part's units in the repository, not in a database that a machine may lose; importing
// them gives back the campaign, whose pending units `campaign run --resume` then computes.
//
// Stages: read the file (comments, quoted RFC 4180 fields), check its header against the
// schema's columns, parse each row into typed values, match every row to a unit of the spec
// (the same indices, phi, Re, d and seed: the file is a run of this spec), then write the
// campaign and its units in one transaction (nothing is stored if any check fails).
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "campaign_internal.h"
#include "db/sqlite_util.h"
#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"
#include "runner_internal.h"

namespace draglab {
namespace campaign {
namespace {

using db::Statement;
using db::Transaction;

[[noreturn]] void bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

/// One CSV record and the line it starts on.
struct Record {
  int line = 0;
  std::vector<std::string> fields;
};

/// The file's records (the first is the header) and its spec-hash comment, if any.
struct UnitsFile {
  std::string path;
  std::vector<Record> records;
  std::string spec_hash;
  int spec_hash_line = 0;
};

std::string read_text(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    bad("units file '" + path + "' is a directory, not a file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) bad("units file '" + path + "' cannot be read: " + std::strerror(errno));
  std::ostringstream whole;
  whole << file.rdbuf();
  std::string text = whole.str();
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\r' && c != '\n') {
      bad("units file '" + path + "' is not a text file (byte " + std::to_string(i) +
          " is a control character)");
    }
  }
  return text;
}

/// Records of RFC 4180 CSV (quoted fields may hold commas, doubled quotes and line breaks);
/// lines starting with '#' outside a record are comments.
UnitsFile split_records(const std::string& path, const std::string& text) {
  UnitsFile file;
  file.path = path;
  const std::string hash_key = "# Spec hash (SHA-256 of the canonical spec): ";
  int line = 1;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t eol = text.find('\n', i);
    const std::size_t end = eol == std::string::npos ? text.size() : eol;
    if (text[i] == '#' || text.find_first_not_of(" \t\r", i) >= end) {
      if (text.compare(i, hash_key.size(), hash_key) == 0) {
        file.spec_hash = text.substr(i + hash_key.size(), end - i - hash_key.size());
        while (!file.spec_hash.empty() &&
               std::isspace(static_cast<unsigned char>(file.spec_hash.back()))) {
          file.spec_hash.pop_back();
        }
        file.spec_hash_line = line;
      }
      i = end + 1;
      ++line;
      continue;
    }
    Record record;
    record.line = line;
    record.fields.emplace_back();
    bool quoted = false;
    for (; i < text.size(); ++i) {
      const char c = text[i];
      if (quoted) {
        if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
          record.fields.back() += '"';
          ++i;
        } else if (c == '"') {
          quoted = false;
        } else {
          if (c == '\n') ++line;
          record.fields.back() += c;
        }
      } else if (c == '"') {
        quoted = true;
      } else if (c == ',') {
        record.fields.emplace_back();
      } else if (c == '\n') {
        break;
      } else if (c != '\r') {
        record.fields.back() += c;
      }
    }
    if (quoted) {
      bad("'" + path + "' line " + std::to_string(record.line) +
          ": a quoted field is not closed before the end of the file");
    }
    ++i;
    ++line;
    file.records.push_back(std::move(record));
  }
  if (file.records.empty()) bad("units file '" + path + "' has no header and no unit");
  return file;
}

/// A column of campaign_units as the schema declares it.
struct Column {
  std::string name, type;
  bool not_null = false;
};

/// The columns of campaign_units (drag_db schema version 4) in the export's order; a test holds
/// this list to the schema, so that a file is checked before any database is opened.
const std::vector<Column>& unit_columns() {
  static const std::vector<Column> kColumns = {{"id", "INTEGER", false},
                                               {"campaign_id", "INTEGER", true},
                                               {"phi_index", "INTEGER", true},
                                               {"re_index", "INTEGER", true},
                                               {"realization", "INTEGER", true},
                                               {"resolution_index", "INTEGER", true},
                                               {"phi", "REAL", true},
                                               {"re_target", "REAL", true},
                                               {"resolution", "REAL", true},
                                               {"seed", "INTEGER", true},
                                               {"status", "TEXT", true},
                                               {"attempts", "INTEGER", true},
                                               {"claimed_by", "TEXT", false},
                                               {"started_at", "TEXT", false},
                                               {"finished_at", "TEXT", false},
                                               {"F", "REAL", false},
                                               {"beta_d2_over_mu", "REAL", false},
                                               {"re", "REAL", false},
                                               {"error_estimate", "REAL", false},
                                               {"steps", "INTEGER", false},
                                               {"wall_s", "REAL", false},
                                               {"mflups", "REAL", false},
                                               {"converged", "INTEGER", false},
                                               {"diagnosis", "TEXT", false},
                                               {"packing_hash", "TEXT", false},
                                               {"code_version", "TEXT", false},
                                               {"result_json", "TEXT", false}};
  return kColumns;
}

std::string column_list(const std::vector<Column>& columns) {
  std::string out;
  for (const Column& c : columns) out += (out.empty() ? "" : ",") + c.name;
  return out;
}

/// Position of each schema column in the file; the header must name each exactly once.
std::vector<std::size_t> check_header(const UnitsFile& file, const std::vector<Column>& columns) {
  const Record& header = file.records.front();
  const std::string where = "'" + file.path + "' line " + std::to_string(header.line);
  std::map<std::string, std::size_t> position;
  for (std::size_t c = 0; c < header.fields.size(); ++c) {
    if (!position.emplace(header.fields[c], c).second) {
      bad(where + ": the header names column '" + header.fields[c] + "' twice");
    }
  }
  std::set<std::string> known;
  for (const Column& c : columns) known.insert(c.name);
  for (const std::string& name : header.fields) {
    if (!known.count(name)) {
      bad(where + ": unknown column '" + name + "' (a units file has the columns of `draglab " +
          "campaign export --csv`: " + column_list(columns) + ")");
    }
  }
  std::vector<std::size_t> out;
  for (const Column& c : columns) {
    const auto it = position.find(c.name);
    if (it == position.end()) {
      bad(where + ": column '" + c.name + "' is missing (a units file has the columns of " +
          "`draglab campaign export --csv`: " + column_list(columns) + ")");
    }
    out.push_back(it->second);
  }
  return out;
}

/// A typed cell: null, integer, real or text.
struct Value {
  enum class Kind { kNull, kInteger, kReal, kText } kind = Kind::kNull;
  std::int64_t integer = 0;
  double real = 0.0;
  std::string text;
};

/// One row of the file, by column name, and where it came from.
struct ImportedUnit {
  int line = 0;
  std::map<std::string, Value> values;
  const Value& at(const std::string& name) const { return values.at(name); }
  std::int64_t index(const std::string& name) const { return at(name).integer; }
  bool finished() const {
    const std::string& s = at("status").text;
    return s == "done" || s == "failed";
  }
};

Value parse_cell(const std::string& cell, const Column& column, const std::string& where) {
  Value v;
  if (cell.empty()) {
    if (column.not_null) bad(where + ": empty, but every unit has one");
    return v;
  }
  if (column.type == "INTEGER") {
    char* end = nullptr;
    errno = 0;
    const long long x = std::strtoll(cell.c_str(), &end, 10);
    if (errno != 0 || end == cell.c_str() || *end != '\0') {
      bad(where + ": '" + cell + "' is not an integer");
    }
    v.kind = Value::Kind::kInteger;
    v.integer = x;
  } else if (column.type == "REAL") {
    char* end = nullptr;
    const double x = std::strtod(cell.c_str(), &end);
    if (end == cell.c_str() || *end != '\0') bad(where + ": '" + cell + "' is not a number");
    if (!std::isfinite(x)) bad(where + ": '" + cell + "' is not a finite number");
    v.kind = Value::Kind::kReal;
    v.real = x;
  } else {
    v.kind = Value::Kind::kText;
    v.text = cell;
  }
  return v;
}

std::vector<ImportedUnit> parse_rows(const UnitsFile& file, const std::vector<Column>& columns,
                                     const std::vector<std::size_t>& position) {
  const std::size_t width = file.records.front().fields.size();
  std::vector<ImportedUnit> units;
  for (std::size_t r = 1; r < file.records.size(); ++r) {
    const Record& record = file.records[r];
    const std::string line = "'" + file.path + "' line " + std::to_string(record.line);
    if (record.fields.size() != width) {
      bad(line + ": " + std::to_string(record.fields.size()) + " fields, the header has " +
          std::to_string(width));
    }
    ImportedUnit unit;
    unit.line = record.line;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string where = line + ", column '" + columns[c].name + "'";
      unit.values[columns[c].name] = parse_cell(record.fields[position[c]], columns[c], where);
    }
    units.push_back(std::move(unit));
  }
  return units;
}

/// What a finished unit must carry for the dataset and the audit trail.
void check_unit_state(const UnitsFile& file, const ImportedUnit& u) {
  const std::string line = "'" + file.path + "' line " + std::to_string(u.line);
  const std::string& status = u.at("status").text;
  static const std::set<std::string> kStatuses = {"pending", "running", "done", "failed"};
  if (!kStatuses.count(status)) {
    bad(line + ", column 'status': '" + status + "' (one of pending, running, done, failed)");
  }
  const Value& record = u.at("result_json");
  if (record.kind == Value::Kind::kText) {
    const auto parsed = nlohmann::json::parse(record.text, nullptr, false);
    if (parsed.is_discarded() || !parsed.is_object()) {
      bad(line + ", column 'result_json': not a JSON object");
    }
  }
  if (status == "done") {
    for (const char* name : {"F", "beta_d2_over_mu", "re", "error_estimate", "wall_s"}) {
      const Value& v = u.at(name);
      const bool stokes_re = std::string(name) == "re" && v.real == 0.0;
      if (v.kind != Value::Kind::kReal || !(v.real > 0.0 || stokes_re)) {
        bad(line + ", column '" + name + "': a done unit needs a positive number here" +
            (std::string(name) == "re" ? " (0 in Stokes flow)" : ""));
      }
    }
    for (const char* name : {"code_version", "packing_hash", "result_json", "finished_at"}) {
      if (u.at(name).kind != Value::Kind::kText) {
        bad(line + ", column '" + std::string(name) + "': a done unit needs it");
      }
    }
  }
  if (status == "failed" && u.at("diagnosis").kind != Value::Kind::kText) {
    bad(line + ", column 'diagnosis': a failed unit needs the engine's diagnosis");
  }
}

using UnitKey = std::tuple<std::int64_t, std::int64_t, std::int64_t, std::int64_t>;

std::string describe(const CampaignSpec& spec, const UnitKey& k) {
  std::ostringstream out;
  out << "phi " << spec.phi[std::get<0>(k)] << ", Re " << spec.re[std::get<1>(k)]
      << ", realization " << std::get<2>(k) << ", resolution index " << std::get<3>(k);
  return out.str();
}

/// Every row is a unit of this spec (indices in range; phi, Re, d and seed as the spec gives
/// them), no unit appears twice and none is missing.
void match_to_spec(const UnitsFile& file, const CampaignSpec& spec,
                   const std::vector<ImportedUnit>& units) {
  const std::string origin = "the spec '" + spec.name + "'";
  std::map<UnitKey, int> seen;
  for (const ImportedUnit& u : units) {
    const std::string line = "'" + file.path + "' line " + std::to_string(u.line);
    const auto in_range = [&](const char* name, std::int64_t size) {
      const std::int64_t i = u.index(name);
      if (i < 0 || i >= size) {
        bad(line + ", column '" + name + "': " + std::to_string(i) + " outside [0, " +
            std::to_string(size - 1) + "] of " + origin);
      }
    };
    in_range("phi_index", static_cast<std::int64_t>(spec.phi.size()));
    in_range("re_index", static_cast<std::int64_t>(spec.re.size()));
    in_range("realization", spec.realizations);
    const double phi = spec.phi[u.index("phi_index")];
    const double re = spec.re[u.index("re_index")];
    const std::vector<double> d = spec.point_resolutions(phi, re);
    in_range("resolution_index", static_cast<std::int64_t>(d.size()));
    const auto same = [&](const char* name, double expected) {
      if (u.at(name).real != expected) {
        std::ostringstream msg;
        msg.precision(17);
        msg << line << ", column '" << name << "': " << u.at(name).real << " where " << origin
            << " gives " << expected << " for this unit: the file is not a run of this spec";
        bad(msg.str());
      }
    };
    same("phi", phi);
    same("re_target", re);
    same("resolution", d[u.index("resolution_index")]);
    const auto seed = static_cast<std::int64_t>(
        internal::packing_seed(spec.seed, static_cast<int>(u.index("phi_index")),
                               static_cast<int>(u.index("realization"))));
    if (u.index("seed") != seed) {
      bad(line + ", column 'seed': " + std::to_string(u.index("seed")) + " where " + origin +
          " gives " + std::to_string(seed) + ": the file is not a run of this spec");
    }
    const UnitKey key{u.index("phi_index"), u.index("re_index"), u.index("realization"),
                      u.index("resolution_index")};
    const auto [it, fresh] = seen.emplace(key, u.line);
    if (!fresh) {
      bad(line + ": unit (" + describe(spec, key) + ") appears twice (also line " +
          std::to_string(it->second) + ")");
    }
  }
  for (std::size_t i = 0; i < spec.phi.size(); ++i) {
    for (std::size_t j = 0; j < spec.re.size(); ++j) {
      const std::size_t resolutions = spec.point_resolutions(spec.phi[i], spec.re[j]).size();
      for (int r = 0; r < spec.realizations; ++r) {
        for (std::size_t k = 0; k < resolutions; ++k) {
          const UnitKey key{i, j, r, k};
          if (!seen.count(key)) {
            bad("'" + file.path + "': unit (" + describe(spec, key) + ") of " + origin +
                " is missing: a units file lists every unit of its spec (campaign export --csv)");
          }
        }
      }
    }
  }
}

void bind_value(Statement& s, int index, const Value& v) {
  switch (v.kind) {
    case Value::Kind::kNull:
      s.bind_null(index);
      break;
    case Value::Kind::kInteger:
      s.bind(index, v.integer);
      break;
    case Value::Kind::kReal:
      s.bind(index, v.real);
      break;
    case Value::Kind::kText:
      s.bind(index, v.text);
      break;
  }
}

/// The campaign and its units, in one transaction: finished units as the file has them, the
/// others pending (a checkpoint does not travel with the file).
std::int64_t store(Database& db, const CampaignSpec& spec, const std::vector<ImportedUnit>& units) {
  Transaction tx(db.handle(), Transaction::Kind::kWrite);
  const std::string spec_json = spec.to_json();
  const std::int64_t id =
      runner::insert_campaign(db, spec, spec_json, draglab::sha256_hex(spec_json));
  static const std::vector<std::string> kCarried = {
      "attempts",  "claimed_by",     "started_at",   "finished_at", "F",      "beta_d2_over_mu",
      "re",        "error_estimate", "steps",        "wall_s",      "mflups", "converged",
      "diagnosis", "packing_hash",   "code_version", "result_json"};
  std::string sql = "UPDATE campaign_units SET status = ?";
  for (const std::string& c : kCarried) sql += ", " + c + " = ?";
  sql +=
      " WHERE campaign_id = ? AND phi_index = ? AND re_index = ? AND realization = ? AND "
      "resolution_index = ?";
  Statement s(db.handle(), sql);
  for (const ImportedUnit& u : units) {
    s.reset();
    const bool finished = u.finished();
    s.bind(1, finished ? u.at("status").text : std::string("pending"));
    int index = 2;
    for (const std::string& c : kCarried) {
      if (finished || c == "attempts") {
        Value v = u.at(c);
        // A finished unit's empty diagnosis is the empty text the runner stored.
        if (c == "diagnosis" && v.kind == Value::Kind::kNull) v.kind = Value::Kind::kText;
        bind_value(s, index, v);
      } else {
        s.bind_null(index);
      }
      ++index;
    }
    s.bind(index, id).bind(index + 1, u.index("phi_index")).bind(index + 2, u.index("re_index"));
    s.bind(index + 3, u.index("realization")).bind(index + 4, u.index("resolution_index"));
    s.run();
  }
  tx.commit();
  return id;
}

}  // namespace

std::string ImportSummary::BriefReport() const {
  std::ostringstream out;
  out << "imported campaign '" << name << "' (id " << campaign_id << "): " << units << " units, "
      << done << " done, " << failed << " failed, " << pending << " to run";
  if (!code_versions.empty()) {
    out << "; finished by";
    for (const std::string& v : code_versions) out << " " << v;
  }
  return out.str();
}

std::string ImportSummary::ToJson() const {
  return nlohmann::json{{"campaign_id", campaign_id},
                        {"campaign", name},
                        {"spec_hash", spec_hash},
                        {"units", units},
                        {"done", done},
                        {"failed", failed},
                        {"pending", pending},
                        {"code_versions", code_versions}}
      .dump(2);
}

namespace {

/// Every check of a units file against its spec; the file's units.
std::vector<ImportedUnit> read_checked(const CampaignSpec& spec, const std::string& units_path) {
  std::string why;
  if (!spec.IsValid(&why)) bad("campaign import: the spec is not valid: " + why);
  const std::string spec_hash = draglab::sha256_hex(spec.to_json());
  const UnitsFile file = split_records(units_path, read_text(units_path));
  if (!file.spec_hash.empty() && file.spec_hash != spec_hash) {
    bad("'" + units_path + "' line " + std::to_string(file.spec_hash_line) +
        ": the file names spec hash " + file.spec_hash.substr(0, 12) + ", the spec '" + spec.name +
        "' has " + spec_hash.substr(0, 12) + ": the file is a run of another spec");
  }
  const std::vector<std::size_t> position = check_header(file, unit_columns());
  std::vector<ImportedUnit> units = parse_rows(file, unit_columns(), position);
  for (const ImportedUnit& u : units) check_unit_state(file, u);
  match_to_spec(file, spec, units);
  return units;
}

}  // namespace

std::vector<std::string> units_file_columns() {
  std::vector<std::string> names;
  for (const Column& c : unit_columns()) names.push_back(c.name + " " + c.type);
  return names;
}

void check_units_file(const CampaignSpec& spec, const std::string& units_path) {
  read_checked(spec, units_path);
}

ImportSummary import_campaign(Database& db, const CampaignSpec& spec,
                              const std::string& units_path) {
  const std::vector<ImportedUnit> units = read_checked(spec, units_path);
  runner::require_campaign_tables(db);
  const std::int64_t existing = runner::find_campaign(db, spec.name, nullptr);
  if (existing != 0) {
    bad("campaign '" + spec.name + "' is already in the database (id " + std::to_string(existing) +
        "): import into a database without it, or resume it there");
  }

  ImportSummary summary;
  summary.campaign_id = store(db, spec, units);
  summary.name = spec.name;
  summary.spec_hash = draglab::sha256_hex(spec.to_json());
  summary.units = static_cast<std::int64_t>(units.size());
  for (const ImportedUnit& u : units) {
    const std::string& status = u.at("status").text;
    if (status == "done") ++summary.done;
    if (status == "failed") ++summary.failed;
    if (!u.finished()) ++summary.pending;
    if (u.finished() && u.at("code_version").kind == Value::Kind::kText) {
      summary.code_versions.insert(u.at("code_version").text);
    }
  }
  return summary;
}

}  // namespace campaign
}  // namespace draglab
