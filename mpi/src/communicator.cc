// mpi/src/communicator.cc: see draglab/mpi/communicator.h.
#include "draglab/mpi/communicator.h"

#include <limits>
#include <stdexcept>

#if DRAGLAB_HAVE_MPI
#include <mpi.h>
#endif

#include "draglab/error.h"
#include "draglab/mpi/world.h"

namespace draglab {
namespace mpi {
namespace {

#if DRAGLAB_HAVE_MPI
// Tags of the ring exchange: what travels down arrives from above, and vice versa.
constexpr int kTagDown = 7101;
constexpr int kTagUp = 7102;

int checked_count(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw Error(ErrorCode::kInvalidArgument,
                std::string("mpi: ") + what +
                    " exceeds 2^31 - 1 elements per rank; use more ranks for this box");
  }
  return static_cast<int>(n);
}

MPI_Comm comm(int handle) { return MPI_Comm_f2c(static_cast<MPI_Fint>(handle)); }

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) {
    throw Error(ErrorCode::kIo, std::string("mpi: ") + what + " failed (a rank may have died)");
  }
}

template <typename T>
void gather(int handle, int size, const std::vector<T>& mine, std::size_t block,
            std::vector<T>* all, MPI_Datatype element, bool root) {
  // Every rank checks the same limit before the first collective call (block is the same on all).
  const int block_count = checked_count(block, "a gathered block");
  if (block == 0 || mine.size() % block != 0) {
    throw std::logic_error("mpi: a gathered vector is not a whole number of blocks");
  }
  MPI_Datatype type = MPI_DATATYPE_NULL;
  check(MPI_Type_contiguous(block_count, element, &type), "MPI_Type_contiguous");
  MPI_Type_commit(&type);
  const int count = static_cast<int>(mine.size() / block);  // blocks: planes of a box
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(counts.size(), 0);
  const int gathered = MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm(handle));
  if (gathered == MPI_SUCCESS && root) {
    long long total = 0;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      offsets[r] = static_cast<int>(total);
      total += counts[r];
    }
    all->resize(static_cast<std::size_t>(total) * block);
  }
  const int code = gathered != MPI_SUCCESS
                       ? gathered
                       : MPI_Gatherv(mine.data(), count, type, root ? all->data() : nullptr,
                                     counts.data(), offsets.data(), type, 0, comm(handle));
  MPI_Type_free(&type);
  check(code, "MPI_Gatherv");
}
#endif

}  // namespace

Communicator Communicator::self() { return Communicator(0, 0, 1); }

Communicator Communicator::world() {
#if DRAGLAB_HAVE_MPI
  if (mpi::size() > 1) {
    return Communicator(static_cast<int>(MPI_Comm_c2f(MPI_COMM_WORLD)), mpi::rank(), mpi::size());
  }
#endif
  return self();
}

Communicator Communicator::split(int color, int key) const {
  if (size_ == 1) return *this;
#if DRAGLAB_HAVE_MPI
  MPI_Comm part = MPI_COMM_NULL;
  check(MPI_Comm_split(comm(handle_), color, key, &part), "MPI_Comm_split");
  int rank = 0, size = 1;
  MPI_Comm_rank(part, &rank);
  MPI_Comm_size(part, &size);
  // Kept for the life of the process (MPI_Finalize frees it): a handful per run.
  return Communicator(static_cast<int>(MPI_Comm_c2f(part)), rank, size);
#else
  (void)color, (void)key;
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

void Communicator::broadcast(std::string* text) const {
  if (size_ == 1) return;
#if DRAGLAB_HAVE_MPI
  long long length = static_cast<long long>(text->size());
  check(MPI_Bcast(&length, 1, MPI_LONG_LONG, 0, comm(handle_)), "MPI_Bcast");
  text->resize(static_cast<std::size_t>(length));
  check(MPI_Bcast(text->data(), checked_count(text->size(), "a broadcast text"), MPI_CHAR, 0,
                  comm(handle_)),
        "MPI_Bcast");
#else
  (void)text;
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

std::vector<double> Communicator::allgather(const std::vector<double>& mine) const {
  if (size_ == 1) return mine;
#if DRAGLAB_HAVE_MPI
  std::vector<double> all(mine.size() * static_cast<std::size_t>(size_));
  const int count = checked_count(mine.size(), "a gathered vector");
  check(MPI_Allgather(mine.data(), count, MPI_DOUBLE, all.data(), count, MPI_DOUBLE, comm(handle_)),
        "MPI_Allgather");
  return all;
#else
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

void Communicator::sum(std::vector<double>* values) const {
  if (size_ == 1) return;
  const std::size_t n = values->size();
  const std::vector<double> all = allgather(*values);
  for (std::size_t k = 0; k < n; ++k) {
    double s = 0.0;
    for (int r = 0; r < size_; ++r) s += all[static_cast<std::size_t>(r) * n + k];
    (*values)[k] = s;
  }
}

double Communicator::sum(double value) const {
  std::vector<double> v{value};
  sum(&v);
  return v[0];
}

std::int64_t Communicator::sum(std::int64_t value) const {
  if (size_ == 1) return value;
#if DRAGLAB_HAVE_MPI
  std::int64_t total = 0;
  check(MPI_Allreduce(&value, &total, 1, MPI_INT64_T, MPI_SUM, comm(handle_)), "MPI_Allreduce");
  return total;
#else
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

std::vector<std::string> Communicator::allgather(const std::string& mine) const {
  if (size_ == 1) return {mine};
#if DRAGLAB_HAVE_MPI
  const int length = checked_count(mine.size(), "a gathered text");
  std::vector<int> lengths(static_cast<std::size_t>(size_)), offsets(lengths.size(), 0);
  check(MPI_Allgather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, comm(handle_)),
        "MPI_Allgather");
  std::size_t total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = checked_count(total, "a gathered text");
    total += static_cast<std::size_t>(lengths[r]);
  }
  std::string all(total, '\0');
  check(MPI_Allgatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(),
                       MPI_CHAR, comm(handle_)),
        "MPI_Allgatherv");
  std::vector<std::string> out;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    out.push_back(
        all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r])));
  }
  return out;
#else
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

void Communicator::gather_to_root(const std::vector<float>& mine, std::size_t block,
                                  std::vector<float>* all) const {
  if (size_ == 1) {
    *all = mine;
    return;
  }
#if DRAGLAB_HAVE_MPI
  gather(handle_, size_, mine, block, all, MPI_FLOAT, is_root());
#else
  (void)block;
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

void Communicator::gather_to_root(const std::vector<std::uint8_t>& mine, std::size_t block,
                                  std::vector<std::uint8_t>* all) const {
  if (size_ == 1) {
    *all = mine;
    return;
  }
#if DRAGLAB_HAVE_MPI
  gather(handle_, size_, mine, block, all, MPI_UINT8_T, is_root());
#else
  (void)block;
  throw std::logic_error("mpi: a communicator of several ranks in a build without MPI");
#endif
}

#if DRAGLAB_HAVE_MPI
struct Communicator::RingExchange::Requests {
  MPI_Request request[4] = {MPI_REQUEST_NULL, MPI_REQUEST_NULL, MPI_REQUEST_NULL, MPI_REQUEST_NULL};
};
#else
struct Communicator::RingExchange::Requests {};
#endif

Communicator::RingExchange::RingExchange() : requests_(std::make_unique<Requests>()) {}
Communicator::RingExchange::~RingExchange() {
#if DRAGLAB_HAVE_MPI
  // Never leave a posted request behind (an exception between start and wait).
  for (MPI_Request& r : requests_->request) {
    if (r != MPI_REQUEST_NULL) MPI_Wait(&r, MPI_STATUS_IGNORE);
  }
#endif
}

void Communicator::RingExchange::start(const Communicator& group, const void* send_down,
                                       std::size_t send_down_bytes, const void* send_up,
                                       std::size_t send_up_bytes, void* receive_down,
                                       std::size_t receive_down_bytes, void* receive_up,
                                       std::size_t receive_up_bytes) {
#if DRAGLAB_HAVE_MPI
  const int n = group.size();
  const int down = (group.rank() + n - 1) % n, up = (group.rank() + 1) % n;
  const MPI_Comm c = comm(group.handle_);
  MPI_Request* r = requests_->request;
  check(MPI_Irecv(receive_down, checked_count(receive_down_bytes, "a halo"), MPI_BYTE, down, kTagUp,
                  c, &r[0]),
        "MPI_Irecv");
  check(MPI_Irecv(receive_up, checked_count(receive_up_bytes, "a halo"), MPI_BYTE, up, kTagDown, c,
                  &r[1]),
        "MPI_Irecv");
  check(MPI_Isend(send_down, checked_count(send_down_bytes, "a halo"), MPI_BYTE, down, kTagDown, c,
                  &r[2]),
        "MPI_Isend");
  check(MPI_Isend(send_up, checked_count(send_up_bytes, "a halo"), MPI_BYTE, up, kTagUp, c, &r[3]),
        "MPI_Isend");
#else
  (void)group, (void)send_down, (void)send_down_bytes, (void)send_up, (void)send_up_bytes;
  (void)receive_down, (void)receive_down_bytes, (void)receive_up, (void)receive_up_bytes;
  throw std::logic_error("mpi: a ring exchange in a build without MPI");
#endif
}

void Communicator::RingExchange::progress() {
#if DRAGLAB_HAVE_MPI
  int done = 0;
  MPI_Testall(4, requests_->request, &done, MPI_STATUSES_IGNORE);
#endif
}

void Communicator::RingExchange::wait() {
#if DRAGLAB_HAVE_MPI
  check(MPI_Waitall(4, requests_->request, MPI_STATUSES_IGNORE), "MPI_Waitall");
#endif
}

}  // namespace mpi
}  // namespace draglab
