// Fuzz target: law references "name", "name@latest", "name@<version>", "name@<hash prefix>", as
// Database::resolve parses them (drag_db/src/db/database.cc) and Database::load binds them, on a
// database seeded with the literature laws plus one law with published, draft and retracted
// versions (so that versions, hash prefixes and warnings all have something to match).
//
// Properties checked beyond "no crash": a reference that loads names the law it loads (the text
// before '@', byte for byte), resolves to that same version, its reference() "name@N" loads the
// same content, and the law evaluates inside its box.
#include <cstddef>
#include <cstdint>
#include <string>

#include "draglab/drag_db/database.h"
#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"
#include "fuzz_util.h"

namespace {

draglab::Database& database() {
  static draglab::Database* db = [] {
    auto* made = new draglab::Database(draglab_fuzz::ScratchDir::get().file("laws.db"));
    draglab::LawRecord r = draglab::literature_record(draglab::find_law_form("bvk2007"));
    r.name = "fuzzlaw";
    r.provenance.kind = "manual";
    r.notes = "fuzz target record";
    made->add_published(r);  // 1: retracted below
    r.parameters[0].value *= 1.1;
    made->add_published(r);  // 2
    r.parameters[0].value *= 1.1;
    made->add_draft(r);  // 3
    made->retract("fuzzlaw", 1, "fuzz target");
    return made;
  }();
  return *db;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  database();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string reference(reinterpret_cast<const char*>(data), size);
  draglab_fuzz::expect_clean([&] {
    const draglab::Database& db = database();
    std::string warning;
    const auto law = db.load(reference, draglab::RangePolicy::kClamp, &warning);
    const draglab::LawRecord& record = law->record();
    const std::string name = reference.substr(0, reference.find('@'));
    if (record.name != name) {
      draglab_fuzz::finding("'" + reference + "' loads " + record.reference() +
                            ", a law of another name");
    }
    const draglab::LawRecord resolved = db.resolve(reference);
    if (resolved.name != record.name || resolved.version != record.version) {
      draglab_fuzz::finding("load and resolve disagree on '" + reference + "'");
    }
    const auto again = db.load(record.reference(), draglab::RangePolicy::kClamp, &warning);
    if (again->record().content_hash != record.content_hash) {
      draglab_fuzz::finding("'" + reference + "' and " + record.reference() + " differ");
    }
    const double phi = 0.5 * (record.validity.phi.min + record.validity.phi.max);
    const double re = record.validity.re.min;
    (void)law->F(phi, re);
  });
  return 0;
}
