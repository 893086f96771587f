// Placeholder: `draglab pipeline` is being written (replaced by the real commands).
#include "cli/cli_context.h"

namespace draglab {
namespace cli {

void add_pipeline_commands(CLI::App& /*app*/, CliContext& /*ctx*/) {}

}  // namespace cli
}  // namespace draglab
