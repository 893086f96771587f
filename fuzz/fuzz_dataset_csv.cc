// Fuzz target: the dataset CSV reader read_dataset_csv (drag_db/src/db/dataset_store.cc), which
// takes a path: the input is written to a scratch file first. An accepted dataset is exported
// with dataset_csv_text and read back.
//
// Properties checked beyond "no crash": the export of an accepted dataset reads back to the same
// dataset (same hash, hence same id: `draglab dataset export` then `import` must reproduce it).
#include <cstddef>
#include <cstdint>
#include <string>

#include "draglab/drag_db/dataset.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto& scratch = draglab_fuzz::ScratchDir::get();
  const std::string path = scratch.write("fuzz.csv", data, size);
  draglab_fuzz::expect_clean([&] {
    const draglab::Dataset dataset = draglab::read_dataset_csv(path);
    if (dataset.points.empty()) draglab_fuzz::finding("accepted dataset has no points");
    const std::string text = draglab::dataset_csv_text(dataset, {"fuzz"});
    const std::string again_path =
        scratch.write("again.csv", reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
    draglab::Dataset again;
    try {
      again = draglab::read_dataset_csv(again_path);
    } catch (const draglab::Error& e) {
      draglab_fuzz::finding(std::string("the export of an accepted dataset is refused: ") +
                            e.what() + "\n" + text);
    }
    if (again.hash != dataset.hash || again.points.size() != dataset.points.size()) {
      draglab_fuzz::finding("the export does not read back to the same dataset:\n" + text);
    }
  });
  return 0;
}
