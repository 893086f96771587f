// averaging.h: time averages of an unsteady drag signal and their standard errors.
//
// A run whose flow stays unsteady at its target Re (vortex shedding in the pores above Re of
// order 100) has no steady drag: F is the time mean of the samples taken at the checks, after
// the start-up is discarded, with a standard error that accounts for their correlation.
//  - Start-up: MSER (White 1997; the marginal standard error rule): the truncation point k
//    minimises sum_{i >= k} (x_i - mean_k)^2 / (n - k)^2 over k <= n/2.
//  - Standard error: Flyvbjerg & Petersen (1989) blocking. The series is averaged in pairs again
//    and again; the naive standard error of each level grows while the blocks are shorter than
//    the correlation time and levels off once they are longer. The estimate is the largest over
//    the levels that keep at least kMinBlocks blocks (conservative: it never reports the
//    small, correlated levels' value).
//  - Unsteadiness: a window of samples whose fluctuation (standard deviation) exceeds the
//    tolerance while its two halves have nearly the same mean (no trend) and nearly the same
//    fluctuation (no decay): the flow is stationary but not steady, and waiting for it to settle
//    would never end. A transient that settles, even slowly or oscillating, decays.
//  - Re control of a settled flow (finite_re_correction): the force is corrected towards the
//    target until Re first reaches its band, then held unless the Re of the velocity filtered
//    over a characteristic time leaves the band, with a few corrections inside it: a flow that
//    fluctuates slowly would otherwise have its force corrected at every swing of Re, and every
//    correction restarts the window on which its unsteadiness is judged.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace draglab {
namespace lbm {

/// Fewest blocks a blocking level may have to count.
constexpr std::size_t kMinBlocks = 16;
/// A fluctuation whose second half keeps more than this fraction of the first half's standard
/// deviation is not decaying.
constexpr double kUndampedFraction = 0.5;

/// MSER truncation index of x (0 for fewer than 4 samples).
std::size_t mser_truncation(const std::vector<double>& x);

/// Blocking standard error of the mean of x[first, end); 0 for fewer than 2 samples.
double blocking_standard_error(const std::vector<double>& x, std::size_t first = 0);

struct TimeAverage {
  double mean = 0.0;
  double standard_error = 0.0;
  std::size_t truncated = 0;  ///< Leading samples discarded (start-up).
  std::size_t used = 0;       ///< Samples averaged.
};
/// The mean of x after the MSER truncation, with its blocking standard error.
TimeAverage time_average(const std::vector<double>& x);
/// The same with a given truncation (for a second series sampled with the first).
TimeAverage time_average(const std::vector<double>& x, std::size_t truncated);

/// True if the last `window` (>= 8) samples of x fluctuate by more than `tolerance` (relative
/// standard deviation) with no trend (the means of the window's halves differ by less than half
/// the standard deviation) and no decay (the second half's standard deviation above
/// kUndampedFraction of the first's).
bool stationary_fluctuating(const std::vector<double>& x, std::size_t window, double tolerance);

/// Steps an averaging run still needs, estimated for its progress report: the more of the
/// averaging time left (in steps) and the samples its relative standard error asks for to reach
/// `tolerance` (the error falls as one over the square root of the samples), with at least the
/// 2 kMinBlocks samples the blocking estimate needs; `used` samples so far, one per
/// `steps_per_sample`. Infinite when the error is not known yet.
double averaging_steps_left(double time_left_steps, double used, double relative_standard_error,
                            double tolerance, double steps_per_sample);

/// The fraction a run reports as its progress: the largest of its estimates since its phase (the
/// start-up, or the average, restarted with it) began. The estimates move back and forth with the
/// MSER start-up and the standard error, and a line that followed them promised two ETAs.
class PhaseProgress {
 public:
  /// The fraction to report for this estimate (clamped to [0, 1]).
  double Show(double estimate) {
    shown_ = std::max(shown_, std::min(std::max(estimate, 0.0), 1.0));
    return shown_;
  }
  /// A new phase: its estimates start afresh (and may be lower).
  void Restart() { shown_ = 0.0; }

 private:
  double shown_ = 0.0;
};

/// Corrections of the force inside Re's band (towards its middle third) once Re has reached
/// it: a steady flow needs one or two.
constexpr int kMaxFineCorrections = 3;

/// The Re control's memory across checks (kept in checkpoints).
struct ReControlState {
  bool reached = false;      ///< Re has been in its band at a settled check.
  int fine_corrections = 0;  ///< Corrections made with Re already in its band.
};

/// At a check where the flow has settled enough for a correction: the Re on which to correct
/// the force towards target_re, or 0 to hold it. re_now is the instantaneous Re, re_filtered
/// that of the mean velocity over the last characteristic time; the band is re_tolerance
/// (relative), its middle third the aim. Updates *state.
double finite_re_correction(double re_now, double re_filtered, double target_re,
                            double re_tolerance, ReControlState* state);

}  // namespace lbm
}  // namespace draglab
