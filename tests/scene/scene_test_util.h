// Helpers for the scene tests: simple poses, and a brute-force reference renderer that shares
// no code with scene.cpp (dense point sampling of each pixel, ViSP's own conversions).
#pragma once

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpPixelMeterConversion.h>

#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace oal::testing {

/// Camera looking straight at the board point (x_m, y_m) from `distance_m` in front of it,
/// rolled by `roll_rad` about its optical axis (roll 0: object x = image right, y = down).
inline vpHomogeneousMatrix FrontoParallel(double distance_m, double x_m = 0.0, double y_m = 0.0,
                                          double roll_rad = 0.0) {
  const double c = std::cos(roll_rad), s = std::sin(roll_rad);
  vpHomogeneousMatrix cMo;
  cMo[0][0] = c;
  cMo[0][1] = -s;
  cMo[1][0] = s;
  cMo[1][1] = c;
  cMo[0][3] = -(c * x_m - s * y_m);
  cMo[1][3] = -(s * x_m + c * y_m);
  cMo[2][3] = distance_m;
  return cMo;
}

/// Ideal pixel of the object point (X, Y, 0); false when it is behind the camera.
inline bool Project(const vpHomogeneousMatrix& cMo, const Lens& camera, double X, double Y,
                    Point2d* pixel) {
  vpColVector p(4);
  p[0] = X;
  p[1] = Y;
  p[2] = 0.0;
  p[3] = 1.0;
  const vpColVector c = cMo * p;
  if (c[2] <= 0.0) return false;
  *pixel = {camera.u0() + camera.px() * c[0] / c[2], camera.v0() + camera.py() * c[1] / c[2]};
  return true;
}

/// Pixel-wise equality (vpImage::operator== is not const).
inline bool SameImage(const vpImage<unsigned char>& a, const vpImage<unsigned char>& b) {
  if (a.getWidth() != b.getWidth() || a.getHeight() != b.getHeight()) return false;
  return std::equal(a.bitmap, a.bitmap + a.getSize(), b.bitmap);
}

/// Fraction of the board-to-line contrast at pixel (u, v): 0 on bare board, 1 on a stripe.
inline double Darkness(const vpImage<unsigned char>& image, const LineTarget& target, int u,
                       int v) {
  return (target.board_grey - image[v][u]) /
         static_cast<double>(target.board_grey - target.line_grey);
}

/// Grey level seen along the ray (x, y, 1) of the camera at oMc.
inline double SampleGrey(const LineTarget& target, const RenderOptions& options,
                         const vpHomogeneousMatrix& oMc, double x, double y) {
  // Ray o + t d in the object frame.
  const double d[3] = {oMc[0][0] * x + oMc[0][1] * y + oMc[0][2],
                       oMc[1][0] * x + oMc[1][1] * y + oMc[1][2],
                       oMc[2][0] * x + oMc[2][1] * y + oMc[2][2]};
  const double t = -oMc[2][3] / d[2];
  if (!(t > 0.0)) return options.background_grey;
  const double X = oMc[0][3] + t * d[0], Y = oMc[1][3] + t * d[1];
  if (std::fabs(X) > 0.5 * target.board_width_m || std::fabs(Y) > 0.5 * target.board_height_m) {
    return options.background_grey;
  }
  for (const TargetLine& line : target.lines) {
    const double ex = line.x2_m - line.x1_m, ey = line.y2_m - line.y1_m;
    const double length = std::hypot(ex, ey);
    const double along = ((X - line.x1_m) * ex + (Y - line.y1_m) * ey) / length;
    const double across = ((X - line.x1_m) * -ey + (Y - line.y1_m) * ex) / length;
    if (along >= 0.0 && along <= length && std::fabs(across) <= 0.5 * line.width_m) {
      return target.line_grey;
    }
  }
  return target.board_grey;
}

/// Mean grey level of pixel (u, v) from n x n point samples (uniform background, no noise,
/// blur or illumination), each ray intersected with the board plane using the inverse pose.
inline double ReferenceGrey(const LineTarget& target, const RenderOptions& options,
                            const vpHomogeneousMatrix& cMo, int u, int v, int n) {
  const vpHomogeneousMatrix oMc = cMo.inverse();
  double sum = 0.0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Point2d ray =
          options.camera.Normalised(u - 0.5 + (i + 0.5) / n, v - 0.5 + (j + 0.5) / n);
      sum += SampleGrey(target, options, oMc, ray.u, ray.v);
    }
  }
  return sum / (n * n);
}

}  // namespace oal::testing
