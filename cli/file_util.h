// cli/file_util.h: files, directories and helper scripts of the draglab commands (written once,
// used by report, sensitivity, lbm and campaign commands).
#pragma once

#include <string>

namespace draglab {
namespace cli {

/// Quotes a path for the shell (single quotes; a quote inside is closed, escaped, reopened).
std::string shell_quote(const std::string& s);
bool file_exists(const std::string& path);       ///< A regular file.
bool directory_exists(const std::string& path);  ///< A directory.
/// mkdir -p; throws UsageError naming `option` (e.g. "--out") if a component cannot be created.
void make_directories(const std::string& path, const std::string& option = "--out");
/// Directory of the running executable ("" if unknown).
std::string executable_dir();
/// A script shipped with draglab: installed next to the executable (bin/../share/draglab), else
/// the source tree's scripts/. Throws std::runtime_error naming both places if neither exists.
std::string find_script(const std::string& name);
/// $DRAGLAB_PYTHON (tests, unusual installs), else Debian's /usr/bin/python3, the interpreter
/// that sees python3-matplotlib.
std::string python_interpreter();

}  // namespace cli
}  // namespace draglab
