// The bed models built into the consumers library. The registry adds them on first use (a static
// library drops self-registering objects nothing references, so the built-ins are named here).
#pragma once

#include <memory>

#include "draglab/consumers/bed_model.h"

namespace draglab {
namespace consumers {
namespace internal {

std::unique_ptr<BedModel> make_dpm_bed_model();
std::unique_ptr<BedModel> make_tfm_bed_model();
std::unique_ptr<BedModel> make_dbm_bed_model();

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
