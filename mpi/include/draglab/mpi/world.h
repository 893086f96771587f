// draglab/mpi/world.h: the MPI world draglab runs in when an MPI launcher (mpirun, mpiexec, Slurm's
// srun) starts it, and the few point-to-point text messages its distributed commands exchange.
//
// Started without a launcher, draglab never calls MPI: the world is one rank. A build without MPI
// (-DDRAGLAB_MPI=OFF, or no mpi.h found) is the same, and refuses a launch with several ranks
// instead of running the same command N times. Messages are polled with a time limit, so that a
// rank whose peer died (under `mpirun --enable-recovery` or `srun --no-kill` the others go on)
// never waits forever.
#pragma once

#include <stdexcept>
#include <string>

namespace draglab {
namespace mpi {

/// True when this build links MPI.
bool available();

/// The number of ranks an MPI launcher started this process among, read from the launcher's
/// environment (OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_... ); 0 when no launcher started it.
int launcher_world_size();

/// Starts MPI (MPI_Init_thread, asking for MPI_THREAD_MULTIPLE) when a launcher started this
/// process; otherwise does nothing. Call once from main, before any other thread exists. Throws
/// Error(kInvalidArgument) when a launcher started several ranks of a build without MPI.
void init(int* argc, char*** argv);

/// Ends MPI if init started it (idempotent). Called by ~Session. Skipped after
/// mark_peer_lost(): MPI_Finalize waits for every rank, a dead one included.
void finalize();

/// Records that a rank of the job died (the job went on, under `mpirun --enable-recovery`).
void mark_peer_lost();

/// init at construction, finalize at destruction: one in main.
class Session {
 public:
  Session(int* argc, char*** argv) { init(argc, argv); }
  ~Session() { finalize(); }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

int rank();                  ///< This process's rank in MPI_COMM_WORLD (0 without MPI).
int size();                  ///< Ranks in MPI_COMM_WORLD (1 without MPI).
bool started_by_launcher();  ///< init found a launcher (size() may still be 1: `mpirun -np 1`).
bool threads_multiple();     ///< MPI_THREAD_MULTIPLE granted (several threads may send).
int local_size();            ///< Ranks on this node (MPI_COMM_TYPE_SHARED), 1 without MPI.
bool rank0_is_local();       ///< Rank 0 runs on this node.
std::string host_name();     ///< This node's name (MPI_Get_processor_name or gethostname).

/// Ends every rank of the job with `code` (MPI_Abort; std::exit without MPI).
[[noreturn]] void abort(int code);

constexpr int kAnySource = -1;

struct Message {
  int source = -1;
  int tag = -1;
  std::string text;
};

/// Sends `text` to rank `dest` with `tag` (0 <= tag < 32768) and waits until MPI no longer
/// needs the buffer, at most `seconds`: false if that did not happen in time. Small messages
/// complete at once whatever the peer does, so this rarely detects a dead peer (heartbeats do);
/// it bounds the wait for a large one. A send that failed marks a peer lost (mark_peer_lost).
bool send(int dest, int tag, const std::string& text, double seconds);

/// Waits up to `seconds` for a message from `source` (kAnySource: any rank); false on timeout.
bool receive(Message* message, double seconds, int source = kAnySource);

/// Collective: rank 0's `text` to every rank (the others' `text` is replaced).
void broadcast(std::string* text);

/// Thrown on a rank other than 0 when rank 0 ended the command: the rank exits with
/// `exit_code`, silently (rank 0 printed the reason).
class EndedByRank0 : public std::runtime_error {
 public:
  explicit EndedByRank0(int exit_code)
      : std::runtime_error("ended by rank 0"), exit_code_(exit_code) {}
  int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

}  // namespace mpi
}  // namespace draglab
