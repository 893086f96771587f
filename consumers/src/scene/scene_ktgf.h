// The kinetic-theory options a scene's [tfm] table declares, written once for the scene's
// validation and the two-fluid model.
#pragma once

#include "draglab/consumers/scene.h"
#include "tfm/ktgf.h"

namespace draglab {
namespace consumers {
namespace internal {

/// The closure set, g0, restitution (the [particles] one unless [tfm] gives it), packing limit
/// and friction of `scene`'s [tfm] table. A name that does not parse leaves the default
/// (Scene::IsValid reports it); ranges are KtgfOptions::IsValid's.
KtgfOptions scene_ktgf_options(const Scene& scene);

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
