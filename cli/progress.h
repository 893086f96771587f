// A time-throttled progress line on stderr for long runs (stage, percent, elapsed, ETA).
// On a terminal it redraws one line; otherwise it prints a line at most every 10 s.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <string>

namespace draglab {
namespace cli {

/// Remaining time of a job from its reported fraction done. Callers report either the fraction
/// of the whole job (the stage text may change freely, e.g. "settle: KE = ...") or a fraction per
/// stage that restarts from 0, so a pass begins at the first report and whenever the fraction
/// drops. The rate is the slower of the pass's average and its recent rate (over the last fifth
/// of the pass, at least 5 s): a job that slows down (a bed model whose later seconds cost more)
/// is not promised the early rate, and trend() says when the two differ by more than 2x.
class EtaEstimate {
 public:
  enum class Trend { kSteady, kSlowing, kSpeedingUp, kStalled };

  /// fraction in [0, 1] at `elapsed_s` since the job started; returns the ETA in seconds, or -1
  /// while less than 0.5 % of the pass is done (too little to extrapolate), when nothing moved
  /// recently (trend kStalled) or when finished.
  double Observe(double fraction, double elapsed_s) {
    if (!started_ || fraction < last_fraction_) {
      started_ = true;
      pass_start_s_ = elapsed_s;
      pass_start_fraction_ = fraction;
      samples_.clear();
    }
    last_fraction_ = fraction;
    if (samples_.empty() || elapsed_s - samples_.back().t >= kSampleSpacingS) {
      samples_.push_back({elapsed_s, fraction});
    }
    trend_ = Trend::kSteady;
    const double done = fraction - pass_start_fraction_;
    if (done <= 0.005 || fraction >= 1.0) return -1.0;
    const double pass_s = elapsed_s - pass_start_s_;
    const double average_rate = done / pass_s;
    const double window = std::max(kMinRecentS, kRecentShare * pass_s);
    while (samples_.size() > 1 && samples_[1].t <= elapsed_s - window) samples_.pop_front();
    const Sample& then = samples_.front();
    double rate = average_rate;
    if (elapsed_s > then.t) {
      const double recent_rate = (fraction - then.f) / (elapsed_s - then.t);
      if (recent_rate <= 0.0) {
        trend_ = Trend::kStalled;
        return -1.0;
      }
      if (recent_rate < 0.5 * average_rate) trend_ = Trend::kSlowing;
      if (recent_rate > 2.0 * average_rate) trend_ = Trend::kSpeedingUp;
      rate = std::min(rate, recent_rate);
    }
    return (1.0 - fraction) / rate;
  }
  /// How the recent rate compares with the average at the last Observe.
  Trend trend() const { return trend_; }

 private:
  struct Sample {
    double t, f;
  };
  static constexpr double kRecentShare = 0.2;      ///< Of the pass's elapsed time.
  static constexpr double kMinRecentS = 5.0;       ///< Shortest recent window.
  static constexpr double kSampleSpacingS = 0.05;  ///< Samples kept at most this often.
  bool started_ = false;
  double pass_start_s_ = 0.0, pass_start_fraction_ = 0.0, last_fraction_ = 0.0;
  std::deque<Sample> samples_;
  Trend trend_ = Trend::kSteady;
};

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled)
      : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0), start_(Clock::now()), last_(start_) {}
  ~ProgressLine() { finish(); }

  /// fraction in [0, 1] of `stage`.
  void update(double fraction, const std::string& stage) {
    if (!enabled_) return;
    const auto now = Clock::now();
    const double eta_s = eta_.Observe(fraction, seconds(start_, now));
    const double since_last = seconds(last_, now);
    if (since_last < (tty_ ? 0.2 : 10.0) && fraction < 1.0) return;
    last_ = now;
    std::string eta = eta_s >= 0.0 ? format_seconds(eta_s) : "?";
    switch (eta_.trend()) {
      case EtaEstimate::Trend::kSlowing:
        eta += " (slowing down: at the recent rate)";
        break;
      case EtaEstimate::Trend::kSpeedingUp:
        eta += " (speeding up)";
        break;
      case EtaEstimate::Trend::kStalled:
        eta += " (no progress lately)";
        break;
      case EtaEstimate::Trend::kSteady:
        break;
    }
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
  Clock::time_point start_, last_;
  EtaEstimate eta_;
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
