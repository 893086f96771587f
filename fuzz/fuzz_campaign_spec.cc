// Fuzz target: the campaign spec reader (campaign/src/spec.cc, TOML through toml++), then what
// `draglab campaign plan` and `campaign run` do with an accepted spec before any LBM work: the
// canonical JSON (stored, read back on --resume) and the plan.
//
// Properties checked beyond "no crash": a spec the parser accepts passes IsValid, and its
// canonical JSON reads back (spec_from_json) to the same JSON.
#include <cstddef>
#include <cstdint>
#include <string>

#include "campaign_internal.h"
#include "draglab/campaign/campaign.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  draglab_fuzz::expect_clean([&] {
    using namespace draglab::campaign;
    const CampaignSpec spec = parse_campaign_spec_text(text, "fuzz.toml");
    std::string error;
    if (!spec.IsValid(&error)) draglab_fuzz::finding("accepted spec fails IsValid: " + error);
    const std::string json = spec.to_json();
    const std::string again = internal::spec_from_json(json).to_json();
    if (again != json) {
      draglab_fuzz::finding("canonical JSON does not round-trip:\n" + json + "\n" + again);
    }
    // A fixed time per node update: 0 would time a real LBM run per input.
    const CampaignPlan plan = plan_campaign(spec, 2, 1e-8);
    (void)plan.FullReport();
  });
  return 0;
}
