// draglab/core/files.h: output files written whole or not at all.
//
// Every output of draglab (packings, LBM fields, exported laws and datasets, figures' data) goes
// through these functions, so that
//  - a path that cannot be written is refused before any work, naming the option, and
//  - a failure while writing (disk full, a file-size limit, an I/O error) leaves no partial file
//    and names the system's reason (errno).
// Errors: draglab::Error with kInvalidArgument for a path the caller gave that cannot be written
// (missing or read-only directory, a directory where a file is expected) and kIo for the system
// failing during the write.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace draglab {
namespace core {

/// The whole text of an input file the user named, checked as what it is: a missing file
/// (kNotFound), a directory, an empty file (only white space) or a file that is not text (a NUL
/// byte, or bytes that are not UTF-8) is refused (kInvalidArgument) naming `what` (e.g. "scene
/// file") and the path, never passed on to a parser that would report a missing key instead.
std::string read_text_input(const std::string& path, const std::string& what);

/// Whether `path` is a regular file (after symbolic links).
bool file_exists(const std::string& path);
/// Whether `path` is a directory (after symbolic links).
bool directory_exists(const std::string& path);
/// mkdir -p: creates `path` and its missing parents; an existing directory is fine. Throws
/// Error(kInvalidArgument) naming `field` (e.g. "--out") and the component that cannot be made.
void make_directories(const std::string& path, const std::string& field);

/// Checks that `path` can be written as a file: not empty, not a directory or a device, its
/// directory exists and a file can be created there (tried with a probe file, so read-only
/// mounts and /proc are caught even for root). `field` names the option in the message.
void check_output_file(const std::string& path, const std::string& field);

/// The same for an output folder created if missing: an existing non-directory, or a nearest
/// existing ancestor that cannot be written, is refused.
void check_output_directory(const std::string& path, const std::string& field);

/// Writes `size` bytes to `path` through a temporary file in the same directory, fsync and a
/// rename: readers see the old file or the new one, never part of one; on failure, and when
/// SIGINT, SIGTERM or SIGHUP (left at their default action) end the process during the write, the
/// temporary file is removed. `field` names the option or the kind of file in the message.
void write_file_atomically(const std::string& path, const void* data, std::size_t size,
                           const std::string& field);
/// The same for a file made of several pieces written one after the other (no copy of them).
struct FilePiece {
  const void* data;
  std::size_t size;
};
void write_file_atomically(const std::string& path, const std::vector<FilePiece>& pieces,
                           const std::string& field);
inline void write_file_atomically(const std::string& path, const std::string& contents,
                                  const std::string& field) {
  write_file_atomically(path, contents.data(), contents.size(), field);
}

}  // namespace core
}  // namespace draglab
