// Placeholder: `draglab fit` is being written (replaced by the real commands).
#include "cli/cli_context.h"

namespace draglab {
namespace cli {

void add_fit_commands(CLI::App& /*app*/, CliContext& /*ctx*/) {}

}  // namespace cli
}  // namespace draglab
