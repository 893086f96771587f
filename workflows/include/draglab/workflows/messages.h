// draglab/workflows/messages.h: how a workflow tells its caller what it is doing.
#pragma once

#include <functional>
#include <string>

namespace draglab {
namespace workflows {

/// Informational messages and warnings of a workflow while it runs. The command line prints
/// them on stderr (info only without --quiet); a program or a test may collect them or leave
/// either empty to drop them.
struct Messages {
  std::function<void(const std::string&)> on_info;
  std::function<void(const std::string&)> on_warning;

  void info(const std::string& message) const {
    if (on_info) on_info(message);
  }
  void warn(const std::string& message) const {
    if (on_warning) on_warning(message);
  }
};

}  // namespace workflows
}  // namespace draglab
