// A time-throttled progress line on stderr for long runs (stage, percent, elapsed, ETA).
// On a terminal it redraws one line; otherwise it prints a line at most every 10 s.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace draglab {
namespace cli {

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled)
      : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0), start_(Clock::now()), last_(start_) {}
  ~ProgressLine() { finish(); }

  /// fraction in [0, 1] of `stage`.
  void update(double fraction, const std::string& stage) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (stage != stage_) {
      stage_ = stage;
      stage_start_ = now;
    }
    const double since_last = seconds(last_, now);
    if (since_last < (tty_ ? 0.2 : 10.0) && fraction < 1.0) return;
    last_ = now;
    const double elapsed = seconds(stage_start_, now);
    std::string eta = "?";
    if (fraction > 0.01 && fraction < 1.0)
      eta = format_seconds(elapsed * (1.0 - fraction) / fraction);
    std::fprintf(stderr, "%s[%s] %5.1f %%  elapsed %s  eta %s%s", tty_ ? "\r" : "", stage.c_str(),
                 100.0 * fraction, format_seconds(seconds(start_, now)).c_str(), eta.c_str(),
                 tty_ ? "   " : "\n");
    printed_ = true;
  }
  void finish() {
    if (enabled_ && tty_ && printed_) std::fputc('\n', stderr);
    printed_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  }
  static std::string format_seconds(double s) {
    char buf[32];
    if (s < 60) {
      std::snprintf(buf, sizeof buf, "%.1fs", s);
    } else {
      std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60,
                    static_cast<int>(s) % 60);
    }
    return buf;
  }
  bool enabled_, tty_, printed_ = false;
  Clock::time_point start_, last_, stage_start_;
  std::string stage_;
};

/// Prints the campaign runner's own progress lines (they carry counts and the ETA already): on a
/// terminal one redrawn line, otherwise a line at most every 10 s; failures always, on their own
/// line. finish() ends a redrawn line.
class CampaignProgressPrinter {
 public:
  explicit CampaignProgressPrinter(bool enabled)
      : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0) {}
  ~CampaignProgressPrinter() { finish(); }
  void operator()(long long finished, long long total, const std::string& line) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    const bool failure = line.find("FAILED") != std::string::npos;
    const double since = std::chrono::duration<double>(now - last_).count();
    if (!failure && finished < total && since < (tty_ ? 0.2 : 10.0)) return;
    last_ = now;
    if (tty_) {
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
      if (failure) std::fputc('\n', stderr);
    } else {
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    printed_ = true;
  }
  void finish() {
    if (printed_ && tty_) std::fputc('\n', stderr);
    printed_ = false;
  }

 private:
  bool enabled_, tty_, printed_ = false;
  std::chrono::steady_clock::time_point last_ =
      std::chrono::steady_clock::now() - std::chrono::hours(1);
};

}  // namespace cli
}  // namespace draglab
