// The remedies of NOTES 3 and 4: refit a read-off line to the feature points of all borders
// by total least squares, and score it by how many of those points lie on it.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "detector/line.h"

namespace oal {

/// A feature point of the whole frame, in the detector's working coordinates.
struct FramePoint {
  Point2d p;                ///< undistorted when the detector corrects distortion
  float run_px = 0.0f;      ///< run length along the border (0: unknown, e.g. edges)
  std::uint8_t sides = 0;   ///< BorderSide bits of the border the point is on
  bool straight = true;     ///< the run lay on one side of the border
  std::int16_t border = 0;  ///< index of the border, 0 = outermost
};

struct SupportStats {
  int points = 0;         ///< feature points within the tolerance
  int borders = 0;        ///< distinct borders among them
  double width_px = 0.0;  ///< mean line width across the line (0 if unknown)
};

/// Width across a line of normal (cos_theta, sin_theta) of the stripe whose run gave
/// `point`: a stripe of width w crosses a horizontal side in a run of w / |cos theta| and a
/// vertical side in a run of w / |sin theta|. 0 when unknown (corner runs, edges).
inline double WidthAcross(const FramePoint& point, double cos_theta, double sin_theta) {
  const bool horizontal = (point.sides & 0x5) != 0;  // kTop | kBottom
  const bool vertical = (point.sides & 0xA) != 0;    // kRight | kLeft
  if (point.run_px <= 0.0f || !point.straight || horizontal == vertical) return 0.0;
  return point.run_px * (horizontal ? std::fabs(cos_theta) : std::fabs(sin_theta));
}

/// The total-least-squares line of the points within `tolerance_px` of `line`; unchanged if
/// fewer than two points are that close.
LineParams RefitLine(const LineParams& line, const std::vector<FramePoint>& points,
                     double tolerance_px);

/// Points, borders and mean width of the support of `line`.
SupportStats MeasureSupport(const LineParams& line, const std::vector<FramePoint>& points,
                            double tolerance_px);

}  // namespace oal
