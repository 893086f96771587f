// draglab/mpi/communicator.h: a group of ranks that work on one computation together (one LBM box
// decomposed across ranks), and the collective operations its solver needs: gathers whose result
// every rank sums in the same order (so that every rank takes the same decisions from bitwise
// equal numbers), a gather to the group's first rank, and a non-blocking exchange with the two
// neighbours of a ring (the halo planes of a slab decomposition).
//
// A Communicator of one rank (self(), or world() without a launcher or without MPI) never calls
// MPI: every collective returns this rank's own contribution. mpi.h stays out of this header (the
// communicator is kept as its Fortran handle), so that code built without MPI compiles the same.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace draglab {
namespace mpi {

class Communicator {
 public:
  /// This process alone (the default of every computation).
  static Communicator self();
  /// Every rank the launcher started (self() when there is one).
  static Communicator world();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  /// The ranks of this communicator that pass the same `color` (>= 0), ordered by `key` then
  /// rank: a new communicator per color. Collective over this communicator.
  Communicator split(int color, int key) const;
  /// Rank 0's `text` to every rank of the group (the others' is replaced). Collective.
  void broadcast(std::string* text) const;

  /// Every rank's `mine` (the same length on every rank), concatenated in rank order, on every
  /// rank. Collective.
  std::vector<double> allgather(const std::vector<double>& mine) const;
  /// The element-wise sum over the ranks of `values`, added in rank order: bitwise the same on
  /// every rank (MPI_Allreduce does not promise that). Collective.
  void sum(std::vector<double>* values) const;
  double sum(double value) const;
  std::int64_t sum(std::int64_t value) const;
  /// Every rank's text, in rank order, on every rank. Collective.
  std::vector<std::string> allgather(const std::string& mine) const;
  /// Rank 0 receives every rank's `mine` (lengths may differ, each a multiple of `block`
  /// elements, the same `block` on every rank) concatenated in rank order into `all` (resized);
  /// the other ranks' `all` is left alone. Counted in blocks (planes of a box), so that a box
  /// of more than 2^31 elements gathers as well. Collective.
  void gather_to_root(const std::vector<float>& mine, std::size_t block,
                      std::vector<float>* all) const;
  void gather_to_root(const std::vector<std::uint8_t>& mine, std::size_t block,
                      std::vector<std::uint8_t>* all) const;

  /// Non-blocking exchange of byte buffers with the ranks below and above this one in a ring
  /// (rank - 1 and rank + 1 modulo size, the same rank when size is 2): start() posts the
  /// receives and sends, wait() completes them. The buffers must stay untouched in between.
  /// Messages sent down are received from above and vice versa; the two directions carry
  /// different tags, so a ring of two ranks works.
  class RingExchange {
   public:
    RingExchange();
    ~RingExchange();
    RingExchange(const RingExchange&) = delete;
    RingExchange& operator=(const RingExchange&) = delete;
    void start(const Communicator& group, const void* send_down, std::size_t send_down_bytes,
               const void* send_up, std::size_t send_up_bytes, void* receive_down,
               std::size_t receive_down_bytes, void* receive_up, std::size_t receive_up_bytes);
    void wait();
    /// Lets the transfer advance (MPI_Testall) without waiting; call it now and then between
    /// start() and wait() from the thread that called start().
    void progress();

   private:
    struct Requests;
    std::unique_ptr<Requests> requests_;
  };

 private:
  Communicator(int handle, int rank, int size) : handle_(handle), rank_(rank), size_(size) {}
  int handle_ = 0;  ///< MPI_Comm_c2f of the communicator (unused when size_ == 1).
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace mpi
}  // namespace draglab
