// Ground truth and the lens helpers (DistortedPixel, FitKud).
#include <gtest/gtest.h>
#include <visp3/core/vpPixelMeterConversion.h>

#include <cmath>
#include <random>
#include <vector>

#include "scene/scene.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::FrontoParallel;
using testing::Project;

Lens WideLens(double kdu = 0.33) {
  return Lens::WithKudKdu(600.0, 590.0, 322.0, 241.0, 0.0, kdu);
}

// The normalised point a distorted pixel sees (ViSP's conversion).
void Ray(const Lens& camera, const Point2d& pixel, double* x, double* y) {
  vpPixelMeterConversion::convertPoint(camera.ViSPCamera(640, 480), pixel.u, pixel.v, *x, *y);
}

TEST(DistortedPixel, RoundTripsThroughVispPixelToMetre) {
  std::mt19937_64 gen(1);
  for (const double kdu : {0.33, 0.05, -0.1}) {
    const Lens camera = WideLens(kdu);
    std::uniform_real_distribution<double> coordinate(-0.7, 0.7);
    for (int trial = 0; trial < 10000; ++trial) {
      const double x = coordinate(gen), y = coordinate(gen);
      const Point2d pixel = camera.Pixel(x, y);
      ASSERT_TRUE(std::isfinite(pixel.u)) << kdu << " " << x << " " << y;
      double xr = 0.0, yr = 0.0;
      Ray(camera, pixel, &xr, &yr);
      ASSERT_NEAR(600.0 * (xr - x), 0.0, 1e-6) << kdu << " " << x << " " << y;
      ASSERT_NEAR(590.0 * (yr - y), 0.0, 1e-6) << kdu << " " << x << " " << y;
    }
  }
}

TEST(DistortedPixel, IsThePinholeWithoutDistortion) {
  const Lens camera = Lens::Pinhole(600.0, 590.0, 322.0, 241.0);
  const Point2d p = camera.Pixel(0.3, -0.2);
  EXPECT_DOUBLE_EQ(p.u, 322.0 + 600.0 * 0.3);
  EXPECT_DOUBLE_EQ(p.v, 241.0 - 590.0 * 0.2);
}

TEST(DistortedPixel, BarrelLensPullsPointsInwardAndUnreachablePointsAreNaN) {
  const Point2d barrel = WideLens(0.33).Pixel(0.5, 0.0);
  EXPECT_LT(barrel.u, 322.0 + 600.0 * 0.5 - 10.0);
  EXPECT_GT(barrel.u, 322.0);
  // kdu = -0.5: r (1 - 0.5 r^2) never exceeds 0.544.
  const Point2d unreachable = WideLens(-0.5).Pixel(0.6, 0.0);
  EXPECT_TRUE(std::isnan(unreachable.u));
}

// Mean squared error of the metre -> pixel model u = u0 + px x (1 + kud r^2) over the image.
double KudError(const Lens& camera, double kud) {
  double sum = 0.0;
  int n = 0;
  for (int v = 0; v < 480; v += 12) {
    for (int u = 0; u < 640; u += 12) {
      double x = 0.0, y = 0.0;
      Ray(camera, {static_cast<double>(u), static_cast<double>(v)}, &x, &y);
      const double r2 = x * x + y * y;
      const double du = camera.u0() + camera.px() * x * (1.0 + kud * r2) - u;
      const double dv = camera.v0() + camera.py() * y * (1.0 + kud * r2) - v;
      sum += du * du + dv * dv;
      ++n;
    }
  }
  return sum / n;
}

TEST(FitKud, MinimisesTheMetreToPixelError) {
  const Lens camera = WideLens(0.33);
  const double kud = FitKud(camera, 640, 480);
  EXPECT_LT(kud, -0.15);
  EXPECT_GT(kud, -0.33);
  const double error = KudError(camera, kud);
  EXPECT_LT(error, KudError(camera, kud + 0.01));
  EXPECT_LT(error, KudError(camera, kud - 0.01));
  EXPECT_LT(error, 0.1 * KudError(camera, 0.0));
  EXPECT_EQ(FitKud(vpCameraParameters(600.0, 600.0, 320.0, 240.0), 640, 480), 0.0);
}

TEST(Truth, FrontoParallelIdealLinesAreAnalytic) {
  const RenderOptions options;
  const SceneRenderer renderer(FourLineTarget(), options);
  const double distance = 0.7, cx = 0.013, cy = -0.021;
  const std::vector<TruthLine> truth = renderer.Truth(FrontoParallel(distance, cx, cy));
  ASSERT_EQ(truth.size(), 4u);
  for (const TruthLine& line : truth) {
    const TargetLine& target_line = renderer.target().lines[line.index];
    ASSERT_TRUE(line.visible);
    const bool vertical = target_line.x1_m == target_line.x2_m;
    const double expected = vertical ? 319.5 + 600.0 * (target_line.x1_m - cx) / distance
                                     : 239.5 + 600.0 * (target_line.y1_m - cy) / distance;
    EXPECT_NEAR(line.ideal.theta_rad, vertical ? 0.0 : kPi / 2.0, 1e-12);
    EXPECT_NEAR(line.ideal.rho_px, expected, 1e-9);
    EXPECT_NEAR(line.width_px, 600.0 * target_line.width_m / distance, 1e-9);
    // Without distortion the fit is the ideal line, and the visible part spans the image.
    EXPECT_NEAR(line.distorted_fit.rho_px, expected, 1e-6);
    EXPECT_NEAR(AngleBetween(line.distorted_fit, line.ideal), 0.0, 1e-9);
    const double span = vertical ? 479.0 : 639.0;
    EXPECT_NEAR(line.visible_length_px, span, 1e-6);
    EXPECT_NEAR(line.visible_length_px,
                std::hypot(line.end_b.u - line.end_a.u, line.end_b.v - line.end_a.v), 1e-12);
    EXPECT_NEAR(std::fabs(line.ideal.SignedDistance(line.end_a.u, line.end_a.v)), 0.0, 1e-9);
  }
}

TEST(Truth, IdealLineIsTheProjectionOfTheEndsUnderAnyPose) {
  RenderOptions options;
  options.camera = WideLens(0.2);
  const SceneRenderer renderer(FourLineTarget(), options);
  PoseSampling sampling;
  sampling.max_tilt_deg = 50.0;
  std::uint64_t state = 99;
  for (int trial = 0; trial < 50; ++trial) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    for (const TruthLine& line : renderer.Truth(cMo)) {
      const TargetLine& t = renderer.target().lines[line.index];
      Point2d a, b;
      if (!Project(cMo, options.camera, t.x1_m, t.y1_m, &a) ||
          !Project(cMo, options.camera, t.x2_m, t.y2_m, &b)) {
        continue;
      }
      const LineParams expected = LineThrough(a, b);
      EXPECT_LT(AngleBetween(line.ideal, expected), 1e-9);
      EXPECT_NEAR(RhoAlignedTo(expected, line.ideal), expected.rho_px, 1e-6);
    }
  }
}

TEST(Truth, DistortedFitFollowsTheDistortedImageOfTheCentreLine) {
  RenderOptions options;
  options.camera = WideLens(0.33);
  const SceneRenderer renderer(TwoLineTarget(), options);
  const vpHomogeneousMatrix cMo = FrontoParallel(0.6, -0.2, 0.05, 0.3);
  for (const TruthLine& line : renderer.Truth(cMo)) {
    ASSERT_TRUE(line.visible);
    // The ends are on the image border and on the distorted image of the centre line.
    for (const Point2d& end : {line.end_a, line.end_b}) {
      const double border = std::min({end.u, 639.0 - end.u, end.v, 479.0 - end.v});
      EXPECT_NEAR(border, 0.0, 1e-6);
      double x = 0.0, y = 0.0;
      Ray(options.camera, end, &x, &y);
      EXPECT_NEAR(line.ideal.SignedDistance(322.0 + 600.0 * x, 241.0 + 590.0 * y), 0.0, 1e-6);
    }
    // The fit is the least-squares line of the visible distorted curve: it beats the ideal
    // line by far, and moving or turning it makes it worse.
    const TargetLine& t = renderer.target().lines[line.index];
    std::vector<Point2d> curve;
    for (int i = 0; i <= 4000; ++i) {
      const double s = i / 4000.0;
      Point2d ideal;
      ASSERT_TRUE(Project(cMo, vpCameraParameters(600.0, 590.0, 322.0, 241.0), t.x1_m,
                          t.y1_m + s * (t.y2_m - t.y1_m), &ideal));
      const Point2d p = options.camera.Pixel((ideal.u - 322.0) / 600.0, (ideal.v - 241.0) / 590.0);
      if (p.u >= 0 && p.u <= 639 && p.v >= 0 && p.v <= 479) curve.push_back(p);
    }
    ASSERT_GT(curve.size(), 500u);
    const auto rms = [&curve](const LineParams& l) {
      double sum = 0.0;
      for (const Point2d& p : curve) sum += l.SignedDistance(p.u, p.v) * l.SignedDistance(p.u, p.v);
      return std::sqrt(sum / curve.size());
    };
    const LineParams& fit = line.distorted_fit;
    EXPECT_LT(rms(fit), 0.5 * rms(line.ideal));
    EXPECT_LT(rms(fit), rms({fit.rho_px + 0.3, fit.theta_rad}));
    EXPECT_LT(rms(fit), rms({fit.rho_px - 0.3, fit.theta_rad}));
    // Turn about the centroid of the curve.
    Point2d c;
    for (const Point2d& p : curve) c = {c.u + p.u / curve.size(), c.v + p.v / curve.size()};
    for (const double turn : {-0.003, 0.003}) {
      const double theta = fit.theta_rad + turn;
      EXPECT_LT(rms(fit), rms({c.u * std::cos(theta) + c.v * std::sin(theta), theta}));
    }
  }
}

TEST(Truth, LinesOutsideTheViewAreNotVisible) {
  const SceneRenderer renderer(TwoLineTarget(), RenderOptions());
  // Looking at the board 0.5 m right of both stripes, from 0.4 m.
  for (const TruthLine& line : renderer.Truth(FrontoParallel(0.4, 0.5, 0.0))) {
    EXPECT_FALSE(line.visible);
    EXPECT_EQ(line.visible_length_px, 0.0);
  }
}

}  // namespace
}  // namespace oal
