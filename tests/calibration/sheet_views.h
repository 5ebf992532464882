// Views of the printed four-line sheet without rendering, for the calibration tests: points
// along each stripe's centre line through a known lens (ViSP's kdu model, exactly).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMath.h>

#include <algorithm>
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
// noise of `sigma_px`; those outside the width x height image are not seen.
inline std::vector<std::vector<Point2d>> SeenAlongStripes(const LineTarget& target,
                                                          const Lens& camera,
                                                          const vpHomogeneousMatrix& cMo,
                                                          double sigma_px, std::mt19937* random,
                                                          int width = 640, int height = 480) {
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
      if (u >= 0.0 && u < width && v >= 0.0 && v < height) seen[k].push_back(Point2d{u, v});
    }
  }
  return seen;
}

// The runs a scan of the image would see across each stripe, through `camera` from `cMo`:
// every 6 mm along the stripe's centre line, the image row (or column, for a stripe running
// nearer horizontal in the image) through the centre line's image is followed to where it
// meets the images of the stripe's two edges. Returns each run's middle (the stripe's seen
// points, as the detector gives them) and fills `runs` with the runs themselves (end minus
// start). `past_end_m` > 0 also crosses each stripe that far beyond its printed ends, where
// a row meets one edge and the end instead (a run through the stripe's end).
inline std::vector<std::vector<Point2d>> RunsAcrossStripes(const LineTarget& target,
                                                           const Lens& camera,
                                                           const vpHomogeneousMatrix& cMo,
                                                           std::vector<std::vector<Point2d>>* runs,
                                                           double past_end_m = 0.0) {
  const vpHomogeneousMatrix oMc = cMo.inverse();
  std::vector<std::vector<Point2d>> middles(target.lines.size());
  runs->assign(target.lines.size(), {});
  const auto pixel_of = [&](double x, double y) {
    const vpColVector c = cMo * vpColVector{x, y, 0.0, 1.0};
    return camera.Pixel(c[0] / c[2], c[1] / c[2]);
  };
  const auto plane_of = [&](const Point2d& pixel) {
    const Point2d x = camera.Normalised(pixel.u, pixel.v);
    const vpColVector o = oMc * vpColVector{0.0, 0.0, 0.0, 1.0};
    const vpColVector d = oMc * vpColVector{x.u, x.v, 1.0, 1.0};
    const double s = -o[2] / (d[2] - o[2]);
    return Point2d{o[0] + s * (d[0] - o[0]), o[1] + s * (d[1] - o[1])};
  };
  for (std::size_t k = 0; k < target.lines.size(); ++k) {
    const TargetLine& stripe = target.lines[k];
    const double length = std::hypot(stripe.x2_m - stripe.x1_m, stripe.y2_m - stripe.y1_m);
    const double ux = (stripe.x2_m - stripe.x1_m) / length,
                 uy = (stripe.y2_m - stripe.y1_m) / length;
    const double half = 0.5 * stripe.width_m;
    // Where a plane point lies across the stripe (metres from the centre line, signed) and
    // how far past the nearer printed end (metres, negative within them).
    const auto across = [&](const Point2d& q) {
      return (q.u - stripe.x1_m) * uy - (q.v - stripe.y1_m) * ux;
    };
    const auto past_end = [&](const Point2d& q) {
      const double t = (q.u - stripe.x1_m) * ux + (q.v - stripe.y1_m) * uy;
      return std::max(-t, t - length);
    };
    for (double s = -past_end_m; s <= length + past_end_m; s += 0.006) {
      const Point2d p = pixel_of(stripe.x1_m + s * ux, stripe.y1_m + s * uy);
      const Point2d a = pixel_of(stripe.x1_m, stripe.y1_m), b = pixel_of(stripe.x2_m, stripe.y2_m);
      // A row across a stripe that runs nearer vertical in the image, else a column.
      const bool row = std::fabs(b.v - a.v) > std::fabs(b.u - a.u);
      const Point2d step = row ? Point2d{1.0, 0.0} : Point2d{0.0, 1.0};
      // The run's ends: where the scan leaves the stripe's ink, an edge or an end, found by
      // bisection on the scan from its middle outwards.
      const auto inside = [&](double t) {
        const Point2d q = plane_of(Point2d{p.u + t * step.u, p.v + t * step.v});
        return std::fabs(across(q)) <= half && past_end(q) <= 0.0;
      };
      if (!inside(0.0)) continue;
      double ends[2];
      for (int side = 0; side < 2; ++side) {
        const double sign = side == 0 ? -1.0 : 1.0;
        double in = 0.0, out = sign;
        while (inside(out)) out *= 2.0;
        for (int i = 0; i < 60; ++i) {
          const double mid = 0.5 * (in + out);
          (inside(mid) ? in : out) = mid;
        }
        ends[side] = 0.5 * (in + out);
      }
      const Point2d middle{p.u + 0.5 * (ends[0] + ends[1]) * step.u,
                           p.v + 0.5 * (ends[0] + ends[1]) * step.v};
      if (middle.u < 0.0 || middle.u >= 640.0 || middle.v < 0.0 || middle.v >= 480.0) continue;
      middles[k].push_back(middle);
      (*runs)[k].push_back(Point2d{(ends[1] - ends[0]) * step.u, (ends[1] - ends[0]) * step.v});
    }
  }
  return middles;
}

}  // namespace oal::test
