// Database: the SQLite drag-law database (database.h, docs/database.md).
//
// Every public write is one BEGIN IMMEDIATE transaction; a failure rolls it back, so nothing is
// ever half-written. Reads that touch several tables run in one read transaction, which in WAL
// mode is a consistent snapshot even while another connection commits.
#include "draglab/drag_db/database.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "db/schema.h"
#include "db/sqlite_util.h"
#include "drag_db_version.h"
#include "draglab/error.h"

namespace draglab {
void check_law_name(const std::string& name) {
  const bool charset_ok = std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_' || c == '-' || c == '.';
  });
  constexpr std::size_t kMaxLength = 100;
  if (name.empty() || name.size() > kMaxLength || !charset_ok ||
      std::isalnum(static_cast<unsigned char>(name[0])) == 0) {
    throw Error(ErrorCode::kInvalidArgument,
                "law name '" + name + "' is invalid: use 1 to " + std::to_string(kMaxLength) +
                    " characters from A-Z a-z 0-9 _ . - starting with a letter or digit (no '@')");
  }
}

namespace {

using db::Statement;
using db::Transaction;

constexpr std::size_t kMinHashPrefix = 4;
// Known names listed in a "no such law" error before it is shortened.
constexpr std::size_t kMaxNamesInError = 40;

// Columns of `laws` read into a LawRecord, in the order read_law_row expects.
constexpr const char* kLawColumns =
    "id, name, version, form, force_kind, normalisation, reynolds, tfm_model, phi_min, phi_max, "
    "re_min, re_max, provenance_kind, citation, dataset_id, data_hash, fitter_settings, "
    "code_version, content_hash, status, created_at, notes, retraction_reason, published_at, "
    "retracted_at";

struct StoredLaw {
  std::int64_t id = 0;
  LawRecord record;
  std::string published_at;
  std::string retracted_at;
};

std::string in_quotes(const std::string& s) { return "'" + s + "'"; }

std::string fmt_double(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string join(const std::vector<std::string>& items, const char* separator = ", ") {
  std::string out;
  for (const std::string& item : items) {
    if (!out.empty()) out += separator;
    out += item;
  }
  return out;
}

StoredLaw read_law_row(const Statement& s) {
  StoredLaw out;
  LawRecord& r = out.record;
  out.id = s.integer(0);
  r.name = s.text(1);
  r.version = static_cast<int>(s.integer(2));
  r.form = s.text(3);
  r.convention.force = force_kind_from_string(s.text(4));
  r.convention.normalisation = normalisation_from_string(s.text(5));
  r.convention.reynolds = reynolds_definition_from_string(s.text(6));
  r.convention.tfm_model = tfm_model_from_string(s.text(7));
  r.validity.phi = {s.real(8), s.real(9)};
  r.validity.re = {s.real(10), s.real(11)};
  r.provenance.kind = s.text(12);
  r.provenance.citation = s.text(13);
  r.provenance.dataset_id = s.text(14);
  r.provenance.data_hash = s.text(15);
  r.provenance.fitter_settings = s.text(16);
  r.provenance.code_version = s.text(17);
  r.content_hash = s.text(18);
  r.status = law_status_from_string(s.text(19));
  r.created_at = s.text(20);
  r.notes = s.text(21);
  r.retraction_reason = s.text(22);
  out.published_at = s.text(23);
  out.retracted_at = s.text(24);
  return out;
}

// Reads the parameter, covariance and extra-input rows of law `id` into `r`.
void read_children(sqlite3* db, std::int64_t id, LawRecord& r) {
  Statement params(db,
                   "SELECT name, value, unit FROM law_parameters WHERE law_id = ?1 "
                   "ORDER BY position");
  params.bind(1, id);
  while (params.step()) r.parameters.push_back({params.text(0), params.real(1), params.text(2)});

  Statement extra(db,
                  "SELECT name, description, min_value, max_value FROM law_extra_inputs "
                  "WHERE law_id = ?1 ORDER BY position");
  extra.bind(1, id);
  while (extra.step()) {
    ExtraInputSpec e;
    e.name = extra.text(0);
    e.description = extra.text(1);
    e.range = {extra.real(2), extra.real(3)};
    r.validity.extra.push_back(e);
  }

  const std::size_t n = r.parameters.size();
  Statement cov(db,
                "SELECT row_index, col_index, value FROM law_covariance WHERE law_id = ?1 "
                "ORDER BY row_index, col_index");
  cov.bind(1, id);
  std::vector<double> values;
  std::size_t count = 0;
  while (cov.step()) {
    if (values.empty()) values.assign(n * n, 0.0);
    const auto i = static_cast<std::size_t>(cov.integer(0));
    const auto j = static_cast<std::size_t>(cov.integer(1));
    if (i >= n || j >= n) {
      throw Error(ErrorCode::kDatabase, r.reference() + ": covariance entry (" + std::to_string(i) +
                                            ", " + std::to_string(j) + ") is outside the " +
                                            std::to_string(n) + " x " + std::to_string(n) +
                                            " parameter matrix");
    }
    values[i * n + j] = cov.real(2);
    ++count;
  }
  if (count != 0 && count != n * n) {
    throw Error(ErrorCode::kDatabase, r.reference() + ": covariance has " + std::to_string(count) +
                                          " entries, expected " + std::to_string(n * n));
  }
  r.covariance = std::move(values);
}

// Laws matching `name` ("" = all), ordered by name then version, with their child rows.
std::vector<StoredLaw> query_laws(sqlite3* db, const std::string& name, bool include_drafts) {
  std::string sql = std::string("SELECT ") + kLawColumns + " FROM laws WHERE 1";
  if (!name.empty()) sql += " AND name = ?1";
  if (!include_drafts) sql += " AND status <> 'draft'";
  sql += " ORDER BY name, version";
  Statement s(db, sql);
  if (!name.empty()) s.bind(1, name);
  std::vector<StoredLaw> out;
  while (s.step()) out.push_back(read_law_row(s));
  for (StoredLaw& law : out) read_children(db, law.id, law.record);
  return out;
}

std::optional<StoredLaw> find_version(sqlite3* db, const std::string& name, int version) {
  Statement s(db,
              std::string("SELECT ") + kLawColumns + " FROM laws WHERE name = ?1 AND version = ?2");
  s.bind(1, name).bind(2, version);
  if (!s.step()) return std::nullopt;
  StoredLaw law = read_law_row(s);
  read_children(db, law.id, law.record);
  return law;
}

std::vector<std::string> known_names(sqlite3* db) {
  Statement s(db, "SELECT DISTINCT name FROM laws ORDER BY name");
  std::vector<std::string> names;
  while (s.step()) names.push_back(s.text(0));
  return names;
}

Error unknown_name_error(sqlite3* db, const std::string& name) {
  std::vector<std::string> names = known_names(db);
  std::string message =
      "no law named " + in_quotes(name) + " in database " + in_quotes(db::database_path(db));
  if (names.empty()) return Error(ErrorCode::kNotFound, message + " (the database holds no laws)");
  std::string list;
  if (names.size() > kMaxNamesInError) {
    const std::size_t more = names.size() - kMaxNamesInError;
    names.resize(kMaxNamesInError);
    list = join(names) + ", ... (" + std::to_string(more) + " more)";
  } else {
    list = join(names);
  }
  return Error(ErrorCode::kNotFound, message + "; known laws: " + list);
}

std::string versions_summary(const std::vector<StoredLaw>& versions) {
  std::vector<std::string> items;
  for (const StoredLaw& v : versions) {
    items.push_back(std::to_string(v.record.version) + " " + to_string(v.record.status));
  }
  return join(items);
}

// The stored version `name@version`, or Error(kNotFound) naming the versions that exist.
StoredLaw require_version(sqlite3* db, const std::string& name, int version) {
  std::optional<StoredLaw> law = find_version(db, name, version);
  if (law) return *law;
  std::vector<StoredLaw> versions = query_laws(db, name, true);
  if (versions.empty()) throw unknown_name_error(db, name);
  throw Error(ErrorCode::kNotFound, "law " + in_quotes(name) + " has no version " +
                                        std::to_string(version) +
                                        " (versions: " + versions_summary(versions) + ")");
}

bool is_all_digits(const std::string& s) {
  return !s.empty() &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

bool is_hex(const std::string& s) {
  return !s.empty() &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isxdigit(c) != 0; });
}

std::string to_lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// ---- validation of a record before it is stored ------------------------------------------

void invalid(const std::string& who, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, who + ": " + what);
}

void validate_name(const std::string& name) { check_law_name(name); }

void validate_range(const std::string& who, const std::string& what, const InputRange& r) {
  if (std::isnan(r.min) || std::isnan(r.max) || r.min > r.max) {
    invalid(who, "validity range of " + what + " [" + fmt_double(r.min) + ", " + fmt_double(r.max) +
                     "] is not an interval (min <= max, no NaN)");
  }
}

// Checks everything add_draft/update_draft store: form, parameters, covariance, convention,
// validity box and provenance. Throws Error(kInvalidArgument) naming the field and its range,
// or Error(kNotFound) for an unknown form.
void validate_record(const LawRecord& r) {
  const std::string who = "law " + in_quotes(r.name);
  validate_name(r.name);
  const LawForm& form = find_law_form(r.form);

  const auto& specs = form.description.parameters;
  if (r.parameters.size() != specs.size()) {
    invalid(who, "form " + in_quotes(r.form) + " takes " + std::to_string(specs.size()) +
                     " parameters, the record has " + std::to_string(r.parameters.size()));
  }
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const LawParameter& p = r.parameters[i];
    if (p.name != specs[i].name) {
      invalid(who, "parameter " + std::to_string(i) + " is " + in_quotes(p.name) + ", form " +
                       in_quotes(r.form) + " expects " + in_quotes(specs[i].name));
    }
    if (!std::isfinite(p.value)) {
      invalid(who,
              "parameter " + in_quotes(p.name) + " = " + fmt_double(p.value) + " must be finite");
    }
    if (p.unit.empty()) invalid(who, "parameter " + in_quotes(p.name) + " has no unit (use \"1\")");
  }

  const std::size_t n = r.parameters.size();
  if (!r.covariance.empty()) {
    if (r.covariance.size() != n * n) {
      invalid(who, "covariance has " + std::to_string(r.covariance.size()) + " entries, expected " +
                       std::to_string(n * n) + " (" + std::to_string(n) + " x " +
                       std::to_string(n) + ", row-major) or none");
    }
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        const double c = r.covariance[i * n + j];
        if (!std::isfinite(c)) {
          invalid(who, "covariance entry (" + std::to_string(i) + ", " + std::to_string(j) +
                           ") is not finite");
        }
      }
      if (r.covariance[i * n + i] < 0.0) {
        invalid(who, "covariance diagonal entry " + std::to_string(i) + " (variance of " +
                         in_quotes(r.parameters[i].name) + ") is negative");
      }
    }
    // Symmetry up to rounding: a covariance matrix from a fitter is symmetric by construction,
    // so anything beyond 1e-9 relative to the variances is a transposition or indexing bug.
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        const double scale = std::sqrt(r.covariance[i * n + i] * r.covariance[j * n + j]) + 1e-300;
        if (std::fabs(r.covariance[i * n + j] - r.covariance[j * n + i]) > 1e-9 * scale) {
          invalid(who, "covariance is not symmetric at (" + std::to_string(i) + ", " +
                           std::to_string(j) + ")");
        }
      }
    }
  }

  // The form's code converts from its own native convention, so a record cannot claim another.
  const NativeConvention& c = form.convention;
  if (r.convention.force != c.force || r.convention.normalisation != c.normalisation ||
      r.convention.reynolds != c.reynolds) {
    invalid(who, std::string("native convention (") + to_string(r.convention.force) + ", " +
                     to_string(r.convention.normalisation) + ", " +
                     to_string(r.convention.reynolds) + ") differs from form " + in_quotes(r.form) +
                     "'s (" + to_string(c.force) + ", " + to_string(c.normalisation) + ", " +
                     to_string(c.reynolds) + ")");
  }

  const ValidityBox& box = r.validity;
  validate_range(who, "phi", box.phi);
  validate_range(who, "Re", box.re);
  if (box.phi.min < 0.0 || box.phi.max >= 1.0) {
    invalid(who, "validity range of phi [" + fmt_double(box.phi.min) + ", " +
                     fmt_double(box.phi.max) + "] must lie within [0, 1)");
  }
  if (box.re.min < 0.0) {
    invalid(who, "validity range of Re starts at " + fmt_double(box.re.min) + ", must be >= 0");
  }
  const auto& extra_specs = form.description.validity.extra;
  if (box.extra.size() != extra_specs.size()) {
    invalid(who, "validity box declares " + std::to_string(box.extra.size()) +
                     " extra inputs, form " + in_quotes(r.form) + " takes " +
                     std::to_string(extra_specs.size()));
  }
  for (std::size_t k = 0; k < extra_specs.size(); ++k) {
    if (box.extra[k].name != extra_specs[k].name) {
      invalid(who, "extra input " + std::to_string(k) + " is " + in_quotes(box.extra[k].name) +
                       ", form " + in_quotes(r.form) + " expects " +
                       in_quotes(extra_specs[k].name));
    }
    validate_range(who, "extra input " + in_quotes(box.extra[k].name), box.extra[k].range);
  }

  const Provenance& p = r.provenance;
  if (p.kind != "literature" && p.kind != "fitted" && p.kind != "manual") {
    invalid(who,
            "provenance kind " + in_quotes(p.kind) + " is not one of: literature, fitted, manual");
  }
  if (p.kind == "literature" && p.citation.empty()) {
    invalid(who, "a literature law needs a citation (provenance.citation)");
  }
  if (p.kind == "fitted" && (p.dataset_id.empty() || p.data_hash.empty())) {
    invalid(who,
            "a fitted law needs the dataset id and data hash it was fitted to "
            "(provenance.dataset_id, provenance.data_hash)");
  }
  if (!p.fitter_settings.empty() && !nlohmann::json::accept(p.fitter_settings)) {
    invalid(who, "provenance.fitter_settings is not valid JSON");
  }
}

// ---- writes (callers hold a write transaction) -------------------------------------------

void bind_content_columns(Statement& s, const LawRecord& r) {
  // Parameters ?3.. of the INSERT/UPDATE statements below, in this order.
  s.bind(3, to_string(r.convention.force));
  s.bind(4, to_string(r.convention.normalisation));
  s.bind(5, to_string(r.convention.reynolds));
  s.bind(6, to_string(r.convention.tfm_model));
  s.bind(7, r.validity.phi.min).bind(8, r.validity.phi.max);
  s.bind(9, r.validity.re.min).bind(10, r.validity.re.max);
  s.bind(11, r.provenance.kind).bind(12, r.provenance.citation);
  s.bind(13, r.provenance.dataset_id).bind(14, r.provenance.data_hash);
  s.bind(15, r.provenance.fitter_settings).bind(16, r.provenance.code_version);
  s.bind(17, r.content_hash).bind(18, r.notes);
}

void insert_children(sqlite3* db, std::int64_t id, const LawRecord& r) {
  Statement param(db,
                  "INSERT INTO law_parameters (law_id, position, name, value, unit) "
                  "VALUES (?1, ?2, ?3, ?4, ?5)");
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const LawParameter& p = r.parameters[i];
    param.bind(1, id).bind(2, static_cast<std::int64_t>(i)).bind(3, p.name);
    param.bind(4, p.value).bind(5, p.unit);
    param.run();
    param.reset();
  }
  Statement extra(db,
                  "INSERT INTO law_extra_inputs (law_id, position, name, description, "
                  "min_value, max_value) VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
  for (std::size_t k = 0; k < r.validity.extra.size(); ++k) {
    const ExtraInputSpec& e = r.validity.extra[k];
    extra.bind(1, id).bind(2, static_cast<std::int64_t>(k)).bind(3, e.name);
    extra.bind(4, e.description).bind(5, e.range.min).bind(6, e.range.max);
    extra.run();
    extra.reset();
  }
  const std::size_t n = r.parameters.size();
  if (!r.covariance.empty()) {
    Statement cov(db,
                  "INSERT INTO law_covariance (law_id, row_index, col_index, value) "
                  "VALUES (?1, ?2, ?3, ?4)");
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        cov.bind(1, id).bind(2, static_cast<std::int64_t>(i));
        cov.bind(3, static_cast<std::int64_t>(j)).bind(4, r.covariance[i * n + j]);
        cov.run();
        cov.reset();
      }
    }
  }
}

void delete_children(sqlite3* db, std::int64_t id) {
  for (const char* table : {"law_parameters", "law_covariance", "law_extra_inputs"}) {
    Statement s(db, std::string("DELETE FROM ") + table + " WHERE law_id = ?1");
    s.bind(1, id);
    s.run();
  }
}

std::string status_phrase(const StoredLaw& law) {
  const LawRecord& r = law.record;
  switch (r.status) {
    case LawStatus::kPublished:
      return "published" + (law.published_at.empty() ? "" : " on " + law.published_at);
    case LawStatus::kRetracted:
      return "retracted" + (law.retracted_at.empty() ? "" : " on " + law.retracted_at) +
             (r.retraction_reason.empty() ? "" : " (" + r.retraction_reason + ")");
    case LawStatus::kDraft:
    default:
      return "a draft";
  }
}

[[noreturn]] void throw_immutable(const StoredLaw& law, const std::string& attempted) {
  throw Error(ErrorCode::kImmutable, "law " + law.record.reference() + " is " + status_phrase(law) +
                                         " and immutable: cannot " + attempted + "; " +
                                         db::kImmutableMarker);
}

// The latest published version among `versions`, or nullptr if none is published.
const StoredLaw* latest_published(const std::vector<StoredLaw>& versions) {
  const StoredLaw* best = nullptr;
  for (const StoredLaw& v : versions) {
    if (v.record.status == LawStatus::kPublished &&
        (!best || v.record.version > best->record.version)) {
      best = &v;
    }
  }
  return best;
}

// Checks the stored content hash against a recomputation (an edit outside draglab shows here).
void verify_content_hash(const LawRecord& r) {
  const std::string computed = content_hash_of(r);
  if (computed != r.content_hash) {
    throw Error(ErrorCode::kDatabase,
                "law " + r.reference() + ": stored content hash " + r.content_hash.substr(0, 12) +
                    "... does not match its form, parameters, convention and validity box (" +
                    computed.substr(0, 12) +
                    "...): the record was changed outside draglab; run a database check");
  }
}

bool file_exists(const std::string& path, struct stat* st) { return ::stat(path.c_str(), st) == 0; }

bool file_exists(const std::string& path) {
  struct stat st {};
  return file_exists(path, &st);
}

// True if `path` exists and holds at least one byte (a -wal or -journal file with content).
bool file_has_content(const std::string& path) {
  struct stat st {};
  return file_exists(path, &st) && st.st_size > 0;
}

std::string parent_directory(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// `path` as an SQLite URI filename ("file:..."), with every byte outside [A-Za-z0-9/._~-]
// percent-encoded so that '?', '#' and '%' in a file name are not read as URI syntax. An absolute
// path gets an empty authority ("file:///abs"), so that one starting with "//" is not read as a
// host name.
std::string sqlite_uri(const std::string& path, const std::string& query) {
  std::string out = path.empty() || path[0] != '/' ? "file:" : "file://";
  for (const char ch : path) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) != 0 || c == '/' || c == '.' || c == '_' || c == '~' || c == '-') {
      out += ch;
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out + "?" + query;
}

// Checks `path` before SQLite sees it, so that the cases SQLite reports only as "unable to open
// database file" get a message naming the path and the right ErrorCode.
void check_database_path(const std::string& path, const DatabaseOptions& options) {
  const bool read_only = options.read_only || options.immutable;
  struct stat st {};
  if (file_exists(path, &st)) {
    if (S_ISDIR(st.st_mode)) {
      throw Error(ErrorCode::kInvalidArgument,
                  in_quotes(path) + " is a directory, not a draglab database file");
    }
    if (!S_ISREG(st.st_mode)) {
      throw Error(ErrorCode::kNotADatabase,
                  in_quotes(path) + " is not a regular file, so not a draglab database");
    }
    if (!read_only && ::access(path.c_str(), W_OK) != 0) {
      throw Error(ErrorCode::kDatabase, "database " + in_quotes(path) + " is not writable (" +
                                            std::strerror(errno) +
                                            "); open it read-only to read it");
    }
    return;
  }
  if (errno != ENOENT && errno != ENOTDIR) {
    throw Error(ErrorCode::kDatabase,
                "cannot access database " + in_quotes(path) + ": " + std::strerror(errno));
  }
  const std::string parent = parent_directory(path);
  struct stat parent_st {};
  if (!file_exists(parent, &parent_st)) {
    if (errno != ENOENT && errno != ENOTDIR) {
      throw Error(ErrorCode::kDatabase, "cannot open database " + in_quotes(path) +
                                            ": cannot access directory " + in_quotes(parent) +
                                            " (" + std::strerror(errno) + ")");
    }
    throw Error(ErrorCode::kInvalidArgument, "cannot open database " + in_quotes(path) +
                                                 ": directory " + in_quotes(parent) +
                                                 " does not exist");
  }
  if (!S_ISDIR(parent_st.st_mode)) {
    throw Error(ErrorCode::kInvalidArgument, "cannot open database " + in_quotes(path) + ": " +
                                                 in_quotes(parent) + " is not a directory");
  }
  if (read_only || !options.create_if_missing) {
    throw Error(ErrorCode::kNotFound, "database file " + in_quotes(path) + " does not exist" +
                                          (read_only ? " (a read-only open does not create it)"
                                                     : " (create_if_missing is off)"));
  }
  // A directory the database cannot be created in is bad input (an output path that cannot be
  // written). Tried with a probe file: access() says yes to root on read-only mounts and /proc.
  std::string probe = (parent == "/" ? std::string() : parent) + "/.draglab_db_probe_XXXXXX";
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) {
    throw Error(ErrorCode::kInvalidArgument, "cannot create database " + in_quotes(path) +
                                                 ": directory " + in_quotes(parent) +
                                                 " is not writable (" + std::strerror(errno) + ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

// Whether a read-only open of `path` must use SQLite's immutable=1. A read-only connection to a
// WAL file uses the -wal file and the -shm index next to it, creating them if they are missing
// (SQLite 3.22+). In a directory the caller cannot write, a missing one cannot be created and
// the open fails; the file can then only be read immutable. That is safe exactly when no
// write-ahead log or rollback journal holds content: nobody can be writing (a writer would need
// to create one of them in that directory) and the file itself is complete. Otherwise throws
// kDatabase saying what to do.
bool needs_immutable_open(const std::string& path) {
  const std::string parent = parent_directory(path);
  if (::access(parent.c_str(), W_OK) == 0) return false;
  if (file_exists(path + "-shm") && file_exists(path + "-wal")) return false;
  const std::string log = file_has_content(path + "-wal")       ? path + "-wal"
                          : file_has_content(path + "-journal") ? path + "-journal"
                                                                : "";
  if (!log.empty()) {
    throw Error(ErrorCode::kDatabase,
                "cannot open database " + in_quotes(path) + " read-only: " + in_quotes(log) +
                    " holds changes not yet written into the database file, and SQLite cannot "
                    "create the -wal/-shm files it needs to read them because directory " +
                    in_quotes(parent) +
                    " is not writable; ask its owner to open the database read-write once (which "
                    "folds the changes into the file), or copy the database and that file to a "
                    "writable directory");
  }
  return true;
}

}  // namespace

// ---- options and reports -----------------------------------------------------------------

bool DatabaseOptions::IsValid(std::string* error) const {
  // One day: a writer that waits longer than that for a lock is stuck, not busy.
  constexpr int kMaxBusyTimeoutMs = 24 * 3600 * 1000;
  if (busy_timeout_ms < 0 || busy_timeout_ms > kMaxBusyTimeoutMs) {
    if (error) {
      *error = "busy_timeout_ms = " + std::to_string(busy_timeout_ms) + " must lie in [0, " +
               std::to_string(kMaxBusyTimeoutMs) + "] (milliseconds)";
    }
    return false;
  }
  return true;
}

std::string DatabaseCheckReport::BriefReport() const {
  std::string line = std::string(ok ? "database OK" : "database has problems") + ": schema " +
                     std::to_string(schema_version) + ", " + std::to_string(laws_checked) +
                     " law versions checked";
  if (!problems.empty()) {
    line += ", " + std::to_string(problems.size()) + " problem" +
            (problems.size() == 1 ? "" : "s") + " (first: " + problems.front() + ")";
  }
  return line;
}

std::string DatabaseCheckReport::FullReport() const {
  std::ostringstream out;
  out << "draglab database check\n";
  out << "  result          : " << (ok ? "OK" : "PROBLEMS FOUND") << "\n";
  out << "  schema version  : " << schema_version << " (this draglab writes "
      << db::latest_schema_version() << ")\n";
  out << "  laws checked    : " << laws_checked << "\n";
  out << "  problems        : " << problems.size() << "\n";
  for (const std::string& p : problems) out << "    - " << p << "\n";
  return out.str();
}

// ---- Database ----------------------------------------------------------------------------

int Database::current_schema_version() { return db::latest_schema_version(); }

std::string Database::default_path() {
  const char* env = std::getenv("DRAGLAB_DB");
  if (env && *env) return env;
  return "./draglab.db";
}

Database::Database(const std::string& path, const DatabaseOptions& options) : path_(path) {
  std::string why;
  if (!options.IsValid(&why)) {
    throw Error(ErrorCode::kInvalidArgument, "invalid database options: " + why);
  }
  if (path.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                "empty database path (Database::default_path() gives $DRAGLAB_DB or "
                "./draglab.db)");
  }
  const bool in_memory = path == ":memory:";
  read_only_ = options.read_only || options.immutable;
  if (!in_memory) check_database_path(path, options);
  immutable_ = !in_memory && (options.immutable || (read_only_ && needs_immutable_open(path)));

  // A file is opened through a URI so that mode=ro and immutable=1 can be given; ":memory:" is
  // SQLite's special name and stays as it is.
  const std::string name = in_memory    ? path
                           : immutable_ ? sqlite_uri(path, "mode=ro&immutable=1")
                           : read_only_ ? sqlite_uri(path, "mode=ro")
                                        : sqlite_uri(path, "mode=rwc");
  const int flags =
      (read_only_ ? SQLITE_OPEN_READONLY : (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE)) |
      SQLITE_OPEN_URI;
  const int rc = sqlite3_open_v2(name.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw Error(ErrorCode::kDatabase, "cannot open database " + in_quotes(path) + ": " + message);
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, options.busy_timeout_ms);

    // Reading the schema is the first access to the file's content: a file that is not SQLite
    // or whose first page is corrupt fails here (kNotADatabase).
    int table_count = 0;
    try {
      Statement s(db_, "SELECT count(*) FROM sqlite_schema");
      s.step();
      table_count = static_cast<int>(s.integer(0));
    } catch (const Error& e) {
      // A read-only connection to a WAL file also opens (or creates) the -wal and -shm files
      // next to it; say so, since SQLite's own message ("unable to open database file",
      // "attempt to write a readonly database") names neither.
      if (!read_only_ || immutable_ || e.code() != ErrorCode::kDatabase) throw;
      throw Error(ErrorCode::kDatabase,
                  std::string(e.what()) + " (a read-only open of a WAL database also needs to " +
                      "read or create " + in_quotes(path + "-wal") + " and " +
                      in_quotes(path + "-shm") +
                      "; check their permissions, or open it immutable if nothing writes to it)");
    }
    {
      Statement s(db_, "PRAGMA application_id");
      s.step();
      const std::int64_t app_id = s.integer(0);
      if (app_id != 0 && app_id != db::kApplicationId) {
        char hex[24];
        std::snprintf(hex, sizeof hex, "0x%08llx", static_cast<unsigned long long>(app_id));
        throw Error(ErrorCode::kNotADatabase, in_quotes(path) +
                                                  " is an SQLite database of another application "
                                                  "(application_id " +
                                                  std::string(hex) + "), not a draglab database");
      }
    }
    int version = db::read_schema_version(db_);
    if (version == 0 && table_count > 0) {
      throw Error(ErrorCode::kNotADatabase, in_quotes(path) +
                                                " is an SQLite database but not a draglab database "
                                                "(it has tables but no schema_version table)");
    }
    if (version > db::latest_schema_version()) {
      throw Error(ErrorCode::kSchemaTooNew,
                  "database " + in_quotes(path) + " has schema version " + std::to_string(version) +
                      ", but this draglab (" + kDragDbVersion + ") knows schema versions up to " +
                      std::to_string(db::latest_schema_version()) + ": upgrade draglab to open it");
    }

    db::exec(db_, "PRAGMA foreign_keys = ON", "enabling foreign keys");
    // Read-only opens leave the journal mode alone: switching it writes the file header.
    if (!read_only_ && !in_memory) {
      // WAL: readers keep a consistent snapshot and are never blocked by a committing writer.
      Statement s(db_, "PRAGMA journal_mode = WAL");
      s.step();
      const std::string mode = to_lower(s.text(0));
      if (mode != "wal") {
        throw Error(ErrorCode::kDatabase, "cannot switch database " + in_quotes(path) +
                                              " to WAL mode (journal mode is " + in_quotes(mode) +
                                              "); is it on a network file system?");
      }
    }

    if (!read_only_ && options.migrate && version < db::latest_schema_version()) {
      Transaction t(db_, Transaction::Kind::kWrite);
      // Re-read under the write lock: another process may have created or migrated the file.
      version = db::read_schema_version(db_);
      const bool new_file = version == 0;
      db::apply_migrations(db_, version, db::latest_schema_version(), kDragDbVersion);
      if (new_file && options.seed_literature) seed_literature();
      t.commit();
    }
  } catch (...) {
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw;
  }
}

Database::~Database() {
  if (db_) sqlite3_close_v2(db_);
}

int Database::schema_version() const { return db::read_schema_version(db_); }

namespace {

// Operations on laws need at least schema 1 (an empty file opened with migrate = false has 0).
// Read-only opens read an older schema as it is (docs/database.md), so every read names the
// schema version it needs.
void require_schema(sqlite3* db, int minimum, const std::string& what) {
  const int version = db::read_schema_version(db);
  if (version < minimum) {
    const bool read_only = sqlite3_db_readonly(db, "main") == 1;
    throw Error(ErrorCode::kDatabase,
                "database " + in_quotes(db::database_path(db)) + " has schema version " +
                    std::to_string(version) + ", " + what + " needs version " +
                    std::to_string(minimum) + " or later: " +
                    (read_only ? "it is open read-only; run `draglab db migrate` on it (needs "
                                 "write permission) to upgrade it"
                               : "open it with migration enabled (`draglab db migrate`)"));
  }
}

// A change asked of a database that this process can only read is bad input, like an output
// path that cannot be written; the remedy names what the user controls (the permissions), since
// the command line opens a database it cannot write read-only by itself.
void require_writable(sqlite3* db) {
  if (sqlite3_db_readonly(db, "main") == 1) {
    const std::string path = db::database_path(db);
    throw Error(ErrorCode::kInvalidArgument,
                "database " + in_quotes(path) +
                    " is open read-only, so it cannot be changed: changing it needs write "
                    "permission on the file and on its directory " +
                    in_quotes(parent_directory(path)) +
                    " (SQLite keeps its -wal and -shm files there), and a read-write open (C "
                    "API: draglab_db_open, not draglab_db_open_readonly)");
  }
}

}  // namespace

std::vector<int> Database::migrate(int target) {
  const int latest = db::latest_schema_version();
  if (target < 0) target = latest;
  if (target > latest) {
    throw Error(ErrorCode::kInvalidArgument,
                "cannot migrate to schema version " + std::to_string(target) +
                    ": this draglab knows versions up to " + std::to_string(latest));
  }
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  const int version = db::read_schema_version(db_);
  if (target < version) {
    throw Error(ErrorCode::kInvalidArgument, "cannot migrate database " + in_quotes(path_) +
                                                 " from schema version " + std::to_string(version) +
                                                 " back to " + std::to_string(target) +
                                                 ": migrations only go forward");
  }
  std::vector<int> applied = db::apply_migrations(db_, version, target, kDragDbVersion);
  t.commit();
  return applied;
}

std::vector<LawRecord> Database::list(const std::string& name, bool include_drafts) const {
  Transaction t(db_, Transaction::Kind::kRead);
  require_schema(db_, 1, "listing laws");
  std::vector<LawRecord> out;
  for (StoredLaw& law : query_laws(db_, name, include_drafts)) out.push_back(std::move(law.record));
  t.commit();
  return out;
}

LawRecord Database::resolve(const std::string& reference) const {
  const LawReference parsed = LawReference::Parse(reference);
  const std::string& name = parsed.name;
  const std::string& selector = parsed.selector;

  Transaction t(db_, Transaction::Kind::kRead);
  require_schema(db_, 1, "resolving a law reference");
  std::vector<StoredLaw> versions = query_laws(db_, name, true);
  if (versions.empty()) throw unknown_name_error(db_, name);

  if (selector == "latest") {
    const StoredLaw* latest = latest_published(versions);
    if (!latest) {
      throw Error(ErrorCode::kNotFound,
                  "law " + in_quotes(name) +
                      " has no published version (versions: " + versions_summary(versions) +
                      "); load a specific one as " + name + "@<version>");
    }
    return latest->record;
  }

  if (is_all_digits(selector) && selector.size() <= 9) {
    const int version = std::atoi(selector.c_str());
    for (const StoredLaw& v : versions) {
      if (v.record.version == version) return v.record;
    }
    // A number can also be a hash prefix made of decimal digits only; fall through if so.
    if (selector.size() < kMinHashPrefix) {
      throw Error(ErrorCode::kNotFound, "law " + in_quotes(name) + " has no version " + selector +
                                            " (versions: " + versions_summary(versions) + ")");
    }
  }

  if (!is_hex(selector)) {
    throw Error(ErrorCode::kInvalidArgument,
                "law reference " + in_quotes(reference) + ": " + in_quotes(selector) +
                    " is neither 'latest', a version number nor a hexadecimal hash prefix");
  }
  if (selector.size() < kMinHashPrefix) {
    throw Error(ErrorCode::kInvalidArgument,
                "law reference " + in_quotes(reference) + ": a hash prefix needs at least " +
                    std::to_string(kMinHashPrefix) + " hexadecimal digits");
  }
  const std::string prefix = to_lower(selector);
  std::vector<const StoredLaw*> matches;
  for (const StoredLaw& v : versions) {
    if (v.record.content_hash.compare(0, prefix.size(), prefix) == 0) matches.push_back(&v);
  }
  if (matches.empty()) {
    throw Error(ErrorCode::kNotFound, "no version of law " + in_quotes(name) +
                                          " has a content hash starting with " + in_quotes(prefix) +
                                          " (versions: " + versions_summary(versions) + ")");
  }
  if (matches.size() > 1) {
    std::vector<std::string> candidates;
    for (const StoredLaw* m : matches) {
      candidates.push_back(m->record.reference() + " (" + m->record.content_hash.substr(0, 16) +
                           "..., " + to_string(m->record.status) + ")");
    }
    throw Error(ErrorCode::kInvalidArgument, "law reference " + in_quotes(reference) +
                                                 " is ambiguous, it matches " + join(candidates) +
                                                 "; give a version number or a longer hash prefix");
  }
  return matches.front()->record;
}

std::shared_ptr<Law> Database::load(const std::string& reference, RangePolicy policy,
                                    std::string* warning) const {
  LawRecord record = resolve(reference);
  verify_content_hash(record);
  if (warning) {
    warning->clear();
    if (record.status == LawStatus::kRetracted) {
      std::string replacement = "there is no published version of " + in_quotes(record.name);
      try {
        const LawRecord latest = resolve(record.name + "@latest");
        replacement = "the latest published version is " + latest.reference();
      } catch (const Error&) {
      }
      *warning = "law " + record.reference() + " is retracted" +
                 (record.retraction_reason.empty() ? "" : " (" + record.retraction_reason + ")") +
                 "; it stays loadable for reproducibility, but " + replacement;
    } else if (record.status == LawStatus::kDraft) {
      *warning =
          "law " + record.reference() + " is an unpublished draft: its parameters may still change";
    }
  }
  return std::make_shared<Law>(std::move(record), policy);
}

LawRecord Database::add_draft(LawRecord record) {
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  require_schema(db_, 1, "storing a law");
  if (record.provenance.code_version.empty()) record.provenance.code_version = kDragDbVersion;
  validate_record(record);

  Statement next(db_, "SELECT coalesce(MAX(version), 0) + 1 FROM laws WHERE name = ?1");
  next.bind(1, record.name);
  next.step();
  record.version = static_cast<int>(next.integer(0));
  record.status = LawStatus::kDraft;
  record.created_at = db::utc_now_iso8601();
  record.retraction_reason.clear();
  record.content_hash = content_hash_of(record);

  Statement insert(db_,
                   "INSERT INTO laws (name, version, force_kind, normalisation, reynolds, "
                   "tfm_model, phi_min, phi_max, re_min, re_max, provenance_kind, citation, "
                   "dataset_id, data_hash, fitter_settings, code_version, content_hash, notes, "
                   "form, status, created_at) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, "
                   "?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18, ?19, 'draft', ?20)");
  insert.bind(1, record.name).bind(2, record.version);
  bind_content_columns(insert, record);
  insert.bind(19, record.form).bind(20, record.created_at);
  insert.run();
  insert_children(db_, sqlite3_last_insert_rowid(db_), record);

  LawRecord stored = require_version(db_, record.name, record.version).record;
  t.commit();
  return stored;
}

LawRecord Database::update_draft(const LawRecord& record) {
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  require_schema(db_, 1, "updating a draft");
  StoredLaw law = require_version(db_, record.name, record.version);
  if (law.record.status != LawStatus::kDraft) throw_immutable(law, "update it");

  LawRecord updated = law.record;
  updated.parameters = record.parameters;
  updated.covariance = record.covariance;
  updated.validity = record.validity;
  updated.provenance = record.provenance;
  if (updated.provenance.code_version.empty()) updated.provenance.code_version = kDragDbVersion;
  updated.notes = record.notes;
  validate_record(updated);
  updated.content_hash = content_hash_of(updated);

  // Children first (the draft guard lets them change), then the row, so that the 'updated'
  // event of schema 2 records the new hash.
  delete_children(db_, law.id);
  insert_children(db_, law.id, updated);
  Statement update(db_,
                   "UPDATE laws SET force_kind = ?3, normalisation = ?4, reynolds = ?5, "
                   "tfm_model = ?6, phi_min = ?7, phi_max = ?8, re_min = ?9, re_max = ?10, "
                   "provenance_kind = ?11, citation = ?12, dataset_id = ?13, data_hash = ?14, "
                   "fitter_settings = ?15, code_version = ?16, content_hash = ?17, notes = ?18 "
                   "WHERE id = ?1 AND version = ?2 AND status = 'draft'");
  update.bind(1, law.id).bind(2, law.record.version);
  bind_content_columns(update, updated);
  update.run();

  LawRecord stored = require_version(db_, record.name, record.version).record;
  t.commit();
  return stored;
}

LawRecord Database::publish(const std::string& name, int version) {
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  require_schema(db_, 1, "publishing a law");
  StoredLaw law = require_version(db_, name, version);
  if (law.record.status != LawStatus::kDraft) throw_immutable(law, "publish it again");
  // Publishing freezes the record: make sure what is frozen is consistent and loadable.
  verify_content_hash(law.record);
  validate_record(law.record);
  Law check_binding(law.record);

  Statement update(db_,
                   "UPDATE laws SET status = 'published', published_at = ?2 "
                   "WHERE id = ?1 AND status = 'draft'");
  update.bind(1, law.id).bind(2, db::utc_now_iso8601());
  update.run();
  LawRecord stored = require_version(db_, name, version).record;
  t.commit();
  return stored;
}

LawRecord Database::add_published(LawRecord record) {
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  const LawRecord draft = add_draft(std::move(record));
  LawRecord stored = publish(draft.name, draft.version);
  t.commit();
  return stored;
}

LawRecord Database::retract(const std::string& name, int version, const std::string& reason) {
  require_writable(db_);
  const bool blank = std::all_of(reason.begin(), reason.end(),
                                 [](unsigned char c) { return std::isspace(c) != 0; });
  if (blank) {
    throw Error(ErrorCode::kInvalidArgument,
                "retracting " + LawReference::Format(name, version) +
                    " needs a reason (it is shown to everyone who loads this version)");
  }
  Transaction t(db_, Transaction::Kind::kWrite);
  require_schema(db_, 1, "retracting a law");
  StoredLaw law = require_version(db_, name, version);
  if (law.record.status == LawStatus::kDraft) {
    throw Error(ErrorCode::kInvalidArgument,
                "law " + law.record.reference() +
                    " is a draft: drafts are deleted, not retracted (delete_draft)");
  }
  if (law.record.status == LawStatus::kRetracted) throw_immutable(law, "retract it again");

  Statement update(db_,
                   "UPDATE laws SET status = 'retracted', retracted_at = ?2, "
                   "retraction_reason = ?3 WHERE id = ?1 AND status = 'published'");
  update.bind(1, law.id).bind(2, db::utc_now_iso8601()).bind(3, reason);
  update.run();
  LawRecord stored = require_version(db_, name, version).record;
  t.commit();
  return stored;
}

void Database::delete_draft(const std::string& name, int version) {
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  require_schema(db_, 1, "deleting a draft");
  StoredLaw law = require_version(db_, name, version);
  if (law.record.status != LawStatus::kDraft) {
    throw Error(ErrorCode::kImmutable,
                "law " + law.record.reference() + " is " + status_phrase(law) +
                    ": published and retracted versions are never deleted (retract it instead)");
  }
  Statement del(db_, "DELETE FROM laws WHERE id = ?1 AND status = 'draft'");
  del.bind(1, law.id);
  del.run();
  t.commit();
}

int Database::seed_literature() {
  require_writable(db_);
  Transaction t(db_, Transaction::Kind::kWrite);
  require_schema(db_, 1, "seeding the literature library");
  int added = 0;
  for (const LawForm* form : all_law_forms()) {
    if (!form->description.literature) continue;
    Statement exists(db_, "SELECT count(*) FROM laws WHERE name = ?1");
    exists.bind(1, form->key());
    exists.step();
    if (exists.integer(0) > 0) continue;
    try {
      LawRecord record = literature_record(*form);
      record.version = 1;
      add_published(std::move(record));
    } catch (const Error& e) {
      // A registered form whose own defaults do not validate is a bug in that form.
      throw Error(ErrorCode::kInternal,
                  "seeding literature law form " + in_quotes(form->key()) + " failed: " + e.what());
    }
    ++added;
  }
  t.commit();
  return added;
}

DatabaseCheckReport Database::check() const {
  DatabaseCheckReport report;
  auto problem = [&report](const std::string& p) {
    report.ok = false;
    report.problems.push_back(p);
  };
  try {
    Transaction t(db_, Transaction::Kind::kRead);
    report.schema_version = db::read_schema_version(db_);
    if (report.schema_version < db::latest_schema_version()) {
      problem("schema version " + std::to_string(report.schema_version) +
              " is older than this draglab's " + std::to_string(db::latest_schema_version()) +
              ": open the database with migration enabled");
    }
    {
      Statement s(db_, "PRAGMA integrity_check");
      while (s.step()) {
        const std::string line = s.text(0);
        if (line != "ok") problem("SQLite integrity: " + line);
      }
    }
    {
      Statement s(db_, "PRAGMA foreign_key_check");
      while (s.step()) {
        problem("table " + s.text(0) + " row " + s.text(1) + " refers to a missing " + s.text(2) +
                " row");
      }
    }
    {
      Statement s(db_, "SELECT name FROM sqlite_schema WHERE type = 'trigger'");
      std::vector<std::string> present;
      while (s.step()) present.push_back(s.text(0));
      for (const std::string& name : db::expected_triggers(report.schema_version)) {
        if (std::find(present.begin(), present.end(), name) == present.end()) {
          problem("trigger " + name +
                  " is missing: immutability is no longer enforced in SQL (it was dropped "
                  "outside draglab)");
        }
      }
    }
    if (report.schema_version >= 1) {
      Statement s(db_, std::string("SELECT ") + kLawColumns + " FROM laws ORDER BY name, version");
      while (s.step()) {
        ++report.laws_checked;
        std::string reference = s.text(1) + "@" + s.text(2);
        try {
          StoredLaw law = read_law_row(s);
          read_children(db_, law.id, law.record);
          const LawRecord& r = law.record;
          const std::string computed = content_hash_of(r);
          if (computed != r.content_hash) {
            problem("law " + reference + ": stored content hash " + r.content_hash.substr(0, 12) +
                    "... differs from the recomputed " + computed.substr(0, 12) +
                    "... (changed outside draglab)");
          }
          Law binding(r);  // known form, matching parameters and extra inputs
          if (r.status != LawStatus::kDraft && law.published_at.empty()) {
            problem("law " + reference + " is " + to_string(r.status) +
                    " but has no publication time");
          }
          if (r.status == LawStatus::kRetracted && r.retraction_reason.empty()) {
            problem("law " + reference + " is retracted without a reason");
          }
        } catch (const Error& e) {
          problem("law " + reference + ": " + e.what());
        }
      }
    }
    t.commit();
  } catch (const Error& e) {
    problem(e.what());
  }
  return report;
}

std::vector<LawEvent> Database::history(const std::string& name, int version) const {
  Transaction t(db_, Transaction::Kind::kRead);
  require_schema(db_, 2, "the law history");
  std::string sql =
      "SELECT name, version, event, at, content_hash, detail FROM law_events WHERE name = ?1";
  if (version > 0) sql += " AND version = ?2";
  sql += " ORDER BY id";
  Statement s(db_, sql);
  s.bind(1, name);
  if (version > 0) s.bind(2, version);
  std::vector<LawEvent> events;
  while (s.step()) {
    LawEvent e;
    e.name = s.text(0);
    e.version = static_cast<int>(s.integer(1));
    e.event = s.text(2);
    e.at = s.text(3);
    e.content_hash = s.text(4);
    e.detail = s.text(5);
    events.push_back(std::move(e));
  }
  t.commit();
  return events;
}

}  // namespace draglab
