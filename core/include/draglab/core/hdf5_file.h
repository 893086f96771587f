// draglab/core/hdf5_file.h: an HDF5 file built in memory and saved whole.
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
