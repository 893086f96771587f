// The campaign runner across MPI ranks. Rank 0 is the single-process runner's database side:
// it alone opens the database (SQLite must never be written by many nodes over a network
// filesystem), claims units most expensive first with the same UPDATE ... RETURNING, and commits
// every result in its own transaction with the same guarded UPDATE. Ranks 1..N-1 only compute:
// they receive a unit, generate its packing, run the LBM engine (OpenMP threads within the rank)
// and send the outcome back.
//
// Kill-safety is the database's, as for one process: a unit is 'running' under its rank's token
// until its result is committed. A worker sends a heartbeat every second; one silent for
// worker_timeout_s is presumed dead, its unit is released to the queue and handed to another
// rank, and a late result from it is refused by the token check. When rank 0 dies, the workers
// notice its silence and end; `--resume` on any number of ranks finishes the campaign.
//
// Units on several ranks ([lbm] ranks_per_unit = k > 1, dividing N - 1): the workers form groups
// of k consecutive ranks, each with its own
// communicator. Rank 0 talks to each group's first rank, the leader, exactly as to a worker; the
// leader passes every unit (and the stop) on to its group by a broadcast, and the group runs the
// unit's box together (lbm::RunOptions::ranks), the leader sending the outcome back.
//
// Messages (tags below) are JSON text.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "campaign_internal.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/mpi/communicator.h"
#include "draglab/mpi/world.h"
#include "runner_internal.h"

namespace draglab {
namespace campaign {
namespace runner {
namespace {

using Clock = std::chrono::steady_clock;

enum Tag : int {
  kReady = 1,      // worker -> 0: give me a unit (sent once at the start)
  kUnit = 2,       // 0 -> worker: a unit to run
  kResult = 3,     // worker -> 0: the outcome of its unit (and ready for the next)
  kHeartbeat = 4,  // worker -> 0: alive, with the fraction of its unit done
  kStop = 5,       // 0 -> worker: no more work
  kPing = 6,       // 0 -> idle worker: rank 0 is alive
};

// How long a send may take before the peer is taken for gone, and how often rank 0 shows an idle
// worker it is alive. A worker that hears nothing from rank 0 for kRank0SilenceSeconds while idle
// ends (rank 0 is gone; the campaign resumes with --resume).
constexpr double kSendSeconds = 60.0;
constexpr double kHeartbeatSeconds = 1.0;
constexpr double kPingSeconds = 5.0;
constexpr double kRank0SilenceSeconds = 120.0;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// Threads of a unit on a worker rank: the node's cores shared among the workers on it.
int workers_on_this_node();

int worker_threads(const RunCampaignOptions& options) {
  if (options.threads_per_unit > 0) return options.threads_per_unit;
  return std::max(1, cores() / workers_on_this_node());
}

int workers_on_this_node() {
  return std::max(1, mpi::local_size() - (mpi::rank0_is_local() ? 1 : 0));
}

/// Units run at once on this node: its worker ranks, k of them per unit.
int units_on_this_node(int ranks_per_unit) {
  return std::max(1, (workers_on_this_node() + ranks_per_unit - 1) / ranks_per_unit);
}

/// The group of a worker rank (ranks 1..N-1 in groups of k consecutive ranks); rank 0 alone.
/// Collective over the world; only when k > 1.
mpi::Communicator unit_group(int ranks_per_unit) {
  const int r = mpi::rank();
  return mpi::Communicator::world().split(r == 0 ? 0 : 1 + (r - 1) / ranks_per_unit, r);
}

bool leads_a_group(int rank, int ranks_per_unit) { return (rank - 1) % ranks_per_unit == 0; }

// ---- rank 0 -------------------------------------------------------------------------------

struct WorkerState {
  bool alive = true;      ///< Not presumed dead.
  bool reachable = true;  ///< No send to it has failed.
  bool heartbeat = true;  ///< It sends heartbeats (until its ready message says otherwise).
  bool idle = false;      ///< Waiting for a unit.
  bool has_unit = false;
  ClaimedUnit unit;
  double unit_cost = 0.0;
  double fraction = 0.0;
  Clock::time_point last_heard = Clock::now();
  Clock::time_point last_ping = Clock::now();
  WorkerReport report;
  std::string token;
};

std::string go_message(bool ok, int exit_code, const std::string& spec_json,
                       int ranks_per_unit = 1) {
  return nlohmann::json{
      {"ok", ok}, {"exit_code", exit_code}, {"spec", spec_json}, {"ranks_per_unit", ranks_per_unit}}
      .dump();
}

CampaignStatus run_rank0(const std::string& db_path, const CampaignSpec& spec,
                         const RunCampaignOptions& options) {
  const int ranks = mpi::size();
  OpenedCampaign opened;
  try {
    validate_run(spec, options);
    opened = open_campaign(db_path, spec, options, units_on_this_node(spec.ranks_per_unit));
  } catch (const Error& e) {
    broadcast_no_go(e.is_bad_input() ? 2 : 1);
    throw;
  } catch (...) {
    broadcast_no_go(1);
    throw;
  }
  const int k = spec.ranks_per_unit;
  std::string go = go_message(true, 0, spec.to_json(), k);
  mpi::broadcast(&go);
  if (k > 1) unit_group(k);  // rank 0 takes part in the split, alone in its group

  Database& db = *opened.db;
  const std::string base_token = mpi::host_name() + ":" + std::to_string(::getpid()) + ":rank";
  std::map<int, WorkerState> workers;  // by rank; with groups, their leaders
  for (int r = 1; r < ranks; ++r) {
    if (!leads_a_group(r, k)) continue;
    const int last = r + k - 1;
    workers[r].token = base_token + std::to_string(r);
    workers[r].report.name = last == r ? "rank " + std::to_string(r)
                                       : "ranks " + std::to_string(r) + "-" + std::to_string(last);
  }
  std::int64_t finished = opened.finished_before, failed_session = 0;
  std::int64_t in_flight = 0;
  double cost_done = 0.0;
  bool queue_empty = false;  // no pending unit was found at the last claim
  std::vector<std::string> notes;
  std::string refusal;  // a worker that cannot run the units (its node's memory)
  const auto start = Clock::now();
  auto last_line = Clock::now() - std::chrono::seconds(10);

  auto report = [&](const std::string& event) {
    if (!options.progress) return;
    if (event.empty() && seconds_since(last_line) < 0.5) return;
    last_line = Clock::now();
    double partial = cost_done;
    for (const auto& [r, w] : workers) {
      if (w.has_unit) partial += w.unit_cost * w.fraction;
    }
    const double fraction =
        opened.session_cost > 0 ? std::min(1.0, partial / opened.session_cost) : 1.0;
    options.progress(finished, opened.total,
                     progress_line(spec.name, finished, opened.total, failed_session, fraction, 0.0,
                                   seconds_since(start), event));
  };

  // A rank presumed dead may only be slow: it is told to stop too, with a short wait. The
  // exit code tells the workers how the run ended.
  auto stop_all = [&](int exit_code) {
    const bool lost =
        std::any_of(workers.begin(), workers.end(), [](const auto& e) { return !e.second.alive; });
    if (lost) mpi::mark_peer_lost();
    const std::string stop = nlohmann::json{{"peer_lost", lost}, {"exit_code", exit_code}}.dump();
    for (auto& [r, w] : workers) {
      if (w.reachable) mpi::send(r, kStop, stop, w.alive ? kSendSeconds : 2.0);
      w.alive = false;
    }
  };

  // Hands a unit to an idle worker; false when the queue is empty.
  auto hand_out = [&](int r, WorkerState& w) {
    ClaimedUnit unit;
    if (!claim_next(db, opened.id, w.token, &unit)) {
      queue_empty = true;
      return false;
    }
    if (!mpi::send(r, kUnit, unit_to_json(unit).dump(), kSendSeconds)) {
      release_unit(db, unit.id, w.token);
      w.alive = w.reachable = false;
      notes.push_back(w.report.name + " did not take a unit: presumed dead");
      return true;
    }
    w.idle = false;
    w.has_unit = true;
    w.unit = unit;
    w.unit_cost = internal::unit_cost_estimate(spec, unit.phi, unit.re_target, unit.resolution);
    w.fraction = 0.0;
    w.last_heard = Clock::now();
    ++in_flight;
    return true;
  };

  auto handle = [&](const mpi::Message& m) {
    auto it = workers.find(m.source);
    if (it == workers.end() || !it->second.reachable) return;
    WorkerState& w = it->second;
    w.last_heard = Clock::now();
    if (!w.alive) {
      // Presumed dead but only slow: back in service. Its unit went to another rank; a late
      // result for it is dropped (the claim is no longer its own).
      w.alive = true;
      notes.push_back(w.report.name + " answered again after being presumed dead");
    }
    const auto j = nlohmann::json::parse(m.text, nullptr, false);
    if (m.tag == kHeartbeat) {
      if (w.has_unit && j.is_object() && j.value("unit", std::int64_t{-1}) == w.unit.id) {
        w.fraction = std::clamp(j.value("fraction", 0.0), 0.0, 1.0);
      }
    } else if (m.tag == kReady) {
      w.idle = true;
      if (j.is_object()) {
        w.report.host = j.value("host", "");
        w.heartbeat = j.value("heartbeat", false);
        const std::string memory = j.value("memory_error", "");
        if (!memory.empty() && refusal.empty()) refusal = w.report.name + ": " + memory;
      }
      if (!w.heartbeat) {
        notes.push_back(w.report.name +
                        " sends no heartbeat (MPI without MPI_THREAD_MULTIPLE): rank 0 waits "
                        "for its results however long, as for a unit in one process");
      }
    } else if (m.tag == kResult) {
      w.idle = true;
      if (!w.has_unit) return;  // the result of a unit handed on: dropped
      const UnitOutcome o = outcome_from_json(nlohmann::json::parse(m.text));
      const bool ours = commit_unit(db, w.unit, w.token, o);
      w.has_unit = false;
      --in_flight;
      cost_done += w.unit_cost;
      ++w.report.units;
      w.report.busy_s += o.wall_s;
      if (ours) {
        ++finished;
        if (!o.done) ++failed_session;
        report(unit_event(w.unit, o) + " (" + w.report.name + ")");
      }
    }
  };

  try {
    report("");
    auto last_pass = Clock::now();
    for (;;) {
      const bool any_alive =
          std::any_of(workers.begin(), workers.end(), [](const auto& e) { return e.second.alive; });
      if (!any_alive) break;
      if (queue_empty && in_flight == 0) break;
      if (!refusal.empty()) {
        throw Error(ErrorCode::kInvalidArgument, refusal);
      }

      // Every waiting message first, then the silences: a backlog is not a death.
      mpi::Message m;
      if (mpi::receive(&m, 0.25)) {
        handle(m);
        while (mpi::receive(&m, 0.0)) handle(m);
      }
      // Rank 0 itself stalled (a suspended job, a slow disk): nobody's silence counts.
      if (seconds_since(last_pass) > 0.5 * options.worker_timeout_s) {
        for (auto& [r, w] : workers) w.last_heard = Clock::now();
      }
      last_pass = Clock::now();

      // Presume silent workers dead; their units go back to the queue.
      for (auto& [r, w] : workers) {
        if (!w.alive || !w.heartbeat) continue;
        if (seconds_since(w.last_heard) <= options.worker_timeout_s) continue;
        w.alive = false;
        w.idle = false;
        std::string note = w.report.name + " silent for " +
                           core::format_number(options.worker_timeout_s) + " s: presumed dead";
        if (w.has_unit) {
          release_unit(db, w.unit.id, w.token);
          w.has_unit = false;
          --in_flight;
          queue_empty = false;
          note += "; its unit (phi = " + core::format_number(w.unit.phi) +
                  ", Re = " + core::format_number(w.unit.re_target) +
                  ", d = " + core::format_number(w.unit.resolution) + ") goes to another rank";
        }
        notes.push_back(note);
        report(note);
      }

      // Idle workers get the next units, or a ping while others finish theirs.
      for (auto& [r, w] : workers) {
        if (!w.alive || !w.idle) continue;
        if (!queue_empty && hand_out(r, w)) continue;
        if (seconds_since(w.last_ping) > kPingSeconds) {
          w.last_ping = Clock::now();
          if (!mpi::send(r, kPing, "", kSendSeconds)) w.alive = w.reachable = false;
        }
      }
      report("");
    }
  } catch (const Error& e) {
    stop_all(e.is_bad_input() ? 2 : 1);
    throw;
  } catch (...) {
    stop_all(1);
    throw;
  }
  stop_all(0);

  CampaignStatus status = campaign_status(db, std::to_string(opened.id));
  const std::int64_t left = status.units_pending + status.units_running;
  if (left > 0) {
    throw Error(ErrorCode::kIo, "every worker rank is gone with " + std::to_string(left) +
                                    " unit(s) of campaign '" + spec.name +
                                    "' left: continue with --resume");
  }
  std::vector<WorkerReport> reports;
  for (const auto& [r, w] : workers) reports.push_back(w.report);
  status.session =
      session_report("mpi", seconds_since(start), worker_threads(options), std::move(reports));
  status.session.notes = notes;
  return status;
}

// ---- ranks 1..N-1 ---------------------------------------------------------------------------

/// Sends a heartbeat every kHeartbeatSeconds from its own thread, also while the rank computes.
/// Needs MPI_THREAD_MULTIPLE; without it the rank sends none and rank 0 cannot tell it from a
/// dead one (it waits for its result, as a single-process run waits for a unit).
class Heartbeat {
 public:
  Heartbeat(std::atomic<double>* fraction, std::atomic<std::int64_t>* unit)
      : fraction_(fraction), unit_(unit), host_(mpi::host_name()) {
    if (!mpi::threads_multiple()) return;
    thread_ = std::thread([this] {
      for (;;) {
        {
          std::unique_lock<std::mutex> lock(mutex_);
          cv_.wait_for(lock, std::chrono::duration<double>(kHeartbeatSeconds));
          if (done_) return;
        }
        beat();  // outside the lock: a slow send never holds up the destructor's notify
      }
    });
  }
  ~Heartbeat() {
    {
      std::lock_guard<std::mutex> g(mutex_);
      done_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  Heartbeat(const Heartbeat&) = delete;
  Heartbeat& operator=(const Heartbeat&) = delete;

  bool beating() const { return thread_.joinable(); }

 private:
  void beat() {
    mpi::send(0, kHeartbeat,
              nlohmann::json{{"unit", unit_->load()}, {"fraction", fraction_->load()}}.dump(),
              kSendSeconds);
  }
  std::atomic<double>* fraction_;
  std::atomic<std::int64_t>* unit_;
  std::string host_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

/// A worker that finds rank 0 gone ends at once, without MPI_Finalize (which would wait for it).
[[noreturn]] void rank0_gone(const std::string& what) {
  mpi::mark_peer_lost();
  throw Error(ErrorCode::kIo, "rank " + std::to_string(mpi::rank()) + ": " + what +
                                  "; the campaign continues with --resume");
}

/// A rank of a unit group other than its leader: runs the units its leader passes on, with the
/// group, until the leader passes on the stop.
CampaignStatus run_group_member(const CampaignSpec& spec, const mpi::Communicator& group,
                                int threads) {
  std::atomic<double> fraction{0.0};
  for (;;) {
    std::string text;
    group.broadcast(&text);
    const nlohmann::json j = nlohmann::json::parse(text);
    if (j.contains("stop")) {
      if (j.value("peer_lost", false)) mpi::mark_peer_lost();
      const int exit_code = j.value("exit_code", 0);
      if (exit_code != 0) throw mpi::EndedByRank0(exit_code);
      return CampaignStatus{};
    }
    execute_unit(spec, unit_from_json(j.at("unit")), threads, &fraction, group);
  }
}

CampaignStatus run_worker(const RunCampaignOptions& options) {
  std::string go;
  mpi::broadcast(&go);
  const nlohmann::json g = nlohmann::json::parse(go);
  if (!g.at("ok").get<bool>()) throw mpi::EndedByRank0(g.at("exit_code").get<int>());
  // The spec as rank 0 read it: the workers need no copy of the spec file.
  const CampaignSpec spec = internal::spec_from_json(g.at("spec").get<std::string>());
  const int k = g.value("ranks_per_unit", 1);
  const mpi::Communicator group = k > 1 ? unit_group(k) : mpi::Communicator::self();
  const int threads = worker_threads(options);
  if (!leads_a_group(mpi::rank(), k)) return run_group_member(spec, group, threads);
  // The leader passes the stop on to its group before it ends, however it ends (rank 0 gone, a
  // message it cannot read): the group's other ranks wait for nothing else.
  struct StopRelay {
    const mpi::Communicator& group;
    bool passed = false;
    void pass(bool peer_lost, int exit_code) {
      if (passed || group.size() == 1) return;
      passed = true;
      std::string text =
          nlohmann::json{{"stop", true}, {"peer_lost", peer_lost}, {"exit_code", exit_code}}.dump();
      group.broadcast(&text);
    }
    ~StopRelay() {
      try {
        pass(true, 1);
      } catch (...) {  // the group is gone too: nothing left to tell
      }
    }
  } relay{group};
  // This node's memory, for its workers' largest units: a refusal goes to rank 0, which stops
  // the run with it (exit 2 on every rank).
  std::string memory_error;
  try {
    check_memory(spec, units_on_this_node(k));
  } catch (const Error& e) {
    memory_error = e.what();
  }

  std::atomic<double> fraction{0.0};
  std::atomic<std::int64_t> current{-1};
  Heartbeat heartbeat(&fraction, &current);
  const std::string ready = nlohmann::json{
      {"host", mpi::host_name()},
      {"heartbeat", heartbeat.beating()},
      {"memory_error",
       memory_error}}.dump();
  if (!mpi::send(0, kReady, ready, kSendSeconds)) rank0_gone("rank 0 did not take a message");
  auto heard = Clock::now();
  for (;;) {
    mpi::Message m;
    if (!mpi::receive(&m, 1.0, 0)) {
      if (seconds_since(heard) > kRank0SilenceSeconds) {
        rank0_gone("rank 0 sent nothing for " + core::format_number(kRank0SilenceSeconds) +
                   " s and is presumed dead");
      }
      continue;
    }
    heard = Clock::now();
    if (m.tag == kStop) {
      const auto j = nlohmann::json::parse(m.text, nullptr, false);
      const bool lost = j.is_object() && j.value("peer_lost", false);
      if (lost) mpi::mark_peer_lost();
      const int exit_code = j.is_object() ? j.value("exit_code", 0) : 0;
      relay.pass(lost, exit_code);
      if (exit_code != 0) throw mpi::EndedByRank0(exit_code);
      break;
    }
    if (m.tag != kUnit) continue;  // a ping
    const nlohmann::json unit_json = nlohmann::json::parse(m.text);
    const ClaimedUnit unit = unit_from_json(unit_json);
    if (group.size() > 1) {
      std::string text = nlohmann::json{{"unit", unit_json}}.dump();
      group.broadcast(&text);
    }
    fraction.store(0.0);
    current.store(unit.id);
    const UnitOutcome o = execute_unit(spec, unit, threads, &fraction, group);
    current.store(-1);
    if (!mpi::send(0, kResult, outcome_to_json(o).dump(), kSendSeconds)) {
      rank0_gone("rank 0 did not take a result");
    }
    heard = Clock::now();
  }
  return CampaignStatus{};
}

}  // namespace

void broadcast_no_go(int exit_code) {
  std::string go = go_message(false, exit_code, "");
  mpi::broadcast(&go);
}

CampaignStatus run_campaign_distributed(const std::string& db_path, const CampaignSpec& spec,
                                        const RunCampaignOptions& options) {
  return mpi::rank() == 0 ? run_rank0(db_path, spec, options) : run_worker(options);
}

}  // namespace runner
}  // namespace campaign
}  // namespace draglab
