// core::run_isolated: a read that crashes, hangs or throws in a child process becomes an error
// in this one. References: POSIX fork/wait semantics (a child killed by a signal is reported by
// WIFSIGNALED; SIGALRM after alarm(s) ends a process that does not handle it).
#include <gtest/gtest.h>

#include <csignal>
#include <string>

#include "draglab/core/isolated.h"
#include "draglab/error.h"

namespace draglab {
namespace {

std::string error_of(const std::function<void()>& work, unsigned seconds = 10,
                     ErrorCode* code = nullptr) {
  try {
    core::run_isolated(work, "file 'x.h5'", seconds, 1ULL << 32);
  } catch (const Error& e) {
    if (code) *code = e.code();
    return e.what();
  }
  return "";
}

TEST(RunIsolated, WorkThatSucceedsReturns) {
  EXPECT_EQ(error_of([] {}), "");
}

TEST(RunIsolated, ADraglabErrorKeepsItsCodeAndMessage) {
  ErrorCode code = ErrorCode::kOk;
  EXPECT_EQ(error_of([] { throw Error(ErrorCode::kNotFound, "no group /packing"); }, 10, &code),
            "no group /packing");
  EXPECT_EQ(code, ErrorCode::kNotFound);
}

TEST(RunIsolated, ACrashIsReportedAsDamageNotSuffered) {
  ErrorCode code = ErrorCode::kOk;
  const std::string message = error_of([] { std::raise(SIGSEGV); }, 10, &code);
  EXPECT_EQ(code, ErrorCode::kInvalidArgument);  // bad input: exit code 2
  EXPECT_NE(message.find("file 'x.h5' is damaged"), std::string::npos) << message;
}

TEST(RunIsolated, AHangIsStoppedAtTheTimeLimit) {
  const std::string message = error_of(
      [] {
        volatile bool forever = true;
        while (forever) {
        }
      },
      1);
  EXPECT_NE(message.find("did not end within 1 s"), std::string::npos) << message;
}

TEST(RunIsolated, OtherExceptionsAreDamageWithTheirMessage) {
  const std::string message = error_of([] { throw std::runtime_error("bad heap object"); });
  EXPECT_NE(message.find("is damaged: bad heap object"), std::string::npos) << message;
}

}  // namespace
}  // namespace draglab
