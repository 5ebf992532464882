#include "detector/line_fit.h"

#include <cmath>

namespace oal {

LineParams RefitLine(const LineParams& line, const std::vector<FramePoint>& points,
                     double tolerance_px) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  double n = 0.0, su = 0.0, sv = 0.0;
  for (const FramePoint& point : points) {
    if (std::fabs(point.p.u * c + point.p.v * s - line.rho_px) > tolerance_px) continue;
    n += 1.0;
    su += point.p.u;
    sv += point.p.v;
  }
  if (n < 2.0) return line;
  const double mu = su / n, mv = sv / n;
  double suu = 0.0, svv = 0.0, suv = 0.0;
  for (const FramePoint& point : points) {
    if (std::fabs(point.p.u * c + point.p.v * s - line.rho_px) > tolerance_px) continue;
    const double du = point.p.u - mu, dv = point.p.v - mv;
    suu += du * du;
    svv += dv * dv;
    suv += du * dv;
  }
  // Direction of largest spread; the normal is perpendicular to it.
  const double direction = 0.5 * std::atan2(2.0 * suv, suu - svv);
  const double theta = direction + kPi / 2.0;
  return Normalized(mu * std::cos(theta) + mv * std::sin(theta), theta);
}

SupportStats MeasureSupport(const LineParams& line, const std::vector<FramePoint>& points,
                            double tolerance_px) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  SupportStats stats;
  int last_border = -1, width_n = 0;
  double width_sum = 0.0;
  for (const FramePoint& point : points) {
    if (std::fabs(point.p.u * c + point.p.v * s - line.rho_px) > tolerance_px) continue;
    ++stats.points;
    if (point.border != last_border) {  // points arrive border by border
      ++stats.borders;
      last_border = point.border;
    }
    const bool horizontal = (point.sides & 0x5) != 0;  // kTop | kBottom
    const bool vertical = (point.sides & 0xA) != 0;    // kRight | kLeft
    if (point.run_px > 0.0f && point.straight && horizontal != vertical) {
      // A stripe of width w crosses a horizontal side in a run of w / |cos theta| and a
      // vertical side in a run of w / |sin theta|.
      width_sum += point.run_px * (horizontal ? std::fabs(c) : std::fabs(s));
      ++width_n;
    }
  }
  stats.width_px = width_n > 0 ? width_sum / width_n : 0.0;
  return stats;
}

}  // namespace oal
