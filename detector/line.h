// The one place where the detector's line parameterisation is stated.
//
// Pixel coordinates: u = column, v = row, pixel centres at integer coordinates, origin at
// the centre of the top-left pixel. A line is the set of points with
//     u·cos(theta) + v·sin(theta) = rho,     theta in [0, pi), rho in pixels (may be < 0),
// which is OpenCV's HoughLines convention. ViSP's vpMeLine uses (i = row, j = column)
// with i·cos(theta) + j·sin(theta) = rho; ToMeLineConvention / FromMeLineConvention at the
// end of this file are the one place that converts between the two.
#pragma once

#include <cmath>
#include <vector>

#include "base/angles.h"

namespace oal {

struct Point2d {
  double u = 0.0;  ///< column, pixels
  double v = 0.0;  ///< row, pixels
};

/// A line in normal form; see the file comment for the convention.
struct LineParams {
  double rho_px = 0.0;
  double theta_rad = 0.0;

  /// Signed distance of (u, v) from the line, pixels.
  double SignedDistance(double u, double v) const {
    return u * std::cos(theta_rad) + v * std::sin(theta_rad) - rho_px;
  }
};

/// Brings theta into [0, pi), flipping the sign of rho when theta is moved by pi.
LineParams Normalized(double rho_px, double theta_rad);

/// The line through two distinct points, normalised to theta in [0, pi).
LineParams LineThrough(const Point2d& a, const Point2d& b);

/// The total-least-squares line through `points` (at least two distinct ones): through
/// their centroid, along the direction of their largest spread.
LineParams FitLine(const std::vector<Point2d>& points);

/// Absolute angle between two lines, in [0, pi/2] (lines are undirected).
double AngleBetween(const LineParams& a, const LineParams& b);

/// rho of `b` expressed in the orientation of `a`: when their thetas lie on opposite sides
/// of the 0/pi wrap, b's rho changes sign. Used to compare rho across the wrap.
double RhoAlignedTo(const LineParams& a, const LineParams& b);

/// True when `a` and `b` are within `max_angle_rad` of each other and their distances from
/// `origin` (rho measured from there, across the 0/pi wrap) within `max_r_px`. Measured from
/// a point near both lines (the detector uses the image centre), the rho gap of two lines a
/// small angle apart does not grow with their distance from the image's top-left corner.
bool NearDuplicate(const LineParams& a, const LineParams& b, const Point2d& origin,
                   double max_angle_rad, double max_r_px);

/// Intersection of two lines; false when they are parallel within `eps_rad`.
bool Intersect(const LineParams& a, const LineParams& b, Point2d* out, double eps_rad = 1e-9);

/// The two points where the line leaves the rectangle [u0, u1] x [v0, v1]; false if it
/// misses the rectangle.
bool ClipToRect(const LineParams& line, double u0, double v0, double u1, double v1, Point2d* a,
                Point2d* b);

/// The same line in vpMeLine's convention, i·cos(theta) + j·sin(theta) = rho with i = row,
/// j = column (pixels): theta_me = pi/2 - theta, rho unchanged, then brought into [0, pi) with
/// Normalized(). The result holds vpMeLine's rho and theta, so its SignedDistance() takes
/// (row, column). vpMeLine's theta spans [0, 2 pi) to encode edge polarity; ours has none.
LineParams ToMeLineConvention(const LineParams& line);

/// The inverse: vpMeLine's (rho, theta), theta anywhere (e.g. [0, 2 pi) as vpMeLine::getTheta
/// gives it), to our convention with theta in [0, pi).
LineParams FromMeLineConvention(const LineParams& me_line);

}  // namespace oal
