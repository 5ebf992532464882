// The remedies of NOTES 3 and 4: refit a read-off line to the feature points of all borders
// by total least squares, and score it by how many of those points lie on it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "detector/line.h"

namespace oal {

/// A feature point of the whole frame, in the detector's working coordinates.
struct FramePoint {
  Point2d p;  ///< undistorted when the detector corrects distortion
  /// The run along its border side: its length times the side's unit direction, pixels, in
  /// the working coordinates as `p` (undistorted with it); (0, 0) when its width is unknown
  /// (edges, runs around a corner of the border).
  float across_u = 0.0f, across_v = 0.0f;
  std::uint16_t sides = 0;  ///< sides of the border the point is on (BorderPoint::sides)
  bool straight = true;     ///< the run lay on one side of the border
  std::int16_t border = 0;  ///< index of the border, 0 = outermost
  /// BorderPoint::background_step: how much lighter one side of its run is than the other.
  float background_step = 0.0f;
};

struct SupportStats {
  int points = 0;         ///< feature points within the tolerance
  int borders = 0;        ///< distinct borders among them
  double width_px = 0.0;  ///< mean line width across the line (0 if unknown)
  /// The extreme points among them along the line, projected onto it (the foot of the line's
  /// normal from the origin when there are none).
  Point2d first, last;
};

/// Width across a line of normal n = (cos_theta, sin_theta) of the stripe whose run gave
/// `point`: a stripe of width w crosses a side of unit direction e in a run of w / |e·n| (a
/// horizontal side: w / |cos theta|, a vertical one: w / |sin theta|). 0 when unknown (corner
/// runs, edges). Linear in n, so an unnormalised normal scales the result.
inline double WidthAcross(const FramePoint& point, double cos_theta, double sin_theta) {
  return std::fabs(static_cast<double>(point.across_u) * cos_theta +
                   static_cast<double>(point.across_v) * sin_theta);
}

/// The total-least-squares line of the points within `tolerance_px` of `line`; with
/// `prefer_straight`, of the straight ones among them when they are at least two and half of
/// them (a run around a border's corner gives the midpoint of its ends, off the stripe's
/// centre line: it votes, but does not fit). Unchanged if fewer than two points are close.
LineParams RefitLine(const LineParams& line, const std::vector<FramePoint>& points,
                     double tolerance_px, bool prefer_straight = false);

/// Points, borders and mean width of the support of `line`.
SupportStats MeasureSupport(const LineParams& line, const std::vector<FramePoint>& points,
                            double tolerance_px);

/// The stretch of a line between the feet of two points on it, e.g. a printed stripe's ends.
struct LineExtent {
  Point2d a, b;
};

/// Calls visit(point, t, d) for each feature point of a straight stretch of `line`: within
/// `tolerance_px` of it, its run along one side of a border (a run around a corner gives the
/// midpoint of its ends, off the centre line), and, given an `extent`, its foot on it (a
/// stripe's line runs on past its ink, over whatever lies there). t is the foot's coordinate
/// along the line (direction (-sin, cos) of theta), d the point's signed distance from it.
template <typename Visit>
void ForEachPointOnStretch(const LineParams& line, const std::vector<FramePoint>& points,
                           double tolerance_px, const std::optional<LineExtent>& extent,
                           Visit visit) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  double t_lo = -HUGE_VAL, t_hi = HUGE_VAL;
  if (extent) {
    const double ta = -extent->a.u * s + extent->a.v * c, tb = -extent->b.u * s + extent->b.v * c;
    t_lo = std::min(ta, tb);
    t_hi = std::max(ta, tb);
  }
  for (const FramePoint& point : points) {
    if (!point.straight) continue;
    const double t = -point.p.u * s + point.p.v * c;
    const double d = point.p.u * c + point.p.v * s - line.rho_px;
    if (t < t_lo || t > t_hi || std::fabs(d) > tolerance_px) continue;
    visit(point, t, d);
  }
}

/// A line's bend: the parabola d = a + b x + k x^2 fitted to the distances d from `line` of its
/// feature points (ForEachPointOnStretch's, up to three stray ones left out: a run cut short by
/// a mark or an edge), x in [-1, 1] over the stretch t in [middle - half, middle + half] that
/// they cover. The parabola averages the points' noise out, where their RMS distance would add
/// it in, and its error grows where the points bunch at the two ends of the line.
struct LineBend {
  double k_px = 0.0;  ///< the bend, signed (positive towards the line's normal)
  /// Its standard error from the points' scatter about the parabola; infinite when they
  /// cannot tell a bend (fewer than 6, or a stretch under a pixel).
  double k_error_px = HUGE_VAL;
  double middle = 0.0, half = 0.0;  ///< the stretch, along the line's direction (-sin, cos)
  int points = 0;                   ///< kept

  bool Tells() const { return std::isfinite(k_error_px); }
};
LineBend FitLineBend(const LineParams& line, const std::vector<FramePoint>& points,
                     double tolerance_px, const std::optional<LineExtent>& extent = std::nullopt);

/// The radial lens error that four straight lines show, and the bend it puts on them. A camera
/// model whose kdu (ViSP's distorted-to-ideal term, x_u = x_d (1 + kdu r^2)) is off by e leaves
/// each corrected point moved by about e r^2 from the principal point: a line at distance rho
/// from it, seen over a stretch of half-length h, bends by k = e rho h^2 / f^2 pixels (f the
/// focal length, pixels), all lines the same way (outwards for e > 0). Each line's k, over its
/// error, is one measurement of e; weighted together they tell e where a line near the
/// principal point, or a short one, tells nothing, and a bend the other lines do not share (a
/// mark beside one stripe) is not a lens.
struct RadialBend {
  double kdu_error = 0.0;          ///< e: the camera's kdu less the lens's
  double kdu_error_sd = HUGE_VAL;  ///< its standard deviation (infinite: the lines cannot tell)
  /// The largest bend, pixels, that |e| less one standard deviation puts on one of the lines
  /// (0 when e is within one standard deviation of none): what the stripes show of the lens.
  double bend_px = 0.0;
  int lines = 0;  ///< lines that told e (a line disagreeing with the others is left out)
};
RadialBend RadialBendOfFour(const std::array<LineParams, 4>& lines,
                            const std::vector<FramePoint>& points, double tolerance_px,
                            const std::array<std::optional<LineExtent>, 4>& extents,
                            const Point2d& principal_point, double focal_px);

}  // namespace oal
