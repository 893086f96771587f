// draglab/core/hdf5_file.h: HDF5 identifiers closed on scope exit, and an HDF5 file built in
// memory and saved whole.
//
// The HDF5 library writes a file in many small pieces; when one fails (disk full), libhdf5
// 1.10 leaves the file half closed and can crash at exit while closing it again. Building the
// file in memory (the "core" driver, no backing store) and saving its image with
// core::write_file_atomically keeps every disk write in one place: a failure is a clean
// draglab::Error (kIo, with errno) and leaves no file behind. Memory: the file's size, small next
// to the data it is written from.
#pragma once

#include <hdf5.h>

#include <string>

namespace draglab {
namespace core {

/// HDF5 prints its own error stack by default; draglab reports its own messages instead.
void silence_hdf5();

/// Closes an HDF5 identifier (file, group, dataset, space, type, attribute) on scope exit;
/// close() closes it earlier and returns the status (e.g. of a file, whose close flushes it).
class Hdf5Handle {
 public:
  Hdf5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Hdf5Handle() { close(); }
  Hdf5Handle(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(const Hdf5Handle&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }
  herr_t close() {
    const herr_t status = id_ >= 0 ? close_(id_) : 0;
    id_ = H5I_INVALID_HID;
    return status;
  }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

class Hdf5MemoryFile {
 public:
  /// `label` names the file in messages (e.g. "packing file 'p.h5'").
  explicit Hdf5MemoryFile(std::string label);
  ~Hdf5MemoryFile();
  Hdf5MemoryFile(const Hdf5MemoryFile&) = delete;
  Hdf5MemoryFile& operator=(const Hdf5MemoryFile&) = delete;

  /// The file's id for H5Gcreate2, H5Dcreate2, ...
  hid_t id() const { return file_; }
  /// Saves the image at `path` (core::write_file_atomically) and closes the file.
  void save(const std::string& path);

 private:
  std::string label_;
  hid_t file_ = H5I_INVALID_HID;
};

}  // namespace core
}  // namespace draglab
