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
  if (window < 4 || x.size() < window) return false;
  const std::size_t first = x.size() - window, half = window / 2;
  double sum_a = 0.0, sum_b = 0.0;
  for (std::size_t i = first; i < first + half; ++i) sum_a += x[i];
  for (std::size_t i = first + half; i < x.size(); ++i) sum_b += x[i];
  const double mean_a = sum_a / static_cast<double>(half);
  const double mean_b = sum_b / static_cast<double>(window - half);
  const double mean = (sum_a + sum_b) / static_cast<double>(window);
  double ss = 0.0;
  for (std::size_t i = first; i < x.size(); ++i) ss += (x[i] - mean) * (x[i] - mean);
  const double sd = std::sqrt(ss / static_cast<double>(window - 1));
  return sd > tolerance * std::abs(mean) && std::abs(mean_b - mean_a) < 0.5 * sd;
}

}  // namespace lbm
}  // namespace draglab
