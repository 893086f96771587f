// cli/file_util.cc: see file_util.h.
#include "cli/file_util.h"

#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <stdexcept>

#include <fmt/core.h>

#include "cli/cli_context.h"

namespace draglab {
namespace cli {

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

bool file_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool directory_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

void make_directories(const std::string& path, const std::string& option) {
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    const std::string partial = path.substr(0, pos);
    if (partial.empty() || directory_exists(partial)) continue;
    if (::mkdir(partial.c_str(), 0777) != 0 && !directory_exists(partial))
      throw UsageError(fmt::format("{}: cannot create directory '{}'", option, partial));
  }
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
  if (file_exists(installed)) return installed;
  const std::string source = std::string(DRAGLAB_SOURCE_SCRIPTS_DIR) + "/" + name;
  if (file_exists(source)) return source;
  throw std::runtime_error(
      fmt::format("the script {} was found neither at {} nor at {}", name, installed, source));
}

std::string python_interpreter() {
  const char* p = std::getenv("DRAGLAB_PYTHON");
  return p && *p ? p : "/usr/bin/python3";
}

}  // namespace cli
}  // namespace draglab
