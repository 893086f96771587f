// campaign/src/unit_export.cc: every column of a campaign's units, straight from the table
// (draglab campaign export). The SQL of the campaign tables lives in campaign/ only.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <sqlite3.h>
#include <nlohmann/json.hpp>

#include "db/sqlite_util.h"
#include "drag_db_version.h"
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

/// "AMD EPYC 7B13, 2 cores" from /proc/cpuinfo (Linux), or the core count alone.
std::string this_machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string model;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 1);
      model.erase(0, model.find_first_not_of(" \t"));
      break;
    }
  }
  const long cores = ::sysconf(_SC_NPROCESSORS_ONLN);
  return (model.empty() ? std::string() : model + ", ") + std::to_string(cores) + " cores";
}

std::string join(const std::set<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "none" : out;
}

}  // namespace

std::string units_provenance(const Database& db, std::int64_t campaign_id,
                             const std::vector<std::string>& notes) {
  const CampaignStatus st = campaign_status(db, std::to_string(campaign_id));
  std::set<std::string> versions, hosts;
  double core_seconds = 0.0;
  std::string first_start, last_finish;
  db::Statement s(db.handle(),
                  "SELECT status, code_version, claimed_by, wall_s, started_at, finished_at "
                  "FROM campaign_units WHERE campaign_id = ?");
  s.bind(1, campaign_id);
  while (s.step()) {
    const std::string status = s.text(0);
    if (status != "done" && status != "failed") continue;
    if (!s.is_null(1)) versions.insert(s.text(1));
    if (!s.is_null(2)) hosts.insert(s.text(2).substr(0, s.text(2).find(':')));
    if (!s.is_null(3)) core_seconds += s.real(3);
    if (!s.is_null(4) && (first_start.empty() || s.text(4) < first_start)) first_start = s.text(4);
    if (!s.is_null(5) && s.text(5) > last_finish) last_finish = s.text(5);
  }
  char cost[64];
  std::snprintf(cost, sizeof cost, "%.0f", core_seconds);
  std::ostringstream out;
  out << "# " << st.name << ": every unit of its spec (draglab campaign export --csv --provenance, "
      << "by draglab " << kDragDbVersion << " on " << this_machine() << ")\n";
  out << "# Spec hash (SHA-256 of the canonical spec): " << st.spec_hash << "\n";
  out << "# Code of the finished units: " << join(versions) << "; hosts: " << join(hosts) << "\n";
  out << "# Cost: " << cost << " core-seconds of LBM units (the finished units' run times)";
  if (!first_start.empty())
    out << ", first start " << first_start << ", last finish " << last_finish;
  out << "\n";
  out << "# Units: " << st.units_total << ", done " << st.units_done << ", failed "
      << st.units_failed << ", not run " << st.units_pending + st.units_running << "\n";
  for (const std::string& note : notes) {
    std::string line = note;
    std::replace(line.begin(), line.end(), '\n', ' ');
    out << "# " << line << "\n";
  }
  out << "# One row per unit; result_json holds the run's whole record (operator and why, "
         "resolution rule, error estimate, warnings); draglab campaign import SPEC FILE restores "
         "the campaign\n";
  return out.str();
}

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
