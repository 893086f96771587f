// averaging.cc: see averaging.h.
#include "averaging.h"

#include <algorithm>
#include <cmath>

namespace draglab {
namespace lbm {

std::size_t mser_truncation(const std::vector<double>& x) {
  const std::size_t n = x.size();
  if (n < 4) return 0;
  // Suffix sums give each candidate's statistic in O(1).
  std::vector<double> sum(n + 1, 0.0), sum2(n + 1, 0.0);
  for (std::size_t i = n; i-- > 0;) {
    sum[i] = sum[i + 1] + x[i];
    sum2[i] = sum2[i + 1] + x[i] * x[i];
  }
  std::size_t best = 0;
  double best_value = HUGE_VAL;
  for (std::size_t k = 0; k <= n / 2; ++k) {
    const double m = static_cast<double>(n - k);
    const double mean = sum[k] / m;
    const double ss = std::max(0.0, sum2[k] - m * mean * mean);
    const double value = ss / (m * m);
    if (value < best_value) {
      best_value = value;
      best = k;
    }
  }
  return best;
}

double blocking_standard_error(const std::vector<double>& x, std::size_t first) {
  if (x.size() < first + 2) return 0.0;
  std::vector<double> level(x.begin() + static_cast<std::ptrdiff_t>(first), x.end());
  double largest = 0.0;
  bool first_level = true;
  while (level.size() >= 2 && (first_level || level.size() >= kMinBlocks)) {
    const double n = static_cast<double>(level.size());
    double mean = 0.0;
    for (double v : level) mean += v;
    mean /= n;
    double ss = 0.0;
    for (double v : level) ss += (v - mean) * (v - mean);
    largest = std::max(largest, std::sqrt(ss / (n - 1.0) / n));
    first_level = false;
    std::vector<double> next(level.size() / 2);
    for (std::size_t i = 0; i < next.size(); ++i) next[i] = 0.5 * (level[2 * i] + level[2 * i + 1]);
    level.swap(next);
  }
  return largest;
}

TimeAverage time_average(const std::vector<double>& x, std::size_t truncated) {
  TimeAverage a;
  a.truncated = std::min(truncated, x.size());
  a.used = x.size() - a.truncated;
  if (a.used == 0) return a;
  double sum = 0.0;
  for (std::size_t i = a.truncated; i < x.size(); ++i) sum += x[i];
  a.mean = sum / static_cast<double>(a.used);
  a.standard_error = blocking_standard_error(x, a.truncated);
  return a;
}

TimeAverage time_average(const std::vector<double>& x) {
  return time_average(x, mser_truncation(x));
}

bool stationary_fluctuating(const std::vector<double>& x, std::size_t window, double tolerance) {
  if (window < 8 || x.size() < window) return false;
  const std::size_t first = x.size() - window, half = window / 2;
  auto mean_sd = [&x](std::size_t begin, std::size_t end, double* mean, double* sd) {
    const double n = static_cast<double>(end - begin);
    double sum = 0.0;
    for (std::size_t i = begin; i < end; ++i) sum += x[i];
    *mean = sum / n;
    double ss = 0.0;
    for (std::size_t i = begin; i < end; ++i) ss += (x[i] - *mean) * (x[i] - *mean);
    *sd = std::sqrt(ss / (n - 1.0));
  };
  double mean = 0.0, sd = 0.0, mean_a = 0.0, sd_a = 0.0, mean_b = 0.0, sd_b = 0.0;
  mean_sd(first, x.size(), &mean, &sd);
  mean_sd(first, first + half, &mean_a, &sd_a);
  mean_sd(first + half, x.size(), &mean_b, &sd_b);
  // Large enough to matter, no drift of the mean, and no decay of the fluctuation: a transient
  // that still settles (however slowly, or with a damped oscillation) fails the last two.
  return sd > tolerance * std::abs(mean) && std::abs(mean_b - mean_a) < 0.5 * sd &&
         sd_b > kUndampedFraction * sd_a;
}

double averaging_steps_left(double time_left_steps, double used, double relative_standard_error,
                            double tolerance, double steps_per_sample) {
  double samples_left = std::max(0.0, 2.0 * static_cast<double>(kMinBlocks) - used);
  if (used >= 2.0 && relative_standard_error > tolerance) {
    if (!std::isfinite(relative_standard_error) || !(tolerance > 0.0)) return HUGE_VAL;
    const double ratio = relative_standard_error / tolerance;
    samples_left = std::max(samples_left, used * (ratio * ratio - 1.0));
  }
  return std::max(time_left_steps, samples_left * steps_per_sample);
}

double finite_re_correction(double re_now, double re_filtered, double target_re,
                            double re_tolerance, ReControlState* state) {
  const auto deviation = [target_re](double re) { return std::abs(re / target_re - 1.0); };
  if (state->reached && deviation(re_filtered) > re_tolerance) return re_filtered;
  if (deviation(re_now) <= re_tolerance / 3.0) {
    state->reached = true;
    return 0.0;
  }
  if (deviation(re_now) <= re_tolerance) {
    state->reached = true;
    if (state->fine_corrections >= kMaxFineCorrections) return 0.0;
    ++state->fine_corrections;
    return re_now;
  }
  // Outside the band on the instantaneous Re only: the start-up's approach, or a swing.
  return state->reached ? 0.0 : re_now;
}

}  // namespace lbm
}  // namespace draglab
