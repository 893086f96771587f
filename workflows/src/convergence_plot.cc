// workflows/src/convergence_plot.cc: see draglab/workflows/convergence_plot.h.
#include "draglab/workflows/convergence_plot.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "draglab/core/files.h"
#include "draglab/error.h"
#include "draglab/workflows/scripts.h"

namespace draglab {
namespace workflows {

bool is_complete_png(const std::string& bytes) {
  // A PNG starts with its 8-byte signature and ends with the IEND chunk (length 0, type, CRC).
  static const std::string kSignature("\x89PNG\r\n\x1a\n", 8);
  static const std::string kEnd("IEND\xae\x42\x60\x82", 8);
  return bytes.size() > kSignature.size() + kEnd.size() &&
         bytes.compare(0, kSignature.size(), kSignature) == 0 &&
         bytes.compare(bytes.size() - kEnd.size(), kEnd.size(), kEnd) == 0;
}

std::string convergence_plot_tool() {
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) return "gnuplot";
  if (python_has_matplotlib()) return "matplotlib";
  return "";
}

void write_convergence_plot(const std::string& path, const std::string& tool,
                            const lbm::ConvergenceResult& result, const std::string& title) {
  const char* tmp_root = std::getenv("TMPDIR");
  std::string tmpl =
      std::string(tmp_root && *tmp_root ? tmp_root : "/tmp") + "/draglab_plot_XXXXXX";
  if (!mkdtemp(tmpl.data()))
    throw std::runtime_error("--plot: cannot create a temporary directory");
  const std::string dir = tmpl;
  // The tool writes into the temporary directory; the PNG is checked whole (a full disk leaves
  // gnuplot a truncated file and exit status 0) and then written atomically in place.
  const std::string partial = dir + "/plot.png";
  std::string command;
  if (tool == "gnuplot") {
    std::ofstream s(dir + "/plot.gp");
    auto escape = [](const std::string& t) {  // gnuplot single-quoted string: '' is a quote
      std::string o;
      for (char ch : t) o += ch == '\'' ? std::string("''") : std::string(1, ch);
      return o;
    };
    s << "set terminal pngcairo size 960,640 noenhanced\n";
    s << "set output '" << escape(partial) << "'\n";
    s << "set logscale xy\nset grid\nset key outside right top\n";
    s << "set xlabel 'wall time (s)'\nset ylabel '|F / F_ref - 1|'\n";
    s << "set title '" << escape(title) << "'\n";
    std::string plot = "plot ";
    int blocks = 0;
    for (const auto& sc : result.schemes) {
      std::string data;
      for (const auto& p : sc.points) {
        if (p.converged && std::isfinite(p.error) && p.error != 0.0 && p.wall_s > 0.0) {
          data += fmt::format("{:.6g} {:.6g} {:.4g}\n", p.wall_s, std::fabs(p.error), p.d);
        }
      }
      if (data.empty()) continue;
      s << "$s" << blocks << " << EOD\n" << data << "EOD\n";
      plot += fmt::format(
          "{}$s{} using 1:2 with linespoints lw 2 pt 7 title '{}', $s{} using "
          "1:2:(sprintf('d=%.3g', "
          "$3)) with labels offset char 0.5,0.7 font ',8' notitle",
          blocks ? ", " : "", blocks, escape(sc.scheme.name()), blocks);
      ++blocks;
    }
    if (blocks == 0) throw std::runtime_error("--plot: no converged point with a finite error");
    s << plot << "\n";
    s.close();
    command = "gnuplot " + shell_quote(dir + "/plot.gp");
  } else {
    nlohmann::json data = nlohmann::json::array();
    for (const auto& sc : result.schemes) {
      nlohmann::json line = {{"name", sc.scheme.name()},
                             {"t", nlohmann::json::array()},
                             {"e", nlohmann::json::array()},
                             {"d", nlohmann::json::array()}};
      for (const auto& p : sc.points) {
        if (p.converged && std::isfinite(p.error) && p.error != 0.0 && p.wall_s > 0.0) {
          line["t"].push_back(p.wall_s);
          line["e"].push_back(std::fabs(p.error));
          line["d"].push_back(p.d);
        }
      }
      if (!line["t"].empty()) data.push_back(line);
    }
    if (data.empty()) throw std::runtime_error("--plot: no converged point with a finite error");
    std::ofstream(dir + "/data.json")
        << nlohmann::json({{"lines", data}, {"title", title}, {"out", partial}}).dump();
    std::ofstream(dir + "/plot.py")
        << "import json, sys\n"
           "import matplotlib\n"
           "matplotlib.use('Agg')\n"
           "import matplotlib.pyplot as plt\n"
           "c = json.load(open(sys.argv[1]))\n"
           "fig, ax = plt.subplots(figsize=(9.6, 6.4))\n"
           "for l in c['lines']:\n"
           "    ax.loglog(l['t'], l['e'], 'o-', label=l['name'])\n"
           "    for t, e, d in zip(l['t'], l['e'], l['d']):\n"
           "        ax.annotate('d=%.3g' % d, (t, e), fontsize=8, xytext=(4, 4),\n"
           "                    textcoords='offset points')\n"
           "ax.set_xlabel('wall time (s)'); ax.set_ylabel('|F / F_ref - 1|')\n"
           "ax.set_title(c['title']); ax.grid(True, which='both', alpha=0.3); ax.legend()\n"
           "fig.savefig(c['out'], dpi=100, format='png')\n";
    command = shell_quote(python_interpreter()) + " " + shell_quote(dir + "/plot.py") + " " +
              shell_quote(dir + "/data.json");
  }
  const int status = std::system((command + " 2>" + shell_quote(dir + "/err.txt")).c_str());
  std::string err;
  {
    std::ifstream e(dir + "/err.txt");
    std::getline(e, err, '\0');
  }
  std::string png;
  {
    std::ifstream in(partial, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    png = bytes.str();
  }
  std::system(("rm -rf " + shell_quote(dir)).c_str());
  if (status != 0 || !is_complete_png(png)) {
    throw Error(ErrorCode::kIo,
                "--plot: " + tool + " failed to write '" + path + "'" +
                    (status == 0 ? ": the PNG it wrote is incomplete (disk full?)" : ": " + err));
  }
  core::write_file_atomically(path, png, "--plot");
}

}  // namespace workflows
}  // namespace draglab
