// Kinematics of the Scorbot ER-VII (5 axes: base, shoulder, elbow, pitch, roll).
//
// FRAMES AND CONVENTIONS (ours; what the real controller does is noted in docs/SCORBOT.md)
//   w  the robot base frame = the world: origin on the base axis at floor level, Z up along the
//      base axis, X forward (base joint at 0), Y to the left (right-handed).
//   e  the tool centre point (TCP) frame, at pitch_to_flange_m + tool_length_m from the pitch
//      axis along the tool axis: z_e along the tool axis pointing out of the flange; with roll 0,
//      x_e lies in the arm's vertical plane on the "upper" side of the tool (for a tool pointing
//      straight down, x_e points radially away from the base), y_e = z_e x x_e.
//   Joints q (radians), in the order of the controller's axes 1..5:
//      q1 base     rotation of the arm plane about Z, 0 = arm along +X, positive counter-clockwise
//                  seen from above;
//      q2 shoulder elevation of the upper arm above the horizontal, positive up;
//      q3 elbow    angle of the forearm relative to the upper arm, positive up (same sense as q2);
//      q4 pitch    angle of the tool axis relative to the forearm, positive up (same sense);
//      q5 roll     rotation of the tool about its own axis, right-handed about +z_e.
//   Chain in the arm plane (radial r, height z): the shoulder axis is at
//   (shoulder_offset_m, shoulder_height_m); the elbow at upper_arm_m along q2; the pitch axis
//   at forearm_m along q2+q3; the TCP at (pitch_to_flange_m + tool_length_m) along
//   q2+q3+q4.
//   ACL Cartesian pose (AclPose): X, Y, Z of the TCP in tenths of a millimetre, P = the tool
//   axis' angle above the horizontal (absolute pitch q2+q3+q4) and R = q5, both in tenths of a
//   degree. So P = -900 points the tool straight down, P = 0 horizontal and outward. The yaw of
//   the tool is not free: it is the base angle atan2(Y, X).
//   Encoder counts: count_i = round((q_i - home_i) * counts_per_deg_i * 180/pi): 0 at the home
//   position (what HOME leaves on the encoders).
//
// WHAT 5 AXES CAN DO
//   The tool axis always lies in the vertical plane through the base axis and the TCP (the arm
//   plane). NearestReachable() keeps the requested TCP position, takes the plane through it and
//   the base axis, projects the requested tool axis into that plane (nearest direction in the
//   plane), and picks the roll that minimises the Frobenius distance between the requested and
//   the reachable rotation (closed form: atan2 of the relevant entries of B^T R). For a pose of
//   another frame rigidly attached to e (the camera, through eMc) the position of that frame is
//   kept instead, by a fixed-point iteration on the TCP position (the offset is small).
//   The pose is then checked against the joint limits through the inverse kinematics
//   (elbow-up solution).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMatrix.h>

#include <array>
#include <string>

namespace oal {

/// Joint angles of axes 1..5 (base, shoulder, elbow, pitch, roll), radians.
using ScorbotJoints = std::array<double, 5>;
/// Encoder counts of axes 1..5.
using ScorbotCounts = std::array<long, 5>;

/// Geometry and joint limits of the arm. Lengths: the ER-VII data sheet's values; how the joint
/// ranges sit around zero and the encoder resolution are ours and unverified on hardware
/// (docs/SCORBOT.md).
struct ScorbotGeometry {
  /// Height of the shoulder axis above the base plane, m; > 0.
  double shoulder_height_m = 0.3585;
  /// Radial offset of the shoulder axis from the base axis, m; >= 0.
  double shoulder_offset_m = 0.050;
  /// Shoulder axis to elbow axis, m; > 0.
  double upper_arm_m = 0.300;
  /// Elbow axis to pitch axis, m; > 0.
  double forearm_m = 0.250;
  /// Pitch axis to the flange, m; > 0.
  double pitch_to_flange_m = 0.251;
  /// Flange to the tool centre point along the tool axis, m; >= 0.
  double tool_length_m = 0.0;
  /// Joint ranges, degrees; min < max. Spans from the data sheet (250, 170, 225, 180, 360).
  std::array<double, 5> joint_min_deg{-125.0, -35.0, -112.5, -90.0, -180.0};
  std::array<double, 5> joint_max_deg{125.0, 135.0, 112.5, 90.0, 180.0};
  /// Joint angles at the home position (encoder counts 0), degrees; inside the ranges.
  /// Default: upper arm 60 deg up, forearm 30 deg down, tool pointing straight down.
  std::array<double, 5> home_deg{0.0, 60.0, -90.0, -60.0, 0.0};
  /// Encoder counts per degree of each joint; > 0. Placeholder values (unverified).
  std::array<double, 5> counts_per_deg{100.0, 100.0, 100.0, 50.0, 50.0};

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
  /// Pitch axis to TCP, m.
  double wrist_to_tcp_m() const { return pitch_to_flange_m + tool_length_m; }
};

/// A Cartesian position as ACL reports and takes it: X, Y, Z in tenths of a millimetre, P and R
/// in tenths of a degree (see the file comment for the pitch convention).
struct AclPose {
  long x = 0, y = 0, z = 0, p = 0, r = 0;
  bool operator==(const AclPose& o) const {
    return x == o.x && y == o.y && z == o.z && p == o.p && r == o.r;
  }
  bool operator!=(const AclPose& o) const { return !(*this == o); }
};

/// Outcome of an inverse kinematics or reachability computation.
struct ScorbotIk {
  bool ok = false;
  ScorbotJoints q{};
  int axis = 0;     ///< 1..5: the joint whose limit is violated; 0: geometry (out of reach)
  std::string why;  ///< when !ok: one line
};

/// Outcome of NearestReachable.
struct ScorbotReach {
  bool ok = false;
  vpHomogeneousMatrix wMe;  ///< the reachable TCP pose (when ok)
  ScorbotJoints q{};        ///< its joints
  std::string why;
};

/// wMe of joints q (no limit check).
vpHomogeneousMatrix ForwardKinematics(const ScorbotGeometry& g, const ScorbotJoints& q);

/// The rotation of the TCP for base angle q1, absolute pitch theta and roll q5 (radians).
vpRotationMatrix ToolRotation(double q1, double theta, double roll);

/// Joints of wMe (elbow-up). Fails when the tool axis is not in the arm plane (by more than
/// `plane_tol_rad`), when the wrist is out of reach, or when a joint leaves its range.
ScorbotIk InverseKinematics(const ScorbotGeometry& g, const vpHomogeneousMatrix& wMe,
                            double plane_tol_rad = 1e-6);

/// 0 when q is inside the ranges, else the 1-based axis of the first violation.
int JointLimitViolation(const ScorbotGeometry& g, const ScorbotJoints& q);

/// The nearest pose the arm can reach to wMe_target, as described in the file comment
/// (position kept, orientation projected). Fails when the tool axis would be perpendicular to
/// the arm plane, or the result is outside the reach or the joint ranges.
ScorbotReach NearestReachable(const ScorbotGeometry& g, const vpHomogeneousMatrix& wMe_target);
/// Same for a frame x attached to the TCP by eMx (the camera: eMc): keeps the position of x.
/// Returns the reachable wMe (not wMx).
ScorbotReach NearestReachable(const ScorbotGeometry& g, const vpHomogeneousMatrix& wMx_target,
                              const vpHomogeneousMatrix& eMx);

/// ACL pose <-> wMe. FromAclPose is exact up to rounding; ToAclPose rounds to the ACL units
/// and assumes wMe is reachable by 5 axes (its yaw is dropped).
vpHomogeneousMatrix FromAclPose(const AclPose& pose);
AclPose ToAclPose(const vpHomogeneousMatrix& wMe);
/// ACL pose of joints q (the controller's own report: FK, then rounding).
AclPose AclPoseOfJoints(const ScorbotGeometry& g, const ScorbotJoints& q);

/// Joints <-> encoder counts (see the file comment).
ScorbotCounts ToCounts(const ScorbotGeometry& g, const ScorbotJoints& q);
ScorbotJoints FromCounts(const ScorbotGeometry& g, const ScorbotCounts& counts);
/// The home joint angles, radians.
ScorbotJoints HomeJoints(const ScorbotGeometry& g);

/// The manipulator Jacobian eJe (6 x 5): the twist (v, w) of the TCP expressed in e, in m/s and
/// rad/s, per unit joint rate (rad/s). A velocity-style law solves v_e = eJe * qdot.
vpMatrix EndEffectorJacobian(const ScorbotGeometry& g, const ScorbotJoints& q);

}  // namespace oal
