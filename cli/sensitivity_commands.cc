// `draglab sensitivity` (being written).
#include "cli/cli_context.h"

namespace draglab {
namespace cli {

void add_sensitivity_commands(CLI::App& app, CliContext& ctx) {
  (void)app;
  (void)ctx;
}

}  // namespace cli
}  // namespace draglab
