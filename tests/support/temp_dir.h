// tests/support/temp_dir.h: a temporary directory for one test, removed with everything in it
// (permissions restored first: tests make directories read-only).
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <stdexcept>
#include <string>

namespace draglab {
namespace test {

class TempDir {
 public:
  /// A new directory under $TMPDIR (else /tmp), named draglab_<tag>_XXXXXX.
  explicit TempDir(const std::string& tag = "test") {
    const char* root = std::getenv("TMPDIR");
    std::string pattern =
        std::string(root && *root ? root : "/tmp") + "/draglab_" + tag + "_XXXXXX";
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed for " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    namespace fs = std::filesystem;
    for (auto it = fs::recursive_directory_iterator(path_, ignored);
         it != fs::recursive_directory_iterator(); it.increment(ignored)) {
      if (it->is_directory(ignored)) {
        fs::permissions(it->path(), fs::perms::owner_all, fs::perm_options::add, ignored);
      }
    }
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ignored);
    fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  /// The path of `name` inside the directory.
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  /// Entries directly inside the directory (checks that nothing was left behind).
  std::size_t entries() const {
    std::error_code ignored;
    return static_cast<std::size_t>(
        std::distance(std::filesystem::directory_iterator(path_, ignored), {}));
  }

 private:
  std::string path_;
};

}  // namespace test
}  // namespace draglab
