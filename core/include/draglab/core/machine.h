// draglab/core/machine.h: what this machine offers, for the size checks made before long work.
#pragma once

namespace draglab {
namespace core {

/// Physical memory in bytes (sysconf), 0 when unknown (then no memory check can be made).
double physical_memory_bytes();

}  // namespace core
}  // namespace draglab
