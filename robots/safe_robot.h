// The one runner between the servo loop and any Robot driver (ros2_control's split,
// shared/STYLE.md): the driver does what it is told; SafeRobot decides what may be told.
//
// RUNNER CONTRACT
//   - Lifecycle: Connect() -> Enable() -> motion commands. A command that is not allowed
//     (not connected / not enabled: kNotReady; stopped: kStopped) is refused without reaching
//     the driver.
//   - Velocity saturation: SetVelocity() scales the whole twist by one factor so that every
//     |vx|, |vy|, |vz| <= max_translation_mps and |wx|, |wy|, |wz| <= max_rotation_radps (the
//     direction is kept, as vpRobot::saturateVelocities does, but silently); CycleReport says
//     by how much (scale < 1, saturated) and which axis limited it.
//   - Workspace box: before every motion the poses of workspace_frame that the motion leads to
//     (for a velocity: after one sampling period; for a move: the target, then its whole path
//     as the driver executes it, Robot::PoseAlongMove(), sampled at least 32 times and at most
//     5 mm of travel apart) must lie inside the axis-aligned box [workspace_min_m,
//     workspace_max_m] of the world frame. Otherwise the motion is refused (kWorkspace, message
//     naming the axis and the bound, and for a path the fraction of the way), the robot is
//     stopped and stays where it was: nothing is sent. During a move the box is checked again
//     at every poll.
//   - Stop-on-error: any failed driver call during motion, any refused motion, a move that
//     times out or ends away from its target, stops the driver (Robot::Stop()) and latches
//     the runner in kStopped; every later motion command fails with kStopped and the reason,
//     until Enable() is called. stop_reason() keeps the first reason.
//   - Stop() stops now and latches; safe in any state, idempotent, never throws.
//   - Emergency stop: RequestEmergencyStop() only stores to a lock-free atomic flag, so a
//     signal handler (the servo loop's Ctrl-C) may call it. The next cycle (SetVelocity(),
//     MovePosition() or a poll inside a move) sees the flag, stops the driver and latches.
//     Enable() clears a flag set before it was called; a request that arrives while Enable()
//     runs (during CON) is kept, so the next cycle stops and latches as for any request, and
//     only a later Enable() clears it.
//   - Timing: every cycle (one velocity command or one move poll, with its checks) is timed
//     on the steady clock; timing() keeps count, last and max; a cycle longer than
//     max_cycle_s (if > 0) stops the robot (kTimeout).
//   - The destructor stops the driver: a SafeRobot never leaves a robot moving.
//   - Not thread-safe, except RequestEmergencyStop().
#pragma once

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpTranslationVector.h>

#include <array>
#include <atomic>
#include <string>

#include "robots/robot.h"

namespace oal {

struct SafetyOptions {
  /// Per-axis limit on |vx|, |vy|, |vz| of a commanded twist, m/s; > 0.
  double max_translation_mps = 0.2;
  /// Per-axis limit on |wx|, |wy|, |wz| of a commanded twist, rad/s; > 0.
  double max_rotation_radps = 0.7;
  /// Whether the workspace box is checked.
  bool workspace_enabled = true;
  /// The frame whose origin must stay inside the box (camera or end effector).
  RobotFrame workspace_frame = RobotFrame::kCamera;
  /// Box corners in the world frame, m; min < max on every axis.
  std::array<double, 3> workspace_min_m{-1, -1, -1};
  std::array<double, 3> workspace_max_m{1, 1, 1};
  /// A move not finished after this much robot time (polls x sampling time), s; > 0.
  double move_timeout_s = 60;
  /// A finished move must end this close to its target: m; > 0.
  double reach_tolerance_m = 1e-3;
  /// ... and rad; > 0.
  double reach_tolerance_rad = 2e-3;
  /// Longest allowed cycle (wall time), s; 0 = not checked; >= 0.
  double max_cycle_s = 0;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
  /// The first axis (0 x, 1 y, 2 z) on which `p`, a position of workspace_frame in the world
  /// frame, m, lies outside the workspace box; -1 when it is inside or the box is disabled.
  int AxisOutsideWorkspace(const std::array<double, 3>& p) const;
  /// Why `p` lies outside the box, e.g. "z = 1.2 m is outside [0.1, 1] m"; "" when it is
  /// inside or the box is disabled.
  std::string OutsideWorkspace(const vpTranslationVector& p) const;
};

enum class SafeRobotState {
  kDisconnected,  ///< before Connect()
  kDisabled,      ///< connected, motion not allowed (after Connect() or Disable())
  kEnabled,       ///< motion allowed
  kStopped,       ///< stopped by Stop(), the emergency flag or an error; Enable() to resume
};
/// "disconnected", "disabled", "enabled", "stopped".
std::string ToString(SafeRobotState state);

/// One velocity cycle.
struct CycleReport {
  RobotResult result;
  /// The twist sent to the driver (after saturation); zero when none was sent (a 6-vector
  /// still: an empty vpColVector copies through memcpy from a null pointer).
  vpColVector twist = vpColVector(6, 0.0);
  double scale = 1;        ///< saturation factor applied to the request, in (0, 1]
  bool saturated = false;  ///< scale < 1
  int limiting_axis = -1;  ///< 0..5 (vx..wz) that set the scale; -1 when not saturated
  double duration_s = 0;   ///< wall time of the cycle
};

/// One position move.
struct MoveReport {
  RobotResult result;
  vpHomogeneousMatrix target;   ///< the pose moved to: NearestReachable() of the request
  vpHomogeneousMatrix reached;  ///< the pose read back at the end (if the move ran)
  int polls = 0;                ///< PollMove() calls
  double duration_s = 0;        ///< wall time of the whole move
};

struct CycleTiming {
  long cycles = 0;
  double last_s = 0;
  double max_s = 0;
  double total_s = 0;
};

class SafeRobot {
 public:
  /// `robot` must outlive the SafeRobot. Throws std::invalid_argument on bad options.
  SafeRobot(Robot& robot, const SafetyOptions& options);
  ~SafeRobot();
  SafeRobot(const SafeRobot&) = delete;
  SafeRobot& operator=(const SafeRobot&) = delete;

  RobotResult Connect();
  /// Allows motion; clears a latched stop and an emergency flag set before the call (not one
  /// requested while it runs: the next cycle acts on that one).
  RobotResult Enable();
  /// Stops and forbids motion until Enable(). Safe in any state, idempotent.
  RobotResult Disable() noexcept;
  /// Stops now and latches kStopped. Safe in any state, idempotent, never throws.
  RobotResult Stop() noexcept;
  /// Async-signal-safe: sets the flag the next cycle acts on.
  void RequestEmergencyStop() noexcept { emergency_.store(true, std::memory_order_relaxed); }
  bool EmergencyStopRequested() const noexcept {
    return emergency_.load(std::memory_order_relaxed);
  }

  /// Reads wMc or wMe; allowed in any connected state. A failure does not stop the robot.
  RobotPose GetPosition(RobotFrame frame);
  /// One velocity cycle: emergency flag, state, saturation, workspace, driver call, timing.
  /// Throws std::invalid_argument if v.size() != 6.
  CycleReport SetVelocity(RobotFrame frame, const vpColVector& v);
  /// A blocking position move of `frame` to the world pose `target` (wMc or wMe) through the
  /// driver's StartMove()/PollMove(), every poll a checked cycle.
  MoveReport MovePosition(RobotFrame frame, const vpHomogeneousMatrix& target);

  /// Whether MovePosition(frame, target) would pass the runner's checks from where the robot
  /// is now: the pose it would move to (NearestReachable()) and ok, or why it would be
  /// refused. Computes only: nothing is sent, nothing is latched (a plan may try poses).
  RobotPose CheckMove(RobotFrame frame, const vpHomogeneousMatrix& target);

  SafeRobotState state() const { return state_; }
  /// Why the robot is stopped (ok when it is not).
  const RobotResult& stop_reason() const { return stop_reason_; }
  const CycleTiming& timing() const { return timing_; }
  const SafetyOptions& options() const { return options_; }
  Robot& robot() { return robot_; }

  /// Scales v (6) by one factor in (0, 1] so every component is within its limit; returns
  /// the scaled twist, the factor and the limiting axis (-1 if none).
  static vpColVector Saturate(const vpColVector& v, double max_translation_mps,
                              double max_rotation_radps, double* scale, int* limiting_axis);

 private:
  static_assert(std::atomic<bool>::is_always_lock_free, "the emergency flag must be lock-free");

  RobotResult CheckMayMove();
  RobotResult Latch(RobotResult why) noexcept;
  /// NearestReachable(), then the target and the path from here in the box.
  RobotPose PlanMove(RobotFrame frame, const vpHomogeneousMatrix& target);
  RobotResult CheckInBox(const vpHomogeneousMatrix& wMb, const std::string& what) const;
  /// The path of a move of `frame` from `from` to `target` (Robot::PoseAlongMove()) in the box.
  RobotResult CheckPathInBox(RobotFrame frame, const vpHomogeneousMatrix& from,
                             const vpHomogeneousMatrix& target) const;
  /// The box frame's pose in the world given the pose wMx of `frame`.
  vpHomogeneousMatrix BoxFramePose(RobotFrame frame, const vpHomogeneousMatrix& wMx) const;
  void RecordCycle(double seconds);

  Robot& robot_;
  SafetyOptions options_;
  double sampling_time_s_ = 0;
  SafeRobotState state_ = SafeRobotState::kDisconnected;
  RobotResult stop_reason_;
  CycleTiming timing_;
  std::atomic<bool> emergency_{false};
};

}  // namespace oal
