// draglab/core/isolated.h: reading a file with a library that can crash on damaged input, in a
// child process, so that the damage becomes a clear error instead of ending draglab.
//
// Why: Debian 12's libhdf5 1.10 crashes, hangs or asks for 2^64 bytes on some damaged files
// (global-heap and metadata-cache defects found by fuzz_packing_hdf5; fuzz/regressions/). No
// check before the read can rule that out, so the read is tried first in a forked child with a
// time limit and (without AddressSanitizer, whose shadow memory needs the address space) a
// memory limit; only a read that succeeded there is repeated in this process.
#pragma once

#include <functional>
#include <string>

namespace draglab {
namespace core {

/// Runs `work` in a child process. Returns when it returned. A draglab::Error it throws is
/// rethrown here with its code and message. When the child is killed by a signal (a crash),
/// exceeds `seconds`, runs out of memory or ends otherwise, throws Error(kInvalidArgument)
/// "`what` is damaged: ..." naming what happened. `work` must not depend on this process's
/// other threads (the child has only the calling thread).
void run_isolated(const std::function<void()>& work, const std::string& what, unsigned seconds,
                  unsigned long long memory_bytes);

}  // namespace core
}  // namespace draglab
