#include "detector/line_fit.h"

#include <algorithm>
#include <cmath>

namespace oal {

LineParams RefitLine(const LineParams& line, const std::vector<FramePoint>& points,
                     double tolerance_px, bool prefer_straight) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  // One pass: sums of the close points' offsets from the first close point (a reference
  // inside the cloud keeps the second moments well conditioned), centred afterwards.
  double n = 0.0, su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
  double ref_u = 0.0, ref_v = 0.0;
  int straight = 0, close = 0;
  for (const FramePoint& point : points) {
    const bool near = std::fabs(point.p.u * c + point.p.v * s - line.rho_px) <= tolerance_px;
    close += near;
    straight += near && point.straight;
  }
  const bool straight_only = prefer_straight && straight >= 2 && 2 * straight >= close;
  for (const FramePoint& point : points) {
    if (straight_only && !point.straight) continue;
    if (std::fabs(point.p.u * c + point.p.v * s - line.rho_px) > tolerance_px) continue;
    if (n == 0.0) {
      ref_u = point.p.u;
      ref_v = point.p.v;
    }
    const double du = point.p.u - ref_u, dv = point.p.v - ref_v;
    n += 1.0;
    su += du;
    sv += dv;
    suu += du * du;
    svv += dv * dv;
    suv += du * dv;
  }
  if (n < 2.0) return line;
  const double mean_du = su / n, mean_dv = sv / n;
  const double cuu = suu - su * mean_du, cvv = svv - sv * mean_dv, cuv = suv - su * mean_dv;
  const double mu = ref_u + mean_du, mv = ref_v + mean_dv;
  // Direction of largest spread; the normal is perpendicular to it.
  const double direction = 0.5 * std::atan2(2.0 * cuv, cuu - cvv);
  const double theta = direction + kPi / 2.0;
  return Normalized(mu * std::cos(theta) + mv * std::sin(theta), theta);
}

SupportStats MeasureSupport(const LineParams& line, const std::vector<FramePoint>& points,
                            double tolerance_px) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  SupportStats stats;
  int last_border = -1, width_n = 0;
  double width_sum = 0.0;
  // Positions along the line's direction (-s, c).
  double t_min = HUGE_VAL, t_max = -HUGE_VAL;
  for (const FramePoint& point : points) {
    if (std::fabs(point.p.u * c + point.p.v * s - line.rho_px) > tolerance_px) continue;
    ++stats.points;
    const double t = -point.p.u * s + point.p.v * c;
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
    if (point.border != last_border) {  // points arrive border by border
      ++stats.borders;
      last_border = point.border;
    }
    const double width = WidthAcross(point, c, s);
    if (width > 0.0) {
      width_sum += width;
      ++width_n;
    }
  }
  stats.width_px = width_n > 0 ? width_sum / width_n : 0.0;
  if (stats.points == 0) t_min = t_max = 0.0;
  const Point2d foot{line.rho_px * c, line.rho_px * s};
  stats.first = Point2d{foot.u - t_min * s, foot.v + t_min * c};
  stats.last = Point2d{foot.u - t_max * s, foot.v + t_max * c};
  return stats;
}

}  // namespace oal
