// Storage of drag datasets (dataset.h) in the datasets table of schema version 4, and their CSV
// form. A dataset's identity is the SHA-256 of the canonical JSON of its points; the row holds
// the same JSON, so what is loaded is byte for byte what was hashed.
#include <sqlite3.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "db/schema.h"
#include "db/sqlite_util.h"
#include "drag_db_version.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"

namespace draglab {
namespace {

using db::Statement;
using db::Transaction;

constexpr int kDatasetSchema = 4;

std::string exact(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// Canonical JSON: fixed key order (nlohmann::json sorts object keys), doubles as %.17g strings so
// that the text, and the hash, do not depend on the JSON library's number formatting.
// `with_timing`: include wall_s. The hash leaves it out, so that the same measurements made on
// another machine, or re-run, are the same dataset; the stored JSON keeps it.
nlohmann::json canonical_points(const std::vector<DatasetPoint>& points, bool with_timing) {
  nlohmann::json array = nlohmann::json::array();
  for (const DatasetPoint& p : points) {
    nlohmann::json resolutions = nlohmann::json::array(), at = nlohmann::json::array();
    for (double d : p.resolutions) resolutions.push_back(exact(d));
    for (double f : p.F_at_resolution) at.push_back(exact(f));
    array.push_back({{"phi", exact(p.phi)},
                     {"re_target", exact(p.re_target)},
                     {"re", exact(p.re)},
                     {"F", exact(p.F)},
                     {"F_standard_error", exact(p.F_standard_error)},
                     {"F_discretisation_error", exact(p.F_discretisation_error)},
                     {"F_uncertainty", exact(p.F_uncertainty)},
                     {"realizations", p.realizations},
                     {"resolutions", resolutions},
                     {"F_at_resolution", at},
                     {"order", exact(p.order)},
                     {"extrapolation", p.extrapolation}});
    // Only per-species points carry y: the text, and the hash, of every other dataset is as
    // before.
    if (p.y > 0.0) array.back()["y"] = exact(p.y);
    if (with_timing) array.back()["wall_s"] = exact(p.wall_s);
  }
  return array;
}

double number_of(const nlohmann::json& j) { return std::stod(j.get<std::string>()); }

std::vector<DatasetPoint> points_from_json(const std::string& text) {
  const nlohmann::json array = nlohmann::json::parse(text);
  std::vector<DatasetPoint> points;
  for (const nlohmann::json& j : array) {
    DatasetPoint p;
    p.phi = number_of(j.at("phi"));
    p.re_target = number_of(j.at("re_target"));
    p.re = number_of(j.at("re"));
    p.F = number_of(j.at("F"));
    p.F_standard_error = number_of(j.at("F_standard_error"));
    p.F_discretisation_error = number_of(j.at("F_discretisation_error"));
    p.F_uncertainty = number_of(j.at("F_uncertainty"));
    p.realizations = j.at("realizations").get<int>();
    for (const auto& d : j.at("resolutions")) p.resolutions.push_back(number_of(d));
    for (const auto& f : j.at("F_at_resolution")) p.F_at_resolution.push_back(number_of(f));
    p.order = number_of(j.at("order"));
    p.extrapolation = j.at("extrapolation").get<std::string>();
    p.wall_s = number_of(j.at("wall_s"));
    if (j.contains("y")) p.y = number_of(j.at("y"));
    points.push_back(p);
  }
  return points;
}

void require_dataset_schema(sqlite3* handle, const std::string& what) {
  const int version = db::read_schema_version(handle);
  if (version < kDatasetSchema) {
    throw Error(ErrorCode::kDatabase,
                "database '" + db::database_path(handle) + "' has schema version " +
                    std::to_string(version) + ", " + what + " needs version " +
                    std::to_string(kDatasetSchema) + ": run `draglab db migrate` on it");
  }
}

Dataset dataset_from_row(const Statement& row, bool with_points) {
  Dataset d;
  d.id = row.text(0);
  d.hash = row.text(1);
  d.campaign_id = row.is_null(2) ? 0 : row.integer(2);
  d.name = row.text(3);
  d.method = row.text(4);
  d.created_at = row.text(5);
  d.code_version = row.text(6);
  if (with_points) d.points = points_from_json(row.text(7));
  return d;
}

constexpr const char* kSelect =
    "SELECT id, hash, campaign_id, name, method, created_at, code_version, points_json "
    "FROM datasets ";

// Validation shared by storing and CSV import: every number a fit will divide by or take the
// log of must be finite and in range.
constexpr double kMaxRe = 1e7;
constexpr double kMaxF = 1e9;
constexpr int kMaxRealizations = 100000;

void validate_point(const DatasetPoint& p, const std::string& where) {
  auto fail = [&](const std::string& field, double value, const std::string& range) {
    throw Error(ErrorCode::kInvalidArgument, where + ": " + field + " = " + exact(value) +
                                                 " is out of range (allowed: " + range + ")");
  };
  if (!(p.phi > 0.0 && p.phi <= 0.74)) fail("phi", p.phi, "(0, 0.74]");
  if (!(p.re >= 0.0 && std::isfinite(p.re))) fail("re", p.re, "finite, >= 0");
  if (!(p.re_target >= 0.0 && std::isfinite(p.re_target))) {
    fail("re_target", p.re_target, "finite, >= 0");
  }
  // Bounds far outside any drag measurement (F at phi = 0.74, Re = 1e4 is of order 1e4), so that
  // an exponent typo (1e300) is caught before it is stored forever.
  if (!(p.re <= kMaxRe)) fail("re", p.re, "[0, 1e7]");
  if (!(p.re_target <= kMaxRe)) fail("re_target", p.re_target, "[0, 1e7]");
  if (!(p.F > 0.0 && p.F <= kMaxF)) fail("F", p.F, "(0, 1e9]");
  if (!(p.F_uncertainty > 0.0 && p.F_uncertainty <= kMaxF)) {
    fail("F_uncertainty", p.F_uncertainty, "(0, 1e9]");
  }
  if (!(p.F_standard_error >= 0.0 && p.F_standard_error <= kMaxF)) {
    fail("F_standard_error", p.F_standard_error, "[0, 1e9]");
  }
  if (!(p.F_discretisation_error >= 0.0 && p.F_discretisation_error <= kMaxF)) {
    fail("F_discretisation_error", p.F_discretisation_error, "[0, 1e9]");
  }
  if (p.realizations < 0 || p.realizations > kMaxRealizations) {
    fail("realizations", p.realizations, "an integer in [0, 100000] (0 = not stated)");
  }
  // A convergence order in d beyond 10 is no measured order (Richardson's is kept in [0.25, 6]).
  if (!(p.order >= 0.0 && p.order <= 10.0)) fail("order", p.order, "[0, 10] (0 = not measured)");
  if (!p.extrapolation.empty() && p.extrapolation != "richardson" &&
      p.extrapolation != "inverse_d" && p.extrapolation != "finest") {
    throw Error(ErrorCode::kInvalidArgument,
                where + ": extrapolation = '" + p.extrapolation +
                    "' is not one of richardson, inverse_d, finest (or empty: not stated)");
  }
  if (!(p.wall_s >= 0.0 && std::isfinite(p.wall_s))) fail("wall_s", p.wall_s, "finite, >= 0");
  if (p.resolutions.size() != p.F_at_resolution.size()) {
    throw Error(ErrorCode::kInvalidArgument, where + ": " + std::to_string(p.resolutions.size()) +
                                                 " resolutions but " +
                                                 std::to_string(p.F_at_resolution.size()) +
                                                 " F_at_resolution values (one F per resolution)");
  }
  for (std::size_t k = 0; k < p.resolutions.size(); ++k) {
    if (!(p.resolutions[k] > 0.0 && p.resolutions[k] <= 1e5)) {
      fail("resolutions", p.resolutions[k], "(0, 1e5] lattice units per diameter");
    }
    if (!(p.F_at_resolution[k] > 0.0 && p.F_at_resolution[k] <= kMaxF)) {
      fail("F_at_resolution", p.F_at_resolution[k], "(0, 1e9]");
    }
  }
}

/// One (phi, Re target) appears once per dataset: two rows for the same point (different F or
/// not) would be fitted as independent measurements.
void check_unique_points(const std::vector<DatasetPoint>& points,
                         const std::vector<std::string>& where) {
  std::map<std::tuple<double, double, double>, std::size_t> seen;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto key = std::make_tuple(points[i].phi, points[i].re_target, points[i].y);
    const auto [it, inserted] = seen.emplace(key, i);
    if (!inserted) {
      const std::string y = points[i].y > 0.0 ? ", y = " + exact(points[i].y) : "";
      throw Error(ErrorCode::kInvalidArgument,
                  where[i] + ": (phi, re_target) = (" + exact(points[i].phi) + ", " +
                      exact(points[i].re_target) + ")" + y + " already given at " +
                      where[it->second] + " (F = " + exact(points[it->second].F) + " there, " +
                      exact(points[i].F) +
                      " here): one row per point (combine repeated measurements first)");
    }
  }
}

}  // namespace

std::string dataset_hash(const std::vector<DatasetPoint>& points) {
  return sha256_hex(canonical_points(points, false).dump());
}

Dataset store_dataset(Database& database, Dataset dataset) {
  sqlite3* handle = database.handle();
  if (dataset.points.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "dataset '" + dataset.name + "' has no points");
  }
  std::vector<std::string> where;
  for (std::size_t i = 0; i < dataset.points.size(); ++i) {
    where.push_back("dataset '" + dataset.name + "', point " + std::to_string(i));
    validate_point(dataset.points[i], where.back());
  }
  check_unique_points(dataset.points, where);
  const std::string points_json = canonical_points(dataset.points, true).dump();
  dataset.hash = dataset_hash(dataset.points);
  dataset.id = dataset.hash.substr(0, 12);
  if (dataset.created_at.empty()) dataset.created_at = db::utc_now_iso8601();
  if (dataset.code_version.empty()) dataset.code_version = kDragDbVersion;
  if (dataset.method.empty()) dataset.method = "{}";
  Transaction t(handle, Transaction::Kind::kWrite);
  require_dataset_schema(handle, "storing a dataset");
  {
    Statement existing(handle, std::string(kSelect) + "WHERE hash = ?1");
    existing.bind(1, dataset.hash);
    if (existing.step()) return dataset_from_row(existing, true);  // same points: same dataset
  }
  Statement insert(handle,
                   "INSERT INTO datasets (id, hash, campaign_id, name, method, created_at, "
                   "code_version, points_json) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)");
  insert.bind(1, dataset.id).bind(2, dataset.hash);
  if (dataset.campaign_id > 0) {
    insert.bind(3, dataset.campaign_id);
  } else {
    insert.bind_null(3);
  }
  insert.bind(4, dataset.name).bind(5, dataset.method).bind(6, dataset.created_at);
  insert.bind(7, dataset.code_version).bind(8, points_json);
  insert.run();
  t.commit();
  dataset.points = points_from_json(points_json);  // exactly what is stored
  return dataset;
}

Dataset load_dataset(const Database& database, const std::string& id_or_prefix) {
  sqlite3* handle = database.handle();
  const bool hex = !id_or_prefix.empty() &&
                   id_or_prefix.find_first_not_of("0123456789abcdef") == std::string::npos;
  if (!hex || id_or_prefix.size() < 4) {
    throw Error(ErrorCode::kNotFound,
                "dataset '" + id_or_prefix +
                    "': a dataset id is at least 4 lower-case hex digits of its hash (see "
                    "`draglab dataset list`)");
  }
  Transaction t(handle, Transaction::Kind::kRead);
  require_dataset_schema(handle, "loading a dataset");
  Statement q(handle, std::string(kSelect) + "WHERE hash >= ?1 AND hash < ?2 ORDER BY hash");
  q.bind(1, id_or_prefix).bind(2, id_or_prefix + "g");  // 'g' sorts after every hex digit
  std::vector<Dataset> found;
  while (q.step()) found.push_back(dataset_from_row(q, true));
  if (found.empty()) {
    throw Error(ErrorCode::kNotFound, "no dataset '" + id_or_prefix + "' in '" + database.path() +
                                          "' (see `draglab dataset list`)");
  }
  if (found.size() > 1) {
    throw Error(ErrorCode::kNotFound, "dataset prefix '" + id_or_prefix + "' is ambiguous (" +
                                          std::to_string(found.size()) +
                                          " datasets): give more digits");
  }
  return found.front();
}

std::vector<Dataset> list_datasets(const Database& database) {
  sqlite3* handle = database.handle();
  Transaction t(handle, Transaction::Kind::kRead);
  if (db::read_schema_version(handle) < kDatasetSchema) return {};
  Statement q(handle, std::string(kSelect) + "ORDER BY created_at DESC, id");
  std::vector<Dataset> all;
  while (q.step()) all.push_back(dataset_from_row(q, false));
  return all;
}

namespace {

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(line);
  while (std::getline(in, item, separator)) {
    const auto b = item.find_first_not_of(" \t\r");
    const auto e = item.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : item.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == separator) out.push_back("");
  return out;
}

}  // namespace

Dataset read_dataset_csv(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw Error(ErrorCode::kInvalidArgument,
                "dataset file '" + path + "' is a directory, not a file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw Error(ErrorCode::kInvalidArgument,
                "dataset file '" + path + "' cannot be read: " + std::strerror(errno));
  }
  std::ostringstream whole;
  whole << file.rdbuf();
  const std::string text = whole.str();
  // A binary file is named as such, not echoed back through "unknown column '...'" messages.
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\r' && c != '\n') {
      throw Error(ErrorCode::kInvalidArgument, "dataset file '" + path +
                                                   "' is not a text file (byte " +
                                                   std::to_string(i) + " is a control character)");
    }
  }
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  std::vector<std::string> header;
  std::map<std::string, std::size_t> column;
  std::vector<std::string> row_where;
  Dataset dataset;
  const std::size_t slash = path.find_last_of('/');
  dataset.name = path.substr(slash == std::string::npos ? 0 : slash + 1);
  if (dataset.name.size() > 4 && dataset.name.substr(dataset.name.size() - 4) == ".csv") {
    dataset.name.resize(dataset.name.size() - 4);
  }
  // A file name need not be UTF-8, but the stored name is printed as JSON: bad bytes become
  // U+FFFD.
  dataset.name =
      nlohmann::json::parse(nlohmann::json(dataset.name)
                                .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace))
          .get<std::string>();
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = "'" + path + "' line " + std::to_string(line_number);
    if (header.empty()) {
      header = split(line, ',');
      static const std::set<std::string> kKnownColumns = {"phi",
                                                          "re",
                                                          "re_target",
                                                          "F",
                                                          "F_uncertainty",
                                                          "F_standard_error",
                                                          "F_discretisation_error",
                                                          "realizations",
                                                          "resolutions",
                                                          "F_at_resolution",
                                                          "order",
                                                          "extrapolation",
                                                          "wall_s",
                                                          "y"};
      for (std::size_t c = 0; c < header.size(); ++c) {
        if (!column.emplace(header[c], c).second) {
          throw Error(ErrorCode::kInvalidArgument,
                      where + ": the header names column '" + header[c] + "' twice");
        }
        // A misspelt optional column would be dropped silently and stored without it forever.
        if (!kKnownColumns.count(header[c])) {
          throw Error(ErrorCode::kInvalidArgument,
                      where + ": unknown column '" + header[c] +
                          "' (required: phi,re,F,F_uncertainty; optional: re_target, "
                          "F_standard_error, F_discretisation_error, realizations, resolutions, "
                          "F_at_resolution, order, extrapolation, wall_s, y)");
        }
      }
      for (const char* required : {"phi", "re", "F", "F_uncertainty"}) {
        if (!column.count(required)) {
          throw Error(ErrorCode::kInvalidArgument,
                      where + ": the header has no column '" + required +
                          "' (required: phi,re,F,F_uncertainty; optional: re_target, "
                          "F_standard_error, F_discretisation_error, realizations, resolutions, "
                          "F_at_resolution, order, extrapolation, wall_s, y)");
        }
      }
      continue;
    }
    const std::vector<std::string> cells = split(line, ',');
    if (cells.size() != header.size()) {
      throw Error(ErrorCode::kInvalidArgument, where + ": " + std::to_string(cells.size()) +
                                                   " columns, the header has " +
                                                   std::to_string(header.size()));
    }
    auto number = [&](const std::string& name, double fallback) {
      const auto it = column.find(name);
      if (it == column.end() || cells[it->second].empty()) return fallback;
      const std::string& text = cells[it->second];
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) {
        throw Error(ErrorCode::kInvalidArgument,
                    where + ", column '" + name + "': '" + text + "' is not a finite number");
      }
      return v;
    };
    auto list = [&](const std::string& name) {
      std::vector<double> values;
      const auto it = column.find(name);
      if (it == column.end() || cells[it->second].empty()) return values;
      for (const std::string& item : split(cells[it->second], ';')) {
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (end == item.c_str() || *end != '\0' || !std::isfinite(v)) {
          throw Error(ErrorCode::kInvalidArgument,
                      where + ", column '" + name + "': '" + item + "' is not a finite number");
        }
        values.push_back(v);
      }
      return values;
    };
    DatasetPoint p;
    p.phi = number("phi", NAN);
    p.re = number("re", NAN);
    p.re_target = number("re_target", p.re);
    p.F = number("F", NAN);
    p.F_uncertainty = number("F_uncertainty", NAN);
    p.F_standard_error = number("F_standard_error", 0.0);
    p.F_discretisation_error = number("F_discretisation_error", 0.0);
    {
      const double realizations = number("realizations", 0.0);
      if (!(realizations >= 0.0 && realizations <= kMaxRealizations &&
            realizations == std::floor(realizations))) {
        throw Error(ErrorCode::kInvalidArgument,
                    where + ", column 'realizations': " + exact(realizations) +
                        " is not an integer in [0, 100000] (0 = not stated)");
      }
      p.realizations = static_cast<int>(realizations);
    }
    p.resolutions = list("resolutions");
    p.F_at_resolution = list("F_at_resolution");
    p.order = number("order", 0.0);
    if (column.count("extrapolation")) p.extrapolation = cells[column["extrapolation"]];
    p.wall_s = number("wall_s", 0.0);
    if (column.count("y")) {
      p.y = number("y", NAN);
      if (!(p.y > 0.0 && p.y <= 100.0)) {
        throw Error(ErrorCode::kInvalidArgument,
                    where + ", column 'y': " + exact(p.y) +
                        " is outside (0, 100] (d_i/<d> of a size class; every row needs one)");
      }
    }
    validate_point(p, where);
    dataset.points.push_back(p);
    row_where.push_back(where);
  }
  if (dataset.points.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "dataset file '" + path + "' has no data rows");
  }
  check_unique_points(dataset.points, row_where);
  dataset.method = nlohmann::json{{"source", "csv"}, {"file", dataset.name}}.dump();
  dataset.hash = dataset_hash(dataset.points);
  dataset.id = dataset.hash.substr(0, 12);
  return dataset;
}

std::string dataset_csv_text(const Dataset& dataset, const std::vector<std::string>& provenance) {
  std::ostringstream out;
  out << "# draglab dataset " << dataset.id << " (" << dataset.name << "), hash " << dataset.hash
      << "\n# canonical drag-only F = F_d/(3 pi mu d eps u); Re = rho eps d u/mu (superficial); "
         "uncertainties absolute, 1 sigma\n";
  for (const std::string& line : provenance) {
    std::istringstream lines(line);
    for (std::string part; std::getline(lines, part);) out << "# " << part << "\n";
  }
  const bool per_species = std::any_of(dataset.points.begin(), dataset.points.end(),
                                       [](const DatasetPoint& p) { return p.y > 0.0; });
  out << "phi,re_target,re,F,F_standard_error,F_discretisation_error,F_uncertainty,realizations,"
         "resolutions,F_at_resolution,order,extrapolation,wall_s"
      << (per_species ? ",y" : "") << '\n';
  auto joined = [](const std::vector<double>& v) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ";" : "") + exact(v[i]);
    return s;
  };
  for (const DatasetPoint& p : dataset.points) {
    out << exact(p.phi) << ',' << exact(p.re_target) << ',' << exact(p.re) << ',' << exact(p.F)
        << ',' << exact(p.F_standard_error) << ',' << exact(p.F_discretisation_error) << ','
        << exact(p.F_uncertainty) << ',' << p.realizations << ',' << joined(p.resolutions) << ','
        << joined(p.F_at_resolution) << ',' << exact(p.order) << ',' << p.extrapolation << ','
        << exact(p.wall_s);
    if (per_species) out << ',' << exact(p.y);
    out << '\n';
  }
  return out.str();
}

void write_dataset_csv(const Dataset& dataset, const std::string& path,
                       const std::vector<std::string>& provenance) {
  const std::string text = dataset_csv_text(dataset, provenance);
  // Write to a temporary name and rename, so a reader never sees half a file; a failure leaves
  // neither the temporary nor a partial file behind.
  const std::string temporary = path + ".tmp";
  const auto fail = [&](ErrorCode code, const std::string& what, int error) {
    std::remove(temporary.c_str());
    throw Error(code, what + " '" + path + "' failed: " + std::strerror(error));
  };
  {
    std::ofstream file(temporary, std::ios::trunc);
    if (!file) fail(ErrorCode::kInvalidArgument, "creating", errno);
    file << text;
    if (!file.flush()) fail(ErrorCode::kDatabase, "writing", errno);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    fail(errno == EISDIR ? ErrorCode::kInvalidArgument : ErrorCode::kDatabase, "moving into place",
         errno);
  }
}

}  // namespace draglab
