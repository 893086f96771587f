// draglab/workflows/convergence_plot.h: the work-precision plot of an LBM convergence study
// (`draglab lbm convergence --plot FILE.png`): |F/F_ref - 1| against wall time, log-log, one
// line per scheme, each point labelled with its resolution d. Only converged points with a
// finite, non-zero error are drawn. Drawn by gnuplot (Debian gnuplot-nox) where installed, else
// by matplotlib under python_interpreter().
#pragma once

#include <string>

#include "draglab/lbm/convergence.h"

namespace draglab {
namespace workflows {

/// "gnuplot", "matplotlib" or "" (neither available).
std::string convergence_plot_tool();

/// Whether `bytes` is a whole PNG: its signature first and the IEND chunk last (a full disk
/// leaves gnuplot a truncated file and exit status 0).
bool is_complete_png(const std::string& bytes);

/// Draws the plot with `tool` in a temporary directory, checks the PNG is whole and writes it
/// to `path` atomically. Throws std::runtime_error when no point can be drawn and
/// draglab::Error(kIo) when the tool fails or the PNG is incomplete; `path` is then untouched.
void write_convergence_plot(const std::string& path, const std::string& tool,
                            const lbm::ConvergenceResult& result, const std::string& title);

}  // namespace workflows
}  // namespace draglab
