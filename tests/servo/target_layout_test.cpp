// Points of the target's plane projected through a lens (servo/target_layout.h): the pixel
// PlaneProjector gives maps back, through ViSP's own pixel-to-metre conversion, to the ideal
// point the homography gives, for barrel and pincushion lenses, near and far from the centre.
#include "servo/target_layout.h"

#include <gtest/gtest.h>
#include <visp3/core/vpPixelMeterConversion.h>
#include <visp3/core/vpRxyzVector.h>

#include <cmath>

#include "detector/lens.h"  // CameraWithKdu

namespace oal {
namespace {

TEST(PlaneProjector, ItsPixelsAreViSPsDistortedProjection) {
  // A plane tilted 25 and 15 degrees, 0.45 m away: its points reach normalised radii of 0.9.
  const vpHomogeneousMatrix cMo(vpTranslationVector(0.03, -0.02, 0.45),
                                vpRotationMatrix(vpRxyzVector(0.44, -0.26, 0.7)));
  const vpHomography plane_to_image = PlaneToImage(cMo);
  for (const double kdu : {-0.3, -0.12, 0.0, 0.05, 0.15, 0.4, 1.2}) {
    const vpCameraParameters camera = CameraWithKdu(600.0, 610.0, 319.5, 239.5, kdu, 640, 480);
    const PlaneProjector projector(plane_to_image, camera);
    int projected = 0;
    for (double X = -0.3; X <= 0.3; X += 0.025) {
      for (double Y = -0.3; Y <= 0.3; Y += 0.025) {
        const double w = cMo[2][0] * X + cMo[2][1] * Y + cMo[2][3];
        const double x = (cMo[0][0] * X + cMo[0][1] * Y + cMo[0][3]) / w;
        const double y = (cMo[1][0] * X + cMo[1][1] * Y + cMo[1][3]) / w;
        Point2d pixel;
        if (!projector.Project({X, Y}, &pixel)) {
          // Only a pincushion lens has ideal radii no pixel reaches: beyond its turning point.
          EXPECT_LT(kdu, 0.0);
          EXPECT_GT(x * x + y * y, -4.0 / (27.0 * kdu)) << "X " << X << " Y " << Y;
          continue;
        }
        ++projected;
        double x_back = 0.0, y_back = 0.0;
        vpPixelMeterConversion::convertPoint(camera, pixel.u, pixel.v, x_back, y_back);
        EXPECT_NEAR(x_back, x, 1e-9) << "kdu " << kdu << " X " << X << " Y " << Y;
        EXPECT_NEAR(y_back, y, 1e-9) << "kdu " << kdu << " X " << X << " Y " << Y;
      }
    }
    EXPECT_GT(projected, 300) << "kdu " << kdu;
  }
}

}  // namespace
}  // namespace oal
