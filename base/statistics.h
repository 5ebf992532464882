// Summary statistics of measured values, as every report states them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace oal {

/// The q-quantile (0..1) of `values`, by nearest rank; 0 for an empty vector.
inline double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = static_cast<std::size_t>(
      std::clamp(std::ceil(q * values.size()) - 1.0, 0.0, values.size() - 1.0));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
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
