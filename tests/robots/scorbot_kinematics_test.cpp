// Scorbot ER-VII kinematics: FK/IK round trips at random joints, the ACL pose conversions, the
// 5-axis projection (NearestReachable), the Jacobian against finite differences, limits.
#include "robots/scorbot_kinematics.h"

#include <gtest/gtest.h>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpRzyxVector.h>

#include <random>
#include <stdexcept>

#include "base/angles.h"
#include "robots/robot.h"

namespace oal {
namespace {

constexpr double kTolM = 1e-9;
constexpr double kTolRad = 1e-9;

ScorbotJoints RandomJoints(const ScorbotGeometry& g, std::mt19937& rng) {
  ScorbotJoints q{};
  for (int i = 0; i < 5; ++i) {
    std::uniform_real_distribution<double> u(vpMath::rad(g.joint_min_deg[i]),
                                             vpMath::rad(g.joint_max_deg[i]));
    q[i] = u(rng);
  }
  return q;
}

void ExpectPoseNear(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b, double tol_m,
                    double tol_rad) {
  const PoseDistance d = Distance(a, b);
  EXPECT_LE(d.translation_m, tol_m);
  EXPECT_LE(d.rotation_rad, tol_rad);
}

TEST(ScorbotKinematics, HomeHasTheToolPointingStraightDown) {
  const ScorbotGeometry g;
  const vpHomogeneousMatrix wMe = ForwardKinematics(g, HomeJoints(g));
  // r = 50 + 300 cos60 + 250 cos(-30) mm, z = 358.5 + 300 sin60 - 250 sin30 - 251 mm.
  EXPECT_NEAR(wMe[0][3], 0.050 + 0.150 + 0.250 * std::cos(kPi / 6), 1e-12);
  EXPECT_NEAR(wMe[1][3], 0.0, 1e-12);
  EXPECT_NEAR(wMe[2][3], 0.3585 + 0.300 * std::sin(kPi / 3) - 0.125 - 0.251, 1e-12);
  EXPECT_NEAR(wMe[2][2], -1.0, 1e-12);  // z_e = -Z
  EXPECT_NEAR(wMe[0][0], 1.0, 1e-12);   // x_e radial (forward)
  const AclPose p = AclPoseOfJoints(g, HomeJoints(g));
  EXPECT_EQ(p.p, -900);
  EXPECT_EQ(p.r, 0);
  EXPECT_EQ(p.y, 0);
  const ScorbotCounts c = ToCounts(g, HomeJoints(g));
  for (long v : c) EXPECT_EQ(v, 0);
}

TEST(ScorbotKinematics, ForwardInverseRoundTripAtRandomJoints) {
  const ScorbotGeometry g;
  std::mt19937 rng(20261123);
  int solved = 0, elbow_up = 0;
  const int trials = 10000;
  for (int k = 0; k < trials; ++k) {
    const ScorbotJoints q = RandomJoints(g, rng);
    const vpHomogeneousMatrix wMe = ForwardKinematics(g, q);
    if (std::hypot(wMe[0][3], wMe[1][3]) < 0.02) continue;  // near the base axis
    // The tool may end up behind the base axis (arm folded back): not the IK's branch.
    const double r_dir = wMe[0][3] * std::cos(q[0]) + wMe[1][3] * std::sin(q[0]);
    if (r_dir <= 0) continue;
    const ScorbotIk ik = InverseKinematics(g, wMe, 1e-6);
    if (!ik.ok) {
      // Only the other elbow branch may fail, on a joint limit.
      EXPECT_GT(q[2], 0) << "trial " << k << ": " << ik.why;
      continue;
    }
    ++solved;
    ExpectPoseNear(ForwardKinematics(g, ik.q), wMe, kTolM, kTolRad);
    if (q[2] < -1e-6) {
      ++elbow_up;
      for (int i = 0; i < 5; ++i) EXPECT_NEAR(ik.q[i], q[i], 1e-7) << "trial " << k << " q" << i;
    }
  }
  EXPECT_GT(solved, trials / 2);
  EXPECT_GT(elbow_up, trials / 3);
}

TEST(ScorbotKinematics, CountsRoundTrip) {
  const ScorbotGeometry g;
  std::mt19937 rng(5);
  for (int k = 0; k < 1000; ++k) {
    const ScorbotJoints q = RandomJoints(g, rng);
    const ScorbotJoints back = FromCounts(g, ToCounts(g, q));
    for (int i = 0; i < 5; ++i) {
      EXPECT_LE(std::abs(back[i] - q[i]), vpMath::rad(0.5 / g.counts_per_deg[i]) + 1e-12);
    }
  }
}

TEST(ScorbotKinematics, AclPoseRoundTrip) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<long> xy(-6000, 6000), z(0, 9000), pitch(-1800, 1799),
      roll(-1799, 1800);
  for (int k = 0; k < 2000; ++k) {
    AclPose p;
    p.x = xy(rng);
    p.y = xy(rng);
    p.z = z(rng);
    p.p = pitch(rng);
    p.r = roll(rng);
    if (std::abs(p.p) > 899 && std::abs(p.p) < 901) continue;  // tool vertical: fine, but
    if (p.x == 0 && p.y == 0) continue;
    const AclPose back = ToAclPose(FromAclPose(p));
    if (std::abs(p.p) > 900) {
      // A pitch beyond the vertical is the same axis as 180 - P with the base turned by pi:
      // ACL's P is within [-90, 90] deg for a TCP in front of the base axis.
      continue;
    }
    EXPECT_EQ(back, p) << "trial " << k;
  }
}

TEST(ScorbotKinematics, NearestReachableKeepsReachablePosesAndProjectsOthers) {
  const ScorbotGeometry g;
  std::mt19937 rng(3);
  int checked = 0;
  for (int k = 0; k < 500; ++k) {
    const ScorbotJoints q = RandomJoints(g, rng);
    if (q[2] > 0) continue;  // elbow-up branch only
    const vpHomogeneousMatrix wMe = ForwardKinematics(g, q);
    if (std::hypot(wMe[0][3], wMe[1][3]) < 0.05) continue;
    const double r_dir = wMe[0][3] * std::cos(q[0]) + wMe[1][3] * std::sin(q[0]);
    if (r_dir <= 0) continue;
    const ScorbotReach same = NearestReachable(g, wMe);
    ASSERT_TRUE(same.ok) << same.why;
    ExpectPoseNear(same.wMe, wMe, 1e-9, 1e-9);
    // Add a yaw about the world Z through the TCP: 5 axes cannot follow it.
    const double yaw = vpMath::rad(10);
    vpHomogeneousMatrix yawed = wMe;
    yawed.insert(vpRotationMatrix(vpRzyxVector(yaw, 0, 0)) * wMe.getRotationMatrix());
    const ScorbotReach r = NearestReachable(g, yawed);
    if (!r.ok) continue;  // the projection may leave the pitch range
    ++checked;
    // The position is kept, the orientation moves toward the request and is reachable.
    EXPECT_NEAR((r.wMe.getTranslationVector() - yawed.getTranslationVector()).frobeniusNorm(), 0,
                1e-12);
    EXPECT_LE(Distance(r.wMe, yawed).rotation_rad, yaw + 1e-9);
    EXPECT_TRUE(InverseKinematics(g, r.wMe, 1e-9).ok);
    // Idempotent.
    const ScorbotReach again = NearestReachable(g, r.wMe);
    ASSERT_TRUE(again.ok);
    ExpectPoseNear(again.wMe, r.wMe, 1e-9, 1e-9);
  }
  EXPECT_GT(checked, 50);
}

TEST(ScorbotKinematics, NearestReachableOfACameraKeepsTheCameraPosition) {
  const ScorbotGeometry g;
  const vpHomogeneousMatrix eMc(0.03, -0.02, 0.05, 0.1, -0.05, 0.2);
  const vpHomogeneousMatrix wMe = ForwardKinematics(g, HomeJoints(g));
  vpHomogeneousMatrix wMc = wMe * eMc;
  wMc.insert(vpRotationMatrix(vpRzyxVector(vpMath::rad(8), 0, 0)) * wMc.getRotationMatrix());
  const ScorbotReach r = NearestReachable(g, wMc, eMc);
  ASSERT_TRUE(r.ok) << r.why;
  const vpHomogeneousMatrix reached = r.wMe * eMc;
  EXPECT_NEAR((reached.getTranslationVector() - wMc.getTranslationVector()).frobeniusNorm(), 0,
              1e-9);
  EXPECT_TRUE(InverseKinematics(g, r.wMe, 1e-9).ok);
}

TEST(ScorbotKinematics, OutOfReachAndOutOfRangeSayWhy) {
  const ScorbotGeometry g;
  AclPose far;
  far.x = 12000;  // 1.2 m: beyond the reach
  far.z = 3000;
  far.p = -900;
  const ScorbotIk a = InverseKinematics(g, FromAclPose(far));
  EXPECT_FALSE(a.ok);
  EXPECT_EQ(a.axis, 0);
  EXPECT_NE(a.why.find("outside the reach"), std::string::npos) << a.why;
  AclPose behind;  // base at 170 deg: outside [-125, 125]
  behind.x = std::lround(-4000 * std::cos(vpMath::rad(10)));
  behind.y = std::lround(4000 * std::sin(vpMath::rad(10)));
  behind.z = 2500;
  behind.p = -900;
  const ScorbotIk b = InverseKinematics(g, FromAclPose(behind));
  EXPECT_FALSE(b.ok);
  EXPECT_EQ(b.axis, 1);
  EXPECT_NE(b.why.find("joint 1 (base)"), std::string::npos) << b.why;
  AclPose level;  // tool horizontal, then turned about the vertical: out of the arm plane
  level.x = 4000;
  level.z = 4000;
  vpHomogeneousMatrix tilted = FromAclPose(level);
  tilted.insert(vpRotationMatrix(vpRzyxVector(0.3, 0, 0)) * tilted.getRotationMatrix());
  const ScorbotIk c = InverseKinematics(g, tilted);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.why.find("out of the arm plane"), std::string::npos) << c.why;
}

TEST(ScorbotKinematics, JacobianMatchesFiniteDifferences) {
  const ScorbotGeometry g;
  std::mt19937 rng(17);
  const double h = 1e-6;
  for (int k = 0; k < 200; ++k) {
    const ScorbotJoints q = RandomJoints(g, rng);
    const vpMatrix J = EndEffectorJacobian(g, q);
    ASSERT_EQ(J.getRows(), 6u);
    ASSERT_EQ(J.getCols(), 5u);
    const vpHomogeneousMatrix wMe = ForwardKinematics(g, q);
    for (unsigned j = 0; j < 5; ++j) {
      ScorbotJoints qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      // The twist in e that takes wMe(q - h) to wMe(q + h) over 2h.
      const vpColVector v = vpExponentialMap::inverse(
          ForwardKinematics(g, qm).inverse() * ForwardKinematics(g, qp), 2 * h);
      for (unsigned i = 0; i < 6; ++i) EXPECT_NEAR(J[i][j], v[i], 1e-6) << "k " << k << " " << i;
    }
    (void)wMe;
  }
}

TEST(ScorbotKinematics, GeometryCheckNamesTheField) {
  ScorbotGeometry g;
  g.forearm_m = -0.25;
  try {
    g.Check();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ScorbotGeometry::forearm_m = -0.25"), std::string::npos)
        << e.what();
  }
  g = ScorbotGeometry();
  g.home_deg[1] = 150;
  EXPECT_THROW(g.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace oal
