// `draglab regress` (being written).
#include "cli/cli_context.h"

namespace draglab {
namespace cli {

void add_regress_commands(CLI::App& app, CliContext& ctx) {
  (void)app;
  (void)ctx;
}

}  // namespace cli
}  // namespace draglab
