#include "base/pose_distance.h"

#include <gtest/gtest.h>
#include <visp3/core/vpThetaUVector.h>

#include <cmath>
#include <random>

#include "base/angles.h"

namespace oal {
namespace {

// What the distance means: ViSP's a^-1 b, its translation's norm and its theta-u angle.
PoseDistance ThroughViSP(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  const vpHomogeneousMatrix aMb = a.inverse() * b;
  return PoseDistance{aMb.getTranslationVector().frobeniusNorm(),
                      vpThetaUVector(aMb.getRotationMatrix()).getTheta()};
}

vpHomogeneousMatrix RandomPose(std::mt19937* random, double max_angle) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  vpColVector axis(3);
  for (int i = 0; i < 3; ++i) axis[i] = unit(*random);
  axis.normalize();
  const double angle = max_angle * (0.5 + 0.5 * unit(*random));
  return vpHomogeneousMatrix(unit(*random), unit(*random), 1.0 + unit(*random), angle * axis[0],
                             angle * axis[1], angle * axis[2]);
}

TEST(PoseDistance, IsViSPsInverseProductAndThetaU) {
  std::mt19937 random(7);
  for (const double max_angle : {1e-6, 0.01, 1.0, 3.0}) {
    for (int i = 0; i < 200; ++i) {
      const vpHomogeneousMatrix a = RandomPose(&random, kPi);
      const vpHomogeneousMatrix b = a * RandomPose(&random, max_angle);
      const PoseDistance ours = Distance(a, b), visp = ThroughViSP(a, b);
      EXPECT_NEAR(ours.translation_m, visp.translation_m, 1e-12);
      EXPECT_NEAR(ours.rotation_rad, visp.rotation_rad, 1e-9) << "max angle " << max_angle;
    }
  }
}

TEST(PoseDistance, TellsTinyTurnsAndHalfTurns) {
  const vpHomogeneousMatrix a(0.1, -0.2, 0.5, 0.3, -0.1, 0.2);
  // A microradian (a pose jump's threshold is a fraction of a degree) and a half turn, where
  // the cosine alone loses the angle.
  for (const double angle : {1e-6, 1e-3, kPi - 1e-6, kPi}) {
    const vpHomogeneousMatrix b = a * vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, angle, 0.0);
    EXPECT_NEAR(Distance(a, b).rotation_rad, angle, 1e-9) << angle;
    EXPECT_NEAR(Distance(a, b).translation_m, 0.0, 1e-15);
  }
  const vpHomogeneousMatrix moved = vpHomogeneousMatrix(0.003, -0.004, 0.0, 0.0, 0.0, 0.0) * a;
  EXPECT_NEAR(Distance(a, moved).translation_m, 0.005, 1e-15);
  EXPECT_NEAR(Distance(a, moved).rotation_rad, 0.0, 1e-12);
}

}  // namespace
}  // namespace oal
