// DPM output files (consumers/src/io/bed_output.h): gas fields and particles in HDF5 with an XDMF 2
// index for ParaView.
//
// Set-up: a 4 x 6 cell gas grid, 0.04 m wide, 0.09 m tall, 5 mm deep (dx = 10 mm, dz = 15 mm, so
// a swapped axis shows in the spacing), eps(i, j) = 0.5 + 0.01 i + 0.05 j and beta(i, j) =
// 100 (i + 1) + 1000 j (a different value in every cell, so a transposed or flipped array
// shows), a uniform gas velocity (0.3, 1.2) m/s with no-slip side walls; five particles whose
// ids are not in index order (as after DemSystem::sort_particles) and a layer table by id. Two
// output times: t = 0.01 s as set up, and t = 0.025 s after one gas step (a non-zero pressure
// field and changed velocities, particles moved).
// Reference: the values that went in. Files are read back with the HDF5 C API and compared
// exactly (doubles are stored as 64-bit IEEE, so the round trip is bit-exact; the face-to-centre
// average is recomputed here in the same order of operations). The XDMF text is checked against
// the conventions that ParaView 5.11's XDMFReader needs (Topology point counts "nz+1 ny+1 nx+1",
// spacing z y x, cell attributes "nz ny nx" = the dataset shape), and every HDF5 path it names
// must exist with the shape the XDMF declares. When /usr/bin/pvpython is installed, ParaView
// itself opens the index (optional: skipped elsewhere).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/error.h"
#include "io/bed_output.h"

namespace draglab {
namespace consumers {
namespace {

constexpr int kNx = 4, kNz = 6;
constexpr double kT0 = 0.01, kT1 = 0.025;

GasOptions SmallGrid() {
  GasOptions o;
  o.nx = kNx;
  o.nz = kNz;
  o.width_m = 0.04;
  o.height_m = 0.09;
  o.depth_m = 0.005;
  o.background_velocity_m_s = 0.5;
  return o;
}

double EpsAt(int i, int j) { return 0.5 + 0.01 * i + 0.05 * j; }
double BetaAt(int i, int j) { return 100.0 * (i + 1) + 1000.0 * j; }

void SetSolids(GasPhase& gas) {
  Eigen::ArrayXXd eps(kNx, kNz), beta(kNx, kNz), zero = Eigen::ArrayXXd::Zero(kNx, kNz);
  for (int j = 0; j < kNz; ++j) {
    for (int i = 0; i < kNx; ++i) {
      eps(i, j) = EpsAt(i, j);
      beta(i, j) = BetaAt(i, j);
    }
  }
  gas.SetVoidFraction(eps);
  gas.SetSolids(eps, beta, zero, zero);
}

/// Five spheres (x width, y height, z depth) with ids 3, 0, 4, 1, 2.
Particles FiveParticles() {
  Particles p;
  const std::int64_t ids[5] = {3, 0, 4, 1, 2};
  for (int k = 0; k < 5; ++k) {
    p.add(0.005 + 0.007 * k, 0.01 + 0.011 * k, 0.0025, 2.0e-3 + 1e-4 * k, 2500.0, 0.1 * k, -0.2 * k,
          0.01 * k);
    p.id[static_cast<std::size_t>(k)] = ids[k];
  }
  return p;
}

const std::vector<int> kLayerById = {5, 4, 3, 2, 1};

/// A fresh directory per test (ctest runs the tests of this file as parallel processes).
std::string FreshDirectory() {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir =
      ::testing::TempDir() + "/bed_output_test_" + std::to_string(::getpid()) + "_" + info->name();
  std::filesystem::remove_all(dir);
  return dir;
}

Scene TestScene() {
  Scene s;
  s.name = "out_test";
  s.source_text = "[scene]\nname = \"out_test\"\n";
  return s;
}

// ---- HDF5 reading helpers (the test's own, independent of the writer) ------------------------

struct H5File {
  explicit H5File(const std::string& path) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  }
  ~H5File() {
    if (id >= 0) H5Fclose(id);
  }
  hid_t id = -1;
};

/// True if every link along `path` ("/t000000/eps") exists.
bool PathExists(hid_t file, const std::string& path) {
  std::string prefix;
  std::stringstream parts(path);
  std::string part;
  while (std::getline(parts, part, '/')) {
    if (part.empty()) continue;
    prefix += "/" + part;
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return !prefix.empty();
}

std::vector<hsize_t> Shape(hid_t file, const std::string& path) {
  const hid_t set = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (set < 0) return {};
  const hid_t space = H5Dget_space(set);
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Dclose(set);
  return dims;
}

template <typename T>
std::vector<T> Read(hid_t file, const std::string& path, hid_t mem_type) {
  std::size_t n = 1;
  for (hsize_t d : Shape(file, path)) n *= static_cast<std::size_t>(d);
  std::vector<T> values(n);
  const hid_t set = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(set, 0) << path;
  if (set < 0) return {};
  EXPECT_GE(H5Dread(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0) << path;
  H5Dclose(set);
  return values;
}

double ReadTime(hid_t file, const std::string& group) {
  double t = -1.0;
  const hid_t attr = H5Aopen_by_name(file, group.c_str(), "time_s", H5P_DEFAULT, H5P_DEFAULT);
  if (attr >= 0) {
    H5Aread(attr, H5T_NATIVE_DOUBLE, &t);
    H5Aclose(attr);
  }
  return t;
}

std::string ShapeText(const std::vector<hsize_t>& dims) {
  std::string s;
  for (hsize_t d : dims) s += (s.empty() ? "" : " ") + std::to_string(d);
  return s;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> AllMatches(const std::string& text, const std::string& pattern) {
  std::vector<std::string> out;
  const std::regex re(pattern);
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
       ++it) {
    out.push_back((*it)[1].str());
  }
  return out;
}

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++n;
  }
  return n;
}

// ---- the run whose files the tests inspect -------------------------------------------------

struct WrittenRun {
  std::string dir, h5, xmf;
  std::vector<std::string> files;
  int outputs = 0;
  // What went in at the second output time (after the gas step, particles moved).
  Eigen::ArrayXXd p1, ux1, uz1;
  Particles particles1;
};

WrittenRun WriteTwoTimes(bool fields, bool particles) {
  WrittenRun run;
  run.dir = FreshDirectory();
  GasPhase gas(SmallGrid());
  SetSolids(gas);
  gas.SetUniformVelocity(0.3, 1.2);
  Particles p = FiveParticles();
  {
    BedOutputWriter writer(TestScene(), "ergun@1", run.dir, fields, particles);
    writer.Write(kT0, gas, p, kLayerById);
    gas.Step(0.5 * gas.StableTimeStep(0.5));
    for (std::size_t k = 0; k < p.size(); ++k) p.y[k] += 1e-3;
    writer.Write(kT1, gas, p, kLayerById);
    writer.Finish();
    run.files = writer.files();
    run.outputs = writer.outputs();
  }
  run.h5 = run.dir + "/out_test_ergun_1.h5";
  run.xmf = run.dir + "/out_test_ergun_1.xmf";
  run.p1 = gas.p();
  run.ux1.resize(kNx, kNz);
  run.uz1.resize(kNx, kNz);
  for (int j = 0; j < kNz; ++j) {
    for (int i = 0; i < kNx; ++i) {
      run.ux1(i, j) = 0.5 * (gas.u()(i, j) + gas.u()(i + 1, j));
      run.uz1(i, j) = 0.5 * (gas.w()(i, j) + gas.w()(i, j + 1));
    }
  }
  run.particles1 = p;
  return run;
}

TEST(BedOutputTest, FieldsAndParticlesRoundTripThroughHdf5) {
  const WrittenRun run = WriteTwoTimes(true, true);
  EXPECT_EQ(run.outputs, 2);
  ASSERT_EQ(run.files.size(), 2u);
  EXPECT_EQ(run.files[0], run.h5);
  EXPECT_EQ(run.files[1], run.xmf);
  H5File f(run.h5);
  ASSERT_GE(f.id, 0) << run.h5;
  EXPECT_DOUBLE_EQ(ReadTime(f.id, "/t000000"), kT0);
  EXPECT_DOUBLE_EQ(ReadTime(f.id, "/t000001"), kT1);
  EXPECT_FALSE(PathExists(f.id, "/t000002"));

  // Gas: shape (1, nz, nx), x fastest; every cell of eps and beta is checked.
  const std::vector<hsize_t> cells{1, kNz, kNx};
  for (const char* name : {"eps", "p", "u_x", "u_z", "beta"}) {
    EXPECT_EQ(Shape(f.id, std::string("/t000000/") + name), cells) << name;
  }
  const std::vector<double> eps = Read<double>(f.id, "/t000000/eps", H5T_NATIVE_DOUBLE);
  const std::vector<double> beta = Read<double>(f.id, "/t000000/beta", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(eps.size(), static_cast<std::size_t>(kNx * kNz));
  ASSERT_EQ(beta.size(), eps.size());
  for (int j = 0; j < kNz; ++j) {
    for (int i = 0; i < kNx; ++i) {
      EXPECT_EQ(eps[static_cast<std::size_t>(j * kNx + i)], EpsAt(i, j)) << i << " " << j;
      EXPECT_EQ(beta[static_cast<std::size_t>(j * kNx + i)], BetaAt(i, j)) << i << " " << j;
    }
  }
  // Cell-centred velocity at t0: the walls (u = 0) halve u_x in the outer columns.
  const std::vector<double> ux0 = Read<double>(f.id, "/t000000/u_x", H5T_NATIVE_DOUBLE);
  const std::vector<double> uz0 = Read<double>(f.id, "/t000000/u_z", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(ux0.size(), eps.size());
  EXPECT_DOUBLE_EQ(ux0[0], 0.15);
  EXPECT_DOUBLE_EQ(ux0[1], 0.3);
  EXPECT_DOUBLE_EQ(ux0[kNx - 1], 0.15);
  EXPECT_DOUBLE_EQ(uz0[5], 1.2);
  // t1: after a gas step, the pressure is non-zero; every cell equals what the solver held.
  const std::vector<double> p1 = Read<double>(f.id, "/t000001/p", H5T_NATIVE_DOUBLE);
  const std::vector<double> ux1 = Read<double>(f.id, "/t000001/u_x", H5T_NATIVE_DOUBLE);
  const std::vector<double> uz1 = Read<double>(f.id, "/t000001/u_z", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(p1.size(), eps.size());
  ASSERT_GT(run.p1.abs().maxCoeff(), 0.0);  // else the comparison below proves nothing
  for (int j = 0; j < kNz; ++j) {
    for (int i = 0; i < kNx; ++i) {
      const std::size_t c = static_cast<std::size_t>(j * kNx + i);
      EXPECT_EQ(p1[c], run.p1(i, j)) << i << " " << j;
      EXPECT_EQ(ux1[c], run.ux1(i, j)) << i << " " << j;
      EXPECT_EQ(uz1[c], run.uz1(i, j)) << i << " " << j;
    }
  }

  // Particles: (N, 3) position and velocity, per-particle id and layer = layer_by_id[id].
  EXPECT_EQ(Shape(f.id, "/t000001/position"), (std::vector<hsize_t>{5, 3}));
  EXPECT_EQ(Shape(f.id, "/t000001/velocity"), (std::vector<hsize_t>{5, 3}));
  for (const char* name : {"diameter", "id", "layer"}) {
    EXPECT_EQ(Shape(f.id, std::string("/t000001/") + name), (std::vector<hsize_t>{5})) << name;
  }
  const Particles& p = run.particles1;
  const std::vector<double> pos = Read<double>(f.id, "/t000001/position", H5T_NATIVE_DOUBLE);
  const std::vector<double> vel = Read<double>(f.id, "/t000001/velocity", H5T_NATIVE_DOUBLE);
  const std::vector<double> dia = Read<double>(f.id, "/t000001/diameter", H5T_NATIVE_DOUBLE);
  const std::vector<std::int64_t> id = Read<std::int64_t>(f.id, "/t000001/id", H5T_NATIVE_INT64);
  const std::vector<int> layer = Read<int>(f.id, "/t000001/layer", H5T_NATIVE_INT);
  ASSERT_EQ(pos.size(), 15u);
  ASSERT_EQ(layer.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(pos[3 * k], p.x[k]);
    EXPECT_EQ(pos[3 * k + 1], p.y[k]);
    EXPECT_EQ(pos[3 * k + 2], p.z[k]);
    EXPECT_EQ(vel[3 * k + 1], p.vy[k]);
    EXPECT_EQ(dia[k], p.diameter[k]);
    EXPECT_EQ(id[k], p.id[k]);
    EXPECT_EQ(layer[k], kLayerById[static_cast<std::size_t>(p.id[k])]);
  }
  // Particle 0 has id 3, so layer 2; at t0 it sat 1 mm lower.
  EXPECT_EQ(layer[0], 2);
  EXPECT_DOUBLE_EQ(Read<double>(f.id, "/t000000/position", H5T_NATIVE_DOUBLE)[1], 0.01);
  std::filesystem::remove_all(run.dir);
}

TEST(BedOutputTest, XdmfIndexFollowsTheParaViewConventionsAndNamesExistingDatasets) {
  const WrittenRun run = WriteTwoTimes(true, true);
  const std::string x = ReadText(run.xmf);
  ASSERT_FALSE(x.empty()) << run.xmf;
  EXPECT_NE(x.find("<Xdmf Version=\"2.0\">"), std::string::npos);
  // One temporal collection per kind, two uniform grids each.
  EXPECT_EQ(Count(x, "GridType=\"Collection\" CollectionType=\"Temporal\""), 2u);
  EXPECT_EQ(Count(x, "<Grid Name=\"gas\" GridType=\"Uniform\">"), 2u);
  EXPECT_EQ(Count(x, "<Grid Name=\"particles\" GridType=\"Uniform\">"), 2u);
  const std::vector<std::string> times = AllMatches(x, "<Time Value=\"([^\"]+)\"");
  ASSERT_EQ(times.size(), 4u);
  EXPECT_DOUBLE_EQ(std::stod(times[0]), kT0);  // gas
  EXPECT_DOUBLE_EQ(std::stod(times[1]), kT1);
  EXPECT_DOUBLE_EQ(std::stod(times[2]), kT0);  // particles
  EXPECT_DOUBLE_EQ(std::stod(times[3]), kT1);

  // Gas grid: point counts z y x = depth (1 cell), height (nz), width (nx).
  EXPECT_EQ(AllMatches(x, "TopologyType=\"3DCoRectMesh\" Dimensions=\"([^\"]+)\""),
            (std::vector<std::string>{"2 7 5", "2 7 5"}));
  const std::vector<std::string> spacing =
      AllMatches(x, "<DataItem Name=\"Spacing\"[^>]*>([^<]+)</DataItem>");
  ASSERT_EQ(spacing.size(), 2u);
  std::istringstream s(spacing[0]);
  double sz = 0, sy = 0, sx = 0;
  s >> sz >> sy >> sx;
  EXPECT_DOUBLE_EQ(sz, 0.005);                                 // depth
  EXPECT_DOUBLE_EQ(sy, 0.015);                                 // dz, height
  EXPECT_DOUBLE_EQ(sx, 0.01);                                  // dx, width
  EXPECT_EQ(Count(x, "Format=\"XML\">0 0 0</DataItem>"), 2u);  // origin
  EXPECT_EQ(Count(x, "TopologyType=\"Polyvertex\" NumberOfElements=\"5\""), 2u);
  EXPECT_EQ(Count(x, "<Geometry GeometryType=\"XYZ\">"), 2u);

  // Every HDF DataItem: the file next to the index, a dataset that exists, and the shape the
  // XDMF declares. 2 times x (5 gas attributes + position + 4 particle attributes).
  const std::regex item("<DataItem Dimensions=\"([^\"]+)\"[^>]*Format=\"HDF\">([^:<]+):([^<]+)<");
  H5File f(run.h5);
  ASSERT_GE(f.id, 0);
  int items = 0;
  for (auto it = std::sregex_iterator(x.begin(), x.end(), item); it != std::sregex_iterator();
       ++it, ++items) {
    const std::string dims = (*it)[1], file = (*it)[2], path = (*it)[3];
    EXPECT_EQ(file, "out_test_ergun_1.h5");
    ASSERT_TRUE(PathExists(f.id, path)) << path;
    EXPECT_EQ(ShapeText(Shape(f.id, path)), dims) << path;
  }
  EXPECT_EQ(items, 2 * (5 + 1 + 4));
  std::filesystem::remove_all(run.dir);
}

TEST(BedOutputTest, OnlyWhatIsAskedForIsWritten) {
  // Particles only: no gas datasets, no gas grid.
  WrittenRun run = WriteTwoTimes(false, true);
  {
    H5File f(run.h5);
    ASSERT_GE(f.id, 0);
    EXPECT_TRUE(PathExists(f.id, "/t000001/position"));
    EXPECT_FALSE(PathExists(f.id, "/t000001/eps"));
  }
  std::string x = ReadText(run.xmf);
  EXPECT_EQ(Count(x, "Name=\"gas\""), 0u);
  EXPECT_EQ(Count(x, "<Grid Name=\"particles\" GridType=\"Uniform\">"), 2u);
  std::filesystem::remove_all(run.dir);
  // Fields only.
  run = WriteTwoTimes(true, false);
  {
    H5File f(run.h5);
    ASSERT_GE(f.id, 0);
    EXPECT_TRUE(PathExists(f.id, "/t000001/eps"));
    EXPECT_FALSE(PathExists(f.id, "/t000001/position"));
  }
  x = ReadText(run.xmf);
  EXPECT_EQ(Count(x, "Name=\"particles\""), 0u);
  EXPECT_EQ(Count(x, "<Grid Name=\"gas\" GridType=\"Uniform\">"), 2u);
  std::filesystem::remove_all(run.dir);
  // Neither: no directory, no file, Write is a no-op.
  run = WriteTwoTimes(false, false);
  EXPECT_TRUE(run.files.empty());
  EXPECT_EQ(run.outputs, 0);
  EXPECT_FALSE(std::filesystem::exists(run.dir));
}

TEST(BedOutputTest, UnwritableDirectoryIsRefusedNamingThePath) {
  try {
    BedOutputWriter writer(TestScene(), "ergun@1", "/proc/x", true, true);
    FAIL() << "no error for /proc/x";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("/proc/x"), std::string::npos) << e.what();
  }
  // A regular file where the directory should be.
  const std::string dir = FreshDirectory();
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/not_a_directory";
  std::ofstream(file) << "x";
  try {
    BedOutputWriter writer(TestScene(), "ergun@1", file, true, false);
    FAIL() << "no error for a file used as the directory";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(BedOutputTest, BadWriteLeavesOnlyCompleteOutputTimes) {
  // A time that does not advance and a particle id without a layer are refused; the file keeps
  // the complete first output time and the index refers to it alone.
  const std::string dir = FreshDirectory();
  GasPhase gas(SmallGrid());
  SetSolids(gas);
  const Particles p = FiveParticles();
  BedOutputWriter writer(TestScene(), "ergun@1", dir, true, true);
  writer.Write(kT0, gas, p, kLayerById);
  try {
    writer.Write(kT0, gas, p, kLayerById);
    FAIL() << "no error for a repeated time";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("t_s"), std::string::npos) << e.what();
  }
  try {
    writer.Write(kT1, gas, p, std::vector<int>{0, 1, 2});  // ids 3 and 4 missing
    FAIL() << "no error for a particle id without a layer";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("particle id 3"), std::string::npos) << e.what();
  }
  writer.Finish();
  EXPECT_EQ(writer.outputs(), 1);
  {
    H5File f(dir + "/out_test_ergun_1.h5");
    ASSERT_GE(f.id, 0);
    EXPECT_TRUE(PathExists(f.id, "/t000000/eps"));
    EXPECT_FALSE(PathExists(f.id, "/t000001"));
  }
  EXPECT_EQ(Count(ReadText(dir + "/out_test_ergun_1.xmf"), "<Time Value="), 2u);  // gas + parts
  std::filesystem::remove_all(dir);
}

TEST(BedOutputTest, ParaViewOpensTheIndexWhenInstalled) {
  // Optional: ParaView is not installed on CI. Its legacy XDMF reader (XDMFReader, the one the
  // docs tell users to pick) must see both times, the gas as image data spanning the box with
  // the width along x and the height along y, and the five particles with their layers.
  const char* pvpython = "/usr/bin/pvpython";
  if (access(pvpython, X_OK) != 0) GTEST_SKIP() << "no " << pvpython;
  const WrittenRun run = WriteTwoTimes(true, true);
  const std::string script = run.dir + "/check.py";
  std::ofstream(script) << R"(import sys
from paraview.simple import XDMFReader
from paraview import servermanager as sm
r = XDMFReader(FileNames=[sys.argv[1]])
r.UpdatePipelineInformation()
print("times", " ".join("%.6g" % t for t in r.TimestepValues))
r.UpdatePipeline(0.025)
o = sm.Fetch(r)
for b in range(o.GetNumberOfBlocks()):
    d = o.GetBlock(b)
    name = o.GetMetaData(b).Get(o.NAME())
    if d.IsA("vtkImageData"):
        e = d.GetCellData().GetArray("eps").GetRange()
        print(name, "dims", *d.GetDimensions(), "bounds", *["%.6g" % v for v in d.GetBounds()],
              "eps", "%.6g %.6g" % e, "cells", d.GetNumberOfCells())
    else:
        l = d.GetPointData().GetArray("layer").GetRange()
        print(name, "points", d.GetNumberOfPoints(), "cells", d.GetNumberOfCells(),
              "layer", "%d %d" % l, "ymax", "%.6g" % d.GetBounds()[3])
)";
  const std::string out = run.dir + "/pv.txt";
  const std::string command =
      std::string(pvpython) + " '" + script + "' '" + run.xmf + "' > '" + out + "' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadText(out);
  const std::string text = ReadText(out);
  EXPECT_NE(text.find("times 0.01 0.025"), std::string::npos) << text;
  // Point dims (nx+1, nz+1, 2); bounds x 0..0.04 (width), y 0..0.09 (height), z 0..0.005.
  EXPECT_NE(text.find("gas dims 5 7 2 bounds 0 0.04 0 0.09 0 0.005 eps 0.5 0.78 cells 24"),
            std::string::npos)
      << text;
  // Layers 1..5 by id; the highest particle (index 4, y = 0.054 + 1 mm) at t1.
  EXPECT_NE(text.find("particles points 5 cells 5 layer 1 5 ymax 0.055"), std::string::npos)
      << text;
  std::filesystem::remove_all(run.dir);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
