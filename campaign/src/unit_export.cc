// campaign/src/unit_export.cc: every column of a campaign's units, straight from the table
// (draglab campaign export). The SQL of the campaign tables lives in campaign/ only.
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include <sqlite3.h>
#include <nlohmann/json.hpp>

#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"

namespace draglab {
namespace campaign {
namespace {

/// RFC 4180: a field with a comma, quote or line break is quoted, its quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string full_precision(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

}  // namespace

UnitsExport export_units(const Database& db, std::int64_t campaign_id) {
  sqlite3* handle = db.handle();
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(handle,
                         "SELECT * FROM campaign_units WHERE campaign_id = ? ORDER BY phi_index, "
                         "re_index, realization, resolution_index",
                         -1, &stmt, nullptr) != SQLITE_OK) {
    throw Error(ErrorCode::kDatabase, std::string("campaign export: ") + sqlite3_errmsg(handle));
  }
  std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> guard(stmt, sqlite3_finalize);
  sqlite3_bind_int64(stmt, 1, campaign_id);
  const int columns = sqlite3_column_count(stmt);
  std::ostringstream csv;
  for (int i = 0; i < columns; ++i) csv << (i ? "," : "") << sqlite3_column_name(stmt, i);
  csv << "\n";
  nlohmann::json units = nlohmann::json::array();
  int rc;
  while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
    nlohmann::json u = nlohmann::json::object();
    for (int i = 0; i < columns; ++i) {
      const std::string name = sqlite3_column_name(stmt, i);
      const int type = sqlite3_column_type(stmt, i);
      std::string text;
      if (type == SQLITE_INTEGER) {
        u[name] = sqlite3_column_int64(stmt, i);
        text = std::to_string(sqlite3_column_int64(stmt, i));
      } else if (type == SQLITE_FLOAT) {
        u[name] = sqlite3_column_double(stmt, i);
        text = full_precision(sqlite3_column_double(stmt, i));
      } else if (type == SQLITE_TEXT) {
        text = reinterpret_cast<const char*>(sqlite3_column_text(stmt, i));
        if (name == "result_json") {
          const auto parsed = nlohmann::json::parse(text, nullptr, false);
          u[name] = parsed.is_discarded() ? nlohmann::json(text) : parsed;
        } else {
          u[name] = text;
        }
      } else {
        u[name] = nullptr;
      }
      csv << (i ? "," : "") << csv_field(text);
    }
    csv << "\n";
    units.push_back(u);
  }
  if (rc != SQLITE_DONE) {
    throw Error(ErrorCode::kDatabase, std::string("campaign export: ") + sqlite3_errmsg(handle));
  }
  UnitsExport out;
  out.count = units.size();
  out.csv = csv.str();
  out.json = units.dump(2);
  return out;
}

std::string export_species_csv(const Database& db, std::int64_t campaign_id, std::size_t* rows) {
  const nlohmann::json units = nlohmann::json::parse(export_units(db, campaign_id).json);
  std::ostringstream csv;
  csv << "unit,phi,re_target,re,resolution,realization,y,x,spheres,F_i,F_i_standard_error,F\n";
  std::size_t count = 0;
  for (const auto& u : units) {
    if (u.value("status", "") != "done") continue;
    const auto& record = u.at("result_json");
    if (!record.is_object() || !record.contains("species")) continue;
    for (const auto& sp : record.at("species")) {
      csv << u.at("id").get<std::int64_t>() << ',' << full_precision(u.at("phi").get<double>())
          << ',' << full_precision(u.at("re_target").get<double>()) << ','
          << full_precision(u.at("re").get<double>()) << ','
          << full_precision(u.at("resolution").get<double>()) << ','
          << u.at("realization").get<std::int64_t>() << ','
          << full_precision(sp.at("diameter_over_sauter").get<double>()) << ','
          << full_precision(sp.at("volume_fraction").get<double>()) << ','
          << sp.at("spheres").get<std::int64_t>() << ',' << full_precision(sp.at("F").get<double>())
          << ',' << full_precision(sp.at("F_standard_error").get<double>()) << ','
          << full_precision(u.at("F").get<double>()) << '\n';
      ++count;
    }
  }
  if (rows != nullptr) *rows = count;
  return csv.str();
}

}  // namespace campaign
}  // namespace draglab
