// Regressions found with fuzz/fuzz_packing_hdf5 (scripts/fuzz.sh packing_hdf5): packing files of
// a valid HDF5 layout that the reader did not expect. Each must give a clear
// Error(kInvalidArgument) naming the item, instead of the heap or stack overflow (an attribute
// of several values read into one), or the allocation of terabytes (a huge, unallocated chunked
// dataset) that they caused.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <stdlib.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "draglab/arrays/packing_io.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace arrays {
namespace {

using TempDir = test::TempDir;

void write_doubles(hid_t group, const char* name, const std::vector<hsize_t>& dims,
                   const std::vector<double>& values) {
  hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  hid_t set = H5Dcreate2(group, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Dclose(set);
  H5Sclose(space);
}

/// A file with /packing holding one sphere (unless `centers_too` is false), plus whatever `add`
/// puts into the group.
std::string make_file(const TempDir& dir, const std::string& name,
                      const std::function<void(hid_t)>& add, bool centers_too = true) {
  const std::string path = dir.file(name);
  hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  hid_t group = H5Gcreate2(file, "packing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (centers_too) write_doubles(group, "centers", {1, 3}, {0.5, 0.5, 0.5});
  write_doubles(group, "radii", {1}, {0.5});
  write_doubles(group, "box_length", {3}, {2.0, 2.0, 2.0});
  add(group);
  H5Gclose(group);
  H5Fclose(file);
  return path;
}

/// An attribute `name` of `count` elements of `type` (data: `count` elements of `mem`).
void add_attribute(hid_t group, const char* name, hid_t type, hid_t mem, hsize_t count,
                   const void* data) {
  hid_t space = H5Screate_simple(1, &count, nullptr);
  hid_t attr = H5Acreate2(group, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, mem, data);
  H5Aclose(attr);
  H5Sclose(space);
}

void expect_clear_error(const std::string& path, const std::string& needle) {
  try {
    read_packing_hdf5(path);
    ADD_FAILURE() << "accepted " << path;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(PackingIoFuzzRegression, SeedAttributeOfSeveralValues) {
  // Was: H5Aread wrote 64 integers into one (stack-buffer-overflow).
  TempDir dir;
  const std::vector<std::uint64_t> seeds(64, 7);
  const std::string path = make_file(dir, "seeds.h5", [&](hid_t g) {
    add_attribute(g, "seed", H5T_STD_U64LE, H5T_NATIVE_UINT64, seeds.size(), seeds.data());
  });
  expect_clear_error(path, "attribute /packing/seed must hold one value, not 64");
}

TEST(PackingIoFuzzRegression, FixedLengthStringAttributeOfSeveralValues) {
  // Was: 50 strings of 40 bytes read into one string of 40 (heap-buffer-overflow).
  TempDir dir;
  const std::string text(50 * 40, 'x');
  const std::string path = make_file(dir, "generator.h5", [&](hid_t g) {
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 40);
    add_attribute(g, "generator", type, type, 50, text.data());
    H5Tclose(type);
  });
  expect_clear_error(path, "attribute /packing/generator must hold one value, not 50");
}

TEST(PackingIoFuzzRegression, VariableLengthStringAttributeOfSeveralValues) {
  // Was: 50 string pointers written over one (stack-buffer-overflow).
  TempDir dir;
  const std::vector<const char*> text(50, "aaaa");
  const std::string path = make_file(dir, "settings.h5", [&](hid_t g) {
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    add_attribute(g, "settings", type, type, text.size(), text.data());
    H5Tclose(type);
  });
  expect_clear_error(path, "attribute /packing/settings must hold one value, not 50");
}

TEST(PackingIoFuzzRegression, HugeUnallocatedCentersDataset) {
  // Was: a vector of 3 * 2^40 doubles allocated before reading (allocation-size-too-big or
  // std::bad_alloc); the file is a few kilobytes.
  TempDir dir;
  const std::string path = make_file(
      dir, "huge.h5",
      [](hid_t g) {
        const hsize_t dims[2] = {hsize_t{1} << 40, 3};
        const hsize_t max[2] = {H5S_UNLIMITED, 3};
        const hsize_t chunk[2] = {1, 3};
        hid_t space = H5Screate_simple(2, dims, max);
        hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
        H5Pset_chunk(dcpl, 2, chunk);
        hid_t set = H5Dcreate2(g, "centers", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
        ASSERT_GE(set, 0);
        H5Dclose(set);
        H5Pclose(dcpl);
        H5Sclose(space);
      },
      false);
  EXPECT_LT(std::filesystem::file_size(path), 100000u);
  expect_clear_error(path, "dataset centers has shape [1099511627776, 3]: more than 30000000");
}

}  // namespace
}  // namespace arrays
}  // namespace draglab
