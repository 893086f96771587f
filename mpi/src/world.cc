// mpi/src/world.cc: see draglab/mpi/world.h.
#include "draglab/mpi/world.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#if DRAGLAB_HAVE_MPI
#include <mpi.h>
#endif

#include "draglab/error.h"

namespace draglab {
namespace mpi {
namespace {

struct State {
  bool initialized_here = false;
  bool launcher = false;
  int rank = 0;
  int size = 1;
  bool multiple = false;
  int local_size = 1;
  bool rank0_local = true;
  std::atomic<bool> peer_lost{false};  // also set by a heartbeat thread's failed send
};

State& state() {
  static State s;
  return s;
}

int env_int(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return 0;
  char* end = nullptr;
  const long n = std::strtol(v, &end, 10);
  return (end && *end == 0 && n > 0 && n < (1 << 24)) ? static_cast<int>(n) : 0;
}

#if DRAGLAB_HAVE_MPI
// Polling interval of the timed waits: short against the messages' purpose (units of seconds or
// more), long enough that an idle rank costs no CPU to speak of.
constexpr auto kPoll = std::chrono::microseconds(500);

bool wait_for(MPI_Request* request, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    int done = 0;
    if (MPI_Test(request, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS) return false;
    if (done) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(kPoll);
  }
}
#endif

}  // namespace

bool available() { return DRAGLAB_HAVE_MPI != 0; }

int launcher_world_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"}) {
    if (const int n = env_int(name)) return n;
  }
  // Slurm's srun with PMIx sets PMIX_RANK without a size variable of its own.
  if (std::getenv("PMIX_RANK") && env_int("SLURM_NTASKS")) return env_int("SLURM_NTASKS");
  return 0;
}

void init(int* argc, char*** argv) {
  State& s = state();
  const int launched = launcher_world_size();
  if (launched == 0) return;
  s.launcher = true;
#if DRAGLAB_HAVE_MPI
  int already = 0;
  MPI_Initialized(&already);
  if (!already) {
    int provided = MPI_THREAD_SINGLE;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_MULTIPLE, &provided) != MPI_SUCCESS) {
      throw Error(ErrorCode::kIo,
                  "MPI_Init_thread failed: the MPI launcher's environment is "
                  "set, but MPI could not start");
    }
    s.initialized_here = true;
    s.multiple = provided >= MPI_THREAD_MULTIPLE;
  }
  // A rank that loses its peers reports it itself (timed waits) instead of MPI aborting.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &s.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &s.size);
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, s.rank, MPI_INFO_NULL, &local);
  MPI_Comm_size(local, &s.local_size);
  int has_rank0 = s.rank == 0 ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &has_rank0, 1, MPI_INT, MPI_MAX, local);
  s.rank0_local = has_rank0 != 0;
  MPI_Comm_free(&local);
#else
  (void)argc;
  (void)argv;
  if (launched > 1) {
    throw Error(ErrorCode::kInvalidArgument,
                "started by an MPI launcher with " + std::to_string(launched) +
                    " ranks, but this draglab was built without MPI (-DDRAGLAB_MPI=OFF or no "
                    "mpi.h): install libopenmpi-dev and rebuild, or run without mpirun/srun");
  }
#endif
}

void finalize() {
#if DRAGLAB_HAVE_MPI
  State& s = state();
  if (!s.initialized_here) return;
  s.initialized_here = false;
  // MPI_Finalize's closing fence would wait forever for a dead rank; the process ends without it
  // (the launcher reports it, the work is committed).
  if (s.peer_lost.load()) return;
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
#endif
}

void mark_peer_lost() { state().peer_lost = true; }

int rank() { return state().rank; }
int size() { return state().size; }
bool started_by_launcher() { return state().launcher; }
bool threads_multiple() { return state().multiple; }
int local_size() { return state().local_size; }
bool rank0_is_local() { return state().rank0_local; }

std::string host_name() {
  char name[256] = {0};
#if DRAGLAB_HAVE_MPI
  if (state().initialized_here) {
    char buf[MPI_MAX_PROCESSOR_NAME] = {0};
    int length = 0;
    if (MPI_Get_processor_name(buf, &length) == MPI_SUCCESS) return std::string(buf, length);
  }
#endif
  ::gethostname(name, sizeof name - 1);
  return name;
}

void abort(int code) {
#if DRAGLAB_HAVE_MPI
  if (state().initialized_here) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

bool send(int dest, int tag, const std::string& text, double seconds) {
#if DRAGLAB_HAVE_MPI
  // The buffer outlives a send that timed out: MPI may still read it (a started send cannot be
  // cancelled), so it is kept, not freed, and the peer is taken for lost.
  auto buffer = std::make_unique<std::string>(text);
  MPI_Request request;
  if (MPI_Isend(buffer->data(), static_cast<int>(buffer->size()), MPI_CHAR, dest, tag,
                MPI_COMM_WORLD, &request) != MPI_SUCCESS) {
    mark_peer_lost();
    return false;
  }
  if (wait_for(&request, seconds)) return true;
  MPI_Request_free(&request);
  static std::mutex abandoned_mutex;
  static std::vector<std::unique_ptr<std::string>> abandoned;
  {
    std::lock_guard<std::mutex> g(abandoned_mutex);
    abandoned.push_back(std::move(buffer));
  }
  mark_peer_lost();
  return false;
#else
  (void)dest, (void)tag, (void)text, (void)seconds;
  throw Error(ErrorCode::kInternal, "mpi::send in a build without MPI");
#endif
}

bool receive(Message* message, double seconds, int source) {
#if DRAGLAB_HAVE_MPI
  const int from = source == kAnySource ? MPI_ANY_SOURCE : source;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  MPI_Status status;
  for (;;) {
    int flag = 0;
    if (MPI_Iprobe(from, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status) != MPI_SUCCESS) {
      std::this_thread::sleep_for(kPoll);  // an error is not a message: the caller must not spin
      return false;
    }
    if (flag) break;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(kPoll);
  }
  int count = 0;
  MPI_Get_count(&status, MPI_CHAR, &count);
  std::vector<char> buffer(static_cast<std::size_t>(count));
  if (MPI_Recv(buffer.data(), count, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE) != MPI_SUCCESS) {
    return false;
  }
  message->source = status.MPI_SOURCE;
  message->tag = status.MPI_TAG;
  message->text.assign(buffer.begin(), buffer.end());
  return true;
#else
  (void)message, (void)seconds, (void)source;
  throw Error(ErrorCode::kInternal, "mpi::receive in a build without MPI");
#endif
}

void broadcast(std::string* text) {
#if DRAGLAB_HAVE_MPI
  if (state().size <= 1) return;
  int length = static_cast<int>(text->size());
  MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
  text->resize(static_cast<std::size_t>(length));
  MPI_Bcast(text->data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
#else
  (void)text;
#endif
}

}  // namespace mpi
}  // namespace draglab
