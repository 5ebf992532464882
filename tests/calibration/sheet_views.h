// Views of the printed four-line sheet without rendering, for the calibration tests: points
// along each stripe's centre line through a known lens (ViSP's kdu model, exactly).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMath.h>

#include <cmath>
#include <random>
#include <vector>

#include "detector/lens.h"
#include "detector/line.h"
#include "target/line_target.h"

namespace oal::test {

// The camera `distance_m` from the sheet's centre, tilted about the sheet's x and y axes and
// rolled about its optical axis.
inline vpHomogeneousMatrix LookingAtTheSheet(double distance_m, double tilt_x_deg,
                                             double tilt_y_deg, double roll_deg) {
  return vpHomogeneousMatrix(0, 0, distance_m, 0, 0, 0) *
         vpHomogeneousMatrix(0, 0, 0, 0, 0, vpMath::rad(roll_deg)) *
         vpHomogeneousMatrix(0, 0, 0, vpMath::rad(tilt_x_deg), 0, 0) *
         vpHomogeneousMatrix(0, 0, 0, 0, vpMath::rad(tilt_y_deg), 0);
}

inline std::vector<vpHomogeneousMatrix> VariedSheetPoses() {
  std::vector<vpHomogeneousMatrix> poses;
  for (int k = 0; k < 12; ++k) {
    const double tilt = 20.0 + 2.0 * (k % 6);
    poses.push_back(LookingAtTheSheet(0.40 + 0.02 * (k % 5), tilt * std::cos(0.9 * k),
                                      tilt * std::sin(0.9 * k), 30.0 * k));
  }
  return poses;
}

// Points every 6 mm along each stripe's centre line, through `camera` from `cMo`, with pixel
// noise of `sigma_px`; those outside the image are not seen.
inline std::vector<std::vector<Point2d>> SeenAlongStripes(const LineTarget& target,
                                                          const Lens& camera,
                                                          const vpHomogeneousMatrix& cMo,
                                                          double sigma_px, std::mt19937* random) {
  std::normal_distribution<double> noise(0.0, sigma_px);
  std::vector<std::vector<Point2d>> seen(target.lines.size());
  for (std::size_t k = 0; k < target.lines.size(); ++k) {
    const TargetLine& stripe = target.lines[k];
    const double length = std::hypot(stripe.x2_m - stripe.x1_m, stripe.y2_m - stripe.y1_m);
    for (double s = 0.0; s <= length; s += 0.006) {
      const double t = s / length;
      const vpColVector o{stripe.x1_m + t * (stripe.x2_m - stripe.x1_m),
                          stripe.y1_m + t * (stripe.y2_m - stripe.y1_m), 0.0, 1.0};
      const vpColVector c = cMo * o;
      // Through ViSP's kdu model exactly, as the renderer draws and the detector undistorts.
      const Point2d pixel = camera.Pixel(c[0] / c[2], c[1] / c[2]);
      const double u = pixel.u + noise(*random), v = pixel.v + noise(*random);
      if (u >= 0.0 && u < 640.0 && v >= 0.0 && v < 480.0) seen[k].push_back(Point2d{u, v});
    }
  }
  return seen;
}

}  // namespace oal::test
