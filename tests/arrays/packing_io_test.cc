// HDF5 packing files: exact round trip, the documented layout as seen by independent readers
// (h5dump from hdf5-tools, h5py under Debian's /usr/bin/python3), clear errors on malformed or
// missing files, and no partial file left behind on a failed write.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/packing_io.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace arrays {
namespace {

using TempDir = test::TempDir;

std::string run(const std::string& command, int* status) {
  std::string out;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) {
    *status = -1;
    return out;
  }
  char buf[4096];
  std::size_t got;
  while ((got = fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, got);
  *status = pclose(pipe);
  return out;
}

Packing small_packing() {
  Packing p;
  p.box_length = {3.0, 3.5, 4.0};
  p.centers = {{0.5, 0.6, 0.7}, {1.9, 2.1, 2.6}, {2.5, 0.25, 3.9}};
  p.radii = {0.5, 0.45, 0.3};
  p.generator = "test";
  p.settings_json = R"({"phi":0.1})";
  p.seed = 1234567890123ULL;
  return p;
}

TEST(PackingIo, RoundTripIsExact) {
  TempDir dir;
  const Packing p = small_packing();
  PackingStatistics stats;
  stats.min_gap = 0.125;
  stats.q6 = 0.03;
  write_packing_hdf5(dir.file("p.h5"), p, &stats);
  const Packing q = read_packing_hdf5(dir.file("p.h5"));
  EXPECT_EQ(q.box_length, p.box_length);
  EXPECT_EQ(q.centers, p.centers);  // doubles stored as IEEE 754 binary64: bit-exact
  EXPECT_EQ(q.radii, p.radii);
  EXPECT_EQ(q.generator, p.generator);
  EXPECT_EQ(q.settings_json, p.settings_json);
  EXPECT_EQ(q.seed, p.seed);
  EXPECT_DOUBLE_EQ(q.phi(), p.phi());
}

TEST(PackingIo, LayoutAsSeenByH5dump) {
  TempDir dir;
  write_packing_hdf5(dir.file("p.h5"), small_packing());
  int status = 0;
  const std::string out = run("h5dump -H '" + dir.file("p.h5") + "'", &status);
  if (status != 0 && out.find("not found") != std::string::npos) GTEST_SKIP() << "no h5dump";
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("GROUP \"packing\""), std::string::npos) << out;
  EXPECT_NE(out.find("DATASET \"centers\""), std::string::npos);
  EXPECT_NE(out.find("( 3, 3 )"), std::string::npos) << "centers must be [N,3]";
  EXPECT_NE(out.find("DATASET \"radii\""), std::string::npos);
  EXPECT_NE(out.find("DATASET \"box_length\""), std::string::npos);
  EXPECT_NE(out.find("ATTRIBUTE \"phi\""), std::string::npos);
  EXPECT_NE(out.find("ATTRIBUTE \"seed\""), std::string::npos);
  EXPECT_NE(out.find("ATTRIBUTE \"generator\""), std::string::npos);
}

TEST(PackingIo, ReadableByH5py) {
  TempDir dir;
  const Packing p = small_packing();
  write_packing_hdf5(dir.file("p.h5"), p);
  int status = 0;
  run("/usr/bin/python3 -c 'import h5py'", &status);
  if (status != 0) GTEST_SKIP() << "h5py not importable by /usr/bin/python3";
  const std::string script =
      "import h5py, math\n"
      "f = h5py.File('" +
      dir.file("p.h5") +
      "', 'r')\n"
      "g = f['packing']\n"
      "c, r, b = g['centers'][()], g['radii'][()], g['box_length'][()]\n"
      "assert c.shape == (3, 3) and r.shape == (3,) and b.shape == (3,)\n"
      "phi = sum(4/3*math.pi*x**3 for x in r) / (b[0]*b[1]*b[2])\n"
      "assert abs(phi - g.attrs['phi']) < 1e-14, (phi, g.attrs['phi'])\n"
      "assert g.attrs['generator'] == 'test', g.attrs['generator']\n"
      "assert int(g.attrs['seed']) == 1234567890123\n"
      "print('ok')\n";
  std::ofstream(dir.file("check.py")) << script;
  const std::string out = run("/usr/bin/python3 '" + dir.file("check.py") + "'", &status);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("ok"), std::string::npos) << out;
}

TEST(PackingIo, UnwritablePathLeavesNothing) {
  TempDir dir;
  const std::string path = dir.file("missing_dir/p.h5");
  try {
    write_packing_hdf5(path, small_packing());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_NE(access(path.c_str(), F_OK), 0);
  EXPECT_NE(access((path + ".partial").c_str(), F_OK), 0);
}

TEST(PackingIo, MalformedFilesGiveClearErrors) {
  TempDir dir;
  auto expect_error = [](const std::string& path, const std::string& needle) {
    try {
      read_packing_hdf5(path);
      ADD_FAILURE() << "expected an error for " << path;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(dir.file("none.h5"), "does not exist");
  std::ofstream(dir.file("text.h5")) << "not hdf5";
  expect_error(dir.file("text.h5"), "not an HDF5 file");
  // An HDF5 file without the /packing group.
  {
    hid_t f = H5Fcreate(dir.file("empty.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(f);
  }
  expect_error(dir.file("empty.h5"), "no group /packing");
  // centers with the wrong shape.
  {
    hid_t f = H5Fcreate(dir.file("shape.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t g = H5Gcreate2(f, "packing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hsize_t dims[2] = {2, 2};
    double data[4] = {0, 0, 0, 0};
    hid_t s = H5Screate_simple(2, dims, nullptr);
    hid_t d = H5Dcreate2(g, "centers", H5T_IEEE_F64LE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(d);
    H5Sclose(s);
    H5Gclose(g);
    H5Fclose(f);
  }
  expect_error(dir.file("shape.h5"), "[N, 3]");
  // Well-shaped files with values no packing has (a damaged file can hold them where libhdf5 read
  // garbage without failing): each is refused, naming the value.
  auto write_one_sphere = [&dir](const std::string& name, double radius, double box_edge) {
    const std::string path = dir.file(name);
    hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t g = H5Gcreate2(f, "packing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    auto put = [g](const char* key, std::vector<hsize_t> dims, const double* values) {
      hid_t s = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
      hid_t d = H5Dcreate2(g, key, H5T_IEEE_F64LE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values);
      H5Dclose(d);
      H5Sclose(s);
    };
    const double center[3] = {0.5, 0.5, 0.5};
    const double box[3] = {box_edge, box_edge, box_edge};
    put("centers", {1, 3}, center);
    put("radii", {1}, &radius);
    put("box_length", {3}, box);
    H5Gclose(g);
    H5Fclose(f);
    return path;
  };
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(read_packing_hdf5_in_process(write_one_sphere("ok.h5", 0.5, 1.0)));
  expect_error(write_one_sphere("huge_radius.h5", 1e300, 1.0), "radius 0 exceeds half");
  expect_error(write_one_sphere("inf_radius.h5", inf, 1.0), "radius 0 exceeds half");
  expect_error(write_one_sphere("nan_radius.h5", std::nan(""), 1.0), "radius 0");
  expect_error(write_one_sphere("inf_box.h5", 0.5, inf), "box_length must be positive and finite");
}

TEST(PackingIo, SpheresFillingMoreThanTheBoxAreRefused) {
  TempDir dir;
  Packing p;
  p.box_length = {1.0, 1.0, 1.0};
  p.centers = {{0.25, 0.5, 0.5}, {0.75, 0.5, 0.5}};
  p.radii = {0.5, 0.5};  // each fits the box; together 2 pi / 6 > 1
  p.generator = "test";
  write_packing_hdf5(dir.file("p.h5"), p);
  ASSERT_GT(p.phi(), 1.0);
  try {
    read_packing_hdf5_in_process(dir.file("p.h5"));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("phi > 1"), std::string::npos) << e.what();
  }
}

// A packing file damaged where libhdf5 1.10 reads a variable-length string attribute (found by
// fuzz_packing_hdf5: fuzz/regressions/libhdf5_global_heap_read.h5; under ASan libhdf5 copies
// about 1 GiB out of a bogus global-heap object). Whatever libhdf5 does with it, the caller
// survives: a well-formed packing or a bad-input error naming the file, never a crash.
TEST(PackingIo, DamagedFileThatCrashesLibhdf5IsBadInputNotACrash) {
  const std::string path =
      std::string(DRAGLAB_FUZZ_REGRESSIONS_DIR) + "/libhdf5_global_heap_read.h5";
  try {
    const Packing p = read_packing_hdf5(path);
    EXPECT_GT(p.size(), 0u);
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input()) << e.what();
    EXPECT_NE(std::string(e.what()).find("libhdf5_global_heap_read.h5"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace arrays
}  // namespace draglab
