// machine.cc: see draglab/core/machine.h.
#include "draglab/core/machine.h"

#include <unistd.h>

namespace draglab {
namespace core {

double physical_memory_bytes() {
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
#else
  return 0.0;
#endif
}

}  // namespace core
}  // namespace draglab
