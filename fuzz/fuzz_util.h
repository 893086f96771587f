// fuzz_util.h: what the libFuzzer targets of fuzz/ share.
//
// A reader answers bad input with draglab::Error naming the problem; that is the expected outcome
// and each target swallows it through expect_clean. Everything else is a finding and stops the
// run with a crash file: a sanitizer report, a leak, a hang, an exception of another type
// (std::bad_alloc, nlohmann::json errors, ... reach libFuzzer's handler), an Error with
// ErrorCode::kInternal (the library's "this is a bug"), or a broken property (finding()).
#pragma once

#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

#include "draglab/error.h"

namespace draglab_fuzz {

/// Reports a broken property and aborts (libFuzzer saves the input as a crash).
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "\n==== draglab fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

/// Runs f; a draglab::Error is the expected answer to bad input, except kInternal.
template <typename F>
void expect_clean(F&& f) {
  try {
    std::forward<F>(f)();
  } catch (const draglab::Error& e) {
    if (e.code() == draglab::ErrorCode::kInternal) {
      finding(std::string("internal error (ErrorCode::kInternal): ") + e.what());
    }
    if (std::string(e.what()).empty()) finding("draglab::Error with an empty message");
  }
}

/// A private temporary directory (removed with its files at exit) for readers that take a path.
class ScratchDir {
 public:
  static ScratchDir& get() {
    static ScratchDir dir;
    return dir;
  }
  const std::string& path() const { return path_; }
  /// path()/name.
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  /// Writes data to path()/name (truncating) and returns the path.
  std::string write(const std::string& name, const std::uint8_t* data, std::size_t size) {
    const std::string p = file(name);
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) finding("cannot write the scratch file " + p);
    return p;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }

 private:
  ScratchDir() {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/draglab-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data())) finding("mkdtemp failed for " + pattern);
    path_ = pattern;
  }
  std::string path_;
};

}  // namespace draglab_fuzz
