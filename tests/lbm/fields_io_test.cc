// Flow-field files (lbm/fields_io.h): the HDF5 layout [nz, ny, nx(, 3)] with x fastest as seen by
// independent readers (h5dump from hdf5-tools, h5py under Debian's /usr/bin/python3), the XDMF 2
// description ParaView needs (3DCoRectMesh, point counts nz+1 ny+1 nx+1, cell-centred
// attributes, the HDF5 file referenced by its base name), an optional check with ParaView's own
// XDMFReader when it is installed, exact round trip, and atomic writes (nothing left behind on
// an error).
//
// Set-up: a 5 x 3 x 4 node field (all edges different so that any axis mix-up shows) whose
// values encode their node: velocity = (i + 10 j + 100 k, -1 - i, 0.5 k), density = 1 + i/8,
// solid = 1 where i == j.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "draglab/error.h"
#include "draglab/lbm/fields_io.h"
#include "draglab/lbm/lbm.h"
#include "support/temp_dir.h"

namespace draglab {
namespace lbm {
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

constexpr int kNx = 5, kNy = 3, kNz = 4;

Fields encoded_fields() {
  Fields f;
  f.dims = {kNx, kNy, kNz};
  const std::size_t n = kNx * kNy * kNz;
  f.velocity.resize(3 * n);
  f.density.resize(n);
  f.solid.resize(n);
  for (int k = 0; k < kNz; ++k) {
    for (int j = 0; j < kNy; ++j) {
      for (int i = 0; i < kNx; ++i) {
        const std::size_t node = i + kNx * (j + kNy * k);  // lbm.h: i + nx (j + ny k)
        f.velocity[3 * node + 0] = static_cast<float>(i + 10 * j + 100 * k);
        f.velocity[3 * node + 1] = static_cast<float>(-1 - i);
        f.velocity[3 * node + 2] = 0.5f * k;
        f.density[node] = 1.0f + i / 8.0f;
        f.solid[node] = i == j ? 1 : 0;
      }
    }
  }
  return f;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(FieldsIo, XdmfPathReplacesTheExtension) {
  EXPECT_EQ(xdmf_path_for("out/flow.h5"), "out/flow.xmf");
  EXPECT_EQ(xdmf_path_for("flow.hdf5"), "flow.xmf");
  EXPECT_EQ(xdmf_path_for("flow"), "flow.xmf");
  EXPECT_EQ(xdmf_path_for("dir.h5/flow"), "dir.h5/flow.xmf");
}

TEST(FieldsIo, RoundTripIsExact) {
  TempDir dir;
  const Fields f = encoded_fields();
  FieldsWriteOptions o;
  o.dx = 1.0 / 16.0;
  o.run_json = R"({"F": 4.29})";
  write_fields(dir.file("f.h5"), f, o);
  double dx = 0.0;
  const Fields g = read_fields(dir.file("f.h5"), &dx);
  EXPECT_EQ(g.dims, f.dims);
  EXPECT_EQ(g.velocity, f.velocity);  // float32 stored as IEEE binary32: bit-exact
  EXPECT_EQ(g.density, f.density);
  EXPECT_EQ(g.solid, f.solid);
  EXPECT_EQ(dx, o.dx);
  EXPECT_EQ(access(dir.file("f.xmf").c_str(), F_OK), 0);
  EXPECT_NE(access(dir.file("f.h5.partial").c_str(), F_OK), 0);
  EXPECT_NE(access(dir.file("f.xmf.partial").c_str(), F_OK), 0);
}

TEST(FieldsIo, LayoutAsSeenByH5dump) {
  TempDir dir;
  write_fields(dir.file("f.h5"), encoded_fields());
  int status = 0;
  const std::string out = run("h5dump -H '" + dir.file("f.h5") + "'", &status);
  if (status != 0 && out.find("not found") != std::string::npos) GTEST_SKIP() << "no h5dump";
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("GROUP \"fields\""), std::string::npos) << out;
  // C order, z slowest: (nz, ny, nx, 3) = (4, 3, 5, 3).
  EXPECT_NE(out.find("( 4, 3, 5, 3 )"), std::string::npos) << "velocity must be [nz,ny,nx,3]";
  EXPECT_NE(out.find("( 4, 3, 5 )"), std::string::npos) << "scalars must be [nz,ny,nx]";
  EXPECT_NE(out.find("H5T_IEEE_F32LE"), std::string::npos);
  EXPECT_NE(out.find("H5T_STD_U8LE"), std::string::npos);
  EXPECT_NE(out.find("ATTRIBUTE \"dx\""), std::string::npos);
}

TEST(FieldsIo, NodeOrderAsSeenByH5py) {
  TempDir dir;
  write_fields(dir.file("f.h5"), encoded_fields());
  int status = 0;
  run("/usr/bin/python3 -c 'import h5py'", &status);
  if (status != 0) GTEST_SKIP() << "h5py not importable by /usr/bin/python3";
  // v[k, j, i] must hold node (i, j, k): the x component encodes i + 10 j + 100 k.
  const std::string script =
      "import h5py\n"
      "g = h5py.File('" +
      dir.file("f.h5") +
      "', 'r')['fields']\n"
      "v, rho, s = g['velocity'][()], g['density'][()], g['solid'][()]\n"
      "assert v.shape == (4, 3, 5, 3) and rho.shape == (4, 3, 5) and s.shape == (4, 3, 5)\n"
      "for k in range(4):\n"
      "  for j in range(3):\n"
      "    for i in range(5):\n"
      "      assert v[k, j, i, 0] == i + 10*j + 100*k and v[k, j, i, 1] == -1 - i\n"
      "      assert v[k, j, i, 2] == 0.5*k and rho[k, j, i] == 1 + i/8\n"
      "      assert s[k, j, i] == (1 if i == j else 0)\n"
      "assert list(g.attrs['dims']) == [5, 3, 4]\n"
      "print('ok')\n";
  std::ofstream(dir.file("check.py")) << script;
  const std::string out = run("/usr/bin/python3 '" + dir.file("check.py") + "'", &status);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("ok"), std::string::npos) << out;
}

TEST(FieldsIo, XdmfDescribesCellsInZyxOrder) {
  TempDir dir;
  FieldsWriteOptions o;
  o.dx = 0.125;
  write_fields(dir.file("flow.h5"), encoded_fields(), o);
  const std::string x = read_text(dir.file("flow.xmf"));
  // Points = cells + 1, z y x.
  EXPECT_NE(x.find("TopologyType=\"3DCoRectMesh\" Dimensions=\"5 4 6\""), std::string::npos) << x;
  EXPECT_NE(x.find("GeometryType=\"ORIGIN_DXDYDZ\""), std::string::npos);
  EXPECT_NE(x.find(">0.125 0.125 0.125<"), std::string::npos) << x;
  EXPECT_NE(x.find("Dimensions=\"4 3 5 3\""), std::string::npos) << x;
  EXPECT_NE(x.find("Dimensions=\"4 3 5\""), std::string::npos) << x;
  // Relative reference: the pair of files can move together.
  EXPECT_NE(x.find(">flow.h5:/fields/velocity<"), std::string::npos) << x;
  EXPECT_EQ(x.find(dir.path()), std::string::npos) << "no absolute path inside the XDMF file";
  // Every attribute is cell-centred.
  std::size_t attributes = 0, cells = 0;
  for (std::size_t p = x.find("<Attribute "); p != std::string::npos;
       p = x.find("<Attribute ", p + 1)) {
    ++attributes;
    if (x.substr(p, x.find('>', p) - p).find("Center=\"Cell\"") != std::string::npos) ++cells;
  }
  EXPECT_EQ(attributes, 3u);
  EXPECT_EQ(cells, 3u);
  // Well-formed XML (Python's parser as an independent check).
  int status = 0;
  const std::string out = run("/usr/bin/python3 -c \"import xml.etree.ElementTree as E; E.parse('" +
                                  dir.file("flow.xmf") + "'); print('xml ok')\"",
                              &status);
  if (status == 0) {
    EXPECT_NE(out.find("xml ok"), std::string::npos) << out;
  } else {
    EXPECT_EQ(out.find("ParseError"), std::string::npos) << out;
  }
}

// ParaView's legacy Xdmf2 reader is the consumer the format is written for; run it when this
// machine has it (python3-paraview), skip otherwise.
TEST(FieldsIo, ParaViewXdmfReaderSeesCellData) {
  int status = 0;
  run("/usr/bin/python3 -c 'import paraview.simple' 2>/dev/null", &status);
  if (status != 0) GTEST_SKIP() << "ParaView's Python module not available";
  TempDir dir;
  FieldsWriteOptions o;
  o.dx = 0.5;
  write_fields(dir.file("flow.h5"), encoded_fields(), o);
  const std::string script =
      "from paraview.simple import XDMFReader\n"
      "from paraview import servermanager as sm\n"
      "r = XDMFReader(FileNames=['" +
      dir.file("flow.xmf") +
      "'])\n"
      "r.UpdatePipeline()\n"
      "o = sm.Fetch(r)\n"
      "print('dims', o.GetDimensions())\n"
      "print('bounds', o.GetBounds())\n"
      "cd = o.GetCellData()\n"
      "v = cd.GetArray('velocity')\n"
      "print('ncomp', v.GetNumberOfComponents(), 'ntuples', v.GetNumberOfTuples())\n"
      "print('v7', v.GetTuple3(7))\n"
      "print('solid', cd.GetArray('solid').GetRange())\n"
      "print('density', cd.GetArray('density').GetRange())\n";
  std::ofstream(dir.file("pv.py")) << script;
  const std::string out = run("cd '" + dir.path() + "' && /usr/bin/python3 pv.py", &status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("dims (6, 4, 5)"), std::string::npos) << out;  // points, x y z
  EXPECT_NE(out.find("bounds (0.0, 2.5, 0.0, 1.5, 0.0, 2.0)"), std::string::npos) << out;
  EXPECT_NE(out.find("ncomp 3 ntuples 60"), std::string::npos) << out;
  // Cell 7 with x fastest is (i, j, k) = (2, 1, 0): velocity (12, -3, 0).
  EXPECT_NE(out.find("v7 (12.0, -3.0, 0.0)"), std::string::npos) << out;
  EXPECT_NE(out.find("solid (0.0, 1.0)"), std::string::npos) << out;
  EXPECT_NE(out.find("density (1.0, 1.5)"), std::string::npos) << out;
}

TEST(FieldsIo, UnwritablePathLeavesNothing) {
  TempDir dir;
  const std::string path = dir.file("missing_dir/f.h5");
  try {
    write_fields(path, encoded_fields());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_NE(access(path.c_str(), F_OK), 0);
  EXPECT_NE(access(dir.file("missing_dir").c_str(), F_OK), 0);
}

TEST(FieldsIo, InconsistentFieldsAreRefusedBeforeWriting) {
  TempDir dir;
  Fields f = encoded_fields();
  f.density.pop_back();
  EXPECT_THROW(write_fields(dir.file("f.h5"), f), Error);
  Fields g = encoded_fields();
  FieldsWriteOptions o;
  o.dx = 0.0;
  EXPECT_THROW(write_fields(dir.file("f.h5"), g, o), Error);
  EXPECT_NE(access(dir.file("f.h5").c_str(), F_OK), 0);
  EXPECT_NE(access(dir.file("f.xmf").c_str(), F_OK), 0);
  EXPECT_NE(access(dir.file("f.h5.partial").c_str(), F_OK), 0);
}

TEST(FieldsIo, MalformedFilesGiveClearErrors) {
  TempDir dir;
  auto expect_error = [](const std::string& path, const std::string& needle) {
    try {
      read_fields(path);
      ADD_FAILURE() << "expected an error for " << path;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(dir.file("none.h5"), "does not exist");
  std::ofstream(dir.file("text.h5")) << "not hdf5";
  expect_error(dir.file("text.h5"), "not an HDF5 file");
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
