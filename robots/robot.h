// The robot interface the servo loop drives, in ViSP's terms, split as ros2_control
// splits it (shared/STYLE.md, "A driver contract that fails safe"):
//
//   Robot      what each driver implements: open communication, allow motion, stop, read the
//              pose, command a position move or a velocity. Small, no policy.
//   SafeRobot  (safe_robot.h) the one runner every caller goes through: velocity saturation,
//              workspace box, stop-on-error, cycle timing, emergency stop.
//
// Frames (ViSP's naming, transforms named by frames, docs/ARCHITECTURE.md):
//   w  world (robot base) frame, fixed;
//   e  end-effector (flange) frame; for vpSimulatorCamera e = c unless a hand-eye is set;
//   c  camera frame: z along the optical axis, x right, y down.
//   wMc, wMe  poses of the camera / end effector in the world; eMc the hand-eye transform,
//   so wMc = wMe * eMc.
// A twist is a vpColVector (vx, vy, vz, wx, wy, wz) in m/s and rad/s, expressed in the frame
// it is commanded in (RobotFrame), as vpRobot::setVelocity(CAMERA_FRAME / END_EFFECTOR_FRAME).
//
// DRIVER CONTRACT (what an implementation of Robot promises)
//   - Lifecycle: Connect() opens communication and must not move the robot; Enable() allows
//     motion; only an enabled robot moves. Disable() stops and forbids motion.
//   - Stop() stops any motion now. It is always safe to call: in any state (also before
//     Connect() and after a failure), any number of times, and it never throws. A driver
//     that cannot confirm the stop (link down) returns an error status, but still tries.
//   - Every other call reports failure as a RobotResult (status + message saying why), never
//     by printing, never by an exception. Exceptions are for programmer errors only (a twist
//     that is not 6 long).
//   - A capability the robot lacks (velocity on a position-only arm) returns kUnsupported.
//   - StartMove() queues a position move and returns at once; PollMove() advances or waits at
//     most one sampling period and says whether the move is finished. Position-only robots
//     (the 5-axis Scorbot over ACL) are driven this way, so the runner can stop a move between
//     two polls.
//   - SetVelocity() applies the twist for one sampling period (simulated robots) or until the
//     next command (real velocity-driven robots); the runner re-sends it every cycle.
//   - NearestReachable() maps a requested pose to the nearest pose the arm can reach (a 5-DOF
//     arm cannot reach every 6-DOF pose); a 6-DOF robot returns the pose unchanged.
//   - PoseAlongMove() says where a position move passes: the pose of `frame` at a fraction of
//     the way, as the driver's own interpolation moves it (the default: the screw from start to
//     target at constant twist, what SimulatedCamera integrates; the Scorbot overrides it with
//     its joint interpolation). The runner checks the path against the workspace box with it
//     before anything is sent, so it must not touch the robot.
//   - No call is thread-safe; the runner's emergency flag is the only cross-context entry.
#pragma once

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <string>
#include <utility>

#include "base/pose_distance.h"  // Distance, used with every robot

namespace oal {

/// Outcome of a robot call. kOk is the only success.
enum class RobotStatus {
  kOk,
  kError,        ///< the driver failed (communication, controller error, injected fault)
  kStopped,      ///< refused: the robot is stopped (Stop(), emergency stop or an earlier
                 ///< error) and must be re-enabled first
  kNotReady,     ///< refused: not connected or not enabled
  kLimit,        ///< a velocity or joint limit of the robot would be exceeded
  kWorkspace,    ///< the motion would leave the configured workspace box
  kUnreachable,  ///< no pose the robot can reach near the requested one
  kUnsupported,  ///< the robot cannot do this (e.g. velocity control on a position-only arm)
  kTimeout,      ///< a move or a reply did not complete in time
};

/// The one place RobotStatus meets strings: "ok", "error", "stopped", "not-ready", "limit",
/// "workspace", "unreachable", "unsupported", "timeout".
std::string ToString(RobotStatus status);

/// A status and, when it is not kOk, a message saying why (one line, for the user).
struct RobotResult {
  RobotStatus status = RobotStatus::kOk;
  std::string message;

  bool ok() const { return status == RobotStatus::kOk; }
  static RobotResult Ok() { return {}; }
  static RobotResult Fail(RobotStatus s, std::string why) { return {s, std::move(why)}; }
};

/// A pose read back or computed by a robot, with the outcome. `pose` is wMc or wMe (see the
/// frame it was asked in); identity when !result.ok().
struct RobotPose {
  RobotResult result;
  vpHomogeneousMatrix pose;
};

/// Progress of a queued position move (Robot::PollMove()).
struct MoveProgress {
  RobotResult result;
  bool done = false;  ///< the move is finished (meaningful when result.ok())
};

/// The frame a pose is read or commanded in, a twist expressed in (vpRobot's CAMERA_FRAME and
/// END_EFFECTOR_FRAME). Poses are always of that frame in the world: wMc or wMe.
enum class RobotFrame { kCamera, kEndEffector };

/// "camera", "end-effector".
std::string ToString(RobotFrame frame);

/// What a robot can do; the servo app picks the law from this.
struct RobotCapabilities {
  bool position = false;       ///< StartMove()/PollMove() work
  bool velocity = false;       ///< SetVelocity() works
  int dof = 6;                 ///< Cartesian degrees of freedom (5 for the Scorbot ER-VII)
  double sampling_time_s = 0;  ///< period of one command/poll cycle, s (> 0)
};

/// The driver interface (see the contract above). Implementations: SimulatedCamera; the
/// ScorbotRobot (scorbot_robot.h), the Scorbot ER-VII over ACL.
class Robot {
 public:
  virtual ~Robot() = default;

  virtual std::string Name() const = 0;
  virtual RobotCapabilities Capabilities() const = 0;

  /// Opens communication (port, controller handshake). Does not move the robot.
  virtual RobotResult Connect() = 0;
  /// Allows motion (servo power on, CON). Requires Connect().
  virtual RobotResult Enable() = 0;
  /// Stops motion and forbids it until Enable(). Safe in any state, idempotent, no throw.
  virtual RobotResult Disable() noexcept = 0;
  /// Stops any motion now (clears queued moves, zero velocity). Safe in any state, idempotent,
  /// no throw. Does not by itself forbid motion: the runner latches that.
  virtual RobotResult Stop() noexcept = 0;

  /// The pose of `frame` in the world: wMc or wMe.
  virtual RobotPose GetPosition(RobotFrame frame) = 0;

  /// Queues a move of `frame` to the world pose `target` (wMc or wMe) and returns at once.
  /// The target should come from NearestReachable(); a driver refuses (kUnreachable) a pose it
  /// cannot reach.
  virtual RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) = 0;
  /// Advances or waits at most one sampling period; done when the queued move has finished.
  /// With no move queued: done.
  virtual MoveProgress PollMove() = 0;

  /// Applies the twist `v` (6, m/s and rad/s) expressed in `frame` for one sampling period
  /// (or until the next command). Throws std::invalid_argument if v.size() != 6.
  virtual RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) = 0;

  /// The nearest pose of `frame` to `target` that the robot can reach (same frame). A 6-DOF
  /// robot without joint limits returns `target`.
  virtual RobotPose NearestReachable(RobotFrame frame, const vpHomogeneousMatrix& target) = 0;

  /// The pose of `frame` (wMc or wMe) at `fraction` in [0, 1] of the way of a position move of
  /// `frame` from the world pose `from` (where the robot is) to `target` (from
  /// NearestReachable()), as this robot executes StartMove(). The path does not depend on the
  /// speed profile: `fraction` is the progress along it, 0 at `from`, 1 at `target`. Computes
  /// only (no communication). kUnreachable when the driver cannot say (e.g. no joints for an
  /// end). Default: the screw motion at constant twist,
  /// from * exp(fraction * log(from^-1 * target)), as SimulatedCamera integrates a move (the
  /// same path whichever frame is given: the screw does not depend on a rigidly attached
  /// frame).
  virtual RobotPose PoseAlongMove(RobotFrame frame, const vpHomogeneousMatrix& from,
                                  const vpHomogeneousMatrix& target, double fraction) const;

  /// The hand-eye transform: the camera in the end-effector frame.
  virtual vpHomogeneousMatrix eMc() const = 0;
  /// What the session has cost on the robot's link so far, one line for the user (commands,
  /// bytes, serial time; `moves` position moves, for a per-move figure); empty for a robot
  /// without one (the default).
  virtual std::string LinkSummary(int /*moves*/) const { return ""; }
};

}  // namespace oal
