#include "robots/scorbot_kinematics.h"

#include <visp3/core/vpMath.h>

#include <cmath>
#include <optional>
#include <sstream>

#include "base/check.h"
#include "base/format.h"

namespace oal {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kLimitSlackRad = 1e-9;
constexpr const char* kAxisName[5] = {"base", "shoulder", "elbow", "pitch", "roll"};

double Deg(double rad) {
  return rad * 180.0 / kPi;
}
double Rad(double deg) {
  return deg * kPi / 180.0;
}

// Angle wrapped into (-pi, pi].
double Wrap(double a) {
  a = std::remainder(a, 2 * kPi);
  return a <= -kPi ? a + 2 * kPi : a;
}

vpColVector Vec3(double x, double y, double z) {
  vpColVector v(3);
  v[0] = x;
  v[1] = y;
  v[2] = z;
  return v;
}

vpColVector Column(const vpRotationMatrix& R, unsigned c) {
  return Vec3(R[0][c], R[1][c], R[2][c]);
}

double Dot(const vpColVector& a, const vpColVector& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

vpColVector Cross(const vpColVector& a, const vpColVector& b) {
  return Vec3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

std::string FormatDeg(double rad) {
  return Number(Deg(rad), 4);
}

// The vertical plane through the base axis and the TCP of wMe, in which a 5-axis arm's tool
// axis must lie: its azimuth q1 (joint 1), the TCP's distance r from the base axis, the
// unit radial direction u and normal n, and wMe's rotation R. None when the TCP is on the
// base axis, where the plane is undefined.
struct ArmPlane {
  double q1 = 0.0, r = 0.0;
  vpColVector u, n;
  vpRotationMatrix R;
};

std::optional<ArmPlane> ArmPlaneOf(const vpHomogeneousMatrix& wMe) {
  ArmPlane plane;
  plane.r = std::hypot(wMe[0][3], wMe[1][3]);
  if (plane.r < 1e-9) return std::nullopt;
  plane.q1 = std::atan2(wMe[1][3], wMe[0][3]);
  plane.u = Vec3(std::cos(plane.q1), std::sin(plane.q1), 0);
  plane.n = Vec3(-std::sin(plane.q1), std::cos(plane.q1), 0);
  plane.R = wMe.getRotationMatrix();
  return plane;
}

// The part of NearestReachable that does not look at the joints: position kept, tool axis
// projected into the arm plane, roll chosen.
bool ProjectOrientation(const vpHomogeneousMatrix& wMe, vpHomogeneousMatrix* out,
                        std::string* why) {
  const std::optional<ArmPlane> plane = ArmPlaneOf(wMe);
  if (!plane) {
    *why = "the TCP is on the base axis: the arm plane is undefined";
    return false;
  }
  const double q1 = plane->q1;
  const vpColVector &u = plane->u, &n = plane->n;
  const vpRotationMatrix& R = plane->R;
  const vpColVector a = Column(R, 2);
  const vpColVector ap = a - Dot(a, n) * n;
  if (ap.frobeniusNorm() < 1e-6) {
    *why = "the tool axis is perpendicular to the arm plane: no 5-axis pose is near";
    return false;
  }
  const double theta = std::atan2(ap[2], Dot(ap, u));
  const vpRotationMatrix B = ToolRotation(q1, theta, 0);
  const vpMatrix M = static_cast<vpMatrix>(B.t()) * static_cast<vpMatrix>(R);
  const double roll = std::atan2(M[1][0] - M[0][1], M[0][0] + M[1][1]);
  *out = vpHomogeneousMatrix(wMe.getTranslationVector(), ToolRotation(q1, theta, roll));
  return true;
}

}  // namespace

void ScorbotGeometry::Check() const {
  const std::string p = "ScorbotGeometry::";
  RequireOption(shoulder_height_m > 0 && std::isfinite(shoulder_height_m), p + "shoulder_height_m",
                shoulder_height_m, "finite and > 0");
  RequireOption(shoulder_offset_m >= 0 && std::isfinite(shoulder_offset_m), p + "shoulder_offset_m",
                shoulder_offset_m, "finite and >= 0");
  RequireOption(upper_arm_m > 0 && std::isfinite(upper_arm_m), p + "upper_arm_m", upper_arm_m,
                "finite and > 0");
  RequireOption(forearm_m > 0 && std::isfinite(forearm_m), p + "forearm_m", forearm_m,
                "finite and > 0");
  RequireOption(pitch_to_flange_m > 0 && std::isfinite(pitch_to_flange_m), p + "pitch_to_flange_m",
                pitch_to_flange_m, "finite and > 0");
  RequireOption(tool_length_m >= 0 && std::isfinite(tool_length_m), p + "tool_length_m",
                tool_length_m, "finite and >= 0");
  for (int i = 0; i < 5; ++i) {
    const std::string idx = "[" + std::to_string(i) + "]";
    RequireOption(std::isfinite(joint_min_deg[i]) && std::isfinite(joint_max_deg[i]) &&
                      joint_min_deg[i] < joint_max_deg[i] &&
                      joint_max_deg[i] - joint_min_deg[i] <= 360,
                  p + "joint_min_deg/joint_max_deg" + idx,
                  std::to_string(joint_min_deg[i]) + " / " + std::to_string(joint_max_deg[i]),
                  "finite, min < max, max - min <= 360");
    RequireOption(home_deg[i] >= joint_min_deg[i] && home_deg[i] <= joint_max_deg[i],
                  p + "home_deg" + idx, home_deg[i], "inside [joint_min_deg, joint_max_deg]");
    RequireOption(counts_per_deg[i] > 0 && std::isfinite(counts_per_deg[i]),
                  p + "counts_per_deg" + idx, counts_per_deg[i], "finite and > 0");
  }
}

vpRotationMatrix ToolRotation(double q1, double theta, double roll) {
  const double c1 = std::cos(q1), s1 = std::sin(q1);
  const double ct = std::cos(theta), st = std::sin(theta);
  const double cr = std::cos(roll), sr = std::sin(roll);
  // Columns in the arm-plane frame (radial, normal, up): x0 = (-st, 0, ct), y0 = (0, -1, 0),
  // a = (ct, 0, st); rotated by the base angle, then by the roll about a.
  const vpColVector x0 = Vec3(-st * c1, -st * s1, ct);
  const vpColVector y0 = Vec3(s1, -c1, 0);
  const vpColVector a = Vec3(ct * c1, ct * s1, st);
  const vpColVector x = cr * x0 + sr * y0;
  const vpColVector y = -sr * x0 + cr * y0;
  vpRotationMatrix R;
  for (unsigned i = 0; i < 3; ++i) {
    R[i][0] = x[i];
    R[i][1] = y[i];
    R[i][2] = a[i];
  }
  return R;
}

vpHomogeneousMatrix ForwardKinematics(const ScorbotGeometry& g, const ScorbotJoints& q) {
  const double t2 = q[1], t23 = q[1] + q[2], theta = q[1] + q[2] + q[3];
  const double r = g.shoulder_offset_m + g.upper_arm_m * std::cos(t2) +
                   g.forearm_m * std::cos(t23) + g.wrist_to_tcp_m() * std::cos(theta);
  const double z = g.shoulder_height_m + g.upper_arm_m * std::sin(t2) +
                   g.forearm_m * std::sin(t23) + g.wrist_to_tcp_m() * std::sin(theta);
  const vpTranslationVector t(r * std::cos(q[0]), r * std::sin(q[0]), z);
  return vpHomogeneousMatrix(t, ToolRotation(q[0], theta, q[4]));
}

int JointLimitViolation(const ScorbotGeometry& g, const ScorbotJoints& q) {
  for (int i = 0; i < 5; ++i) {
    if (!(q[i] >= Rad(g.joint_min_deg[i]) - kLimitSlackRad &&
          q[i] <= Rad(g.joint_max_deg[i]) + kLimitSlackRad)) {
      return i + 1;
    }
  }
  return 0;
}

ScorbotIk InverseKinematics(const ScorbotGeometry& g, const vpHomogeneousMatrix& wMe,
                            double plane_tol_rad) {
  ScorbotIk ik;
  const std::optional<ArmPlane> plane = ArmPlaneOf(wMe);
  if (!plane) {
    ik.why = "the TCP is on the base axis";
    return ik;
  }
  const double q1 = plane->q1, r = plane->r, pz = wMe[2][3];
  const vpColVector &u = plane->u, &n = plane->n;
  const vpRotationMatrix& R = plane->R;
  const vpColVector a = Column(R, 2);
  if (std::abs(Dot(a, n)) > std::sin(plane_tol_rad)) {
    ik.why = "the tool axis is " + FormatDeg(std::asin(std::min(1.0, std::abs(Dot(a, n))))) +
             " deg out of the arm plane (5 axes: the yaw follows the base)";
    return ik;
  }
  const double theta = std::atan2(a[2], Dot(a, u));
  const double L = g.wrist_to_tcp_m();
  const double dr = r - L * std::cos(theta) - g.shoulder_offset_m;
  const double dz = pz - L * std::sin(theta) - g.shoulder_height_m;
  const double a2 = g.upper_arm_m, a3 = g.forearm_m;
  double D = (dr * dr + dz * dz - a2 * a2 - a3 * a3) / (2 * a2 * a3);
  if (std::abs(D) > 1 + 1e-9) {
    std::ostringstream s;
    s.precision(4);
    s << "the wrist is " << std::hypot(dr, dz) * 1e3 << " mm from the shoulder, outside the reach ["
      << std::abs(a2 - a3) * 1e3 << ", " << (a2 + a3) * 1e3 << "] mm";
    ik.why = s.str();
    return ik;
  }
  D = std::max(-1.0, std::min(1.0, D));
  const double q3 = -std::acos(D);  // elbow up
  const double q2 = std::atan2(dz, dr) - std::atan2(a3 * std::sin(q3), a2 + a3 * std::cos(q3));
  const double q4 = Wrap(theta - q2 - q3);
  const vpRotationMatrix B = ToolRotation(q1, theta, 0);
  const vpColVector x = Column(R, 0);
  const double q5 = std::atan2(Dot(x, Column(B, 1)), Dot(x, Column(B, 0)));
  ik.q = {q1, Wrap(q2), Wrap(q3), q4, q5};
  if (const int axis = JointLimitViolation(g, ik.q)) {
    ik.axis = axis;
    ik.why = std::string("joint ") + std::to_string(axis) + " (" + kAxisName[axis - 1] + ") at " +
             FormatDeg(ik.q[axis - 1]) + " deg is outside its range [" +
             std::to_string(g.joint_min_deg[axis - 1]) + ", " +
             std::to_string(g.joint_max_deg[axis - 1]) + "] deg";
    return ik;
  }
  ik.ok = true;
  return ik;
}

ScorbotReach NearestReachable(const ScorbotGeometry& g, const vpHomogeneousMatrix& wMe_target) {
  ScorbotReach reach;
  if (!ProjectOrientation(wMe_target, &reach.wMe, &reach.why)) return reach;
  const ScorbotIk ik = InverseKinematics(g, reach.wMe, 1e-6);
  if (!ik.ok) {
    reach.why = ik.why;
    return reach;
  }
  reach.q = ik.q;
  reach.ok = true;
  return reach;
}

ScorbotReach NearestReachable(const ScorbotGeometry& g, const vpHomogeneousMatrix& wMx_target,
                              const vpHomogeneousMatrix& eMx) {
  const vpHomogeneousMatrix xMe = eMx.inverse();
  vpHomogeneousMatrix wMe_d = wMx_target * xMe;
  ScorbotReach reach;
  vpHomogeneousMatrix projected;
  for (int k = 0; k < 50; ++k) {
    if (!ProjectOrientation(wMe_d, &projected, &reach.why)) return reach;
    const vpTranslationVector err =
        wMx_target.getTranslationVector() - (projected * eMx).getTranslationVector();
    if (err.frobeniusNorm() < 1e-10) break;
    const vpTranslationVector t = wMe_d.getTranslationVector() + err;
    wMe_d.insert(t);
  }
  const ScorbotIk ik = InverseKinematics(g, projected, 1e-6);
  if (!ik.ok) {
    reach.why = ik.why;
    return reach;
  }
  reach.wMe = projected;
  reach.q = ik.q;
  reach.ok = true;
  return reach;
}

vpHomogeneousMatrix FromAclPose(const AclPose& pose) {
  const double x = pose.x * 1e-4, y = pose.y * 1e-4, z = pose.z * 1e-4;
  const double q1 = (pose.x == 0 && pose.y == 0) ? 0.0 : std::atan2(y, x);
  return vpHomogeneousMatrix(vpTranslationVector(x, y, z),
                             ToolRotation(q1, Rad(pose.p * 0.1), Rad(pose.r * 0.1)));
}

AclPose ToAclPose(const vpHomogeneousMatrix& wMe) {
  const double px = wMe[0][3], py = wMe[1][3];
  const double q1 = std::hypot(px, py) < 1e-12 ? 0.0 : std::atan2(py, px);
  const vpRotationMatrix R = wMe.getRotationMatrix();
  const vpColVector a = Column(R, 2);
  const double theta = std::atan2(a[2], a[0] * std::cos(q1) + a[1] * std::sin(q1));
  const vpRotationMatrix B = ToolRotation(q1, theta, 0);
  const vpColVector x = Column(R, 0);
  const double roll = std::atan2(Dot(x, Column(B, 1)), Dot(x, Column(B, 0)));
  AclPose p;
  p.x = std::lround(px * 1e4);
  p.y = std::lround(py * 1e4);
  p.z = std::lround(wMe[2][3] * 1e4);
  p.p = std::lround(Deg(theta) * 10);
  p.r = std::lround(Deg(roll) * 10);
  return p;
}

AclPose AclPoseOfJoints(const ScorbotGeometry& g, const ScorbotJoints& q) {
  AclPose p = ToAclPose(ForwardKinematics(g, q));
  // Pitch and roll straight from the joints (no wrap-around ambiguity).
  p.p = std::lround(Deg(q[1] + q[2] + q[3]) * 10);
  p.r = std::lround(Deg(q[4]) * 10);
  return p;
}

ScorbotCounts ToCounts(const ScorbotGeometry& g, const ScorbotJoints& q) {
  ScorbotCounts c{};
  for (int i = 0; i < 5; ++i) {
    c[i] = std::lround(Deg(q[i] - Rad(g.home_deg[i])) * g.counts_per_deg[i]);
  }
  return c;
}

ScorbotJoints FromCounts(const ScorbotGeometry& g, const ScorbotCounts& counts) {
  ScorbotJoints q{};
  for (int i = 0; i < 5; ++i) {
    q[i] = Rad(g.home_deg[i] + static_cast<double>(counts[i]) / g.counts_per_deg[i]);
  }
  return q;
}

ScorbotJoints HomeJoints(const ScorbotGeometry& g) {
  ScorbotJoints q{};
  for (int i = 0; i < 5; ++i) q[i] = Rad(g.home_deg[i]);
  return q;
}

vpMatrix EndEffectorJacobian(const ScorbotGeometry& g, const ScorbotJoints& q) {
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  const vpHomogeneousMatrix wMe = ForwardKinematics(g, q);
  const vpColVector p = Vec3(wMe[0][3], wMe[1][3], wMe[2][3]);
  // Points on the shoulder, elbow and pitch axes, and those axes (-n: raising is positive).
  const double t2 = q[1], t23 = q[1] + q[2];
  const double r_s = g.shoulder_offset_m, z_s = g.shoulder_height_m;
  const double r_e = r_s + g.upper_arm_m * std::cos(t2), z_e = z_s + g.upper_arm_m * std::sin(t2);
  const double r_w = r_e + g.forearm_m * std::cos(t23), z_w = z_e + g.forearm_m * std::sin(t23);
  const vpColVector o[3] = {Vec3(r_s * c1, r_s * s1, z_s), Vec3(r_e * c1, r_e * s1, z_e),
                            Vec3(r_w * c1, r_w * s1, z_w)};
  const vpColVector k = Vec3(s1, -c1, 0);
  const vpColVector zw = Vec3(0, 0, 1);
  const vpRotationMatrix R = wMe.getRotationMatrix();
  const vpColVector a = Column(R, 2);
  vpMatrix wJ(6, 5, 0.0);
  auto set = [&wJ](unsigned col, const vpColVector& v, const vpColVector& w) {
    for (unsigned i = 0; i < 3; ++i) {
      wJ[i][col] = v[i];
      wJ[i + 3][col] = w[i];
    }
  };
  set(0, Cross(zw, p), zw);
  for (unsigned j = 0; j < 3; ++j) set(j + 1, Cross(k, p - o[j]), k);
  set(4, Vec3(0, 0, 0), a);
  vpMatrix RtRt(6, 6, 0.0);
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) {
      RtRt[i][j] = R[j][i];
      RtRt[i + 3][j + 3] = R[j][i];
    }
  }
  return RtRt * wJ;
}

}  // namespace oal
