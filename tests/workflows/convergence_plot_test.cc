// workflows/convergence_plot.h and scripts.h: the LBM work-precision plot and the figure
// scripts' runner.
//
// Set-up: a convergence result filled by hand (two schemes, errors halving as the wall time
// doubles). References: a PNG is whole when it starts with the 8-byte PNG signature and ends
// with the IEND chunk (PNG specification, ISO/IEC 15948, 5.2 and 11.2.5); a plot with no
// converged finite point is refused; a failed tool leaves the target untouched.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "draglab/core/files.h"
#include "draglab/error.h"
#include "draglab/workflows/convergence_plot.h"
#include "draglab/workflows/scripts.h"
#include "support/temp_dir.h"

namespace draglab {
namespace {

const std::string kSignature("\x89PNG\r\n\x1a\n", 8);
const std::string kEnd("\0\0\0\0IEND\xae\x42\x60\x82", 12);

lbm::ConvergenceResult two_schemes(bool converged) {
  lbm::ConvergenceResult r;
  r.reference_F = 10.0;
  for (int k = 0; k < 2; ++k) {
    lbm::SchemeConvergence sc;
    double wall = 0.5, error = 0.08 * (k + 1);
    for (double d : {8.0, 12.0, 16.0}) {
      lbm::ConvergencePoint p;
      p.d = d;
      p.converged = converged;
      p.error = error;
      p.wall_s = wall;
      sc.points.push_back(p);
      wall *= 2.0;
      error /= 2.0;
    }
    r.schemes.push_back(sc);
  }
  return r;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CompletePng, SignatureFirstAndIendLast) {
  const std::string whole = kSignature + std::string(40, 'x') + kEnd;
  EXPECT_TRUE(workflows::is_complete_png(whole));
  EXPECT_FALSE(workflows::is_complete_png(whole.substr(0, whole.size() - 1)));  // truncated
  EXPECT_FALSE(workflows::is_complete_png("GIF89a" + whole.substr(6)));
  EXPECT_FALSE(workflows::is_complete_png(""));
}

TEST(ConvergencePlot, NoConvergedPointIsRefusedAndNothingWritten) {
  test::TempDir dir;
  const std::string tool = workflows::convergence_plot_tool();
  if (tool.empty()) GTEST_SKIP() << "neither gnuplot nor matplotlib: nothing draws the plot";
  EXPECT_THROW(workflows::write_convergence_plot(dir.file("p.png"), tool, two_schemes(false), "t"),
               std::runtime_error);
  EXPECT_FALSE(core::file_exists(dir.file("p.png")));
}

TEST(ConvergencePlot, WritesAWholePng) {
  test::TempDir dir;
  const std::string tool = workflows::convergence_plot_tool();
  if (tool.empty()) GTEST_SKIP() << "neither gnuplot nor matplotlib: nothing draws the plot";
  workflows::write_convergence_plot(dir.file("p.png"), tool, two_schemes(true), "it's a title");
  EXPECT_TRUE(workflows::is_complete_png(read_all(dir.file("p.png"))));
  EXPECT_EQ(dir.entries(), 1u);  // no temporary file left beside it
}

TEST(ConvergencePlot, AFailingToolLeavesTheTargetUntouched) {
  test::TempDir dir;
  { std::ofstream(dir.file("p.png")) << "old"; }
  ::setenv("DRAGLAB_PYTHON", "/bin/false", 1);
  try {
    workflows::write_convergence_plot(dir.file("p.png"), "matplotlib", two_schemes(true), "t");
    ADD_FAILURE() << "a failing tool must throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kIo);
  }
  ::unsetenv("DRAGLAB_PYTHON");
  EXPECT_EQ(read_all(dir.file("p.png")), "old");
}

TEST(Scripts, ShellQuoteSurvivesTheShell) {
  const std::string nasty = "a b'c\"$HOME`x`\\";
  const std::string command = "printf %s " + workflows::shell_quote(nasty);
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buf[256] = {};
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, pipe);
  ::pclose(pipe);
  EXPECT_EQ(std::string(buf, n), nasty);
}

TEST(Scripts, MissingScriptOrInterpreterIsARuntimeFailureThatSaysWhatToDo) {
  try {
    workflows::find_script("no_such_script.py");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("neither"), std::string::npos) << e.what();
  }
  ::setenv("DRAGLAB_PYTHON", "/bin/false", 1);
  try {
    workflows::run_figure_script("draglab_report.py", {"b.json", "out"}, "b.json", "out/r.md");
    ADD_FAILURE() << "a Python without matplotlib must throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("python3-matplotlib"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("b.json"), std::string::npos) << e.what();
  }
  ::unsetenv("DRAGLAB_PYTHON");
}

}  // namespace
}  // namespace draglab
