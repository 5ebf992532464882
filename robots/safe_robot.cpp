#include "robots/safe_robot.h"

#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/check.h"
#include "base/format.h"

namespace oal {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

constexpr const char* kAxisName[6] = {"vx", "vy", "vz", "wx", "wy", "wz"};
constexpr const char* kBoxAxis[3] = {"x", "y", "z"};

}  // namespace

void SafetyOptions::Check() const {
  const std::string p = "SafetyOptions::";
  RequireOption(max_translation_mps > 0 && std::isfinite(max_translation_mps),
                p + "max_translation_mps", max_translation_mps, "finite and > 0");
  RequireOption(max_rotation_radps > 0 && std::isfinite(max_rotation_radps),
                p + "max_rotation_radps", max_rotation_radps, "finite and > 0");
  for (int i = 0; i < 3; ++i) {
    RequireOption(std::isfinite(workspace_min_m[i]) && std::isfinite(workspace_max_m[i]) &&
                      workspace_min_m[i] < workspace_max_m[i],
                  p + "workspace_min_m/workspace_max_m [" + kBoxAxis[i] + "]",
                  Number(workspace_min_m[i]) + " / " + Number(workspace_max_m[i]),
                  "finite and min < max");
  }
  RequireOption(move_timeout_s > 0 && std::isfinite(move_timeout_s), p + "move_timeout_s",
                move_timeout_s, "finite and > 0");
  RequireOption(reach_tolerance_m > 0, p + "reach_tolerance_m", reach_tolerance_m, "> 0");
  RequireOption(reach_tolerance_rad > 0, p + "reach_tolerance_rad", reach_tolerance_rad, "> 0");
  RequireOption(max_cycle_s >= 0 && std::isfinite(max_cycle_s), p + "max_cycle_s", max_cycle_s,
                "finite and >= 0");
}

std::string ToString(SafeRobotState state) {
  switch (state) {
    case SafeRobotState::kDisconnected:
      return "disconnected";
    case SafeRobotState::kDisabled:
      return "disabled";
    case SafeRobotState::kEnabled:
      return "enabled";
    case SafeRobotState::kStopped:
      return "stopped";
  }
  return "unknown";
}

SafeRobot::SafeRobot(Robot& robot, const SafetyOptions& options)
    : robot_(robot), options_(options) {
  options_.Check();
  sampling_time_s_ = robot_.Capabilities().sampling_time_s;
  if (!(sampling_time_s_ > 0)) {
    throw std::invalid_argument("SafeRobot: robot '" + robot_.Name() +
                                "' reports a sampling time <= 0");
  }
}

SafeRobot::~SafeRobot() {
  robot_.Stop();
}

RobotResult SafeRobot::Connect() {
  RobotResult r = robot_.Connect();
  if (r.ok() && state_ == SafeRobotState::kDisconnected) state_ = SafeRobotState::kDisabled;
  return r;
}

RobotResult SafeRobot::Enable() {
  if (state_ == SafeRobotState::kDisconnected) {
    return RobotResult::Fail(RobotStatus::kNotReady, "not connected: call Connect() first");
  }
  // Cleared before the driver call: a request that arrives during CON survives Enable().
  const bool requested_before = emergency_.exchange(false, std::memory_order_relaxed);
  RobotResult r = robot_.Enable();
  if (!r.ok()) {
    if (requested_before) emergency_.store(true, std::memory_order_relaxed);
    return r;
  }
  stop_reason_ = RobotResult::Ok();
  state_ = SafeRobotState::kEnabled;
  return r;
}

RobotResult SafeRobot::Disable() noexcept {
  RobotResult r = robot_.Disable();
  if (state_ != SafeRobotState::kDisconnected) state_ = SafeRobotState::kDisabled;
  return r;
}

RobotResult SafeRobot::Stop() noexcept {
  return Latch(RobotResult::Fail(RobotStatus::kStopped, "Stop() called"));
}

RobotResult SafeRobot::Latch(RobotResult why) noexcept {
  RobotResult stop = robot_.Stop();
  if (state_ == SafeRobotState::kEnabled) {
    state_ = SafeRobotState::kStopped;
    stop_reason_ = std::move(why);
  }
  return stop;
}

RobotResult SafeRobot::CheckMayMove() {
  if (emergency_.load(std::memory_order_relaxed)) {
    Latch(RobotResult::Fail(RobotStatus::kStopped, "emergency stop requested"));
  }
  switch (state_) {
    case SafeRobotState::kEnabled:
      return RobotResult::Ok();
    case SafeRobotState::kDisconnected:
      return RobotResult::Fail(RobotStatus::kNotReady, "not connected: call Connect() first");
    case SafeRobotState::kDisabled:
      return RobotResult::Fail(RobotStatus::kNotReady, "not enabled: call Enable() first");
    case SafeRobotState::kStopped:
      break;
  }
  return RobotResult::Fail(RobotStatus::kStopped,
                           "robot stopped (" + stop_reason_.message + "); Enable() to resume");
}

vpHomogeneousMatrix SafeRobot::BoxFramePose(RobotFrame frame,
                                            const vpHomogeneousMatrix& wMx) const {
  if (frame == options_.workspace_frame) return wMx;
  if (frame == RobotFrame::kCamera) return wMx * robot_.eMc().inverse();  // wMe = wMc * cMe
  return wMx * robot_.eMc();                                              // wMc = wMe * eMc
}

int SafetyOptions::AxisOutsideWorkspace(const std::array<double, 3>& p) const {
  if (!workspace_enabled) return -1;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(p[i] >= workspace_min_m[i] && p[i] <= workspace_max_m[i])) return static_cast<int>(i);
  }
  return -1;
}

std::string SafetyOptions::OutsideWorkspace(const vpTranslationVector& p) const {
  const int axis = AxisOutsideWorkspace({p[0], p[1], p[2]});
  if (axis < 0) return "";
  const auto i = static_cast<std::size_t>(axis);
  std::ostringstream s;
  s << kBoxAxis[i] << " = " << p[static_cast<unsigned>(axis)] << " m is outside ["
    << workspace_min_m[i] << ", " << workspace_max_m[i] << "] m";
  return s.str();
}

RobotResult SafeRobot::CheckInBox(const vpHomogeneousMatrix& wMb, const std::string& what) const {
  // Read in place: the path check calls this for every sample of a move.
  const std::array<double, 3> p{wMb[0][3], wMb[1][3], wMb[2][3]};
  const int axis = options_.AxisOutsideWorkspace(p);
  if (axis < 0) return RobotResult::Ok();
  const auto i = static_cast<std::size_t>(axis);
  std::ostringstream s;
  s << what << " would take the " << ToString(options_.workspace_frame) << " to " << kBoxAxis[i]
    << " = " << p[i] << " m, outside the workspace box [" << options_.workspace_min_m[i] << ", "
    << options_.workspace_max_m[i] << "] m";
  return RobotResult::Fail(RobotStatus::kWorkspace, s.str());
}

RobotResult SafeRobot::CheckPathInBox(RobotFrame frame, const vpHomogeneousMatrix& from,
                                      const vpHomogeneousMatrix& target) const {
  if (!options_.workspace_enabled) return RobotResult::Ok();
  // Sampling: kCoarse equal steps of the fraction, each split further so that two samples are
  // at most kMaxStepM apart in the box frame's position. A smooth path then leaves the box by
  // at most about half a step (2.5 mm) between two samples without being seen; the check at
  // every poll still watches the real motion. fraction 0 is where the robot already is.
  constexpr int kCoarse = 32;
  constexpr double kMaxStepM = 0.005;
  constexpr int kMaxSplit = 10000;  // bounds the work for absurd paths (kilometres)
  auto origin_at = [&](double fraction, vpHomogeneousMatrix* wMb) {
    const RobotPose p = robot_.PoseAlongMove(frame, from, target, fraction);
    if (!p.result.ok()) {
      return RobotResult::Fail(p.result.status,
                               "cannot tell the path of the move to check it against the "
                               "workspace box: " +
                                   p.result.message);
    }
    *wMb = BoxFramePose(frame, p.pose);
    return RobotResult::Ok();
  };
  vpHomogeneousMatrix previous;
  if (RobotResult r = origin_at(0, &previous); !r.ok()) return r;
  for (int i = 0; i < kCoarse; ++i) {
    const double f0 = static_cast<double>(i) / kCoarse;
    const double f1 = static_cast<double>(i + 1) / kCoarse;
    vpHomogeneousMatrix end;
    if (RobotResult r = origin_at(f1, &end); !r.ok()) return r;
    const double chord =
        (end.getTranslationVector() - previous.getTranslationVector()).frobeniusNorm();
    const int split =
        std::isfinite(chord)
            ? std::min(kMaxSplit, std::max(1, static_cast<int>(std::ceil(chord / kMaxStepM))))
            : 1;
    for (int j = 1; j <= split; ++j) {
      const double f = j == split ? f1 : f0 + (f1 - f0) * j / split;
      vpHomogeneousMatrix wMb = end;
      if (j < split) {
        if (RobotResult r = origin_at(f, &wMb); !r.ok()) return r;
      }
      std::ostringstream what;
      what << "the move's path, at " << f << " of the way,";
      if (RobotResult r = CheckInBox(wMb, what.str()); !r.ok()) return r;
    }
    previous = end;
  }
  return RobotResult::Ok();
}

void SafeRobot::RecordCycle(double seconds) {
  ++timing_.cycles;
  timing_.last_s = seconds;
  timing_.total_s += seconds;
  if (seconds > timing_.max_s) timing_.max_s = seconds;
}

RobotPose SafeRobot::GetPosition(RobotFrame frame) {
  if (state_ == SafeRobotState::kDisconnected) {
    RobotPose p;
    p.result = RobotResult::Fail(RobotStatus::kNotReady, "not connected: call Connect() first");
    return p;
  }
  return robot_.GetPosition(frame);
}

vpColVector SafeRobot::Saturate(const vpColVector& v, double max_translation_mps,
                                double max_rotation_radps, double* scale, int* limiting_axis) {
  if (v.size() != 6) {
    throw std::invalid_argument("SafeRobot: twist has " + std::to_string(v.size()) +
                                " entries, expected 6");
  }
  double s = 1;
  int axis = -1;
  for (unsigned i = 0; i < 6; ++i) {
    const double limit = i < 3 ? max_translation_mps : max_rotation_radps;
    const double a = std::abs(v[i]);
    if (a > limit && limit / a < s) {
      s = limit / a;
      axis = static_cast<int>(i);
    }
  }
  if (scale) *scale = s;
  if (limiting_axis) *limiting_axis = axis;
  return s < 1 ? v * s : v;
}

CycleReport SafeRobot::SetVelocity(RobotFrame frame, const vpColVector& v) {
  const Clock::time_point start = Clock::now();
  CycleReport report;
  auto finish = [&](RobotResult r) {
    report.result = std::move(r);
    report.duration_s = Seconds(start);
    RecordCycle(report.duration_s);
    if (report.result.ok() && options_.max_cycle_s > 0 &&
        report.duration_s > options_.max_cycle_s) {
      RobotResult why = RobotResult::Fail(
          RobotStatus::kTimeout, "cycle took " + Number(report.duration_s) + " s > max_cycle_s " +
                                     Number(options_.max_cycle_s));
      Latch(why);
      report.result = std::move(why);
    }
    return report;
  };
  if (v.size() != 6) {
    throw std::invalid_argument("SafeRobot::SetVelocity: twist has " + std::to_string(v.size()) +
                                " entries, expected 6");
  }
  for (unsigned i = 0; i < 6; ++i) {
    if (!std::isfinite(v[i])) {
      RobotResult why = RobotResult::Fail(
          RobotStatus::kLimit, std::string("twist component ") + kAxisName[i] + " is not finite");
      Latch(why);
      return finish(why);
    }
  }
  if (RobotResult r = CheckMayMove(); !r.ok()) return finish(r);
  report.twist = Saturate(v, options_.max_translation_mps, options_.max_rotation_radps,
                          &report.scale, &report.limiting_axis);
  report.saturated = report.scale < 1;
  if (options_.workspace_enabled) {
    const RobotPose now = robot_.GetPosition(frame);
    if (!now.result.ok()) {
      Latch(now.result);
      return finish(now.result);
    }
    const vpHomogeneousMatrix next =
        now.pose * vpExponentialMap::direct(report.twist, sampling_time_s_);
    if (RobotResult r = CheckInBox(BoxFramePose(frame, next), "the velocity command"); !r.ok()) {
      Latch(r);
      return finish(r);
    }
  }
  RobotResult r = robot_.SetVelocity(frame, report.twist);
  if (!r.ok()) Latch(r);
  return finish(r);
}

RobotPose SafeRobot::PlanMove(RobotFrame frame, const vpHomogeneousMatrix& target) {
  RobotPose reach = robot_.NearestReachable(frame, target);
  if (!reach.result.ok()) return reach;
  if (RobotResult r = CheckInBox(BoxFramePose(frame, reach.pose), "the move target"); !r.ok()) {
    reach.result = r;
    return reach;
  }
  // The path too, as the driver will execute it (a joint-interpolated arm swings out on an
  // arc), before anything is sent.
  if (options_.workspace_enabled) {
    const RobotPose from = robot_.GetPosition(frame);
    if (!from.result.ok()) return {from.result, reach.pose};
    if (RobotResult r = CheckPathInBox(frame, from.pose, reach.pose); !r.ok()) {
      reach.result = r;
    }
  }
  return reach;
}

RobotPose SafeRobot::CheckMove(RobotFrame frame, const vpHomogeneousMatrix& target) {
  if (state_ == SafeRobotState::kDisconnected) {
    return {RobotResult::Fail(RobotStatus::kNotReady, "not connected"), vpHomogeneousMatrix()};
  }
  return PlanMove(frame, target);
}

MoveReport SafeRobot::MovePosition(RobotFrame frame, const vpHomogeneousMatrix& target) {
  const Clock::time_point move_start = Clock::now();
  MoveReport report;
  auto fail = [&](RobotResult r) {
    Latch(r);
    report.result = std::move(r);
    report.duration_s = Seconds(move_start);
    return report;
  };
  if (RobotResult r = CheckMayMove(); !r.ok()) {
    report.result = r;
    return report;
  }
  const RobotPose reach = PlanMove(frame, target);
  report.target = reach.pose;
  if (!reach.result.ok()) return fail(reach.result);
  if (RobotResult r = robot_.StartMove(frame, report.target); !r.ok()) return fail(r);
  const int max_polls = static_cast<int>(std::ceil(options_.move_timeout_s / sampling_time_s_));
  for (;;) {
    const Clock::time_point cycle_start = Clock::now();
    if (RobotResult r = CheckMayMove(); !r.ok()) return fail(r);
    if (report.polls >= max_polls) {
      return fail(RobotResult::Fail(
          RobotStatus::kTimeout,
          "move not finished after " + Number(options_.move_timeout_s) + " s (move_timeout_s)"));
    }
    const MoveProgress progress = robot_.PollMove();
    ++report.polls;
    if (!progress.result.ok()) return fail(progress.result);
    const RobotPose now = robot_.GetPosition(frame);
    if (!now.result.ok()) return fail(now.result);
    report.reached = now.pose;
    if (RobotResult r = CheckInBox(BoxFramePose(frame, now.pose), "the move"); !r.ok()) {
      return fail(r);
    }
    const double cycle_s = Seconds(cycle_start);
    RecordCycle(cycle_s);
    if (options_.max_cycle_s > 0 && cycle_s > options_.max_cycle_s) {
      return fail(RobotResult::Fail(
          RobotStatus::kTimeout,
          "cycle took " + Number(cycle_s) + " s > max_cycle_s " + Number(options_.max_cycle_s)));
    }
    if (progress.done) break;
  }
  const PoseDistance d = Distance(report.target, report.reached);
  if (d.translation_m > options_.reach_tolerance_m ||
      d.rotation_rad > options_.reach_tolerance_rad) {
    return fail(RobotResult::Fail(
        RobotStatus::kError, "move ended " + Number(d.translation_m * 1e3) + " mm and " +
                                 Number(vpMath::deg(d.rotation_rad)) + " deg from its target"));
  }
  report.result = RobotResult::Ok();
  report.duration_s = Seconds(move_start);
  return report;
}

}  // namespace oal
