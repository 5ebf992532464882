// A free-flying camera robot on vpSimulatorCamera: 6 DOF, velocity and position.
//
// Velocity: SetVelocity() integrates the twist over one sampling period through the
// exponential map, as vpSimulatorCamera does: wMc <- wMc * vpExponentialMap::direct(v, dt).
// A twist in the end-effector frame is first carried to the camera frame with the hand-eye
// (v_c = cVe * v_e). A twist above the hardware limits (max_translation_mps /
// max_rotation_radps, per axis) is refused with kLimit rather than clamped: saturation is the
// runner's job (SafeRobot), and vpRobot::saturateVelocities would print.
// Position: StartMove() + PollMove(). MoveMode::kJump sets the pose on the first poll;
// MoveMode::kIntegrate moves along the constant twist log(wMc^-1 * wMc_target) / T, one
// sampling period per poll, T = move_duration_s, lengthened to whole periods and so that the
// twist stays within the hardware limits.
// Time is simulated: nothing sleeps. Time() counts the integrated periods.
// Fault injection for tests: InjectFault() makes the next motion command (SetVelocity,
// StartMove or PollMove), or a later one, fail with the given status and message.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/robot/vpSimulatorCamera.h>

#include <functional>
#include <string>

#include "robots/robot.h"

namespace oal {

struct SimulatedCameraOptions {
  enum class MoveMode { kJump, kIntegrate };

  /// Sampling time of one velocity command / move poll, s; in (0, 1].
  double sampling_time_s = 0.04;
  /// Hardware limit on |vx|, |vy|, |vz|, m/s; > 0.
  double max_translation_mps = 1.0;
  /// Hardware limit on |wx|, |wy|, |wz|, rad/s; > 0.
  double max_rotation_radps = 3.14159265358979323846;
  /// How a position move is executed (see the file comment).
  MoveMode move_mode = MoveMode::kJump;
  /// Duration of a kIntegrate move, s; >= 0 (0: as fast as the limits allow).
  double move_duration_s = 1.0;
  /// Initial camera pose in the world.
  vpHomogeneousMatrix wMc;
  /// Hand-eye: the camera in the end-effector frame (identity: e = c, as vpSimulatorCamera).
  vpHomogeneousMatrix eMc;
  /// Tests: called at the start of every PollMove() of a queued move with the poll's number in
  /// that move (0 first), e.g. to act while the camera is on its way. Empty: none.
  std::function<void(int poll)> on_poll;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

class SimulatedCamera final : public Robot {
 public:
  explicit SimulatedCamera(const SimulatedCameraOptions& options = SimulatedCameraOptions());

  std::string Name() const override { return "simulated-camera"; }
  RobotCapabilities Capabilities() const override;
  RobotResult Connect() override;
  RobotResult Enable() override;
  RobotResult Disable() noexcept override;
  RobotResult Stop() noexcept override;
  RobotPose GetPosition(RobotFrame frame) override;
  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override;
  MoveProgress PollMove() override;
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override;
  RobotPose NearestReachable(RobotFrame frame, const vpHomogeneousMatrix& target) override;
  vpHomogeneousMatrix eMc() const override { return options_.eMc; }

  /// Places the camera (tests, start pose); does not need Enable().
  void SetPose(const vpHomogeneousMatrix& wMc);
  /// The camera pose without the lifecycle checks.
  vpHomogeneousMatrix wMc() const;
  /// Simulated time, s: sampling periods integrated so far.
  double Time() const { return time_s_; }
  /// A motion command (SetVelocity, StartMove, PollMove) fails with `status` and `message`:
  /// the next one, or the one after `after_commands` more succeed. Fires once. The failing
  /// command stops the camera where it is. A PollMove() with no move queued counts too, but
  /// moves nothing and reports the move done.
  void InjectFault(RobotStatus status = RobotStatus::kError, std::string message = "injected fault",
                   int after_commands = 0);
  bool moving() const { return move_steps_left_ > 0; }

 private:
  RobotResult CheckCanMove();
  RobotResult CheckLimits(const vpColVector& v_c) const;
  void Integrate(const vpColVector& v_c);

  SimulatedCameraOptions options_;
  vpSimulatorCamera sim_;
  bool connected_ = false;
  bool enabled_ = false;
  double time_s_ = 0;
  // Queued move: target camera pose and the constant camera-frame twist to it.
  vpHomogeneousMatrix move_target_wMc_;
  vpColVector move_twist_;
  int move_steps_left_ = 0;
  int move_polls_ = 0;  // polls of the queued move so far
  bool move_jump_ = false;
  // Injected fault.
  bool fault_armed_ = false;
  int fault_countdown_ = 0;
  RobotResult fault_;
};

}  // namespace oal
