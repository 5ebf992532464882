// Summary statistics of measured values, as every report states them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
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

}  // namespace oal
