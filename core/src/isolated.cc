// core/src/isolated.cc: see draglab/core/isolated.h.
#include "draglab/core/isolated.h"

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <string>

#include "draglab/error.h"

#if defined(__SANITIZE_ADDRESS__)
#define DRAGLAB_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DRAGLAB_ASAN 1
#endif
#endif

namespace draglab {
namespace core {
namespace {

// The child's exit codes.
constexpr int kDone = 0;
constexpr int kDraglabError = 3;
constexpr int kOtherException = 4;

void write_all(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
}

std::string read_all(int fd) {
  std::string out;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

[[noreturn]] void child(const std::function<void()>& work, int fd, unsigned seconds,
                        unsigned long long memory_bytes) {
#if !defined(DRAGLAB_ASAN)
  struct rlimit limit {};
  limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(memory_bytes);
  ::setrlimit(RLIMIT_AS, &limit);
#else
  (void)memory_bytes;
#endif
  ::alarm(seconds);  // SIGALRM's default action ends the child
  int code = kDone;
  std::string message;
  std::int32_t error_code = 0;
  try {
    work();
  } catch (const Error& e) {
    code = kDraglabError;
    error_code = static_cast<std::int32_t>(e.code());
    message = e.what();
  } catch (const std::bad_alloc&) {
    code = kOtherException;
    message = "reading it needs more memory than the limit";
  } catch (const std::exception& e) {
    code = kOtherException;
    message = e.what();
  } catch (...) {
    code = kOtherException;
    message = "an unknown exception";
  }
  if (code == kDraglabError) write_all(fd, &error_code, sizeof error_code);
  write_all(fd, message.data(), message.size());
  ::close(fd);
  ::_exit(code);  // no atexit handlers, no flush of the parent's stdio buffers
}

}  // namespace

void run_isolated(const std::function<void()>& work, const std::string& what, unsigned seconds,
                  unsigned long long memory_bytes) {
  int fds[2];
  if (::pipe(fds) != 0) {
    throw Error(ErrorCode::kIo, what + ": cannot create a pipe: " + std::strerror(errno));
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(ErrorCode::kIo, what + ": cannot start a process: " + std::strerror(error));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(work, fds[1], seconds, memory_bytes);
  }
  ::close(fds[1]);
  const std::string report = read_all(fds[0]);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code == kDone) return;
    if (code == kDraglabError && report.size() >= sizeof(std::int32_t)) {
      std::int32_t error_code = 0;
      std::memcpy(&error_code, report.data(), sizeof error_code);
      throw Error(static_cast<ErrorCode>(error_code), report.substr(sizeof error_code));
    }
    if (code == kOtherException) {
      throw Error(ErrorCode::kInvalidArgument, what + " is damaged: " + report);
    }
    throw Error(ErrorCode::kInvalidArgument,
                what + " is damaged: its reader failed (exit status " + std::to_string(code) + ")");
  }
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGALRM) {
      throw Error(
          ErrorCode::kInvalidArgument,
          what + " is damaged: reading it did not end within " + std::to_string(seconds) + " s");
    }
    throw Error(ErrorCode::kInvalidArgument, what + " is damaged: its reader crashed on it (" +
                                                 std::string(::strsignal(sig)) + ")");
  }
  throw Error(ErrorCode::kInvalidArgument, what + " is damaged: reading it failed");
}

}  // namespace core
}  // namespace draglab
