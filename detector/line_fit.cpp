#include "detector/line_fit.h"

#include <algorithm>
#include <cmath>

#include "base/statistics.h"

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

// How far a feature point's position may be off the stripe's centre line in a way that does
// not average out over the neighbouring points, pixels.
constexpr double kPointBiasPx = 0.05;

// The least-squares parabola d = a + b x + k x^2 through samples (x, d): its coefficients and
// the inverse of its normal matrix (for the leverage of a sample and the error of k).
struct Parabola {
  std::array<double, 3> coefficients{};
  std::array<std::array<double, 3>, 3> inverse{};

  double At(double x) const {
    return coefficients[0] + x * (coefficients[1] + x * coefficients[2]);
  }
  // How much of the fit at x is the sample at x itself (the hat matrix's diagonal).
  double Leverage(double x) const {
    const double v[3] = {1.0, x, x * x};
    double h = 0.0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) h += v[i] * inverse[i][j] * v[j];
    }
    return h;
  }
};

struct SagittaSample {
  double x = 0.0, d = 0.0;
  bool kept = true;
};

// The parabola through the kept samples; false when they are fewer than 6 or do not
// determine it.
bool FitParabola(const std::vector<SagittaSample>& samples, Parabola* fit) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, d0 = 0, d1 = 0, d2 = 0;
  for (const SagittaSample& sample : samples) {
    if (!sample.kept) continue;
    const double x = sample.x, d = sample.d, x2 = x * x;
    s0 += 1.0, s1 += x, s2 += x2, s3 += x2 * x, s4 += x2 * x2;
    d0 += d, d1 += x * d, d2 += x2 * d;
  }
  if (s0 < 6.0) return false;
  // The normal matrix [s0 s1 s2; s1 s2 s3; s2 s3 s4] is symmetric: its inverse is its
  // cofactors over its determinant.
  const double c00 = s2 * s4 - s3 * s3, c01 = s2 * s3 - s1 * s4, c02 = s1 * s3 - s2 * s2;
  const double c11 = s0 * s4 - s2 * s2, c12 = s1 * s2 - s0 * s3, c22 = s0 * s2 - s1 * s1;
  const double det = s0 * c00 + s1 * c01 + s2 * c02;
  if (!(std::fabs(det) > 1e-12)) return false;
  fit->inverse = {{{c00 / det, c01 / det, c02 / det},
                   {c01 / det, c11 / det, c12 / det},
                   {c02 / det, c12 / det, c22 / det}}};
  for (int i = 0; i < 3; ++i) {
    const auto& row = fit->inverse[static_cast<std::size_t>(i)];
    fit->coefficients[static_cast<std::size_t>(i)] = row[0] * d0 + row[1] * d1 + row[2] * d2;
  }
  return true;
}

}  // namespace

LineBend FitLineBend(const LineParams& line, const std::vector<FramePoint>& points,
                     double tolerance_px, const std::optional<LineExtent>& extent) {
  LineBend bend;
  std::vector<SagittaSample> samples;
  double t_min = HUGE_VAL, t_max = -HUGE_VAL;
  ForEachPointOnStretch(line, points, tolerance_px, extent,
                        [&](const FramePoint&, double t, double d) {
                          samples.push_back(SagittaSample{t, d, true});
                          t_min = std::min(t_min, t);
                          t_max = std::max(t_max, t);
                        });
  if (samples.size() < 6 || !(t_max - t_min > 1.0)) return bend;
  // Along the line, x in [-1, 1] over the stretch the points cover.
  bend.middle = 0.5 * (t_min + t_max);
  bend.half = 0.5 * (t_max - t_min);
  for (SagittaSample& sample : samples) sample.x = (sample.x - bend.middle) / bend.half;
  Parabola fit;
  if (!FitParabola(samples, &fit)) return bend;
  // A stray point (a run cut short by a mark or by the sheet's edge) bends a parabola through
  // a dozen points by a pixel. Up to three are left out, each the one farthest from the fit of
  // the others (its residual over 1 - its leverage, so that it cannot pull that fit towards
  // itself, even at a line's end) when beyond four robust sigmas of all such distances and a
  // third of a pixel.
  std::vector<double> magnitudes;
  for (int round = 0; round < 3 && samples.size() - static_cast<std::size_t>(round) > 6; ++round) {
    magnitudes.clear();
    double worst_distance = 0.0;
    SagittaSample* worst = nullptr;
    for (SagittaSample& sample : samples) {
      if (!sample.kept) continue;
      const double free = 1.0 - fit.Leverage(sample.x);
      const double distance = free > 1e-6 ? std::fabs(sample.d - fit.At(sample.x)) / free : 0.0;
      magnitudes.push_back(distance);
      if (distance > worst_distance) worst_distance = distance, worst = &sample;
    }
    const double median = MedianInPlace(&magnitudes);
    if (worst == nullptr || !(worst_distance > std::max(4.0 * 1.4826 * median, 1.0 / 3.0))) break;
    worst->kept = false;
    Parabola refit;
    if (!FitParabola(samples, &refit)) {
      worst->kept = true;
      break;
    }
    fit = refit;
  }
  double squares = 0.0, kept = 0.0;
  for (const SagittaSample& sample : samples) {
    if (!sample.kept) continue;
    const double r = sample.d - fit.At(sample.x);
    squares += r * r;
    kept += 1.0;
  }
  bend.k_px = fit.coefficients[2];
  // The points' scatter about the parabola, and a bias that does not scatter: a run's midpoint
  // lies a few hundredths of a pixel off the centre line where blur, a crossing stripe or the
  // printed end weighs on both its ends alike, the same on neighbouring borders. Where the
  // points bunch at the line's two ends, such a bias alone can fake a bend.
  const double scatter = squares / (kept - 3.0) + kPointBiasPx * kPointBiasPx;
  bend.k_error_px = std::sqrt(scatter * fit.inverse[2][2]);
  bend.points = static_cast<int>(kept);
  return bend;
}

namespace {

// One line's measurement of a radial lens error e: its bend k = e g, with g = rho h^2 / f^2.
struct RadialSample {
  double g = 0.0, k = 0.0, k_error = 0.0;
  bool used = true;
};

// The weighted least-squares e of the used samples and its standard deviation.
void CombineRadial(const std::vector<RadialSample>& samples, RadialBend* out) {
  double sgg = 0.0, sgk = 0.0;
  out->lines = 0;
  for (const RadialSample& sample : samples) {
    if (!sample.used) continue;
    const double w = 1.0 / (sample.k_error * sample.k_error);
    sgg += w * sample.g * sample.g;
    sgk += w * sample.g * sample.k;
    ++out->lines;
  }
  // A standard deviation of one in kdu (lines through the principal point, or too short to
  // bend) says nothing about a lens.
  if (!(sgg >= 1.0)) {
    *out = RadialBend{};
    return;
  }
  out->kdu_error = sgk / sgg;
  out->kdu_error_sd = 1.0 / std::sqrt(sgg);
}

}  // namespace

RadialBend RadialBendOfFour(const std::array<LineParams, 4>& lines,
                            const std::vector<FramePoint>& points, double tolerance_px,
                            const std::array<std::optional<LineExtent>, 4>& extents,
                            const Point2d& principal_point, double focal_px) {
  std::vector<RadialSample> samples;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const LineBend bend = FitLineBend(lines[i], points, tolerance_px, extents[i]);
    if (!bend.Tells()) continue;
    const double c = std::cos(lines[i].theta_rad), s = std::sin(lines[i].theta_rad);
    // The line's signed distance from the principal point, along its normal.
    const double rho = lines[i].rho_px - (principal_point.u * c + principal_point.v * s);
    const double g = rho * bend.half * bend.half / (focal_px * focal_px);
    samples.push_back(RadialSample{g, bend.k_px, bend.k_error_px});
  }
  RadialBend result;
  CombineRadial(samples, &result);
  if (result.lines >= 3) {
    // A line whose bend the others do not share by more than three of its errors is a mark
    // beside a stripe or a run cut short, not a lens: the most discordant one is left out.
    RadialSample* worst = nullptr;
    double worst_z = 3.0;
    for (RadialSample& sample : samples) {
      const double z = std::fabs(sample.k - result.kdu_error * sample.g) / sample.k_error;
      if (z > worst_z) worst_z = z, worst = &sample;
    }
    if (worst != nullptr) {
      worst->used = false;
      CombineRadial(samples, &result);
    }
  }
  if (result.lines == 0) return result;
  const double beyond_doubt = std::max(0.0, std::fabs(result.kdu_error) - result.kdu_error_sd);
  for (const RadialSample& sample : samples) {
    if (sample.used) result.bend_px = std::max(result.bend_px, beyond_doubt * std::fabs(sample.g));
  }
  return result;
}

}  // namespace oal
