#include "robots/simulated_camera.h"

#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpVelocityTwistMatrix.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/check.h"

namespace oal {
namespace {

void CheckTwistSize(const vpColVector& v) {
  if (v.size() != 6) {
    throw std::invalid_argument("SimulatedCamera::SetVelocity: twist has " +
                                std::to_string(v.size()) + " entries, expected 6");
  }
}

}  // namespace

void SimulatedCameraOptions::Check() const {
  const std::string p = "SimulatedCameraOptions::";
  RequireOption(sampling_time_s > 0 && sampling_time_s <= 1, p + "sampling_time_s", sampling_time_s,
                "0 < sampling_time_s <= 1");
  RequireOption(max_translation_mps > 0 && std::isfinite(max_translation_mps),
                p + "max_translation_mps", max_translation_mps, "finite and > 0");
  RequireOption(max_rotation_radps > 0 && std::isfinite(max_rotation_radps),
                p + "max_rotation_radps", max_rotation_radps, "finite and > 0");
  RequireOption(move_duration_s >= 0 && std::isfinite(move_duration_s), p + "move_duration_s",
                move_duration_s, "finite and >= 0");
  RequireOption(wMc.isAnHomogeneousMatrix(), p + "wMc", 0, "a rigid transform");
  RequireOption(eMc.isAnHomogeneousMatrix(), p + "eMc", 0, "a rigid transform");
}

SimulatedCamera::SimulatedCamera(const SimulatedCameraOptions& options) : options_(options) {
  options_.Check();
  sim_.setSamplingTime(options_.sampling_time_s);
  // ViSP's own clamp stays above ours, so it never fires (it would print): CheckLimits()
  // refuses a twist above the hardware limits first.
  sim_.setMaxTranslationVelocity(2 * options_.max_translation_mps);
  sim_.setMaxRotationVelocity(2 * options_.max_rotation_radps);
  sim_.setPosition(options_.wMc);
}

RobotCapabilities SimulatedCamera::Capabilities() const {
  RobotCapabilities c;
  c.position = true;
  c.velocity = true;
  c.dof = 6;
  c.sampling_time_s = options_.sampling_time_s;
  return c;
}

RobotResult SimulatedCamera::Connect() {
  connected_ = true;
  return RobotResult::Ok();
}

RobotResult SimulatedCamera::Enable() {
  if (!connected_) return RobotResult::Fail(RobotStatus::kNotReady, "not connected");
  enabled_ = true;
  return RobotResult::Ok();
}

RobotResult SimulatedCamera::Disable() noexcept {
  Stop();
  enabled_ = false;
  return RobotResult::Ok();
}

RobotResult SimulatedCamera::Stop() noexcept {
  move_steps_left_ = 0;
  move_jump_ = false;
  return RobotResult::Ok();
}

vpHomogeneousMatrix SimulatedCamera::wMc() const {
  return sim_.getPosition();
}

void SimulatedCamera::SetPose(const vpHomogeneousMatrix& wMc) {
  sim_.setPosition(wMc);
}

void SimulatedCamera::InjectFault(RobotStatus status, std::string message, int after_commands) {
  fault_armed_ = true;
  fault_countdown_ = std::max(0, after_commands);
  fault_ = RobotResult::Fail(status, std::move(message));
}

RobotPose SimulatedCamera::GetPosition(RobotFrame frame) {
  RobotPose p;
  if (!connected_) {
    p.result = RobotResult::Fail(RobotStatus::kNotReady, "not connected");
    return p;
  }
  p.pose = frame == RobotFrame::kCamera ? wMc() : wMc() * options_.eMc.inverse();
  return p;
}

RobotResult SimulatedCamera::CheckCanMove() {
  if (fault_armed_ && fault_countdown_-- == 0) {
    fault_armed_ = false;
    Stop();
    return fault_;
  }
  if (!connected_) return RobotResult::Fail(RobotStatus::kNotReady, "not connected");
  if (!enabled_) return RobotResult::Fail(RobotStatus::kNotReady, "not enabled");
  return RobotResult::Ok();
}

RobotResult SimulatedCamera::CheckLimits(const vpColVector& v_c) const {
  static const char* const kAxis[6] = {"vx", "vy", "vz", "wx", "wy", "wz"};
  for (unsigned i = 0; i < 6; ++i) {
    const double limit = i < 3 ? options_.max_translation_mps : options_.max_rotation_radps;
    if (!std::isfinite(v_c[i]) || std::abs(v_c[i]) > limit * (1 + 1e-12)) {
      std::ostringstream s;
      s << "camera-frame " << kAxis[i] << " = " << v_c[i] << (i < 3 ? " m/s" : " rad/s")
        << " exceeds the hardware limit " << limit;
      return RobotResult::Fail(RobotStatus::kLimit, s.str());
    }
  }
  return RobotResult::Ok();
}

void SimulatedCamera::Integrate(const vpColVector& v_c) {
  sim_.setVelocity(vpRobot::CAMERA_FRAME, v_c);
  time_s_ += options_.sampling_time_s;
}

RobotResult SimulatedCamera::SetVelocity(RobotFrame frame, const vpColVector& v) {
  CheckTwistSize(v);
  if (RobotResult r = CheckCanMove(); !r.ok()) return r;
  // A velocity command replaces a queued move.
  move_steps_left_ = 0;
  move_jump_ = false;
  vpColVector v_c = v;
  if (frame == RobotFrame::kEndEffector) {
    v_c = vpVelocityTwistMatrix(options_.eMc.inverse()) * v;  // cVe * v_e
  }
  if (RobotResult r = CheckLimits(v_c); !r.ok()) return r;
  Integrate(v_c);
  return RobotResult::Ok();
}

RobotResult SimulatedCamera::StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) {
  if (RobotResult r = CheckCanMove(); !r.ok()) return r;
  if (!target.isAnHomogeneousMatrix()) {
    return RobotResult::Fail(RobotStatus::kUnreachable, "target is not a rigid transform");
  }
  move_target_wMc_ = frame == RobotFrame::kCamera ? target : target * options_.eMc;
  move_polls_ = 0;
  if (options_.move_mode == SimulatedCameraOptions::MoveMode::kJump) {
    move_jump_ = true;
    move_steps_left_ = 1;
    return RobotResult::Ok();
  }
  // Constant twist to the target: log(cMcd), spread over whole periods, within the limits.
  const double dt = options_.sampling_time_s;
  const vpColVector log_c = vpExponentialMap::inverse(wMc().inverse() * move_target_wMc_, 1.0);
  double needed_s = options_.move_duration_s;
  for (unsigned i = 0; i < 6; ++i) {
    const double limit = i < 3 ? options_.max_translation_mps : options_.max_rotation_radps;
    needed_s = std::max(needed_s, std::abs(log_c[i]) / limit);
  }
  const int steps = std::max(1, static_cast<int>(std::ceil(needed_s / dt - 1e-9)));
  move_twist_ = log_c / (steps * dt);
  move_jump_ = false;
  move_steps_left_ = steps;
  return RobotResult::Ok();
}

MoveProgress SimulatedCamera::PollMove() {
  MoveProgress p;
  if (move_steps_left_ == 0 && !fault_armed_) {
    p.done = true;
    return p;
  }
  if (move_steps_left_ > 0 && options_.on_poll) options_.on_poll(move_polls_++);
  if (RobotResult r = CheckCanMove(); !r.ok()) {
    p.result = r;
    return p;
  }
  if (move_steps_left_ <= 0) {
    // Nothing queued (the poll only counted towards an armed fault): nothing to integrate.
    move_steps_left_ = 0;
    p.done = true;
    return p;
  }
  if (move_jump_) {
    sim_.setPosition(move_target_wMc_);
    time_s_ += options_.sampling_time_s;
  } else {
    Integrate(move_twist_);
  }
  if (--move_steps_left_ == 0) {
    // The integrated screw ends on the target up to rounding; land on it exactly.
    sim_.setPosition(move_target_wMc_);
    move_jump_ = false;
  }
  p.done = move_steps_left_ == 0;
  return p;
}

RobotPose SimulatedCamera::NearestReachable(RobotFrame /*frame*/,
                                            const vpHomogeneousMatrix& target) {
  RobotPose p;
  p.pose = target;
  return p;
}

}  // namespace oal
