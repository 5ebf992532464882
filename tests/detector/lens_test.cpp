#include "detector/lens.h"

#include <gtest/gtest.h>
#include <visp3/core/vpPixelMeterConversion.h>

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

}  // namespace
}  // namespace oal
