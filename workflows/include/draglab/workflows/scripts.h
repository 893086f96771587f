// draglab/workflows/scripts.h: the files shipped with draglab (the Python figure scripts of the
// report, Fig. 4/5 and Fig. 6; campaign presets and scenes) and the interpreter that runs the
// scripts.
//
// The C++ side computes every number and writes a JSON bundle; a script only draws from it, so a
// figure can be redrawn without rerunning. Scripts need matplotlib, which Debian's
// /usr/bin/python3 sees (python3-matplotlib); it may not be the python3 first on PATH.
#pragma once

#include <string>
#include <vector>

namespace draglab {
namespace workflows {

/// Quotes a path for the shell (single quotes; a quote inside is closed, escaped, reopened).
std::string shell_quote(const std::string& s);

/// Directory of the running executable ("" if unknown).
std::string executable_dir();

/// A script shipped with draglab: installed next to the executable (bin/../share/draglab), else
/// the source tree's scripts/. Throws std::runtime_error naming both places if neither exists.
std::string find_script(const std::string& name);

/// A data file shipped with draglab (e.g. "campaigns/quick.toml", "scenes/dpm_tiny.toml"): in
/// the source tree's data/, else under the installed share/draglab (relative to the executable,
/// so installs are relocatable); "" if neither exists.
std::string find_shipped_file(const std::string& relative);

/// $DRAGLAB_PYTHON (tests, unusual installs), else Debian's /usr/bin/python3.
std::string python_interpreter();

/// Whether python_interpreter() can import matplotlib.
bool python_has_matplotlib();

/// Runs `python script args...` with the script's messages on stderr (stdout stays the caller's
/// for results and JSON). Throws std::runtime_error (a runtime failure, exit 1) when matplotlib
/// is missing or the script fails or does not write `expected_file`; the message says how to
/// draw the figure later from `bundle`, which is kept.
void run_figure_script(const std::string& script_name, const std::vector<std::string>& args,
                       const std::string& bundle, const std::string& expected_file);

}  // namespace workflows
}  // namespace draglab
