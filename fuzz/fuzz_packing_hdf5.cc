// Fuzz target: the packing file reader read_packing_hdf5 (arrays/src/packing_io.cc), which takes
// a path. Two kinds of input:
//   * an HDF5 file (the input starts with the HDF5 signature, as the seeds do): written as it is
//     and read. The HDF5 library is not instrumented, so libFuzzer sees only our reader's
//     coverage; this mode mostly tests how the reader copes with what the library returns for
//     a damaged file.
//   * anything else: a recipe (FuzzedDataProvider) for a well-formed HDF5 file whose layout the
//     reader may not expect: /packing missing or not a group, datasets missing or of another
//     type, rank, shape (empty, huge and unallocated, chunked), values (NaN, negative, outside
//     the box), attributes of other types and with several elements. The file is written with
//     the HDF5 API, then read.
//
// Properties checked beyond "no crash": an accepted packing has spheres, positive radii and box
// edges and centres inside the box, and write_packing_hdf5 then read_packing_hdf5 gives it back.
#include <hdf5.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/packing_io.h"
#include "fuzz_util.h"

namespace {

constexpr char kSignature[] = "\x89HDF\r\n\x1a\n";

/// A value that is often interesting to the reader's checks.
double pick_value(FuzzedDataProvider& in) {
  static const double kValues[] = {0.0,
                                   0.5,
                                   1.0,
                                   -1.0,
                                   2.0,
                                   1e-300,
                                   1e300,
                                   std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::denorm_min(),
                                   3.0};
  if (in.ConsumeBool()) return in.PickValueInArray(kValues);
  return in.ConsumeFloatingPoint<double>();
}

hsize_t pick_dim(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange(0, 7)) {
    case 0:
      return 0;
    case 1:  // huge: only possible unallocated (chunked), read back as fill values
      return hsize_t{1} << in.ConsumeIntegralInRange(20, 62);
    case 2:
      return in.ConsumeIntegral<std::uint64_t>() >> in.ConsumeIntegralInRange(0, 63);
    default:
      return in.ConsumeIntegralInRange<hsize_t>(1, 6);
  }
}

/// A file type for a dataset or attribute; closed by the caller unless predefined (*owned false).
hid_t pick_type(FuzzedDataProvider& in, bool* owned) {
  *owned = false;
  switch (in.ConsumeIntegralInRange(0, 9)) {
    case 0:
      return H5T_IEEE_F32LE;
    case 1:
      return H5T_STD_I32LE;
    case 2:
      return H5T_STD_U8LE;
    case 3:
      return H5T_STD_I64BE;
    case 4: {  // fixed-length string
      *owned = true;
      hid_t t = H5Tcopy(H5T_C_S1);
      H5Tset_size(t, in.ConsumeIntegralInRange<std::size_t>(1, 40));
      return t;
    }
    case 5: {  // variable-length string
      *owned = true;
      hid_t t = H5Tcopy(H5T_C_S1);
      H5Tset_size(t, H5T_VARIABLE);
      H5Tset_cset(t, in.ConsumeBool() ? H5T_CSET_UTF8 : H5T_CSET_ASCII);
      return t;
    }
    case 6: {  // compound of one double
      *owned = true;
      hid_t t = H5Tcreate(H5T_COMPOUND, sizeof(double));
      H5Tinsert(t, "x", 0, H5T_IEEE_F64LE);
      return t;
    }
    default:
      return H5T_IEEE_F64LE;
  }
}

/// A dataspace: scalar, null or simple of rank 1..3.
hid_t pick_space(FuzzedDataProvider& in, bool chunked, std::vector<hsize_t>* dims) {
  dims->clear();
  const int kind = in.ConsumeIntegralInRange(0, 9);
  if (kind == 0) return H5Screate(H5S_SCALAR);
  if (kind == 1) return H5Screate(H5S_NULL);
  const int rank = in.ConsumeIntegralInRange(1, 3);
  for (int k = 0; k < rank; ++k) dims->push_back(pick_dim(in));
  std::vector<hsize_t> max(dims->size(), chunked ? H5S_UNLIMITED : 0);
  return H5Screate_simple(rank, dims->data(), chunked ? max.data() : nullptr);
}

std::size_t element_count(const std::vector<hsize_t>& dims) {
  std::size_t n = 1;
  for (hsize_t d : dims) {
    if (d > 4096 || n * d > 4096) return std::numeric_limits<std::size_t>::max();
    n *= static_cast<std::size_t>(d);
  }
  return n;
}

/// Writes values (through a double or string memory type) into a dataset or attribute.
void fill(FuzzedDataProvider& in, hid_t object, bool attribute, hid_t file_type,
          std::size_t count) {
  if (count == 0 || count > 4096) return;
  const H5T_class_t cls = H5Tget_class(file_type);
  if (cls == H5T_STRING) {
    hid_t mem = H5Tcopy(file_type);
    if (H5Tis_variable_str(file_type) > 0) {
      std::vector<std::string> text(count);
      std::vector<const char*> pointers(count);
      for (std::size_t i = 0; i < count; ++i) {
        text[i] = in.ConsumeRandomLengthString(64);
        pointers[i] = text[i].c_str();
      }
      attribute ? H5Awrite(object, mem, pointers.data())
                : H5Dwrite(object, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data());
    } else {
      const std::size_t width = H5Tget_size(file_type);
      std::vector<char> bytes(width * count);
      for (char& c : bytes) c = static_cast<char>(in.ConsumeIntegral<std::uint8_t>());
      attribute ? H5Awrite(object, mem, bytes.data())
                : H5Dwrite(object, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data());
    }
    H5Tclose(mem);
    return;
  }
  if (cls == H5T_COMPOUND) return;  // left as fill values
  std::vector<double> values(count);
  for (double& v : values) v = pick_value(in);
  attribute ? H5Awrite(object, H5T_NATIVE_DOUBLE, values.data())
            : H5Dwrite(object, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
}

/// Values that fit a well-formed packing of n spheres in a box of edge `box` (so that the recipe
/// reaches the reader's later checks and the round trip often).
void fill_plausible(FuzzedDataProvider& in, hid_t set, const char* name, std::size_t count) {
  std::vector<double> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    if (std::strcmp(name, "box_length") == 0) {
      values[i] = 4.0;
    } else if (std::strcmp(name, "radii") == 0) {
      values[i] = 0.5;
    } else {
      values[i] = in.ConsumeFloatingPointInRange<double>(0.0, 3.99);
    }
    if (in.ConsumeIntegralInRange(0, 15) == 0) values[i] = pick_value(in);
  }
  H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
}

void add_dataset(FuzzedDataProvider& in, hid_t group, const char* name, hsize_t n) {
  if (in.ConsumeIntegralInRange(0, 15) == 0) return;  // missing
  const bool chunked = in.ConsumeIntegralInRange(0, 3) == 0;
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  bool owned = false;
  hid_t type = H5T_IEEE_F64LE;
  hid_t space = -1;
  std::vector<hsize_t> dims;
  const bool plausible = in.ConsumeIntegralInRange(0, 3) != 0;
  if (plausible) {  // the expected shape: [n, 3], [n] or [3]
    if (std::strcmp(name, "centers") == 0) dims = {n, 3};
    if (std::strcmp(name, "radii") == 0) dims = {n};
    if (std::strcmp(name, "box_length") == 0) dims = {3};
    std::vector<hsize_t> max(dims.size(), H5S_UNLIMITED);
    space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(),
                             chunked ? max.data() : nullptr);
  } else {
    type = pick_type(in, &owned);
    space = pick_space(in, chunked, &dims);
  }
  if (chunked && !dims.empty()) {
    std::vector<hsize_t> chunk(dims.size());
    for (hsize_t& c : chunk) c = in.ConsumeIntegralInRange<hsize_t>(1, 8);
    H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
    if (in.ConsumeBool()) {
      const double fill_value = pick_value(in);
      H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &fill_value);
    }
  }
  hid_t set = H5Dcreate2(group, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (set >= 0) {
    const std::size_t count = H5Sget_select_npoints(space) > 0 ? element_count(dims) : 0;
    if (plausible && count <= 4096) {
      fill_plausible(in, set, name, count);
    } else {
      fill(in, set, false, type, H5Sget_simple_extent_type(space) == H5S_SCALAR ? 1 : count);
    }
    H5Dclose(set);
  }
  if (owned) H5Tclose(type);
  H5Sclose(space);
  H5Pclose(dcpl);
}

void add_attribute(FuzzedDataProvider& in, hid_t group, const char* name) {
  if (in.ConsumeIntegralInRange(0, 3) == 0) return;
  bool owned = false;
  hid_t type = H5T_STD_U64LE;
  if (in.ConsumeBool()) {
    type = pick_type(in, &owned);
  } else if (std::strcmp(name, "generator") == 0 || std::strcmp(name, "settings") == 0) {
    owned = true;
    type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
  }
  std::vector<hsize_t> dims;
  hid_t space = -1;
  if (in.ConsumeBool()) {
    space = H5Screate(H5S_SCALAR);
  } else {
    dims.push_back(in.ConsumeIntegralInRange<hsize_t>(0, 5));
    space = H5Screate_simple(1, dims.data(), nullptr);
  }
  hid_t attr = H5Acreate2(group, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  if (attr >= 0) {
    fill(in, attr, true, type, dims.empty() ? 1 : element_count(dims));
    H5Aclose(attr);
  }
  if (owned) H5Tclose(type);
  H5Sclose(space);
}

/// Builds the recipe's file at path; false if HDF5 could not create it.
bool build_file(FuzzedDataProvider& in, const std::string& path) {
  hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) return false;
  const int layout = in.ConsumeIntegralInRange(0, 15);
  if (layout == 0) {         // no /packing
  } else if (layout == 1) {  // /packing is a dataset
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t set =
        H5Dcreate2(file, "packing", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (set >= 0) H5Dclose(set);
    H5Sclose(space);
  } else {
    hid_t group = H5Gcreate2(file, "packing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (group >= 0) {
      const hsize_t n =
          in.ConsumeIntegralInRange(0, 7) == 0 ? pick_dim(in) : in.ConsumeIntegralInRange(0, 12);
      for (const char* name : {"centers", "radii", "box_length"}) add_dataset(in, group, name, n);
      for (const char* name : {"generator", "settings", "seed", "phi", "n"}) {
        add_attribute(in, group, name);
      }
      H5Gclose(group);
    }
  }
  return H5Fclose(file) >= 0;
}

void check(const draglab::arrays::Packing& p, const std::string& what) {
  if (p.size() == 0 || p.centers.size() != p.size()) draglab_fuzz::finding(what + ": no spheres");
  for (int a = 0; a < 3; ++a) {
    if (!(p.box_length[a] > 0.0)) draglab_fuzz::finding(what + ": box edge not positive");
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p.radii[i] > 0.0)) draglab_fuzz::finding(what + ": radius not positive");
    for (int a = 0; a < 3; ++a) {
      if (!(p.centers[i][a] >= 0.0 && p.centers[i][a] < p.box_length[a])) {
        draglab_fuzz::finding(what + ": centre outside the box");
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // the recipe's failed calls are expected
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto& scratch = draglab_fuzz::ScratchDir::get();
  std::string path;
  if (size >= 8 && std::memcmp(data, kSignature, 8) == 0) {
    path = scratch.write("fuzz.h5", data, size);
  } else {
    FuzzedDataProvider in(data, size);
    path = scratch.file("fuzz.h5");
    if (!build_file(in, path)) return 0;
  }
  draglab_fuzz::expect_clean([&] {
    const draglab::arrays::Packing packing = draglab::arrays::read_packing_hdf5_in_process(path);
    check(packing, "accepted packing");
    const std::string again_path = scratch.file("again.h5");
    draglab::arrays::write_packing_hdf5(again_path, packing);
    draglab::arrays::Packing again;
    try {
      again = draglab::arrays::read_packing_hdf5_in_process(again_path);
    } catch (const draglab::Error& e) {
      draglab_fuzz::finding(std::string("a written packing is refused: ") + e.what());
    }
    if (again.centers != packing.centers || again.radii != packing.radii ||
        again.box_length != packing.box_length || again.seed != packing.seed ||
        again.generator != packing.generator || again.settings_json != packing.settings_json) {
      draglab_fuzz::finding("write then read does not give the packing back");
    }
  });
  return 0;
}
