#include "detector/line.h"

#include <algorithm>
#include <limits>

namespace oal {

LineParams Normalized(double rho_px, double theta_rad) {
  double theta = std::fmod(theta_rad, 2.0 * kPi);
  if (theta < 0.0) theta += 2.0 * kPi;
  double rho = rho_px;
  if (theta >= kPi) {
    theta -= kPi;
    rho = -rho;
  }
  if (theta >= kPi) {  // theta == pi after rounding: a tiny negative angle became 2 pi - pi.
    theta = 0.0;       // (rho, pi) is (-rho, 0)
    rho = -rho;
  }
  return LineParams{rho, theta};
}

LineParams LineThrough(const Point2d& a, const Point2d& b) {
  const double du = b.u - a.u;
  const double dv = b.v - a.v;
  // The normal of direction (du, dv) is (-dv, du).
  const double theta = std::atan2(du, -dv);
  const double rho = a.u * std::cos(theta) + a.v * std::sin(theta);
  return Normalized(rho, theta);
}

LineParams FitLine(const std::vector<Point2d>& points) {
  double mu = 0.0, mv = 0.0;
  for (const Point2d& p : points) {
    mu += p.u;
    mv += p.v;
  }
  mu /= static_cast<double>(points.size());
  mv /= static_cast<double>(points.size());
  double suu = 0.0, svv = 0.0, suv = 0.0;
  for (const Point2d& p : points) {
    suu += (p.u - mu) * (p.u - mu);
    svv += (p.v - mv) * (p.v - mv);
    suv += (p.u - mu) * (p.v - mv);
  }
  const double theta = 0.5 * std::atan2(2.0 * suv, suu - svv) + kPi / 2.0;
  return Normalized(mu * std::cos(theta) + mv * std::sin(theta), theta);
}

double AngleBetween(const LineParams& a, const LineParams& b) {
  double d = std::fabs(a.theta_rad - b.theta_rad);
  d = std::fmod(d, kPi);
  return std::min(d, kPi - d);
}

double RhoAlignedTo(const LineParams& a, const LineParams& b) {
  return std::fabs(a.theta_rad - b.theta_rad) > kPi / 2.0 ? -b.rho_px : b.rho_px;
}

bool NearDuplicate(const LineParams& a, const LineParams& b, const Point2d& origin,
                   double max_angle_rad, double max_r_px) {
  if (AngleBetween(a, b) > max_angle_rad) return false;
  const auto from_origin = [&origin](const LineParams& line) {
    return LineParams{-line.SignedDistance(origin.u, origin.v), line.theta_rad};
  };
  const LineParams a0 = from_origin(a), b0 = from_origin(b);
  return std::fabs(RhoAlignedTo(a0, b0) - a0.rho_px) <= max_r_px;
}

bool Intersect(const LineParams& a, const LineParams& b, Point2d* out, double eps_rad) {
  const double ca = std::cos(a.theta_rad), sa = std::sin(a.theta_rad);
  const double cb = std::cos(b.theta_rad), sb = std::sin(b.theta_rad);
  const double det = ca * sb - sa * cb;  // sin(theta_b - theta_a)
  if (std::fabs(det) < std::sin(eps_rad)) return false;
  out->u = (a.rho_px * sb - b.rho_px * sa) / det;
  out->v = (ca * b.rho_px - cb * a.rho_px) / det;
  return true;
}

bool ClipToRect(const LineParams& line, double u0, double v0, double u1, double v1, Point2d* a,
                Point2d* b) {
  // Parametrise the line as foot + t * dir and clip t against the four slabs.
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  const Point2d foot{line.rho_px * c, line.rho_px * s};
  const Point2d dir{-s, c};
  double t_min = -std::numeric_limits<double>::infinity();
  double t_max = std::numeric_limits<double>::infinity();
  auto clip = [&](double p, double d, double lo, double hi) {
    if (std::fabs(d) < 1e-12) return p >= lo && p <= hi;
    double t0 = (lo - p) / d, t1 = (hi - p) / d;
    if (t0 > t1) std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
    return t_min <= t_max;
  };
  if (!clip(foot.u, dir.u, u0, u1) || !clip(foot.v, dir.v, v0, v1)) return false;
  *a = Point2d{foot.u + t_min * dir.u, foot.v + t_min * dir.v};
  *b = Point2d{foot.u + t_max * dir.u, foot.v + t_max * dir.v};
  return true;
}

LineParams ToMeLineConvention(const LineParams& line) {
  // u = j, v = i: j·cos(t) + i·sin(t) = rho  <=>  i·cos(pi/2 - t) + j·sin(pi/2 - t) = rho.
  return Normalized(line.rho_px, kPi / 2.0 - line.theta_rad);
}

LineParams FromMeLineConvention(const LineParams& me_line) {
  // The map theta -> pi/2 - theta is its own inverse.
  return Normalized(me_line.rho_px, kPi / 2.0 - me_line.theta_rad);
}

}  // namespace oal
