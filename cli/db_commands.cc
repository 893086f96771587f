// `draglab db info|check|migrate`.
#include <sys/stat.h>

#include <iostream>
#include <map>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "drag_db_version.h"
#include "draglab/error.h"

namespace draglab {
namespace cli {
namespace {

long long file_size(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<long long>(st.st_size) : -1;
}

void run_info(const CliContext& ctx) {
  auto db = ctx.open_database();
  std::map<std::string, int> by_status;
  std::map<std::string, int> by_kind;
  const std::vector<LawRecord> records = db->list();
  for (const LawRecord& r : records) {
    ++by_status[to_string(r.status)];
    ++by_kind[r.provenance.kind];
  }
  if (ctx.json) {
    ctx.print_json({{"path", db->path()},
                    {"schema_version", db->schema_version()},
                    {"code_schema_version", Database::current_schema_version()},
                    {"code_version", kDragDbVersion},
                    {"law_versions", records.size()},
                    {"by_status", by_status},
                    {"by_provenance", by_kind},
                    {"file_bytes", file_size(db->path())}});
    return;
  }
  std::cout << fmt::format("database        {}\n", db->path());
  std::cout << fmt::format("schema version  {} (this draglab writes {})\n", db->schema_version(),
                           Database::current_schema_version());
  std::cout << fmt::format("draglab         {}\n", kDragDbVersion);
  std::cout << fmt::format("law versions    {}", records.size());
  for (const auto& [status, n] : by_status) std::cout << fmt::format(", {} {}", n, status);
  std::cout << '\n';
  std::cout << fmt::format("file size       {} bytes\n", file_size(db->path()));
}

void run_check(const CliContext& ctx) {
  auto db = ctx.open_database(/*read_only=*/true);
  const DatabaseCheckReport report = db->check();
  if (ctx.json) {
    ctx.print_json({{"path", db->path()},
                    {"ok", report.ok},
                    {"schema_version", report.schema_version},
                    {"laws_checked", report.laws_checked},
                    {"problems", report.problems}});
  } else {
    std::cout << report.FullReport();
  }
  if (!report.ok)
    throw Error(ErrorCode::kDatabase, "database check failed: " + report.BriefReport());
}

void run_migrate(const CliContext& ctx) {
  DatabaseOptions options;
  options.migrate = false;  // migrate explicitly below, to report what was applied
  options.create_if_missing = false;
  Database db(ctx.resolved_db_path(), options);
  const int before = db.schema_version();
  const std::vector<int> applied = db.migrate();
  if (ctx.json) {
    ctx.print_json(
        {{"path", db.path()}, {"from", before}, {"to", db.schema_version()}, {"applied", applied}});
    return;
  }
  if (applied.empty()) {
    std::cout << fmt::format("{}: schema version {} is current; nothing to do\n", db.path(),
                             before);
  } else {
    std::cout << fmt::format("{}: migrated schema {} -> {}\n", db.path(), before,
                             db.schema_version());
  }
}

}  // namespace

void add_db_commands(CLI::App& app, CliContext& ctx) {
  CLI::App* db = app.add_subcommand("db", "Database information, integrity check, migrations");
  db->require_subcommand(1);
  db->footer(
      "Examples:\n  draglab db info\n  draglab db check --json\n  draglab db migrate --db old.db");
  auto* info = db->add_subcommand("info", "Path, schema version, number of law versions");
  info->footer("Examples:\n  draglab db info\n  draglab db info --db other.db --json");
  info->callback([&ctx] { ctx.action = [&ctx] { run_info(ctx); }; });
  auto* check = db->add_subcommand(
      "check",
      "SQLite integrity check, schema version, recomputed content hashes (exit 1 on a "
      "problem)");
  check->footer("Example:\n  draglab db check --json");
  check->callback([&ctx] { ctx.action = [&ctx] { run_check(ctx); }; });
  auto* migrate = db->add_subcommand("migrate", "Apply forward schema migrations");
  migrate->footer("Example:\n  draglab db migrate --db old.db");
  migrate->callback([&ctx] { ctx.action = [&ctx] { run_migrate(ctx); }; });
}

}  // namespace cli
}  // namespace draglab
