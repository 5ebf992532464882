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

namespace {

double Parabola(const std::array<double, 3>& fit, double x) {
  return fit[0] + x * (fit[1] + x * fit[2]);
}

// The normal equations of the least-squares parabola d = a + b x + k x^2 through samples
// (x, d), as sums that a sample can be added to or taken out of.
struct ParabolaSums {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, d0 = 0, d1 = 0, d2 = 0;

  void Add(const Point2d& sample, double weight) {
    const double x = sample.u, d = sample.v, x2 = x * x;
    s0 += weight, s1 += weight * x, s2 += weight * x2, s3 += weight * x2 * x;
    s4 += weight * x2 * x2;
    d0 += weight * d, d1 += weight * x * d, d2 += weight * x2 * d;
  }
  // {a, b, k}, and the k diagonal entry of the inverse normal matrix; false when the samples
  // do not determine the parabola.
  bool Solve(std::array<double, 3>* fit, double* inverse_kk) const {
    auto det3 = [](double a, double b, double c, double d, double e, double f, double g, double h,
                   double i) {
      return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    };
    const double det = det3(s0, s1, s2, s1, s2, s3, s2, s3, s4);
    if (!(std::fabs(det) > 1e-12)) return false;
    *fit = {det3(d0, s1, s2, d1, s2, s3, d2, s3, s4) / det,
            det3(s0, d0, s2, s1, d1, s3, s2, d2, s4) / det,
            det3(s0, s1, d0, s1, s2, d1, s2, s3, d2) / det};
    *inverse_kk = (s0 * s2 - s1 * s1) / det;
    return true;
  }
};

// How far each kept sample lies from the parabola fitted to the other kept ones: a stray
// sample cannot pull that fit towards itself, so it stands out even at a line's end.
void DeletedResiduals(const std::vector<Point2d>& samples, const std::vector<char>& kept,
                      const ParabolaSums& sums, std::vector<double>* residuals) {
  residuals->assign(samples.size(), 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!kept[i]) continue;
    ParabolaSums others = sums;
    others.Add(samples[i], -1.0);
    std::array<double, 3> fit{};
    double unused = 0.0;
    if (others.Solve(&fit, &unused)) (*residuals)[i] = samples[i].v - Parabola(fit, samples[i].u);
  }
}

}  // namespace

double LineSagitta(const LineParams& line, const std::vector<FramePoint>& points,
                   double tolerance_px, const std::optional<LineExtent>& extent) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  double t_lo = -HUGE_VAL, t_hi = HUGE_VAL;
  if (extent) {
    const double ta = -extent->a.u * s + extent->a.v * c, tb = -extent->b.u * s + extent->b.v * c;
    t_lo = std::min(ta, tb);
    t_hi = std::max(ta, tb);
  }
  auto near = [&](const FramePoint& point) {
    const double t = -point.p.u * s + point.p.v * c;
    return t >= t_lo && t <= t_hi &&
           std::fabs(point.p.u * c + point.p.v * s - line.rho_px) <= tolerance_px;
  };
  // Only runs along one side of a border: one around a border's corner gives the midpoint of
  // its ends, off the stripe's centre line, a bend that is not the lens's.
  auto counts = [&](const FramePoint& point) { return point.straight && near(point); };
  // The points as (x, d): along the line, scaled to [-1, 1] over the stretch they cover, and
  // their distance from it.
  std::vector<Point2d> samples;
  double t_min = HUGE_VAL, t_max = -HUGE_VAL;
  for (const FramePoint& point : points) {
    if (!counts(point)) continue;
    const double t = -point.p.u * s + point.p.v * c;
    samples.push_back(Point2d{t, point.p.u * c + point.p.v * s - line.rho_px});
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  if (samples.size() < 6 || !(t_max - t_min > 1.0)) return 0.0;
  const double middle = 0.5 * (t_min + t_max), half = 0.5 * (t_max - t_min);
  for (Point2d& sample : samples) sample.u = (sample.u - middle) / half;
  // A stray point (a run cut short by a mark or by the sheet's edge) bends a parabola through
  // a dozen points by a pixel: up to three are left out, each the one farthest from the fit of
  // the others when beyond four robust sigmas of all such distances (and a third of a pixel).
  std::vector<char> kept(samples.size(), 1);
  ParabolaSums sums;
  for (const Point2d& sample : samples) sums.Add(sample, 1.0);
  std::vector<double> residuals, magnitudes;
  for (int round = 0; round < 3 && sums.s0 > 6.5; ++round) {
    DeletedResiduals(samples, kept, sums, &residuals);
    magnitudes.clear();
    std::size_t worst = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!kept[i]) continue;
      magnitudes.push_back(std::fabs(residuals[i]));
      if (std::fabs(residuals[i]) > std::fabs(residuals[worst]) || !kept[worst]) worst = i;
    }
    auto median = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
    std::nth_element(magnitudes.begin(), median, magnitudes.end());
    if (!(std::fabs(residuals[worst]) > std::max(4.0 * 1.4826 * *median, 1.0 / 3.0))) break;
    kept[worst] = 0;
    sums.Add(samples[worst], -1.0);
  }
  std::array<double, 3> fit{};  // d = fit[0] + fit[1] x + fit[2] x^2: fit[2] is the sagitta
  double inverse_kk = 0.0;
  if (!sums.Solve(&fit, &inverse_kk)) return 0.0;
  double squares = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double r = samples[i].v - Parabola(fit, samples[i].u);
    if (kept[i]) squares += r * r;
  }
  const double k_error = std::sqrt(squares / (sums.s0 - 3.0) * inverse_kk);
  // The bend beyond what the points' own scatter allows: points bunched at the two ends of a
  // line (the borders of a scan near its ends) tell a curvature poorly.
  const double beyond = std::max(0.0, std::fabs(fit[2]) - 1.0 * k_error);
  return std::copysign(beyond, fit[2]);
}

double StraightnessOfFour(const std::array<LineParams, 4>& lines,
                          const std::vector<FramePoint>& points, double tolerance_px,
                          const std::array<std::optional<LineExtent>, 4>& extents) {
  std::array<double, 4> bends{};
  for (std::size_t k = 0; k < bends.size(); ++k) {
    bends[k] = std::fabs(LineSagitta(lines[k], points, tolerance_px, extents[k]));
  }
  std::sort(bends.begin(), bends.end());
  return bends[2];
}

}  // namespace oal
