// workflows/src/scripts.cc: see draglab/workflows/scripts.h.
#include "draglab/workflows/scripts.h"

#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <stdexcept>

#include <fmt/core.h>

#include "draglab/core/files.h"

namespace draglab {
namespace workflows {

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

std::string executable_dir() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "";
  const std::string path(buf, static_cast<std::size_t>(n));
  return path.substr(0, path.rfind('/'));
}

std::string find_script(const std::string& name) {
  const std::string installed = executable_dir() + "/../" + DRAGLAB_INSTALL_SHARE_DIR + "/" + name;
  if (core::file_exists(installed)) return installed;
  const std::string source = std::string(DRAGLAB_SOURCE_SCRIPTS_DIR) + "/" + name;
  if (core::file_exists(source)) return source;
  throw std::runtime_error(
      fmt::format("the script {} was found neither at {} nor at {}", name, installed, source));
}

std::string find_shipped_file(const std::string& relative) {
  const std::string source = std::string(DRAGLAB_SOURCE_DATA_DIR) + "/" + relative;
  if (core::file_exists(source)) return source;
  const std::string installed =
      executable_dir() + "/../" + DRAGLAB_INSTALL_SHARE_DIR + "/" + relative;
  if (core::file_exists(installed)) return installed;
  return "";
}

std::string python_interpreter() {
  const char* p = std::getenv("DRAGLAB_PYTHON");
  return p && *p ? p : "/usr/bin/python3";
}

bool python_has_matplotlib() {
  const std::string probe =
      shell_quote(python_interpreter()) + " -c 'import matplotlib' >/dev/null 2>&1";
  return std::system(probe.c_str()) == 0;
}

void run_figure_script(const std::string& script_name, const std::vector<std::string>& args,
                       const std::string& bundle, const std::string& expected_file) {
  const std::string python = python_interpreter();
  const std::string script = find_script(script_name);
  std::string command = shell_quote(python) + " " + shell_quote(script);
  for (const std::string& a : args) command += " " + shell_quote(a);
  if (!python_has_matplotlib()) {
    throw std::runtime_error(fmt::format(
        "{} cannot import matplotlib: install the Debian package python3-matplotlib "
        "(apt-get install python3-matplotlib) and rerun, or draw the figures later with '{}'. "
        "The data {} were written.",
        python, command, bundle));
  }
  const int status = std::system((command + " 1>&2").c_str());
  if (status != 0 || !core::file_exists(expected_file)) {
    throw std::runtime_error(
        fmt::format("the figure script failed (exit status {}): '{}'; the data {} were kept",
                    status, command, bundle));
  }
}

}  // namespace workflows
}  // namespace draglab
