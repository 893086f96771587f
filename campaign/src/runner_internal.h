// Private pieces of the campaign runner shared by the single-process runner (runner.cc) and the
// MPI runner (distributed_runner.cc): opening a campaign, claiming, running and committing units.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/database.h"
#include "draglab/lbm/lbm.h"
#include "draglab/mpi/communicator.h"

namespace draglab {
namespace campaign {
namespace runner {

/// An exclusive flock on "<db>.campaign-<id>.lock", held while a process runs the campaign. The
/// kernel releases it when the process dies (SIGKILL included), so a stale lock never blocks a
/// resume; the file itself stays (removing it would race with a process about to lock it). A
/// filesystem without locks is Error(kInvalidArgument).
class CampaignLock {
 public:
  CampaignLock(const std::string& db_path, std::int64_t campaign_id, const std::string& name);
  ~CampaignLock();
  /// Throws Error(kInvalidArgument) when the filesystem of `db_path` cannot take a lock (a
  /// probe file next to it, removed again), before the campaign writes anything.
  static void check_filesystem(const std::string& db_path);
  CampaignLock(const CampaignLock&) = delete;
  CampaignLock& operator=(const CampaignLock&) = delete;

 private:
  std::string path_;
  int fd_ = -1;
};

/// A unit claimed by a worker.
struct ClaimedUnit {
  std::int64_t id = 0;
  double phi = 0, re_target = 0, resolution = 0;
  std::int64_t seed = 0;
  int realization = 0;
};

/// What one unit produced.
struct UnitOutcome {
  bool done = false;
  lbm::RunResult run;
  std::string diagnosis;
  std::string packing_hash;
  double wall_s = 0.0;
  /// A unit resumed from its checkpoint: the wall seconds of its earlier parts (the unit's cost,
  /// stored as its wall_s, is this part's plus these).
  double earlier_parts_s = 0.0;
  nlohmann::json result;
};

/// The campaign found or created, locked, its dead claims released, and its work counted.
struct OpenedCampaign {
  std::unique_ptr<Database> db;
  std::int64_t id = 0;
  std::unique_ptr<CampaignLock> lock;
  std::int64_t total = 0, pending = 0, finished_before = 0;
  double session_cost = 0.0;  ///< Estimated cost of the pending units (for the ETA).
};

/// Refuses (Error(kInvalidArgument)) a spec whose largest unit, `workers` at once, needs more
/// than 80 % of this node's memory.
void check_memory(const CampaignSpec& spec, int workers);

/// Checks the memory of `workers_per_node` units at once, then opens the campaign as above.
OpenedCampaign open_campaign(const std::string& db_path, const CampaignSpec& spec,
                             const RunCampaignOptions& options, int workers_per_node);

DatabaseOptions worker_db_options();
/// Writes the campaign row and one pending unit per (phi, Re, realization, resolution) of the
/// spec (most expensive first), inside the caller's transaction; returns the campaign's id.
std::int64_t insert_campaign(Database& db, const CampaignSpec& spec, const std::string& spec_json,
                             const std::string& spec_hash);
/// The id of the campaign named `name` (0 if none), and its spec hash.
std::int64_t find_campaign(const Database& db, const std::string& name, std::string* spec_hash);
/// Database schema version 4 or later, else Error(kDatabase) naming `draglab db migrate`.
void require_campaign_tables(const Database& db);

/// Claims the next pending unit (most expensive first) for `token`; false when none is left.
bool claim_next(Database& db, std::int64_t campaign_id, const std::string& token,
                ClaimedUnit* unit);

/// Generates the unit's packing and runs the LBM engine, on the ranks of `group` together
/// (every one of them calls it with the same unit); failures are outcomes, not exceptions.
/// `checkpoint`: the run's checkpoint file (lbm::RunOptions::checkpoint), empty for none.
UnitOutcome execute_unit(const CampaignSpec& spec, const ClaimedUnit& unit, int threads,
                         std::atomic<double>* fraction,
                         const mpi::Communicator& group = mpi::Communicator::self(),
                         const std::string& checkpoint = "", double checkpoint_interval = 600.0);

/// Where a unit run by this process keeps its checkpoint: beside the database, so that the
/// process that takes the unit over after a kill goes on from it.
std::string unit_checkpoint_path(const std::string& db_path, std::int64_t campaign_id,
                                 std::int64_t unit_id);

/// Commits an outcome; false if the unit was no longer claimed by `token` (nothing written).
bool commit_unit(Database& db, const ClaimedUnit& unit, const std::string& token,
                 const UnitOutcome& o);

/// Returns a unit claimed by `token` to the queue (its worker is presumed dead).
void release_unit(Database& db, std::int64_t unit_id, const std::string& token);

/// The progress line and the event of a finished unit. `fraction` is the share of the session's
/// work done, `restored` the part of it that resumed units brought from their checkpoints: the
/// ETA extrapolates only the rate of the work this session did.
std::string progress_line(const std::string& name, std::int64_t finished, std::int64_t total,
                          std::int64_t failed, double fraction, double restored, double elapsed_s,
                          const std::string& event);
std::string unit_event(const ClaimedUnit& unit, const UnitOutcome& o);

int cores();

/// The session report of a run: its wall time and what each worker did.
SessionReport session_report(const std::string& mode, double wall_s, int threads_per_unit,
                             std::vector<WorkerReport> workers);

/// Every check of a run before any work: the spec and the options (Error(kInvalidArgument)).
void validate_run(const CampaignSpec& spec, const RunCampaignOptions& options);

/// Rank 0: tells the workers waiting for the run's start that it will not start.
void broadcast_no_go(int exit_code);

/// The MPI runner (distributed_runner.cc); called by run_campaign on every rank when the world
/// has several.
CampaignStatus run_campaign_distributed(const std::string& db_path, const CampaignSpec& spec,
                                        const RunCampaignOptions& options);

/// Messages between rank 0 and the workers (JSON text; doubles round-trip exactly, non-finite
/// numbers travel as null).
nlohmann::json unit_to_json(const ClaimedUnit& unit);
ClaimedUnit unit_from_json(const nlohmann::json& j);
nlohmann::json outcome_to_json(const UnitOutcome& o);
UnitOutcome outcome_from_json(const nlohmann::json& j);

}  // namespace runner
}  // namespace campaign
}  // namespace draglab
