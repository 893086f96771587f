// core/src/files.cc: see draglab/core/files.h.
#include "draglab/core/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

#include "draglab/error.h"

namespace draglab {
namespace core {
namespace {

std::string quoted(const std::string& s) { return "'" + s + "'"; }

std::string parent_directory(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// Temporary files being written, removed when SIGINT, SIGTERM or SIGHUP ends the process in the
// middle of a write (a SIGKILL can still leave one; never a partial file under the final name).
// The handler only reads these slots and calls unlink, both async-signal-safe.
constexpr int kTemporarySlots = 32;
std::atomic<const char*> g_temporaries[kTemporarySlots];

void remove_temporaries_and_reraise(int sig) {
  for (auto& slot : g_temporaries) {
    const char* path = slot.load();
    if (path) ::unlink(path);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// Installed once, and only for signals whose disposition is still the default: a program that
// handles or ignores them (Python, nohup) keeps its own behaviour.
void install_temporary_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction current {};
      if (::sigaction(sig, nullptr, &current) != 0) continue;
      if ((current.sa_flags & SA_SIGINFO) != 0 || current.sa_handler != SIG_DFL) continue;
      struct sigaction cleanup {};
      cleanup.sa_handler = remove_temporaries_and_reraise;
      sigemptyset(&cleanup.sa_mask);
      ::sigaction(sig, &cleanup, nullptr);
    }
  });
}

/// Registers a temporary file for removal on a terminating signal while it lives.
class TemporaryRegistration {
 public:
  explicit TemporaryRegistration(const std::string& path) {
    install_temporary_cleanup();
    for (int i = 0; i < kTemporarySlots; ++i) {
      const char* empty = nullptr;
      if (g_temporaries[i].compare_exchange_strong(empty, path.c_str())) {
        slot_ = i;
        return;
      }
    }
  }
  ~TemporaryRegistration() {
    if (slot_ >= 0) g_temporaries[slot_].store(nullptr);
  }
  TemporaryRegistration(const TemporaryRegistration&) = delete;
  TemporaryRegistration& operator=(const TemporaryRegistration&) = delete;

 private:
  int slot_ = -1;  // -1: more writes at once than slots; that file is not cleaned up
};

[[noreturn]] void bad_path(const std::string& field, const std::string& path,
                           const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, field + " " + quoted(path) + ": " + what);
}

/// Whether a file can be created in `dir`: a probe file is made and removed (access(2) says yes
/// to root on read-only mounts and in /proc).
bool can_create_in(const std::string& dir, int* error) {
  std::string probe = dir + "/.draglab_probe_XXXXXX";
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) {
    *error = errno;
    return false;
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return true;
}

void check_can_create_in(const std::string& dir, const std::string& path,
                         const std::string& field) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) {
    bad_path(field, path, "directory " + quoted(dir) + " does not exist (create it first)");
  }
  if (!S_ISDIR(st.st_mode)) bad_path(field, path, quoted(dir) + " is not a directory");
  int error = 0;
  if (!can_create_in(dir, &error)) {
    bad_path(field, path,
             "cannot create files in directory " + quoted(dir) + ": " + std::strerror(error));
  }
}

/// errno values that mean the path itself cannot be written (the caller's input), not that the
/// system failed while writing.
bool is_path_error(int error) {
  return error == ENOENT || error == EACCES || error == EPERM || error == EISDIR ||
         error == ENOTDIR || error == EROFS || error == ENAMETOOLONG || error == ELOOP;
}

}  // namespace

namespace {

/// Offset of the first byte that is not part of valid UTF-8 text (or a NUL), or npos.
std::size_t first_non_text_byte(const std::string& text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned char c = p[i];
    if (c == 0) return i;
    const int extra = c < 0x80           ? 0
                      : (c >> 5) == 0x6  ? 1
                      : (c >> 4) == 0xe  ? 2
                      : (c >> 3) == 0x1e ? 3
                                         : -1;
    if (extra < 0 || i + static_cast<std::size_t>(extra) >= n + (extra == 0 ? 1 : 0)) return i;
    for (int k = 1; k <= extra; ++k) {
      if ((p[i + static_cast<std::size_t>(k)] >> 6) != 0x2) return i;
    }
    i += static_cast<std::size_t>(extra) + 1;
  }
  return std::string::npos;
}

}  // namespace

std::string read_text_input(const std::string& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int error = errno;
    throw Error(error == ENOENT ? ErrorCode::kNotFound : ErrorCode::kInvalidArgument,
                what + " " + quoted(path) + " cannot be read: " + std::strerror(error));
  }
  if (S_ISDIR(st.st_mode)) {
    throw Error(ErrorCode::kInvalidArgument,
                what + " " + quoted(path) + " is a directory, not a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error(ErrorCode::kInvalidArgument,
                what + " " + quoted(path) + " cannot be read: " + std::strerror(errno));
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::string content = text.str();
  if (content.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw Error(ErrorCode::kInvalidArgument, what + " " + quoted(path) + " is empty");
  }
  const std::size_t bad = first_non_text_byte(content);
  if (bad != std::string::npos) {
    throw Error(ErrorCode::kInvalidArgument,
                what + " " + quoted(path) + " is not a text file (byte " + std::to_string(bad) +
                    " is " + (content[bad] == 0 ? "a NUL" : "not UTF-8") + ")");
  }
  return content;
}

bool file_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool directory_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

void make_directories(const std::string& path, const std::string& field) {
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    const std::string partial = path.substr(0, pos);
    if (partial.empty() || directory_exists(partial)) continue;
    if (::mkdir(partial.c_str(), 0777) != 0 && !directory_exists(partial)) {
      const int error = errno;
      bad_path(field, path,
               "cannot create directory " + quoted(partial) + ": " + std::strerror(error));
    }
  }
}

void check_output_file(const std::string& path, const std::string& field) {
  if (path.empty()) throw Error(ErrorCode::kInvalidArgument, field + ": empty path (give a file)");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) bad_path(field, path, "is a directory (give a file name inside it)");
    if (!S_ISREG(st.st_mode)) bad_path(field, path, "exists and is not a regular file");
  }
  check_can_create_in(parent_directory(path), path, field);
}

void check_output_directory(const std::string& path, const std::string& field) {
  if (path.empty()) {
    throw Error(ErrorCode::kInvalidArgument, field + ": empty path (give a folder)");
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) bad_path(field, path, "exists and is not a directory");
    check_can_create_in(path, path, field);
    return;
  }
  // A missing folder is created with its missing parents: the nearest existing ancestor must be
  // a directory where folders can be created.
  std::string ancestor = parent_directory(path);
  while (::stat(ancestor.c_str(), &st) != 0 && ancestor != "/" && ancestor != ".") {
    ancestor = parent_directory(ancestor);
  }
  check_can_create_in(ancestor, path, field);
}

void write_file_atomically(const std::string& path, const void* data, std::size_t size,
                           const std::string& field) {
  write_file_atomically(path, std::vector<FilePiece>{{data, size}}, field);
}

void write_file_atomically(const std::string& path, const std::vector<FilePiece>& pieces,
                           const std::string& field) {
  if (path.empty()) throw Error(ErrorCode::kInvalidArgument, field + ": empty path (give a file)");
  std::string temporary = path + ".tmp_XXXXXX";
  // Registered before mkstemp fills in the name: the slot points at this string's buffer.
  const TemporaryRegistration registration(temporary);
  const int fd = ::mkstemp(temporary.data());
  if (fd < 0) {
    const int error = errno;
    throw Error(
        is_path_error(error) ? ErrorCode::kInvalidArgument : ErrorCode::kIo,
        field + " " + quoted(path) + ": cannot create a file there: " + std::strerror(error));
  }
  ::fchmod(fd, 0644);  // mkstemp makes 0600; outputs are ordinary files
  const auto fail = [&](const std::string& step, int error) {
    ::unlink(temporary.c_str());
    throw Error(error == EISDIR ? ErrorCode::kInvalidArgument : ErrorCode::kIo,
                field + " " + quoted(path) + ": " + step + " failed: " + std::strerror(error) +
                    " (nothing was written)");
  };
  for (const FilePiece& piece : pieces) {
    const char* bytes = static_cast<const char*>(piece.data);
    std::size_t written = 0;
    while (written < piece.size) {
      const ssize_t n = ::write(fd, bytes + written, piece.size - written);
      if (n < 0) {
        if (errno == EINTR) continue;
        const int error = errno;
        ::close(fd);
        fail("writing", error);
      }
      written += static_cast<std::size_t>(n);
    }
  }
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    const int error = errno;
    ::close(fd);
    fail("writing", error);
  }
  if (::close(fd) != 0) fail("writing", errno);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) fail("moving the file into place", errno);
}

}  // namespace core
}  // namespace draglab
