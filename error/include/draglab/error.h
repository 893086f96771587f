// draglab/error.h: the one exception type of draglab (its C++ API and every module).
//
// Every failure carries an ErrorCode so that the C ABI (draglab.h) can map it to an integer
// status and the CLI to an exit code (bad input -> 2, everything else -> 1).
#pragma once

#include <stdexcept>
#include <string>

namespace draglab {

/// Error categories. The numeric values are the status codes of the C ABI (draglab.h).
enum class ErrorCode : int {
  kOk = 0,
  kInvalidArgument =
      1,               ///< A value outside its allowed range (NaN, eps not in (0,1], Re < 0, ...).
  kOutOfValidity = 2,  ///< Inside the physical range but outside the law's validity box.
  kNotFound = 3,       ///< Unknown law name, version, hash prefix or form key.
  kImmutable = 4,      ///< Attempt to change a published or retracted law version.
  kDatabase = 5,       ///< SQLite failure (I/O, locking, constraint).
  kSchemaTooNew = 6,   ///< The database was written by a newer draglab.
  kNotADatabase = 7,   ///< The file is not a draglab/SQLite database or is corrupt.
  kInternal = 8,       ///< A bug: please report it.
  kIo = 9,             ///< The system could not write or read a file (disk full, I/O error).
};

/// Exception thrown by the C++ API. what() is a complete, user-facing message that names the
/// offending field and its allowed range where that applies.
class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }
  /// True for errors caused by the caller's input (CLI exit code 2): a value out of range, an
  /// unknown name, a change asked of an immutable version, or a file that is not a database this
  /// draglab can open (another application's, or a newer schema).
  bool is_bad_input() const noexcept {
    return code_ == ErrorCode::kInvalidArgument || code_ == ErrorCode::kOutOfValidity ||
           code_ == ErrorCode::kNotFound || code_ == ErrorCode::kNotADatabase ||
           code_ == ErrorCode::kImmutable || code_ == ErrorCode::kSchemaTooNew;
  }

 private:
  ErrorCode code_;
};

}  // namespace draglab
