// Summary statistics of measured values, as every report states them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <type_traits>
#include <vector>

namespace oal {

namespace statistics_internal {
template <typename T>
bool IsNaN(T value) {
  if constexpr (std::is_floating_point_v<T>) return std::isnan(value);
  return false;
}
}  // namespace statistics_internal

/// The k-th smallest (0-based) of values[0, n), k < n, NaNs counted as the largest; `values`
/// is reordered. The value std::nth_element finds, by a quickselect whose partitions do not branch
/// on the values: the order of residuals is random, so a branch per value mispredicts half the
/// time, and this takes a third of std::nth_element's time over a few hundred of them. T: a
/// floating-point or integer type.
template <typename T>
T NthSmallest(T* values, std::size_t n, std::size_t k) {
  std::size_t lo = 0, hi = n;
  while (hi - lo > 1) {
    const T a = values[lo], b = values[lo + (hi - lo) / 2], c = values[hi - 1];
    const T pivot = std::max(std::min(a, b), std::min(std::max(a, b), c));
    // [lo, less_end) < pivot, then [less_end, equal_end) == pivot: the pivot is one of the
    // values, so every pass narrows the range (unless it is a NaN).
    std::size_t less_end = lo;
    for (std::size_t i = lo; i < hi; ++i) {
      const T x = values[i];
      values[i] = values[less_end];
      values[less_end] = x;
      less_end += x < pivot;
    }
    if (k < less_end) {
      hi = less_end;
      continue;
    }
    std::size_t equal_end = less_end;
    for (std::size_t i = less_end; i < hi; ++i) {
      const T x = values[i];
      values[i] = values[equal_end];
      values[equal_end] = x;
      equal_end += x == pivot;
    }
    if (k < equal_end) return pivot;
    if (equal_end == lo) break;  // a NaN pivot equals nothing: sorting ends it
    lo = equal_end;
  }
  if (hi - lo == 1) return values[lo];
  // After a NaN pivot: NaNs last, as the partitions leave them (std::sort needs a strict weak
  // order).
  std::sort(values + lo, values + hi, [](T a, T b) {
    using statistics_internal::IsNaN;
    return a < b || (IsNaN(b) && !IsNaN(a));
  });
  return values[k];
}

/// The median of `values` (of an even count, the upper of the middle two), reordering them;
/// 0 for an empty vector.
template <typename T>
T MedianInPlace(std::vector<T>* values) {
  return values->empty() ? T{0} : NthSmallest(values->data(), values->size(), values->size() / 2);
}

/// The q-quantile (0..1) of `values`, by nearest rank; 0 for an empty vector.
inline double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = static_cast<std::size_t>(
      std::clamp(std::ceil(q * values.size()) - 1.0, 0.0, values.size() - 1.0));
  return NthSmallest(values.data(), values.size(), k);
}

/// The arithmetic mean; 0 for an empty vector.
inline double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0
                        : std::accumulate(values.begin(), values.end(), 0.0) /
                              static_cast<double>(values.size());
}

/// Count, mean, maximum and quantiles of a non-negative per-frame measure in bounded memory:
/// the first kExactSamples values are kept (a short input reports exact quantiles, by nearest
/// rank), beyond them a histogram of logarithmic bins 1 % wide, whose quantiles are within
/// 0.5 % of the exact ones: an hour of video costs what a minute does.
class SampleStats {
 public:
  void push_back(double value) {
    ++count_;
    sum_ += value;
    max_ = count_ == 1 ? value : std::max(max_, value);
    if (bins_.empty() && exact_.size() < kExactSamples) {
      exact_.push_back(value);
      return;
    }
    if (bins_.empty()) {
      for (const double kept : exact_) Bin(kept);
      std::vector<double>().swap(exact_);
    }
    Bin(value);
  }
  std::size_t size() const { return count_; }
  double mean() const { return sum_ / static_cast<double>(count_); }
  double max() const { return max_; }
  double Quantile(double q) const {
    if (bins_.empty()) return oal::Quantile(exact_, q);
    const double rank =
        std::clamp(std::ceil(q * static_cast<double>(count_)), 1.0, static_cast<double>(count_));
    std::size_t seen = 0;
    for (std::size_t i = 0; i < bins_.size(); ++i) {
      seen += bins_[i];
      if (static_cast<double>(seen) >= rank) {
        return i == 0 ? 0.0 : std::min(max_, kSmallest * std::pow(kBinGrowth, i - 0.5));
      }
    }
    return max_;
  }

 private:
  static constexpr std::size_t kExactSamples = 4096;
  static constexpr double kSmallest = 1e-6;  // smaller values (and zero) share bin 0
  static constexpr double kBinGrowth = 1.01;
  static constexpr std::size_t kMaxBins = 8192;  // up to 1e-6 * 1.01^8192, about 1e29

  void Bin(double value) {
    std::size_t bin = 0;
    if (value >= kSmallest) {
      bin = 1 + static_cast<std::size_t>(
                    std::min(std::log(value / kSmallest) / std::log(kBinGrowth), kMaxBins - 2.0));
    }
    if (bin >= bins_.size()) bins_.resize(bin + 1, 0);
    ++bins_[bin];
  }

  std::size_t count_ = 0;
  double sum_ = 0.0, max_ = 0.0;
  std::vector<double> exact_;
  std::vector<std::uint32_t> bins_;
};

}  // namespace oal
