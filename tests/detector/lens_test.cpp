#include "detector/lens.h"

#include <gtest/gtest.h>
#include <visp3/core/vpPixelMeterConversion.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <vector>

namespace oal {
namespace {

TEST(PointUndistorter, MatchesVispPixelToMetreConversion) {
  vpCameraParameters camera;
  camera.initPersProjWithDistortion(600.0, 590.0, 322.0, 241.0, -0.25, 0.33);
  const PointUndistorter undistorter(camera);
  ASSERT_TRUE(undistorter.active());
  for (double u : {0.0, 100.5, 322.0, 639.0}) {
    for (double v : {0.0, 57.25, 479.0}) {
      double x = 0.0, y = 0.0;
      vpPixelMeterConversion::convertPoint(camera, u, v, x, y);
      const Point2d ideal = undistorter.Undistort({u, v});
      EXPECT_NEAR(ideal.u, 322.0 + 600.0 * x, 1e-9);
      EXPECT_NEAR(ideal.v, 241.0 + 590.0 * y, 1e-9);
    }
  }
}

TEST(PointUndistorter, InactiveWithoutDistortionModel) {
  const vpCameraParameters camera(600.0, 600.0, 320.0, 240.0);
  const PointUndistorter undistorter(camera);
  EXPECT_FALSE(undistorter.active());
  const Point2d p = undistorter.Undistort({12.0, 400.0});
  EXPECT_DOUBLE_EQ(p.u, 12.0);
  EXPECT_DOUBLE_EQ(p.v, 400.0);
}

// Lenses in OpenCV's model: the sample camera of OpenCV's calibration tutorial (its
// out_camera_data.yml), a mild 720p webcam lens and a lens ~100 degrees across at 720p.
struct NamedLens {
  const char* name;
  Lens lens;
  int width, height;
};

std::vector<NamedLens> OpenCvLenses() {
  return {
      {"opencv-sample",
       Lens::WithDistortion(535.9157, 535.9157, 342.2832, 235.5708,
                            {-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392}),
       640, 480},
      {"webcam-720p",
       Lens::WithDistortion(1002.0, 1000.0, 641.2, 357.9, {0.08, -0.15, 0.0004, 0.0002, 0.06}),
       1280, 720},
      {"wide-100",
       Lens::WithDistortion(730.0, 730.0, 642.5, 357.5, {-0.28, 0.08, 0.0006, -0.0004, -0.01}),
       1280, 720},
      {"rational",
       Lens::WithDistortion(600.0, 600.0, 319.5, 239.5,
                            {0.3, 0.02, 0.0, 0.0, 0.0, 0.62, 0.05, 0.0}),
       640, 480},
  };
}

TEST(Lens, OpenCvModelRoundTripsOverTheImage) {
  for (const NamedLens& c : OpenCvLenses()) {
    ASSERT_EQ(c.lens.model(), Lens::Model::kOpenCV) << c.name;
    double worst = 0.0;
    for (int v = 0; v < c.height; v += 7) {
      for (int u = 0; u < c.width; u += 7) {
        const Point2d ideal = c.lens.Normalised(u, v);
        ASSERT_TRUE(std::isfinite(ideal.u)) << c.name << " (" << u << ", " << v << ")";
        const Point2d back = c.lens.Pixel(ideal.u, ideal.v);
        worst = std::max(worst, std::hypot(back.u - u, back.v - v));
      }
    }
    EXPECT_LT(worst, 1e-6) << c.name;
  }
}

TEST(Lens, PixelIsOpenCvsProjection) {
  for (const NamedLens& c : OpenCvLenses()) {
    const auto d = c.lens.distortion().ToArray();
    const cv::Matx33d k(c.lens.px(), 0.0, c.lens.u0(), 0.0, c.lens.py(), c.lens.v0(), 0.0, 0.0,
                        1.0);
    std::vector<cv::Point3d> rays;
    for (double x = -0.8; x <= 0.8; x += 0.2) {
      for (double y = -0.5; y <= 0.5; y += 0.25) rays.emplace_back(x, y, 1.0);
    }
    std::vector<cv::Point2d> projected;
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k,
                      std::vector<double>(d.begin(), d.end()), projected);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Point2d p = c.lens.Pixel(rays[i].x, rays[i].y);
      EXPECT_NEAR(p.u, projected[i].x, 1e-9) << c.name;
      EXPECT_NEAR(p.v, projected[i].y, 1e-9) << c.name;
    }
  }
}

TEST(Lens, NormalisedDerivativeIsTheMapsSlope) {
  std::vector<NamedLens> lenses = OpenCvLenses();
  lenses.push_back({"visp", Lens::WithKdu(600.0, 590.0, 322.0, 241.0, 0.33, 640, 480), 640, 480});
  lenses.push_back({"pinhole", Lens::Pinhole(600.0, 590.0, 322.0, 241.0), 640, 480});
  constexpr double h = 1e-4;
  for (const NamedLens& c : lenses) {
    for (const Point2d& p : {Point2d{13.0, 17.0}, Point2d{0.4 * c.width, 0.8 * c.height},
                             Point2d{c.width - 5.0, 0.5 * c.height}}) {
      const auto d = c.lens.NormalisedDerivative(p.u, p.v, c.lens.Normalised(p.u, p.v));
      const Point2d du = c.lens.Normalised(p.u + h, p.v), du_ = c.lens.Normalised(p.u - h, p.v);
      const Point2d dv = c.lens.Normalised(p.u, p.v + h), dv_ = c.lens.Normalised(p.u, p.v - h);
      EXPECT_NEAR(d[0], (du.u - du_.u) / (2 * h), 1e-8) << c.name;
      EXPECT_NEAR(d[1], (dv.u - dv_.u) / (2 * h), 1e-8) << c.name;
      EXPECT_NEAR(d[2], (du.v - du_.v) / (2 * h), 1e-8) << c.name;
      EXPECT_NEAR(d[3], (dv.v - dv_.v) / (2 * h), 1e-8) << c.name;
    }
  }
}

TEST(Lens, UndistorterMapsToTheIdealPixel) {
  for (const NamedLens& c : OpenCvLenses()) {
    const PointUndistorter undistorter(c.lens);
    ASSERT_TRUE(undistorter.active());
    const Point2d ideal = c.lens.Normalised(21.0, 33.0);
    const Point2d p = undistorter.Undistort({21.0, 33.0});
    EXPECT_NEAR(p.u, c.lens.u0() + c.lens.px() * ideal.u, 1e-9) << c.name;
    EXPECT_NEAR(p.v, c.lens.v0() + c.lens.py() * ideal.v, 1e-9) << c.name;
  }
}

// A short run at a distorted pixel maps as the undistortion moves its two ends: near the
// corners of a strong lens the run is longer on the ideal image than in the distorted one.
TEST(Lens, UndistorterMapsAShortVectorAsItMapsItsEnds) {
  std::vector<NamedLens> lenses = OpenCvLenses();
  lenses.push_back({"visp", Lens::WithKdu(600.0, 590.0, 322.0, 241.0, 0.33, 640, 480), 640, 480});
  lenses.push_back({"pinhole", Lens::Pinhole(600.0, 590.0, 322.0, 241.0), 640, 480});
  for (const NamedLens& c : lenses) {
    const PointUndistorter undistorter(c.lens);
    for (const Point2d& p : {Point2d{13.0, 17.0}, Point2d{0.5 * c.width, 0.5 * c.height},
                             Point2d{c.width - 5.0, c.height - 9.0}}) {
      for (const Point2d& run : {Point2d{0.02, 0.0}, Point2d{-0.012, 0.016}}) {
        const Point2d ideal = undistorter.Undistort(p);
        const Point2d mapped = undistorter.UndistortVector(p, ideal, run);
        const Point2d a = undistorter.Undistort({p.u - 0.5 * run.u, p.v - 0.5 * run.v});
        const Point2d b = undistorter.Undistort({p.u + 0.5 * run.u, p.v + 0.5 * run.v});
        EXPECT_NEAR(mapped.u, b.u - a.u, 1e-7) << c.name << " at " << p.u << ", " << p.v;
        EXPECT_NEAR(mapped.v, b.v - a.v, 1e-7) << c.name << " at " << p.u << ", " << p.v;
      }
    }
  }
}

TEST(Lens, ViSPCameraIsTheBestOneTermApproximation) {
  for (const NamedLens& c : OpenCvLenses()) {
    ASSERT_TRUE(c.lens.IsViSPApproximation());
    const Lens one_term = c.lens.ViSPCamera(c.width, c.height);
    ASSERT_EQ(one_term.model(), Lens::Model::kViSP) << c.name;
    // Moving the fitted kdu either way makes the ideal pixels worse (on another grid).
    const auto error = [&c](double kdu) {
      const Lens l = Lens::WithKudKdu(c.lens.px(), c.lens.py(), c.lens.u0(), c.lens.v0(), 0.0, kdu);
      double sum = 0.0;
      for (int v = 0; v < c.height; v += 16) {
        for (int u = 0; u < c.width; u += 16) {
          const Point2d a = c.lens.Normalised(u, v), b = l.Normalised(u, v);
          sum += std::pow(c.lens.px() * (a.u - b.u), 2) + std::pow(c.lens.py() * (a.v - b.v), 2);
        }
      }
      return sum;
    };
    EXPECT_LT(error(one_term.kdu()), error(one_term.kdu() + 0.03)) << c.name;
    EXPECT_LT(error(one_term.kdu()), error(one_term.kdu() - 0.03)) << c.name;
    EXPECT_NEAR(one_term.kud(), FitKud(one_term, c.width, c.height), 1e-12) << c.name;
  }
  const Lens visp = Lens::WithKdu(600.0, 590.0, 322.0, 241.0, 0.33, 640, 480);
  EXPECT_FALSE(visp.IsViSPApproximation());
  EXPECT_EQ(Lens(visp.ViSPCamera(640, 480)), visp);
}

TEST(Lens, ModelThatFoldsOverIsRefusedAndUnreachedPointsAreNaN) {
  // k1 = -0.6: r (1 - 0.6 r^2) turns back at r^2 = 1 / 1.8, distorted radius 0.50.
  const Lens folding = Lens::WithDistortion(400.0, 400.0, 319.5, 239.5, {-0.6, 0, 0, 0, 0});
  EXPECT_NEAR(folding.max_ideal_r2(), 1.0 / 1.8, 0.003);
  EXPECT_TRUE(std::isnan(folding.Pixel(0.8, 0.0).u));
  EXPECT_TRUE(std::isnan(folding.Normalised(639.0, 479.0).u));  // distorted radius 0.99
  EXPECT_TRUE(std::isfinite(folding.Normalised(330.0, 250.0).u));
  EXPECT_THROW(CheckInvertibleOver(folding, 640, 480, "RenderOptions::camera"),
               std::invalid_argument);
  for (const NamedLens& c : OpenCvLenses()) {
    EXPECT_NO_THROW(CheckInvertibleOver(c.lens, c.width, c.height, "camera")) << c.name;
  }
}

TEST(Lens, ModelNamesAndSpecialCases) {
  EXPECT_EQ(LensModelName(Lens::Pinhole(1, 1, 0, 0)), "perspectiveProjWithoutDistortion");
  EXPECT_EQ(LensModelName(Lens::WithKdu(600, 600, 320, 240, 0.1, 640, 480)),
            "perspectiveProjWithDistortion");
  EXPECT_EQ(LensModelName(OpenCvLenses()[0].lens), "plumb_bob");
  EXPECT_EQ(LensModelName(OpenCvLenses()[3].lens), "rational_polynomial");
  // All-zero coefficients are the pinhole, whichever model was asked for.
  EXPECT_EQ(Lens::WithDistortion(600, 600, 320, 240, Distortion()).model(), Lens::Model::kPinhole);
  EXPECT_EQ(Lens::WithKdu(600, 600, 320, 240, 0.0, 640, 480).model(), Lens::Model::kPinhole);
  vpCameraParameters visp;
  visp.initPersProjWithDistortion(600, 600, 320, 240, 0.0, 0.0);
  EXPECT_EQ(Lens(visp).model(), Lens::Model::kPinhole);
}

}  // namespace
}  // namespace oal
