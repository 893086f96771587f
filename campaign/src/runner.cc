// The campaign runner: creates the campaign and its unit rows, claims units one at a time with a
// single UPDATE ... RETURNING (so no unit runs twice), runs them on `jobs` worker threads with
// one database connection each, and commits every finished unit in its own transaction.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "campaign_internal.h"
#include "db/sqlite_util.h"
#include "drag_db_version.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/drag_db/database.h"
#include "draglab/error.h"
#include "draglab/lbm/case_run.h"
#include "draglab/lbm/lbm.h"
#include "draglab/mpi/world.h"
#include "runner_internal.h"

namespace draglab {
namespace campaign {
namespace runner {

using db::Statement;
using db::Transaction;
using Clock = std::chrono::steady_clock;

/// ISO 8601 UTC with milliseconds: finished units are ordered and compared by it.
std::string now_iso8601_ms() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const long ms = static_cast<long>(
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &utc);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03ldZ", buf, ms);
  return out;
}

std::string format_duration(double s) {
  char buf[32];
  if (!std::isfinite(s) || s < 0) return "?";
  if (s < 60) {
    std::snprintf(buf, sizeof buf, "%.0fs", s);
  } else if (s < 3600) {
    std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s) / 3600,
                  (static_cast<int>(s) % 3600) / 60);
  }
  return buf;
}

DatabaseOptions worker_db_options() {
  DatabaseOptions o;
  o.create_if_missing = false;
  o.seed_literature = false;
  o.busy_timeout_ms = 120000;  // units commit rarely; waiting is always better than failing
  return o;
}

void require_campaign_tables(const Database& db) {
  if (db.schema_version() < 4) {
    throw Error(ErrorCode::kDatabase, "database '" + db.path() + "' has schema version " +
                                          std::to_string(db.schema_version()) +
                                          "; campaigns need version 4: run `draglab db migrate`");
  }
}

CampaignLock::CampaignLock(const std::string& db_path, std::int64_t campaign_id,
                           const std::string& name) {
  path_ = db_path + ".campaign-" + std::to_string(campaign_id) + ".lock";
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw Error(ErrorCode::kDatabase, "cannot create the campaign lock file '" + path_ + "'");
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    if (error != EWOULDBLOCK) {
      ::close(fd_);
      throw Error(ErrorCode::kInvalidArgument,
                  "cannot lock '" + path_ + "': " + std::strerror(error) +
                      ": the database's filesystem does not support locks (a network "
                      "filesystem?); put the database on a local disk of the node that runs "
                      "the campaign (rank 0 under MPI)");
    }
    char holder[128] = {0};
    const ssize_t got = ::pread(fd_, holder, sizeof holder - 1, 0);
    if (got > 0) holder[got] = 0;
    std::string who(holder);
    while (!who.empty() && (who.back() == '\n' || who.back() == ' ')) who.pop_back();
    ::close(fd_);
    throw Error(ErrorCode::kDatabase,
                "campaign '" + name + "' is being run by another process (" +
                    (who.empty() ? std::string("lock file ") + path_ : who) +
                    "); one process at a time runs a campaign: wait for it, or stop it and use "
                    "--resume");
  }
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);
  const std::string me = "pid " + std::to_string(::getpid()) + " on " + host + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t w = ::pwrite(fd_, me.data(), me.size(), 0);
  }
}
void CampaignLock::check_filesystem(const std::string& db_path) {
  const std::string probe = db_path + ".campaign-probe-" + std::to_string(::getpid()) + ".lock";
  const int fd = ::open(probe.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return;  // a folder that cannot be written: the database reports it
  const int locked = ::flock(fd, LOCK_EX | LOCK_NB);
  const int error = errno;
  ::close(fd);
  ::unlink(probe.c_str());
  if (locked != 0) {
    throw Error(ErrorCode::kInvalidArgument,
                "cannot lock '" + probe + "': " + std::strerror(error) +
                    ": the database's filesystem does not support locks (a network "
                    "filesystem?); put the database on a local disk of the node that runs "
                    "the campaign (rank 0 under MPI)");
  }
}

CampaignLock::~CampaignLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

bool claim_next(Database& db, std::int64_t campaign_id, const std::string& token,
                ClaimedUnit* unit) {
  Transaction tx(db.handle(), Transaction::Kind::kWrite);
  // Units are created in order of decreasing estimated cost (longest first balances the workers).
  Statement s(db.handle(),
              "UPDATE campaign_units SET status = 'running', attempts = attempts + 1, "
              "claimed_by = ?, started_at = ? WHERE id = (SELECT id FROM campaign_units WHERE "
              "campaign_id = ? AND status = 'pending' ORDER BY id LIMIT 1) "
              "RETURNING id, phi, re_target, resolution, seed, realization");
  s.bind(1, token).bind(2, now_iso8601_ms()).bind(3, campaign_id);
  bool got = false;
  if (s.step()) {
    unit->id = s.integer(0);
    unit->phi = s.real(1);
    unit->re_target = s.real(2);
    unit->resolution = s.real(3);
    unit->seed = s.integer(4);
    unit->realization = static_cast<int>(s.integer(5));
    got = true;
    s.run();
  }
  tx.commit();
  return got;
}

std::string unit_checkpoint_path(const std::string& db_path, std::int64_t campaign_id,
                                 std::int64_t unit_id) {
  return db_path + ".campaign-" + std::to_string(campaign_id) + "-unit-" + std::to_string(unit_id) +
         ".checkpoint";
}

UnitOutcome execute_unit(const CampaignSpec& spec, const ClaimedUnit& unit, int threads,
                         std::atomic<double>* fraction, const mpi::Communicator& group,
                         const std::string& checkpoint, double checkpoint_interval) {
  UnitOutcome out;
  const auto start = Clock::now();
  try {
    const arrays::RandomPackingOptions po =
        internal::packing_options(spec, unit.phi, static_cast<std::uint64_t>(unit.seed));
    arrays::GenerationSummary summary;
    const arrays::Packing packing = arrays::generate_random_packing(po, &summary);
    out.packing_hash = internal::packing_hash(packing);
    lbm::CaseOptions co;
    lbm::RunOptions& ro = co.run;
    ro.collision = lbm::collision_from_string(spec.collision);
    ro.boundary = lbm::boundary_from_string(spec.boundary);
    ro.re = unit.re_target;
    ro.tolerance = spec.tolerance;
    ro.precision = lbm::precision_from_string(spec.precision);
    ro.max_steps = spec.max_steps;
    ro.threads = threads;
    ro.ranks = group;
    ro.checkpoint = checkpoint;
    ro.checkpoint_interval = checkpoint_interval;
    ro.throw_on_failure = false;  // a failed unit is a result: recorded with its diagnosis
    co.resolution = unit.resolution;
    const lbm::ProgressCallback progress = [fraction](double f, const std::string& stage) {
      if (stage == "lbm run") fraction->store(std::clamp(f, 0.0, 1.0));
    };
    std::string stale;
    lbm::CaseResult result;
    try {
      result = lbm::run_case(packing, co, progress);
    } catch (const Error& e) {
      // A checkpoint another run wrote (an earlier code version that planned the unit
      // differently, or a damaged file): the unit starts afresh.
      if (checkpoint.empty() || e.code() != ErrorCode::kInvalidArgument ||
          std::string(e.what()).rfind("checkpoint '", 0) != 0) {
        throw;
      }
      stale = e.what();
      std::remove(checkpoint.c_str());
      result = lbm::run_case(packing, co, progress);
    }
    out.run = result.run;
    out.earlier_parts_s = out.run.earlier_parts_wall_s;
    if (!stale.empty()) out.run.warnings.push_back("started afresh: " + stale);
    out.done = out.run.converged && std::isfinite(out.run.F);
    out.diagnosis = out.run.converged ? "" : out.run.diagnosis;
    if (out.run.converged && !std::isfinite(out.run.F)) out.diagnosis = "non-finite drag";
    // The run's own record (every scalar, the scheme, the lattice), with where the unit's
    // packing came from.
    result.run = out.run;
    out.result = nlohmann::json::parse(result.ToJson(co));
    out.result["box_length"] = packing.box_length;
    out.result["packing_seed"] = unit.seed;
    out.result["packing_wall_s"] = summary.wall_s;
    out.result["lbm_wall_s"] = out.run.wall_s;
    out.result["threads"] = threads;
  } catch (const std::exception& e) {
    // Bad geometry for this unit (gap too small, packing not found) or an engine refusal:
    // recorded as a failed unit, the others go on.
    out.done = false;
    out.diagnosis = e.what();
    out.result = {{"exception", e.what()}};
  }
  out.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

void bind_or_null(Statement& s, int index, double x) {
  if (std::isfinite(x)) {
    s.bind(index, x);
  } else {
    s.bind_null(index);
  }
}

/// Commits a unit's outcome; false if the unit was no longer ours (another process took it over
/// after this one was presumed dead), in which case nothing is written.
bool commit_unit(Database& db, const ClaimedUnit& unit, const std::string& token,
                 const UnitOutcome& o) {
  Transaction tx(db.handle(), Transaction::Kind::kWrite);
  Statement s(db.handle(),
              "UPDATE campaign_units SET status = ?, finished_at = ?, F = ?, beta_d2_over_mu = ?, "
              "re = ?, error_estimate = ?, steps = ?, wall_s = ?, mflups = ?, converged = ?, "
              "diagnosis = ?, packing_hash = ?, code_version = ?, result_json = ? "
              "WHERE id = ? AND status = 'running' AND claimed_by = ?");
  s.bind(1, o.done ? "done" : "failed").bind(2, now_iso8601_ms());
  bind_or_null(s, 3, o.done ? o.run.F : NAN);
  bind_or_null(s, 4, o.done ? o.run.beta_d2_over_mu : NAN);
  bind_or_null(s, 5, o.done ? o.run.re : NAN);
  bind_or_null(s, 6, o.done ? o.run.error_estimate : NAN);
  s.bind(7, o.run.steps).bind(8, o.wall_s + o.earlier_parts_s);
  bind_or_null(s, 9, o.run.mflups);
  s.bind(10, o.done ? 1 : 0).bind(11, o.diagnosis).bind(12, o.packing_hash);
  s.bind(13, kDragDbVersion).bind(14, o.result.dump()).bind(15, unit.id).bind(16, token);
  s.run();
  const bool ours = sqlite3_changes(db.handle()) == 1;
  tx.commit();
  return ours;
}

std::int64_t find_campaign(const Database& db, const std::string& name, std::string* spec_hash) {
  Statement s(db.handle(), "SELECT id, spec_hash FROM campaigns WHERE name = ?");
  s.bind(1, name);
  if (!s.step()) return 0;
  if (spec_hash) *spec_hash = s.text(1);
  return s.integer(0);
}

/// One unit to create, with its cost estimate (creation order: most expensive first).
struct PlannedUnit {
  int phi_index, re_index, realization, resolution_index;
  double resolution, cost;
};

std::int64_t insert_campaign(Database& db, const CampaignSpec& spec, const std::string& spec_json,
                             const std::string& spec_hash) {
  std::vector<PlannedUnit> plan;
  for (int i = 0; i < static_cast<int>(spec.phi.size()); ++i) {
    for (int j = 0; j < static_cast<int>(spec.re.size()); ++j) {
      const std::vector<double> resolutions = spec.point_resolutions(spec.phi[i], spec.re[j]);
      for (int r = 0; r < spec.realizations; ++r) {
        for (int k = 0; k < static_cast<int>(resolutions.size()); ++k) {
          const double d = resolutions[k];
          plan.push_back(
              {i, j, r, k, d, internal::unit_cost_estimate(spec, spec.phi[i], spec.re[j], d)});
        }
      }
    }
  }
  std::stable_sort(plan.begin(), plan.end(),
                   [](const PlannedUnit& a, const PlannedUnit& b) { return a.cost > b.cost; });
  Statement c(db.handle(),
              "INSERT INTO campaigns (name, spec_json, spec_hash, created_at, code_version) "
              "VALUES (?, ?, ?, ?, ?)");
  c.bind(1, spec.name).bind(2, spec_json).bind(3, spec_hash).bind(4, db::utc_now_iso8601());
  c.bind(5, kDragDbVersion);
  c.run();
  const std::int64_t id = sqlite3_last_insert_rowid(db.handle());
  Statement u(db.handle(),
              "INSERT INTO campaign_units (campaign_id, phi_index, re_index, realization, "
              "resolution_index, phi, re_target, resolution, seed) VALUES (?, ?, ?, ?, ?, ?, ?, ?, "
              "?)");
  for (const PlannedUnit& p : plan) {
    u.reset();
    u.bind(1, id).bind(2, p.phi_index).bind(3, p.re_index).bind(4, p.realization);
    u.bind(5, p.resolution_index).bind(6, spec.phi[p.phi_index]).bind(7, spec.re[p.re_index]);
    u.bind(8, p.resolution);
    u.bind(9, static_cast<std::int64_t>(
                  internal::packing_seed(spec.seed, p.phi_index, p.realization)));
    u.run();
  }
  return id;
}

std::int64_t create_campaign(Database& db, const CampaignSpec& spec, const std::string& spec_json,
                             const std::string& spec_hash) {
  Transaction tx(db.handle(), Transaction::Kind::kWrite);
  const std::int64_t id = insert_campaign(db, spec, spec_json, spec_hash);
  tx.commit();
  return id;
}

/// Memory of the largest unit times the workers, against the machine: refused before any work.
void check_memory(const CampaignSpec& spec, int workers) {
  double nodes = 0.0, d = 0.0;
  for (double phi : spec.phi) {
    const int n = internal::packing_options(spec, phi, 1).n;
    for (double re : spec.re) {
      for (double point_d : spec.point_resolutions(phi, re)) {
        const double point_nodes = std::pow(std::cbrt(n * M_PI / (6.0 * phi)) * point_d, 3);
        if (point_nodes > nodes) nodes = point_nodes, d = point_d;
      }
    }
  }
  const double bytes =
      lbm::estimated_run_bytes(nodes, lbm::precision_from_string(spec.precision)) * workers;
  const double memory = lbm::physical_memory_bytes();
  if (memory > 0 && bytes > 0.8 * memory) {
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "[lbm] resolutions: the largest unit (d = %g) needs about %.1f GiB per worker, "
                  "%.1f GiB for %d workers: more than 80 %% of this machine's %.1f GiB; lower the "
                  "resolution, the spheres per box, or --jobs",
                  d, bytes / workers / 1073741824.0, bytes / 1073741824.0, workers,
                  memory / 1073741824.0);
    throw Error(ErrorCode::kInvalidArgument, buf);
  }
}

OpenedCampaign open_campaign(const std::string& db_path, const CampaignSpec& spec,
                             const RunCampaignOptions& options, int workers_per_node) {
  check_memory(spec, workers_per_node);
  // Before anything is written: a campaign that could not be locked must not leave a database.
  CampaignLock::check_filesystem(db_path);
  OpenedCampaign c;
  c.db = std::make_unique<Database>(db_path);
  Database& db = *c.db;
  require_campaign_tables(db);
  const std::string spec_json = spec.to_json();
  const std::string spec_hash = draglab::sha256_hex(spec_json);
  std::string stored_hash;
  std::int64_t id = find_campaign(db, spec.name, &stored_hash);
  if (id != 0 && !options.resume) {
    throw Error(ErrorCode::kInvalidArgument,
                "campaign '" + spec.name + "' already exists (id " + std::to_string(id) +
                    "): use --resume to continue it, or give the spec another [campaign] name");
  }
  if (id != 0 && stored_hash != spec_hash) {
    throw Error(
        ErrorCode::kInvalidArgument,
        "campaign '" + spec.name + "' (id " + std::to_string(id) +
            ") was created from a different spec (spec hash " + stored_hash.substr(0, 12) +
            ", this one " + spec_hash.substr(0, 12) +
            "); a campaign's spec cannot change: give the new spec another [campaign] name");
  }
  if (id == 0) {
    try {
      id = create_campaign(db, spec, spec_json, spec_hash);
    } catch (const Error&) {
      // Another process created it at the same moment: continue only with --resume.
      if (find_campaign(db, spec.name, nullptr) == 0) throw;
      throw Error(ErrorCode::kInvalidArgument,
                  "campaign '" + spec.name + "' was just created by another process");
    }
  }
  c.id = id;
  c.lock = std::make_unique<CampaignLock>(db_path, id, spec.name);

  // Units left 'running' by a process that died (the lock proves it is gone) run again.
  {
    Transaction tx(db.handle(), Transaction::Kind::kWrite);
    Statement s(db.handle(),
                "UPDATE campaign_units SET status = 'pending', claimed_by = NULL, started_at = "
                "NULL WHERE campaign_id = ? AND status = 'running'");
    s.bind(1, id).run();
    tx.commit();
  }

  // The session's work: pending units and their estimated costs (for the ETA).
  Statement s(db.handle(),
              "SELECT status, phi, re_target, resolution FROM campaign_units "
              "WHERE campaign_id = ?");
  s.bind(1, id);
  while (s.step()) {
    ++c.total;
    if (s.text(0) == "pending") {
      ++c.pending;
      c.session_cost += internal::unit_cost_estimate(spec, s.real(1), s.real(2), s.real(3));
    } else {
      ++c.finished_before;
    }
  }
  return c;
}

void release_unit(Database& db, std::int64_t unit_id, const std::string& token) {
  Transaction tx(db.handle(), Transaction::Kind::kWrite);
  Statement s(db.handle(),
              "UPDATE campaign_units SET status = 'pending', claimed_by = NULL, started_at = NULL "
              "WHERE id = ? AND status = 'running' AND claimed_by = ?");
  s.bind(1, unit_id).bind(2, token).run();
  tx.commit();
}

std::string progress_line(const std::string& name, std::int64_t finished, std::int64_t total,
                          std::int64_t failed, double fraction, double restored, double elapsed_s,
                          const std::string& event) {
  const double done_here = fraction - restored;
  const double eta = done_here > 0.005 ? elapsed_s * (1.0 - fraction) / done_here : NAN;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "campaign %s: %lld/%lld units (%lld failed this run), %.1f %% of the work, "
                "elapsed %s, eta %s%s",
                name.c_str(), static_cast<long long>(finished), static_cast<long long>(total),
                static_cast<long long>(failed), 100.0 * fraction,
                format_duration(elapsed_s).c_str(), format_duration(eta).c_str(),
                event.empty() ? "" : ("; " + event).c_str());
  return buf;
}

std::string unit_event(const ClaimedUnit& unit, const UnitOutcome& o) {
  char event[512];
  std::snprintf(event, sizeof event, "phi = %g, Re = %g, d = %g, realization %d: %s", unit.phi,
                unit.re_target, unit.resolution, unit.realization,
                o.done ? "done" : ("FAILED: " + o.diagnosis).c_str());
  return event;
}

int cores() { return std::max(1u, std::thread::hardware_concurrency()); }

SessionReport session_report(const std::string& mode, double wall_s, int threads_per_unit,
                             std::vector<WorkerReport> workers) {
  SessionReport r;
  r.mode = mode;
  r.wall_s = wall_s;
  r.threads_per_unit = threads_per_unit;
  double busy = 0.0;
  for (const WorkerReport& w : workers) busy += w.busy_s;
  r.workers = std::move(workers);
  if (wall_s > 0 && !r.workers.empty()) {
    r.parallel_efficiency = std::min(1.0, busy / (wall_s * static_cast<double>(r.workers.size())));
  }
  return r;
}

nlohmann::json unit_to_json(const ClaimedUnit& unit) {
  return {{"id", unit.id},
          {"phi", unit.phi},
          {"re_target", unit.re_target},
          {"resolution", unit.resolution},
          {"seed", unit.seed},
          {"realization", unit.realization}};
}

ClaimedUnit unit_from_json(const nlohmann::json& j) {
  ClaimedUnit u;
  u.id = j.at("id").get<std::int64_t>();
  u.phi = j.at("phi").get<double>();
  u.re_target = j.at("re_target").get<double>();
  u.resolution = j.at("resolution").get<double>();
  u.seed = j.at("seed").get<std::int64_t>();
  u.realization = j.at("realization").get<int>();
  return u;
}

namespace {
nlohmann::json number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }
double number_from(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return (it == j.end() || it->is_null()) ? NAN : it->get<double>();
}
}  // namespace

nlohmann::json outcome_to_json(const UnitOutcome& o) {
  return {{"done", o.done},
          {"diagnosis", o.diagnosis},
          {"packing_hash", o.packing_hash},
          {"wall_s", o.wall_s},
          {"earlier_parts_s", o.earlier_parts_s},
          {"result", o.result},
          {"F", number(o.run.F)},
          {"beta_d2_over_mu", number(o.run.beta_d2_over_mu)},
          {"re", number(o.run.re)},
          {"error_estimate", number(o.run.error_estimate)},
          {"steps", o.run.steps},
          {"mflups", number(o.run.mflups)}};
}

UnitOutcome outcome_from_json(const nlohmann::json& j) {
  UnitOutcome o;
  o.done = j.at("done").get<bool>();
  o.diagnosis = j.at("diagnosis").get<std::string>();
  o.packing_hash = j.at("packing_hash").get<std::string>();
  o.wall_s = j.at("wall_s").get<double>();
  o.earlier_parts_s = j.value("earlier_parts_s", 0.0);
  o.result = j.at("result");
  o.run.F = number_from(j, "F");
  o.run.beta_d2_over_mu = number_from(j, "beta_d2_over_mu");
  o.run.re = number_from(j, "re");
  o.run.error_estimate = number_from(j, "error_estimate");
  o.run.steps = j.at("steps").get<std::int64_t>();
  o.run.mflups = number_from(j, "mflups");
  return o;
}

void validate_run(const CampaignSpec& spec, const RunCampaignOptions& options) {
  std::string error;
  if (!spec.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  if (options.jobs < 0 || options.jobs > 1024) {
    throw Error(ErrorCode::kInvalidArgument,
                "jobs = " + std::to_string(options.jobs) + " is outside [0, 1024] (0 = all cores)");
  }
  if (options.threads_per_unit < 0 || options.threads_per_unit > 1024) {
    throw Error(ErrorCode::kInvalidArgument,
                "threads per unit = " + std::to_string(options.threads_per_unit) +
                    " is outside [0, 1024] (0 = cores / jobs)");
  }
  if (!(options.checkpoint_interval >= 0.0 && options.checkpoint_interval <= 1e6)) {
    throw Error(ErrorCode::kInvalidArgument,
                "checkpoint interval = " + core::format_number(options.checkpoint_interval) +
                    " s is outside [0, 1e6]");
  }
  if (!(options.worker_timeout_s >= 1.0 && options.worker_timeout_s <= 86400.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                "worker timeout = " + core::format_number(options.worker_timeout_s) +
                    " s is outside [1, 86400]");
  }
  const int job = mpi::size();
  if (spec.ranks_per_unit > 1 && spec.ranks_per_unit > job - 1) {
    throw Error(ErrorCode::kInvalidArgument,
                "[lbm] ranks_per_unit = " + std::to_string(spec.ranks_per_unit) +
                    " is larger than the job: a unit on " + std::to_string(spec.ranks_per_unit) +
                    " ranks needs at least " + std::to_string(spec.ranks_per_unit + 1) +
                    " (rank 0 holds the database), and this job has " + std::to_string(job) +
                    "; start it with mpirun -np " + std::to_string(spec.ranks_per_unit + 1) +
                    " or more, or lower ranks_per_unit");
  }
  if (spec.ranks_per_unit > 1 && (job - 1) % spec.ranks_per_unit != 0) {
    // A smaller last group could not hold the units sized for ranks_per_unit ranks.
    throw Error(
        ErrorCode::kInvalidArgument,
        "[lbm] ranks_per_unit = " + std::to_string(spec.ranks_per_unit) +
            " does not divide the job's " + std::to_string(job - 1) +
            " worker ranks (rank 0 holds the database); start it with mpirun -np " +
            std::to_string(1 + (job - 1) / spec.ranks_per_unit * spec.ranks_per_unit) + " or -np " +
            std::to_string(1 + ((job - 1) / spec.ranks_per_unit + 1) * spec.ranks_per_unit) +
            ", or choose a ranks_per_unit that divides " + std::to_string(job - 1));
  }
}

}  // namespace runner

using db::Statement;
using runner::format_duration;
using runner::require_campaign_tables;

void cancel_distributed_run(int exit_code) {
  if (mpi::size() > 1 && mpi::rank() == 0) runner::broadcast_no_go(exit_code);
}

CampaignStatus run_campaign(const std::string& db_path, const CampaignSpec& spec,
                            const RunCampaignOptions& options) {
  using namespace runner;
  // Under MPI every check happens on rank 0 inside the distributed runner, which tells the
  // workers the outcome: a rank that failed alone would leave the others waiting.
  if (mpi::size() > 1) return run_campaign_distributed(db_path, spec, options);
  validate_run(spec, options);
  const int jobs = options.jobs == 0 ? cores() : options.jobs;
  OpenedCampaign opened = open_campaign(db_path, spec, options, jobs);
  const std::int64_t id = opened.id;
  const double session_cost = opened.session_cost;
  const std::int64_t pending = opened.pending, finished_before = opened.finished_before,
                     total = opened.total;
  const int workers = static_cast<int>(
      std::max<std::int64_t>(1, std::min<std::int64_t>(jobs, std::max<std::int64_t>(pending, 1))));
  const int threads =
      options.threads_per_unit > 0 ? options.threads_per_unit : std::max(1, cores() / workers);

  std::mutex mutex;  // guards the counters below, the progress callback and first_error
  std::int64_t finished = finished_before, failed_session = 0;
  double cost_done = 0.0;
  std::vector<std::atomic<double>> fractions(workers);
  std::vector<double> in_flight_cost(workers, 0.0);
  // A unit resumed from its checkpoint reports at once the progress it had: that part is not
  // this session's work (restored_cost), or the ETA after a resume would be a few seconds.
  std::vector<bool> resuming(workers, false);
  double restored_cost = 0.0;
  std::vector<double> busy_s(workers, 0.0);
  std::vector<int> units_run(workers, 0);
  for (auto& f : fractions) f.store(0.0);
  std::exception_ptr first_error;
  std::atomic<bool> stop{false};
  const auto start = Clock::now();
  const std::string host = mpi::host_name();

  auto report = [&](const std::string& event) {
    // Caller holds `mutex`.
    if (!options.progress) return;
    double partial = cost_done;
    for (int w = 0; w < workers; ++w) {
      const double f = fractions[w].load();
      if (resuming[w] && f > 0.0) {
        restored_cost += in_flight_cost[w] * f;
        resuming[w] = false;
      }
      partial += in_flight_cost[w] * f;
    }
    const double fraction = session_cost > 0 ? std::min(1.0, partial / session_cost) : 1.0;
    const double restored = session_cost > 0 ? std::min(1.0, restored_cost / session_cost) : 0.0;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    options.progress(finished, total,
                     progress_line(spec.name, finished, total, failed_session, fraction, restored,
                                   elapsed, event));
  };

  auto worker = [&](int w) {
    try {
      Database wdb(db_path, worker_db_options());
      const std::string token = host + ":" + std::to_string(::getpid()) + ":" + std::to_string(w);
      ClaimedUnit unit;
      while (!stop.load() && !lbm::stop_requested() && claim_next(wdb, id, token, &unit)) {
        const std::string checkpoint = unit_checkpoint_path(db_path, id, unit.id);
        {
          std::lock_guard<std::mutex> g(mutex);
          fractions[w].store(0.0);
          in_flight_cost[w] =
              internal::unit_cost_estimate(spec, unit.phi, unit.re_target, unit.resolution);
          resuming[w] = !checkpoint.empty() && core::file_exists(checkpoint);
        }
        std::atomic<double>& fraction = fractions[w];
        // Engine progress also refreshes the line (the callback throttles).
        const UnitOutcome o =
            execute_unit(spec, unit, threads, &fraction, mpi::Communicator::self(), checkpoint,
                         options.checkpoint_interval);
        if (o.run.stopped_on_request) {
          // A stop was asked (lbm::request_stop: SIGTERM, SIGINT): not a result. The unit goes
          // back to the queue, its checkpoint kept for the run that resumes it.
          release_unit(wdb, unit.id, token);
          std::lock_guard<std::mutex> g(mutex);
          in_flight_cost[w] = 0.0;
          busy_s[w] += o.wall_s;
          break;
        }
        const bool ours = commit_unit(wdb, unit, token, o);
        std::lock_guard<std::mutex> g(mutex);
        cost_done += in_flight_cost[w];
        in_flight_cost[w] = 0.0;
        busy_s[w] += o.wall_s;
        ++units_run[w];
        if (!ours) continue;
        ++finished;
        if (!o.done) ++failed_session;
        report(unit_event(unit, o));
      }
    } catch (...) {
      std::lock_guard<std::mutex> g(mutex);
      if (!first_error) first_error = std::current_exception();
      stop.store(true);
    }
  };
  {
    std::lock_guard<std::mutex> g(mutex);
    report("");
  }
  std::vector<std::thread> pool;
  for (int w = 0; w < workers; ++w) pool.emplace_back(worker, w);
  // The main thread refreshes the progress line while the units run (ETA of long units).
  std::atomic<bool> all_done{false};
  std::thread ticker([&] {
    while (!all_done.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      if (all_done.load()) break;
      std::lock_guard<std::mutex> g(mutex);
      report("");
    }
  });
  for (auto& t : pool) t.join();
  all_done.store(true);
  ticker.join();
  if (first_error) std::rethrow_exception(first_error);
  CampaignStatus status = campaign_status(*opened.db, std::to_string(id));
  status.session = session_report(
      "threads", std::chrono::duration<double>(Clock::now() - start).count(), threads, [&] {
        std::vector<WorkerReport> r;
        for (int w = 0; w < workers; ++w) {
          r.push_back({"worker " + std::to_string(w), host, units_run[w], busy_s[w]});
        }
        return r;
      }());
  return status;
}

std::string SessionReport::FullReport() const {
  if (mode.empty()) return "";
  std::ostringstream s;
  char line[256];
  std::snprintf(line, sizeof line, "%-10s %-20s %6s %12s %7s\n", "worker", "host", "units", "busy",
                "busy %");
  s << line;
  for (const WorkerReport& w : workers) {
    std::snprintf(line, sizeof line, "%-10s %-20s %6d %12s %6.1f%%\n", w.name.c_str(),
                  w.host.c_str(), w.units, runner::format_duration(w.busy_s).c_str(),
                  wall_s > 0 ? 100.0 * w.busy_s / wall_s : 0.0);
    s << line;
  }
  std::snprintf(
      line, sizeof line, "parallel efficiency %.1f %% (%zu %s x %s, %d thread%s per unit)\n",
      100.0 * parallel_efficiency, workers.size(), mode == "mpi" ? "ranks" : "workers",
      runner::format_duration(wall_s).c_str(), threads_per_unit, threads_per_unit == 1 ? "" : "s");
  s << line;
  for (const std::string& n : notes) s << "note: " << n << "\n";
  return s.str();
}

std::string SessionReport::ToJson() const {
  nlohmann::json j = {{"mode", mode},
                      {"wall_s", wall_s},
                      {"threads_per_unit", threads_per_unit},
                      {"parallel_efficiency", parallel_efficiency},
                      {"notes", notes},
                      {"workers", nlohmann::json::array()}};
  for (const WorkerReport& w : workers) {
    j["workers"].push_back(
        {{"name", w.name}, {"host", w.host}, {"units", w.units}, {"busy_s", w.busy_s}});
  }
  return j.dump();
}

std::string CampaignStatus::BriefReport() const {
  std::ostringstream s;
  s << "campaign " << name << " (id " << id << "): " << units_done << "/" << units_total
    << " units done, " << units_failed << " failed, " << units_pending + units_running << " to run";
  return s.str();
}

std::string CampaignStatus::FullReport() const {
  std::ostringstream s;
  s << BriefReport() << "\n";
  s << "  spec hash   " << spec_hash << "\n";
  s << "  created at  " << created_at << "\n";
  s << "  pending     " << units_pending << ", running " << units_running << "\n";
  s << "  LBM time    " << format_duration(wall_s) << " (sum over finished units)\n";
  for (const UnitInProgress& u : in_progress) {
    char head[160];
    std::snprintf(head, sizeof head, "  unit %lld (phi %g, Re %g, d %g, realization %d, %s): ",
                  static_cast<long long>(u.unit_id), u.phi, u.re_target, u.resolution,
                  u.realization, u.status.c_str());
    s << head;
    if (!u.unreadable.empty()) {
      s << "checkpoint unreadable: " << u.unreadable << "\n";
      continue;
    }
    s << "checkpoint " << format_duration(u.checkpoint_age_s) << " old, "
      << u.progress.BriefReport() << "\n";
  }
  return s.str();
}

namespace {

/// Seconds since `path` was last written (0 if it cannot be read).
double file_age_seconds(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return 0.0;
  return std::max(0.0, std::difftime(std::time(nullptr), st.st_mtime));
}

/// The unfinished units of a campaign whose checkpoint exists, with what it records.
std::vector<UnitInProgress> units_in_progress(const Database& db, std::int64_t campaign_id) {
  std::vector<UnitInProgress> out;
  if (db.path().empty() || db.path() == ":memory:") return out;
  Statement s(db.handle(),
              "SELECT id, phi, re_target, resolution, realization, status FROM campaign_units "
              "WHERE campaign_id = ? AND status IN ('running', 'pending') ORDER BY id");
  s.bind(1, campaign_id);
  while (s.step()) {
    const std::string checkpoint =
        runner::unit_checkpoint_path(db.path(), campaign_id, s.integer(0));
    if (!core::file_exists(checkpoint)) continue;
    UnitInProgress u;
    u.unit_id = s.integer(0);
    u.phi = s.real(1);
    u.re_target = s.real(2);
    u.resolution = s.real(3);
    u.realization = static_cast<int>(s.integer(4));
    u.status = s.text(5);
    u.checkpoint_age_s = file_age_seconds(checkpoint);
    try {
      u.progress = lbm::read_checkpoint_progress(checkpoint);
    } catch (const Error& e) {
      u.unreadable = e.what();  // being replaced this instant, or damaged: say so, go on
    }
    out.push_back(std::move(u));
  }
  return out;
}

}  // namespace

CampaignStatus campaign_status(const Database& db, const std::string& id_or_name) {
  require_campaign_tables(db);
  const bool numeric =
      !id_or_name.empty() && id_or_name.find_first_not_of("0123456789") == std::string::npos;
  Statement s(db.handle(), numeric ? "SELECT id, name, spec_hash, created_at FROM campaigns "
                                     "WHERE id = ?"
                                   : "SELECT id, name, spec_hash, created_at FROM campaigns "
                                     "WHERE name = ?");
  if (numeric) {
    s.bind(1, static_cast<std::int64_t>(std::stoll(id_or_name)));
  } else {
    s.bind(1, id_or_name);
  }
  if (!s.step()) {
    throw Error(ErrorCode::kNotFound, "no campaign with " + std::string(numeric ? "id" : "name") +
                                          " '" + id_or_name + "' (see `draglab campaign status`)");
  }
  CampaignStatus st;
  st.id = s.integer(0);
  st.name = s.text(1);
  st.spec_hash = s.text(2);
  st.created_at = s.text(3);
  Statement c(db.handle(),
              "SELECT status, count(*), coalesce(sum(wall_s), 0) FROM campaign_units WHERE "
              "campaign_id = ? GROUP BY status");
  c.bind(1, st.id);
  while (c.step()) {
    const std::string status = c.text(0);
    const std::int64_t n = c.integer(1);
    st.units_total += n;
    if (status == "done") st.units_done = n;
    if (status == "failed") st.units_failed = n;
    if (status == "pending") st.units_pending = n;
    if (status == "running") st.units_running = n;
    if (status == "done" || status == "failed") st.wall_s += c.real(2);
  }
  st.in_progress = units_in_progress(db, st.id);
  return st;
}

std::vector<CampaignStatus> list_campaigns(const Database& db) {
  require_campaign_tables(db);
  std::vector<std::string> ids;
  {
    Statement s(db.handle(), "SELECT id FROM campaigns ORDER BY id");
    while (s.step()) ids.push_back(std::to_string(s.integer(0)));
  }
  std::vector<CampaignStatus> out;
  for (const auto& i : ids) out.push_back(campaign_status(db, i));
  return out;
}

std::vector<UnitRecord> list_units(const Database& db, std::int64_t campaign_id) {
  require_campaign_tables(db);
  Statement s(db.handle(),
              "SELECT id, campaign_id, phi, re_target, realization, resolution, status, F, "
              "beta_d2_over_mu, re, error_estimate, steps, wall_s, mflups, diagnosis, "
              "packing_hash, code_version, finished_at FROM campaign_units WHERE campaign_id = ? "
              "ORDER BY phi_index, re_index, realization, resolution_index");
  s.bind(1, campaign_id);
  std::vector<UnitRecord> out;
  auto real_or_nan = [&s](int c) {
    return s.is_null(c) ? std::numeric_limits<double>::quiet_NaN() : s.real(c);
  };
  while (s.step()) {
    UnitRecord u;
    u.id = s.integer(0);
    u.campaign_id = s.integer(1);
    u.phi = s.real(2);
    u.re_target = s.real(3);
    u.realization = static_cast<int>(s.integer(4));
    u.resolution = s.real(5);
    u.status = s.text(6);
    u.F = real_or_nan(7);
    u.beta_d2_over_mu = real_or_nan(8);
    u.re = real_or_nan(9);
    u.error_estimate = real_or_nan(10);
    u.steps = s.is_null(11) ? 0 : s.integer(11);
    u.wall_s = s.is_null(12) ? 0.0 : s.real(12);
    u.mflups = s.is_null(13) ? 0.0 : s.real(13);
    u.diagnosis = s.is_null(14) ? "" : s.text(14);
    u.packing_hash = s.is_null(15) ? "" : s.text(15);
    u.code_version = s.is_null(16) ? "" : s.text(16);
    u.finished_at = s.is_null(17) ? "" : s.text(17);
    out.push_back(u);
  }
  return out;
}

CampaignSpec stored_spec(const Database& db, std::int64_t campaign_id) {
  require_campaign_tables(db);
  Statement s(db.handle(), "SELECT spec_json FROM campaigns WHERE id = ?");
  s.bind(1, campaign_id);
  if (!s.step()) {
    throw Error(ErrorCode::kNotFound, "no campaign with id " + std::to_string(campaign_id));
  }
  return internal::spec_from_json(s.text(0));
}

}  // namespace campaign
}  // namespace draglab
