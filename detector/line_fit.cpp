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

double LineSagitta(const LineParams& line, const std::vector<FramePoint>& points,
                   double tolerance_px) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  double t_min = HUGE_VAL, t_max = -HUGE_VAL;
  int n = 0;
  for (const FramePoint& point : points) {
    if (std::fabs(point.p.u * c + point.p.v * s - line.rho_px) > tolerance_px) continue;
    const double t = -point.p.u * s + point.p.v * c;
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
    ++n;
  }
  if (n < 6 || !(t_max - t_min > 1.0)) return 0.0;
  const double middle = 0.5 * (t_min + t_max), half = 0.5 * (t_max - t_min);
  // Least squares d = a + b x + k x^2 over x in [-1, 1]: k is the sagitta.
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, d0 = 0, d1 = 0, d2 = 0;
  for (const FramePoint& point : points) {
    const double d = point.p.u * c + point.p.v * s - line.rho_px;
    if (std::fabs(d) > tolerance_px) continue;
    const double x = (-point.p.u * s + point.p.v * c - middle) / half, x2 = x * x;
    s0 += 1.0, s1 += x, s2 += x2, s3 += x2 * x, s4 += x2 * x2;
    d0 += d, d1 += x * d, d2 += x2 * d;
  }
  auto det3 = [](double a, double b, double cc, double d, double e, double f, double g, double h,
                 double i) {
    return a * (e * i - f * h) - b * (d * i - f * g) + cc * (d * h - e * g);
  };
  const double det = det3(s0, s1, s2, s1, s2, s3, s2, s3, s4);
  if (!(std::fabs(det) > 1e-12)) return 0.0;
  return det3(s0, s1, d0, s1, s2, d1, s2, s3, d2) / det;
}

double StraightnessOfFour(const std::array<LineParams, 4>& lines,
                          const std::vector<FramePoint>& points, double tolerance_px) {
  std::array<double, 4> bends{};
  for (std::size_t k = 0; k < bends.size(); ++k) {
    bends[k] = std::fabs(LineSagitta(lines[k], points, tolerance_px));
  }
  std::sort(bends.begin(), bends.end());
  return bends[2];
}

}  // namespace oal
