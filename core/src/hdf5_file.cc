// core/src/hdf5_file.cc: see draglab/core/hdf5_file.h.
#include "draglab/core/hdf5_file.h"

#include <cstdint>
#include <string>
#include <vector>

#include "draglab/core/files.h"
#include "draglab/error.h"

namespace draglab {
namespace core {

void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

Hdf5MemoryFile::Hdf5MemoryFile(std::string label) : label_(std::move(label)) {
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  // Grow the image 1 MiB at a time; never write it to disk by itself (backing_store = 0).
  if (access < 0 || H5Pset_fapl_core(access, 1 << 20, 0) < 0) {
    if (access >= 0) H5Pclose(access);
    throw Error(ErrorCode::kInternal, label_ + ": cannot set up an in-memory HDF5 file");
  }
  // The name only identifies the image inside the library; nothing is created under it.
  file_ = H5Fcreate(
      ("draglab_memory_image_" + std::to_string(reinterpret_cast<std::uintptr_t>(this))).c_str(),
      H5F_ACC_TRUNC, H5P_DEFAULT, access);
  H5Pclose(access);
  if (file_ < 0) throw Error(ErrorCode::kIo, label_ + ": cannot create an in-memory HDF5 file");
}

Hdf5MemoryFile::~Hdf5MemoryFile() {
  if (file_ >= 0) H5Fclose(file_);
}

void Hdf5MemoryFile::save(const std::string& path) {
  if (H5Fflush(file_, H5F_SCOPE_GLOBAL) < 0) {
    throw Error(ErrorCode::kIo, label_ + ": cannot complete the in-memory HDF5 image");
  }
  const ssize_t size = H5Fget_file_image(file_, nullptr, 0);
  if (size < 0) throw Error(ErrorCode::kIo, label_ + ": cannot read the in-memory HDF5 image");
  std::vector<char> image(static_cast<std::size_t>(size));
  if (H5Fget_file_image(file_, image.data(), image.size()) != size) {
    throw Error(ErrorCode::kIo, label_ + ": cannot read the in-memory HDF5 image");
  }
  H5Fclose(file_);
  file_ = H5I_INVALID_HID;
  write_file_atomically(path, image.data(), image.size(), label_);
}

}  // namespace core
}  // namespace draglab
