// Small synthetic images for detector unit tests: straight anti-aliased stripes on a flat
// background, with known parameters.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "detector/image_view.h"
#include "detector/line.h"

namespace oal::testing {

/// An owned grey image with a view of it.
struct TestImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;

  TestImage(int w, int h, std::uint8_t grey)
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * h, grey) {}
  GrayImageView View() const { return GrayImageView{pixels.data(), width, height, width}; }
  std::uint8_t& At(int u, int v) { return pixels[static_cast<std::size_t>(v) * width + u]; }
};

/// Paints the stripe of `width_px` centred on `line` with grey level `grey`, anti-aliased by
/// 8 x 8 supersampling.
inline void PaintStripe(TestImage* image, const LineParams& line, double width_px,
                        std::uint8_t grey) {
  constexpr int kSub = 8;
  for (int v = 0; v < image->height; ++v) {
    for (int u = 0; u < image->width; ++u) {
      if (std::fabs(line.SignedDistance(u, v)) > width_px / 2.0 + 1.0) continue;
      int inside = 0;
      for (int i = 0; i < kSub; ++i) {
        for (int j = 0; j < kSub; ++j) {
          const double su = u - 0.5 + (j + 0.5) / kSub, sv = v - 0.5 + (i + 0.5) / kSub;
          inside += std::fabs(line.SignedDistance(su, sv)) <= width_px / 2.0;
        }
      }
      const double coverage = static_cast<double>(inside) / (kSub * kSub);
      std::uint8_t& pixel = image->At(u, v);
      pixel = static_cast<std::uint8_t>(std::lround(pixel * (1.0 - coverage) + grey * coverage));
    }
  }
}

/// Adds Gaussian noise of `sigma` grey levels with a fixed seed.
inline void AddNoise(TestImage* image, double sigma, unsigned seed) {
  std::mt19937 generator(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (std::uint8_t& pixel : image->pixels) {
    pixel = static_cast<std::uint8_t>(std::clamp(std::lround(pixel + noise(generator)), 0L, 255L));
  }
}

}  // namespace oal::testing
