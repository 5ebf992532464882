#include "base/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace oal {
namespace {

// Values with runs of equal ones (residuals of points on one pixel, a clamped scale), drawn by
// a fixed linear congruential generator.
std::vector<double> ValuesWithTies(std::size_t n, std::uint64_t seed) {
  std::vector<double> values(n);
  std::uint64_t state = seed;
  for (double& value : values) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    value = static_cast<double>((state >> 33) % 97) * 0.25;
  }
  return values;
}

TEST(NthSmallest, FindsWhatSortingFindsForEveryRankWithTiesAndOrders) {
  for (std::size_t n : {1u, 2u, 3u, 24u, 25u, 26u, 100u, 401u}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      std::vector<double> values = ValuesWithTies(n, seed);
      std::vector<double> sorted = values;
      std::sort(sorted.begin(), sorted.end());
      for (std::size_t k = 0; k < n; ++k) {
        std::vector<double> scratch = values;
        EXPECT_EQ(NthSmallest(scratch.data(), n, k), sorted[k]) << "n " << n << " k " << k;
        // A permutation of the input.
        std::sort(scratch.begin(), scratch.end());
        EXPECT_EQ(scratch, sorted);
      }
      // Already sorted, reversed and all equal: the pivot's worst cases.
      std::vector<double> ascending = sorted, descending(sorted.rbegin(), sorted.rend());
      std::vector<double> equal(n, 1.5);
      EXPECT_EQ(NthSmallest(ascending.data(), n, n / 2), sorted[n / 2]);
      EXPECT_EQ(NthSmallest(descending.data(), n, n / 2), sorted[n / 2]);
      EXPECT_EQ(NthSmallest(equal.data(), n, n / 2), 1.5);
    }
  }
}

// NaNs among the values (a point a lens could not undistort) count as the largest, NaN pivots
// included.
TEST(NthSmallest, EndsWithNaNs) {
  std::vector<double> values = ValuesWithTies(100, 5);
  for (std::size_t i = 0; i < values.size(); i += 7) values[i] = std::nan("");
  values.front() = values[50] = values.back() = std::nan("");  // NaN pivots
  std::vector<double> finite;
  for (const double value : values) {
    if (!std::isnan(value)) finite.push_back(value);
  }
  std::sort(finite.begin(), finite.end());
  for (std::size_t k = 0; k < values.size(); ++k) {
    std::vector<double> scratch = values;
    const double found = NthSmallest(scratch.data(), scratch.size(), k);
    if (k < finite.size()) {
      EXPECT_EQ(found, finite[k]) << k;
    } else {
      EXPECT_TRUE(std::isnan(found)) << k;
    }
  }
  std::vector<double> one_nan = ValuesWithTies(60, 6), sorted = one_nan;
  std::sort(sorted.begin(), sorted.end());
  one_nan.push_back(std::nan(""));
  EXPECT_EQ(NthSmallest(one_nan.data(), one_nan.size(), 10), sorted[10]);
}

TEST(NthSmallest, OfIntegers) {
  std::vector<int> values{7, 3, 9, 3, 1, 8, 3, 6};
  std::vector<int> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k < values.size(); ++k) {
    std::vector<int> scratch = values;
    EXPECT_EQ(NthSmallest(scratch.data(), scratch.size(), k), sorted[k]) << k;
  }
}

TEST(MedianInPlace, IsTheUpperMiddleValueAndZeroForNone) {
  std::vector<double> none;
  EXPECT_EQ(MedianInPlace(&none), 0.0);
  std::vector<double> odd{5.0, 1.0, 3.0};
  EXPECT_EQ(MedianInPlace(&odd), 3.0);
  std::vector<double> even{4.0, 1.0, 3.0, 2.0};
  EXPECT_EQ(MedianInPlace(&even), 3.0);
}

TEST(Quantile, ByNearestRank) {
  const std::vector<double> values{10.0, 40.0, 20.0, 30.0, 50.0};
  EXPECT_EQ(Quantile(values, 0.0), 10.0);
  EXPECT_EQ(Quantile(values, 0.5), 30.0);
  EXPECT_EQ(Quantile(values, 0.95), 50.0);
  EXPECT_EQ(Quantile({}, 0.5), 0.0);
}

}  // namespace
}  // namespace oal
