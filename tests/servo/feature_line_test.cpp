// The vpFeatureLine builders against ViSP's own projection of 3-D lines (vpLine::projection
// through vpFeatureBuilder::create), with and without lens distortion, and ViSP's vpMeLine
// path (vpFeatureBuilder::create(vpFeatureLine&, cam, vpMeLine)) for comparison.
#include "servo/feature_line.h"

#include <gtest/gtest.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpLine.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpPoint.h>
#include <visp3/me/vpMeLine.h>
#include <visp3/visual_features/vpFeatureBuilder.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "detector/line.h"
#include "scene/scene.h"

namespace oal {
namespace {

constexpr double kExactTol = 1e-9;  // rho (normalised units) and theta (rad), exact paths
constexpr int kWidth = 640, kHeight = 480;

// Anisotropic pixels and an off-centre principal point, so that a px/py or u0/v0 mix-up shows.
vpCameraParameters PinholeCamera() {
  return vpCameraParameters(600.0, 620.0, 321.3, 238.7);
}

// The same intrinsics with a cheap wide lens (scene.h: kdu ≈ +0.33 at 640x480, px = 600).
vpCameraParameters DistortedCamera() {
  const Lens pinhole = PinholeCamera();
  vpCameraParameters camera(pinhole.px(), pinhole.py(), pinhole.u0(), pinhole.v0(), 0.0, 0.33);
  const double kud = FitKud(camera, kWidth, kHeight);
  return vpCameraParameters(pinhole.px(), pinhole.py(), pinhole.u0(), pinhole.v0(), kud, 0.33);
}

vpHomogeneousMatrix TestPose() {
  return vpHomogeneousMatrix(0.04, -0.03, 0.9, vpMath::rad(12.0), vpMath::rad(-18.0),
                             vpMath::rad(35.0));
}

struct Point3 {
  double x, y, z;
};

// A 3-D segment in the object frame, its projection and ViSP's feature for it.
struct ProjectedLine {
  Point3 a, b;                              // object frame, metres
  std::array<double, 2> xa{}, xb{};         // normalised image coordinates of the ends
  double visp_rho = 0.0, visp_theta = 0.0;  // vpFeatureBuilder::create(s, vpLine)
};

// ViSP's projection of the 3-D line through a and b: vpLine as the intersection of two planes
// containing both points, moved by cMo and projected, then vpFeatureBuilder::create.
ProjectedLine ProjectWithVisp(const Point3& a, const Point3& b, const vpHomogeneousMatrix& cMo) {
  ProjectedLine out;
  out.a = a;
  out.b = b;
  const vpColVector d{b.x - a.x, b.y - a.y, b.z - a.z};
  // A helper axis least aligned with d, then two normals orthogonal to d.
  vpColVector e(3, 0.0);
  const double ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
  e[(ax <= ay && ax <= az) ? 0 : (ay <= az ? 1 : 2)] = 1.0;
  const vpColVector n1 = vpColVector::crossProd(d, e).normalize();
  const vpColVector n2 = vpColVector::crossProd(d, n1).normalize();
  const double d1 = -(n1[0] * a.x + n1[1] * a.y + n1[2] * a.z);
  const double d2 = -(n2[0] * a.x + n2[1] * a.y + n2[2] * a.z);
  vpLine line;
  line.setWorldCoordinates(n1[0], n1[1], n1[2], d1, n2[0], n2[1], n2[2], d2);
  line.track(cMo);  // changeFrame + projection
  vpFeatureLine feature;
  vpFeatureBuilder::create(feature, line);
  out.visp_rho = feature.getRho();
  out.visp_theta = feature.getTheta();

  for (int end = 0; end < 2; ++end) {
    const Point3& p = end == 0 ? a : b;
    vpPoint point(p.x, p.y, p.z);
    point.track(cMo);
    (end == 0 ? out.xa : out.xb) = {point.get_x(), point.get_y()};
  }
  return out;
}

// Ideal (undistorted) pixel of a normalised point, written out here rather than taken from
// the code under test.
Point2d IdealPixel(const Lens& camera, const std::array<double, 2>& xy) {
  return Point2d{camera.u0() + camera.px() * xy[0], camera.v0() + camera.py() * xy[1]};
}

bool InImage(const Point2d& p) {
  return p.u >= 0.0 && p.u <= kWidth - 1.0 && p.v >= 0.0 && p.v <= kHeight - 1.0;
}

// Random 3-D segments near the object origin whose (distorted and ideal) images lie in the
// image and are at least 150 px long. Fixed seed.
std::vector<ProjectedLine> RandomLines(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-0.35, 0.35), z(-0.15, 0.15);
  const Lens camera = DistortedCamera();
  std::vector<ProjectedLine> lines;
  while (static_cast<int>(lines.size()) < count) {
    const Point3 a{xy(rng), xy(rng), z(rng)}, b{xy(rng), xy(rng), z(rng)};
    const ProjectedLine line = ProjectWithVisp(a, b, TestPose());
    const Point2d ia = IdealPixel(camera, line.xa), ib = IdealPixel(camera, line.xb);
    const Point2d da = camera.Pixel(line.xa[0], line.xa[1]);
    const Point2d db = camera.Pixel(line.xb[0], line.xb[1]);
    if (!InImage(ia) || !InImage(ib) || !InImage(da) || !InImage(db)) continue;
    if (std::hypot(ia.u - ib.u, ia.v - ib.v) < 150.0) continue;
    lines.push_back(line);
  }
  return lines;
}

// (rho, theta) and (-rho, theta + pi) are one line: compare after choosing the orientation of
// `actual` that is closer to `expected`, angles modulo 2 pi.
void ExpectSameLine(double expected_rho, double expected_theta, double actual_rho,
                    double actual_theta, double tol) {
  if (std::cos(actual_theta - expected_theta) < 0.0) {
    actual_rho = -actual_rho;
    actual_theta += kPi;
  }
  EXPECT_NEAR(actual_rho, expected_rho, tol);
  EXPECT_NEAR(std::remainder(actual_theta - expected_theta, 2.0 * kPi), 0.0, tol);
}

// vpMeLine with its (rho, theta) set directly, as its tracking would leave them, so that
// vpFeatureBuilder::create(s, cam, vpMeLine) can be called on a known line.
class MeLineWithParams : public vpMeLine {
 public:
  void Set(const LineParams& me_line) {
    rho = me_line.rho_px;
    theta = me_line.theta_rad;
  }
};

Point2d ProjectOnto(const LineParams& line, const Point2d& p) {
  const double d = line.SignedDistance(p.u, p.v);
  return Point2d{p.u - d * std::cos(line.theta_rad), p.v - d * std::sin(line.theta_rad)};
}

// How far a feature line is from the true image of the segment: the larger distance of the
// segment's two ends from it, in (ideal) pixels along x.
double EndErrorPx(const ProjectedLine& truth, double rho, double theta, double px) {
  auto distance = [&](const std::array<double, 2>& xy) {
    return std::fabs(xy[0] * std::cos(theta) + xy[1] * std::sin(theta) - rho) * px;
  };
  return std::max(distance(truth.xa), distance(truth.xb));
}

TEST(FeatureLine, MatchesVispProjectionWithoutDistortion) {
  const Lens camera = PinholeCamera();
  for (const ProjectedLine& truth : RandomLines(200, 11)) {
    const LineParams pixel_line =
        LineThrough(IdealPixel(camera, truth.xa), IdealPixel(camera, truth.xb));
    vpFeatureLine ours;
    BuildFeatureLineFromUndistorted(pixel_line, camera, &ours);
    ExpectSameLine(truth.visp_rho, truth.visp_theta, ours.getRho(), ours.getTheta(), kExactTol);
    // Without distortion the distorted-image path is exact too.
    vpFeatureLine via_segment;
    BuildFeatureLineFromDistorted(IdealPixel(camera, truth.xa), IdealPixel(camera, truth.xb),
                                  camera, &via_segment);
    ExpectSameLine(truth.visp_rho, truth.visp_theta, via_segment.getRho(), via_segment.getTheta(),
                   kExactTol);
  }
}

TEST(FeatureLine, VispMeLinePathAgreesWithoutDistortion) {
  // Checks ToMeLineConvention against ViSP's own vpMeLine -> vpFeatureLine conversion.
  const Lens camera = PinholeCamera();
  for (const ProjectedLine& truth : RandomLines(200, 12)) {
    const LineParams pixel_line =
        LineThrough(IdealPixel(camera, truth.xa), IdealPixel(camera, truth.xb));
    MeLineWithParams me_line;
    me_line.Set(ToMeLineConvention(pixel_line));
    vpFeatureLine visp;
    vpFeatureBuilder::create(visp, camera.ViSPCamera(640, 480), me_line);
    ExpectSameLine(truth.visp_rho, truth.visp_theta, visp.getRho(), visp.getTheta(), kExactTol);
  }
}

TEST(FeatureLine, ExactWithDistortionFromUndistortedPixels) {
  // OalDetector with the camera reports lines in undistorted pixels: the conversion is exact
  // whatever kdu is.
  const Lens camera = DistortedCamera();
  ASSERT_EQ(camera.model(), Lens::Model::kViSP);
  for (const ProjectedLine& truth : RandomLines(200, 13)) {
    const LineParams undistorted =
        LineThrough(IdealPixel(camera, truth.xa), IdealPixel(camera, truth.xb));
    vpFeatureLine ours;
    BuildFeatureLineFromUndistorted(undistorted, camera, &ours);
    ExpectSameLine(truth.visp_rho, truth.visp_theta, ours.getRho(), ours.getTheta(), kExactTol);
  }
}

TEST(FeatureLine, DistortedImageLineApproximationBeatsVispWhichIgnoresKdu) {
  // The image of a 3-D line through the lens is a curve; fit a straight line to it as an edge
  // tracker would (vpMeLine, or our detector without the camera), then convert it:
  //  * ViSP's vpFeatureBuilder::create(s, cam, vpMeLine) ignores kdu;
  //  * ours undistorts points of the fitted segment and refits.
  // Lines are kept when they pass at least 100 px from the principal point (a line through it
  // stays straight under radial distortion, and both ways are then exact).
  constexpr double kVispMinMeanErrorPx = 3.0;  // what ignoring a cheap wide lens costs
  constexpr double kOursMaxErrorPx = 1.0;      // the curve's sag left by the approximation
  constexpr double kMinGain = 5.0;             // ours is better, line by line, by this factor
  const Lens camera = DistortedCamera();
  const Point2d centre{camera.u0(), camera.v0()};
  double visp_sum = 0.0, ours_max = 0.0;
  int lines = 0;
  for (const ProjectedLine& truth : RandomLines(300, 14)) {
    const LineParams ideal =
        LineThrough(IdealPixel(camera, truth.xa), IdealPixel(camera, truth.xb));
    if (std::fabs(ideal.SignedDistance(centre.u, centre.v)) < 100.0) continue;
    // The distorted image of the segment, densely sampled, and its straight fit.
    std::vector<Point2d> curve;
    for (int k = 0; k <= 200; ++k) {
      const double t = k / 200.0;
      curve.push_back(camera.Pixel(truth.xa[0] + t * (truth.xb[0] - truth.xa[0]),
                                   truth.xa[1] + t * (truth.xb[1] - truth.xa[1])));
    }
    const LineParams fitted = FitLine(curve);
    const Point2d end_a = ProjectOnto(fitted, curve.front()),
                  end_b = ProjectOnto(fitted, curve.back());

    MeLineWithParams me_line;
    me_line.Set(ToMeLineConvention(fitted));
    vpFeatureLine visp;
    vpFeatureBuilder::create(visp, camera.ViSPCamera(640, 480), me_line);
    const double visp_error = EndErrorPx(truth, visp.getRho(), visp.getTheta(), camera.px());

    vpFeatureLine ours;
    BuildFeatureLineFromDistorted(end_a, end_b, camera, &ours);
    const double ours_error = EndErrorPx(truth, ours.getRho(), ours.getTheta(), camera.px());

    EXPECT_LT(ours_error, kOursMaxErrorPx);
    EXPECT_LT(ours_error * kMinGain, visp_error);
    visp_sum += visp_error;
    ours_max = std::max(ours_max, ours_error);
    ++lines;
  }
  ASSERT_GE(lines, 50);
  EXPECT_GT(visp_sum / lines, kVispMinMeanErrorPx);
  RecordProperty("visp_mean_error_px", std::to_string(visp_sum / lines));
  RecordProperty("ours_max_error_px", std::to_string(ours_max));
}

TEST(FeatureLine, SegmentApproximationReportsTheSag) {
  const Lens camera = DistortedCamera();
  double rms = -1.0;
  // A horizontal segment near the top of the image bows under barrel distortion.
  UndistortedLineFromDistortedSegment({20.0, 20.0}, {620.0, 20.0}, camera, 16, &rms);
  EXPECT_GT(rms, 0.1);
  UndistortedLineFromDistortedSegment({20.0, 20.0}, {620.0, 20.0}, PinholeCamera(), 16, &rms);
  EXPECT_NEAR(rms, 0.0, 1e-9);
  EXPECT_THROW(UndistortedLineFromDistortedSegment({1.0, 2.0}, {1.0, 2.0}, camera),
               std::invalid_argument);
  EXPECT_THROW(UndistortedLineFromDistortedSegment({1.0, 2.0}, {5.0, 2.0}, camera, 1),
               std::invalid_argument);
}

TEST(FeatureLine, DetectedLineChoosesThePath) {
  const Lens camera = DistortedCamera();
  DetectedLine line;
  line.line = LineThrough({100.0, 50.0}, {500.0, 400.0});
  line.end_a = {100.0, 50.0};
  line.end_b = {500.0, 400.0};
  vpFeatureLine exact, approximate, expected_exact, expected_approximate;
  BuildFeatureLine(line, true, camera, &exact);
  BuildFeatureLineFromUndistorted(line.line, camera, &expected_exact);
  BuildFeatureLine(line, false, camera, &approximate);
  BuildFeatureLineFromDistorted(line.end_a, line.end_b, camera, &expected_approximate);
  EXPECT_EQ(exact.getRho(), expected_exact.getRho());
  EXPECT_EQ(exact.getTheta(), expected_exact.getTheta());
  EXPECT_EQ(approximate.getRho(), expected_approximate.getRho());
  EXPECT_EQ(approximate.getTheta(), expected_approximate.getTheta());
  EXPECT_NE(exact.getRho(), approximate.getRho());
}

TEST(FeatureLine, MetricAndUndistortedRoundTrip) {
  const Lens camera = PinholeCamera();
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> rho(-900.0, 900.0), theta(0.0, kPi);
  for (int trial = 0; trial < 10000; ++trial) {
    const LineParams line{rho(rng), theta(rng)};
    const MetricLine metric = MetricLineFromUndistorted(line, camera);
    EXPECT_GE(metric.theta_rad, 0.0);
    EXPECT_LT(metric.theta_rad, kPi);
    const LineParams back = UndistortedFromMetricLine(metric, camera);
    EXPECT_NEAR(AngleBetween(back, line), 0.0, 1e-12);
    EXPECT_NEAR(RhoAlignedTo(line, back), line.rho_px, 1e-9);
  }
}

TEST(FeatureLine, AlignedToPicksTheNearerOrientation) {
  const MetricLine line{0.2, 0.3};
  const MetricLine same = AlignedTo(line, 0.1);
  EXPECT_DOUBLE_EQ(same.rho_m, 0.2);
  EXPECT_DOUBLE_EQ(same.theta_rad, 0.3);
  const MetricLine flipped = AlignedTo(line, 0.3 - kPi + 0.2);
  EXPECT_DOUBLE_EQ(flipped.rho_m, -0.2);
  EXPECT_NEAR(flipped.theta_rad, 0.3 - kPi, 1e-15);
  // Across the +-pi wrap: theta near -pi is close to a reference near +pi.
  const MetricLine wrapped = AlignedTo(MetricLine{0.5, 0.05}, kPi - 0.1);
  EXPECT_DOUBLE_EQ(wrapped.rho_m, -0.5);
  EXPECT_NEAR(wrapped.theta_rad, 0.05 - kPi, 1e-15);
}

// --- vpMeLine convention (detector/line.h) -------------------------------------------------

// Two (rho, theta) pairs denote the same line in one convention: same angle modulo pi, and
// rho equal once the orientation is aligned.
void ExpectSameLineParams(const LineParams& expected, const LineParams& actual, double tol) {
  ExpectSameLine(expected.rho_px, expected.theta_rad, actual.rho_px, actual.theta_rad, tol);
}

TEST(MeLineConvention, KnownLines) {
  // A vertical line u = 10 (column 10): ours theta = 0; vpMeLine: j = 10, theta_me = pi/2.
  const LineParams vertical = ToMeLineConvention({10.0, 0.0});
  EXPECT_NEAR(vertical.rho_px, 10.0, 1e-12);
  EXPECT_NEAR(vertical.theta_rad, kPi / 2.0, 1e-12);
  // A horizontal line v = 7 (row 7): ours theta = pi/2; vpMeLine: i = 7, theta_me = 0.
  const LineParams horizontal = ToMeLineConvention({7.0, kPi / 2.0});
  EXPECT_NEAR(horizontal.rho_px, 7.0, 1e-12);
  EXPECT_NEAR(horizontal.theta_rad, 0.0, 1e-12);
  // vpMeLine's theta in [pi, 2 pi) (the other polarity) is the same line.
  const LineParams from_polar = FromMeLineConvention({-7.0, kPi});
  EXPECT_NEAR(from_polar.rho_px, 7.0, 1e-12);
  EXPECT_NEAR(from_polar.theta_rad, kPi / 2.0, 1e-12);
}

TEST(MeLineConvention, RoundTripsAtRandomLinesIncludingTheWrap) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> rho(-1000.0, 1000.0), theta(0.0, kPi);
  std::uniform_real_distribution<double> tiny_exp(-16.0, -1.0), row(-100.0, 600.0);
  std::vector<double> thetas;
  for (int k = 0; k < 5000; ++k) thetas.push_back(theta(rng));
  // Near 0, pi/2 and pi (both sides where the range allows), and the exact ends.
  for (int k = 0; k < 1000; ++k) {
    const double eps = std::pow(10.0, tiny_exp(rng));
    thetas.push_back(eps);
    thetas.push_back(kPi - eps);
    thetas.push_back(kPi / 2.0 - eps);
    thetas.push_back(kPi / 2.0 + eps);
  }
  thetas.push_back(0.0);
  thetas.push_back(std::nextafter(kPi, 0.0));
  thetas.push_back(kPi / 2.0);
  for (double t : thetas) {
    const LineParams line{rho(rng), t};
    const LineParams me = ToMeLineConvention(line);
    EXPECT_GE(me.theta_rad, 0.0);
    EXPECT_LT(me.theta_rad, kPi);
    // The same points: (u, v) on our line <=> (i = v, j = u) on vpMeLine's.
    const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
    const double free = row(rng);  // the better-conditioned coordinate is chosen freely
    const Point2d p = std::fabs(c) > std::fabs(s) ? Point2d{(line.rho_px - free * s) / c, free}
                                                  : Point2d{free, (line.rho_px - free * c) / s};
    EXPECT_NEAR(me.SignedDistance(p.v, p.u), 0.0, 1e-8) << "theta " << t;
    const LineParams back = FromMeLineConvention(me);
    EXPECT_GE(back.theta_rad, 0.0);
    EXPECT_LT(back.theta_rad, kPi);
    ExpectSameLineParams(line, back, 1e-9);
    // From vpMeLine's side, with its theta anywhere in [0, 2 pi).
    const LineParams me_any{rho(rng), 2.0 * t};
    ExpectSameLineParams(me_any, ToMeLineConvention(FromMeLineConvention(me_any)), 1e-9);
  }
}

}  // namespace
}  // namespace oal
