// A stripe's runs read at every column or row between the tracker's (calibration/dense_runs.h):
// on a drawn stripe they lie on its centre line and are as long as it is wide, and nothing is
// read where a hand or a pen lies over it.
#include "calibration/dense_runs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace oal {
namespace {

constexpr double kPaper = 200.0, kInk = 40.0;

// A grey image of the paper with a dark stripe of `width` px whose centre line passes through
// (u0, v0) in direction (du, dv) (unit), each pixel the stripe's cover of it (8 x 8 samples)
// blurred as a lens does (a Gaussian of 0.8 px).
struct DrawnStripe {
  int width_px = 320, height_px = 240;
  double u0 = 160.0, v0 = 120.0, du = 1.0, dv = 0.0, width = 8.0;
  std::vector<std::uint8_t> pixels;

  // The stripe drawn at `angle` (radians from the image's rows).
  static DrawnStripe At(double angle) {
    DrawnStripe stripe;
    stripe.du = std::cos(angle);
    stripe.dv = std::sin(angle);
    stripe.Draw();
    return stripe;
  }
  double Across(double u, double v) const { return (u - u0) * dv - (v - v0) * du; }
  GrayImageView View() const {
    return GrayImageView{pixels.data(), width_px, height_px, static_cast<std::ptrdiff_t>(width_px)};
  }
  void Draw() {
    pixels.assign(static_cast<std::size_t>(width_px * height_px), 0);
    std::vector<double> grey(pixels.size());
    for (int v = 0; v < height_px; ++v) {
      for (int u = 0; u < width_px; ++u) {
        int inside = 0;
        for (int i = 0; i < 8; ++i) {
          for (int j = 0; j < 8; ++j) {
            const double su = u - 0.5 + (i + 0.5) / 8.0, sv = v - 0.5 + (j + 0.5) / 8.0;
            inside += std::fabs(Across(su, sv)) <= 0.5 * width ? 1 : 0;
          }
        }
        const double cover = inside / 64.0;
        grey[static_cast<std::size_t>(v * width_px + u)] = kPaper + cover * (kInk - kPaper);
      }
    }
    grey = Blurred(Blurred(grey, 1, width_px), width_px, height_px);
    for (std::size_t i = 0; i < grey.size(); ++i) {
      pixels[i] = static_cast<std::uint8_t>(std::lround(grey[i]));
    }
  }
  // `grey` blurred along one axis: `step` 1 along the rows, the image's width along columns,
  // `count` pixels along that axis.
  std::vector<double> Blurred(const std::vector<double>& grey, int step, int count) const {
    constexpr int kRadius = 3;
    double kernel[2 * kRadius + 1], sum = 0.0;
    for (int k = -kRadius; k <= kRadius; ++k) {
      kernel[k + kRadius] = std::exp(-0.5 * k * k / (0.8 * 0.8));
      sum += kernel[k + kRadius];
    }
    std::vector<double> out(grey.size());
    for (std::size_t i = 0; i < grey.size(); ++i) {
      const int along = step == 1 ? static_cast<int>(i) % width_px : static_cast<int>(i) / width_px;
      double value = 0.0;
      for (int k = -kRadius; k <= kRadius; ++k) {
        const int at = std::min(std::max(along + k, 0), count - 1);
        value += kernel[k + kRadius] * grey[i + static_cast<std::ptrdiff_t>(at - along) * step];
      }
      out[i] = value / sum;
    }
    return out;
  }
  // Paints a rectangle of pixels `grey`.
  void Paint(int u_first, int u_last, int v_first, int v_last, std::uint8_t grey) {
    for (int v = v_first; v <= v_last; ++v) {
      for (int u = u_first; u <= u_last; ++u) {
        pixels[static_cast<std::size_t>(v * width_px + u)] = grey;
      }
    }
  }
  // The runs a tracker would give: one every `step` px along the stripe, across it.
  StripeRuns Found(double step, double from, double to) const {
    StripeRuns found;
    for (double s = from; s <= to; s += step) {
      found.middles.push_back(Point2d{u0 + s * du, v0 + s * dv});
      found.runs.push_back(Point2d{width * dv, -width * du});
    }
    return found;
  }
};

TEST(DenseStripeRuns, ReadsEveryColumnOnTheCentreLineAsWideAsTheStripe) {
  const DrawnStripe stripe = DrawnStripe::At(0.35);  // 20 deg: read down the columns
  const StripeRuns found = stripe.Found(20.0, -120.0, 120.0);
  const StripeRuns dense = DenseStripeRuns(stripe.View(), found);
  // From the first found run's column to the last's: 2 * 120 * cos(20 deg) = 225 columns.
  ASSERT_GE(dense.middles.size(), 215u);
  ASSERT_EQ(dense.runs.size(), dense.middles.size());
  const double length = stripe.width / stripe.du;
  double offset_sum = 0.0;
  for (std::size_t i = 0; i < dense.middles.size(); ++i) {
    const Point2d& m = dense.middles[i];
    EXPECT_NEAR(stripe.Across(m.u, m.v), 0.0, 0.05) << "column " << m.u;
    EXPECT_EQ(dense.runs[i].u, 0.0);
    EXPECT_NEAR(dense.runs[i].v, length, 0.15) << "column " << m.u;
    offset_sum += stripe.Across(m.u, m.v);
  }
  // What the calibration averages: no bias to either side.
  EXPECT_NEAR(offset_sum / dense.middles.size(), 0.0, 0.005);
}

TEST(DenseStripeRuns, ReadsEveryRowOfAStripeNearerTheColumns) {
  const DrawnStripe stripe = DrawnStripe::At(1.9);  // 109 deg: read along the rows
  const StripeRuns dense = DenseStripeRuns(stripe.View(), stripe.Found(16.0, -96.0, 96.0));
  ASSERT_GE(dense.middles.size(), 175u);
  for (std::size_t i = 0; i < dense.middles.size(); ++i) {
    EXPECT_NEAR(stripe.Across(dense.middles[i].u, dense.middles[i].v), 0.0, 0.05);
    EXPECT_EQ(dense.runs[i].v, 0.0);
  }
}

TEST(DenseStripeRuns, ReadsNothingUnderAHandOrAPen) {
  DrawnStripe stripe = DrawnStripe::At(0.2);
  stripe.Paint(100, 130, 60, 180, 70);    // a hand: dark over the stripe and the paper
  stripe.Paint(200, 202, 20, 220, 60);    // a pen across the stripe
  stripe.Paint(240, 250, 100, 200, 250);  // a glare spot over the stripe
  const StripeRuns dense = DenseStripeRuns(stripe.View(), stripe.Found(20.0, -140.0, 140.0));
  ASSERT_GE(dense.middles.size(), 180u);
  for (const Point2d& m : dense.middles) {
    EXPECT_NEAR(stripe.Across(m.u, m.v), 0.0, 0.05) << "column " << m.u;
    EXPECT_FALSE(m.u >= 100.0 && m.u <= 130.0) << "read under the hand, column " << m.u;
    EXPECT_FALSE(m.u >= 200.0 && m.u <= 202.0) << "read on the pen, column " << m.u;
    EXPECT_FALSE(m.u >= 240.0 && m.u <= 250.0) << "read in the glare, column " << m.u;
  }
}

TEST(DenseStripeRuns, KeepsTooFewRunsAsTheyAre) {
  const DrawnStripe stripe = DrawnStripe::At(0.0);
  const StripeRuns found = stripe.Found(20.0, -10.0, 10.0);  // two runs
  const StripeRuns dense = DenseStripeRuns(stripe.View(), found);
  ASSERT_EQ(dense.middles.size(), 2u);
  EXPECT_EQ(dense.middles[0].u, found.middles[0].u);
}

}  // namespace
}  // namespace oal
