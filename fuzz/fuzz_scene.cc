// Fuzz target: the scene reader (consumers/src/scene/scene.cc, TOML through toml++) and what
// `draglab scene check` does with an accepted scene: its hash and particle numbers, the bed
// model's own settings, and for each law of the scene that the (seeded) database knows, the
// derived numbers (U_mf, time steps, bubble leakage).
//
// Properties checked beyond "no crash": an accepted scene passes IsValid and names a registered
// bed model.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/database.h"
#include "fuzz_util.h"

namespace {

/// A database seeded with the literature laws (what `scene check` opens on first use).
draglab::Database& database() {
  static draglab::Database db(draglab_fuzz::ScratchDir::get().file("laws.db"));
  return db;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  database();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  using namespace draglab::consumers;
  Scene scene;
  bool parsed = false;
  draglab_fuzz::expect_clean([&] {
    scene = parse_scene(text, "fuzz.toml");
    parsed = true;
  });
  if (!parsed) return 0;
  std::string error;
  if (!scene.IsValid(&error)) draglab_fuzz::finding("accepted scene fails IsValid: " + error);
  (void)scene.hash();
  (void)scene.particle_count();
  (void)scene.bed_height_mf_m();
  (void)scene.jet_center_m();
  const BedModel& model = find_bed_model(scene.solver);  // an Error here is a finding
  draglab_fuzz::expect_clean([&] {
    (void)model.Settings(scene);
    (void)model.time_resolution_of(scene);
  });
  // At most three laws per input: each is a Brent solve for U_mf.
  for (std::size_t i = 0; i < scene.laws.size() && i < 3; ++i) {
    draglab_fuzz::expect_clean([&] {
      std::string warning;
      const auto law = database().load(scene.laws[i], draglab::RangePolicy::kError, &warning);
      (void)derive_scene(scene, *law).BriefReport();
    });
  }
  return 0;
}
