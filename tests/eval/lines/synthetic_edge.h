// Images of a straight edge with exact pixel coverage, for the edge reference's tests.
#pragma once

#include <visp3/core/vpImage.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "detector/line.h"

namespace oal::test {

// A straight edge, exact box-filtered coverage (64 x 64 samples in the pixels it crosses):
// grey `dark` where u·cosθ + v·sinθ < ρ, `bright` beyond, rounded to 8 bits, plus optional
// Gaussian noise.
inline vpImage<unsigned char> SyntheticEdge(int width, int height, const LineParams& edge,
                                            double dark, double bright, double noise_sigma,
                                            unsigned seed) {
  constexpr int kSub = 64;
  const double c = std::cos(edge.theta_rad), s = std::sin(edge.theta_rad);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma > 0.0 ? noise_sigma : 1.0);
  vpImage<unsigned char> image(static_cast<unsigned>(height), static_cast<unsigned>(width));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double d = edge.SignedDistance(u, v);
      double coverage = d > 0.0 ? 1.0 : 0.0;
      if (std::fabs(d) < 0.75) {  // the pixel square may straddle the edge
        int inside = 0;
        for (int i = 0; i < kSub; ++i) {
          for (int j = 0; j < kSub; ++j) {
            const double uu = u - 0.5 + (i + 0.5) / kSub, vv = v - 0.5 + (j + 0.5) / kSub;
            inside += uu * c + vv * s > edge.rho_px ? 1 : 0;
          }
        }
        coverage = static_cast<double>(inside) / (kSub * kSub);
      }
      double grey = dark + (bright - dark) * coverage;
      if (noise_sigma > 0.0) grey += noise(rng);
      image[v][u] = static_cast<unsigned char>(std::lround(std::clamp(grey, 0.0, 255.0)));
    }
  }
  return image;
}

}  // namespace oal::test
