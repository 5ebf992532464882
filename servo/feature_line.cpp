#include "servo/feature_line.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "detector/lens.h"

namespace oal {

MetricLine MetricLineFromUndistorted(const LineParams& undistorted, const Lens& camera) {
  // u' = u0 + px·x, v' = v0 + py·y in u'·c + v'·s = rho gives
  //   (px·c)·x + (py·s)·y = rho - u0·c - v0·s,  then normalise the normal (px·c, py·s).
  const double c = std::cos(undistorted.theta_rad), s = std::sin(undistorted.theta_rad);
  const double nx = camera.px() * c, ny = camera.py() * s;
  const double norm = std::hypot(nx, ny);
  const double rhs = undistorted.rho_px - camera.u0() * c - camera.v0() * s;
  MetricLine line{rhs / norm, std::atan2(ny, nx)};
  // s >= 0 for theta in [0, pi), so theta_m is in [0, pi]; pi only for an input outside
  // line.h's range: fold it back.
  if (line.theta_rad >= kPi) {
    line.theta_rad -= kPi;
    line.rho_m = -line.rho_m;
  } else if (line.theta_rad < 0.0) {
    line.theta_rad += kPi;
    line.rho_m = -line.rho_m;
  }
  return line;
}

LineParams UndistortedFromMetricLine(const MetricLine& line, const Lens& camera) {
  // x = (u' - u0)/px, y = (v' - v0)/py in x·c + y·s = rho.
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  const double nu = c / camera.px(), nv = s / camera.py();
  const double norm = std::hypot(nu, nv);
  const double rhs = line.rho_m + camera.u0() * nu + camera.v0() * nv;
  return Normalized(rhs / norm, std::atan2(nv, nu));
}

LineParams UndistortedLineFromDistortedSegment(const Point2d& a, const Point2d& b,
                                               const Lens& camera, int samples, double* rms_px) {
  if (samples < 2) {
    throw std::invalid_argument("UndistortedLineFromDistortedSegment: samples = " +
                                std::to_string(samples) + ". Violated constraint: samples >= 2");
  }
  if (a.u == b.u && a.v == b.v) {
    throw std::invalid_argument(
        "UndistortedLineFromDistortedSegment: a == b. Violated constraint: distinct end points");
  }
  // Undistorted pixels of the samples: ViSP's pixel -> metre (kdu when the camera model has
  // distortion), then metre -> pixel without distortion.
  std::vector<Point2d> points(static_cast<std::size_t>(samples));
  double mean_u = 0.0, mean_v = 0.0;
  for (int k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) / (samples - 1);
    const Point2d ideal = camera.Normalised(a.u + t * (b.u - a.u), a.v + t * (b.v - a.v));
    const double x = ideal.u, y = ideal.v;
    Point2d& p = points[static_cast<std::size_t>(k)];
    p.u = camera.u0() + camera.px() * x;
    p.v = camera.v0() + camera.py() * y;
    mean_u += p.u;
    mean_v += p.v;
  }
  mean_u /= samples;
  mean_v /= samples;
  // Total least squares: the normal is the direction of least scatter.
  double suu = 0.0, svv = 0.0, suv = 0.0;
  for (const Point2d& p : points) {
    const double du = p.u - mean_u, dv = p.v - mean_v;
    suu += du * du;
    svv += dv * dv;
    suv += du * dv;
  }
  const double direction = 0.5 * std::atan2(2.0 * suv, suu - svv);
  const double theta = direction + kPi / 2.0;
  const LineParams fit = Normalized(mean_u * std::cos(theta) + mean_v * std::sin(theta), theta);
  if (rms_px != nullptr) {
    double sum = 0.0;
    for (const Point2d& p : points) {
      const double d = fit.SignedDistance(p.u, p.v);
      sum += d * d;
    }
    *rms_px = std::sqrt(sum / samples);
  }
  return fit;
}

MetricLine AlignedTo(const MetricLine& line, double reference_theta_rad) {
  auto wrap = [](double angle) {  // into (-pi, pi]
    angle = std::remainder(angle, 2.0 * kPi);
    return angle <= -kPi ? angle + 2.0 * kPi : angle;
  };
  const double theta = wrap(line.theta_rad);
  const double flipped = wrap(line.theta_rad + kPi);
  if (std::fabs(wrap(flipped - reference_theta_rad)) <
      std::fabs(wrap(theta - reference_theta_rad))) {
    return MetricLine{-line.rho_m, flipped};
  }
  return MetricLine{line.rho_m, theta};
}

void BuildFeatureLine(const MetricLine& line, vpFeatureLine* feature) {
  feature->buildFrom(line.rho_m, line.theta_rad);
}

void BuildFeatureLineFromUndistorted(const LineParams& undistorted, const Lens& camera,
                                     vpFeatureLine* feature) {
  BuildFeatureLine(MetricLineFromUndistorted(undistorted, camera), feature);
}

void BuildFeatureLineFromDistorted(const Point2d& a, const Point2d& b, const Lens& camera,
                                   vpFeatureLine* feature, int samples) {
  const LineParams undistorted = UndistortedLineFromDistortedSegment(a, b, camera, samples);
  BuildFeatureLine(MetricLineFromUndistorted(undistorted, camera), feature);
}

void BuildFeatureLine(const DetectedLine& line, bool detector_undistorts, const Lens& camera,
                      vpFeatureLine* feature) {
  if (detector_undistorts) {
    BuildFeatureLineFromUndistorted(line.line, camera, feature);
  } else {
    BuildFeatureLineFromDistorted(line.end_a, line.end_b, camera, feature);
  }
}

}  // namespace oal
