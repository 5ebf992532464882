#include "calibration/hand_eye_routine.h"

#include <visp3/core/vpMath.h>

#include <cmath>
#include <sstream>

#include "detector/options.h"  // RequireOption

namespace oal {
namespace {

std::string Fixed(double value, int digits) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

bool Interrupted(const std::atomic<bool>* interrupt) {
  return interrupt != nullptr && interrupt->load(std::memory_order_relaxed);
}

// The target's pose once two successive frames agree (the arm and its camera stand still);
// nullopt with `why` when no pose is seen or it keeps moving.
std::optional<vpHomogeneousMatrix> StillPose(const MeasureTarget& measure,
                                             const HandEyeRoutineOptions& options,
                                             const std::atomic<bool>* interrupt, std::string* why) {
  std::optional<vpHomogeneousMatrix> previous;
  for (int frame = 0; frame < options.max_frames_per_station; ++frame) {
    if (Interrupted(interrupt)) {
      *why = "interrupted";
      return std::nullopt;
    }
    std::optional<vpHomogeneousMatrix> cMo = measure(why);
    if (!cMo) {
      previous.reset();
      continue;
    }
    if (previous) {
      const PoseDistance moved = Distance(*previous, *cMo);
      if (moved.translation_m * 1e3 <= options.still_mm &&
          vpMath::deg(moved.rotation_rad) <= options.still_deg) {
        return cMo;
      }
      *why = "the target's pose kept changing (by " + Fixed(moved.translation_m * 1e3, 2) +
             " mm between the last two frames): the arm or the target is not still";
    }
    previous = cMo;
  }
  return std::nullopt;
}

// Ends the routine early: the arm stopped, the reason kept.
HandEyeRoutineResult& StopHere(SafeRobot& robot, const std::string& why,
                               HandEyeRoutineResult* result) {
  robot.Stop();
  result->completed = false;
  result->stopped = why;
  return *result;
}

}  // namespace

void HandEyeRoutineOptions::Check() const {
  stations.Check();
  RequireOption(still_mm > 0.0 && still_mm <= 100.0, "HandEyeRoutineOptions::still_mm", still_mm,
                "0 < still_mm <= 100");
  RequireOption(still_deg > 0.0 && still_deg <= 10.0, "HandEyeRoutineOptions::still_deg", still_deg,
                "0 < still_deg <= 10");
  RequireOption(max_frames_per_station >= 2 && max_frames_per_station <= 1000,
                "HandEyeRoutineOptions::max_frames_per_station", max_frames_per_station,
                "2 <= max_frames_per_station <= 1000");
}

HandEyeRoutineResult RunHandEyeRoutine(SafeRobot& robot, const vpHomogeneousMatrix& eMc_guess,
                                       const MeasureTarget& measure,
                                       const HandEyeRoutineOptions& options,
                                       const std::function<void(const std::string&)>& progress,
                                       const std::atomic<bool>* interrupt) {
  options.Check();
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  HandEyeRoutineResult result;
  const RobotPose start = robot.GetPosition(RobotFrame::kEndEffector);
  if (!start.result.ok()) {
    return StopHere(robot, "the arm's pose cannot be read: " + start.result.message, &result);
  }
  std::string why;
  const std::optional<vpHomogeneousMatrix> cMo_start = StillPose(measure, options, interrupt, &why);
  if (!cMo_start) {
    return StopHere(robot, "no pose of the target where the arm stands: " + why, &result);
  }
  const std::vector<vpHomogeneousMatrix> planned =
      HandEyeStations(start.pose, eMc_guess, *cMo_start, options.stations);
  const int count = static_cast<int>(planned.size());
  for (int k = 0; k < count; ++k) {
    HandEyeStation station;
    station.wMe_planned = planned[k];
    const std::string name = "station " + std::to_string(k + 1) + "/" + std::to_string(count);
    if (Interrupted(interrupt)) return StopHere(robot, "interrupted at " + name, &result);
    const RobotPose plan = robot.CheckMove(RobotFrame::kEndEffector, planned[k]);
    if (!plan.result.ok()) {
      station.skipped = "skipped before moving: " + plan.result.message;
      say(name + ": " + station.skipped);
      result.stations.push_back(station);
      continue;
    }
    const MoveReport move = robot.MovePosition(RobotFrame::kEndEffector, planned[k]);
    if (!move.result.ok()) {
      result.stations.push_back(station);
      return StopHere(robot, name + ": the move failed: " + move.result.message, &result);
    }
    const std::optional<vpHomogeneousMatrix> cMo = StillPose(measure, options, interrupt, &why);
    const RobotPose wMe = robot.GetPosition(RobotFrame::kEndEffector);
    if (Interrupted(interrupt)) return StopHere(robot, "interrupted at " + name, &result);
    if (!wMe.result.ok()) {
      result.stations.push_back(station);
      return StopHere(robot, name + ": the arm's pose cannot be read: " + wMe.result.message,
                      &result);
    }
    if (!cMo) {
      station.skipped = "no pair: " + why;
    } else {
      station.taken = true;
      result.pairs.push_back({wMe.pose, *cMo});
    }
    say(name + ": " +
        (station.taken ? "pair " + std::to_string(result.pairs.size()) + " taken"
                       : station.skipped));
    result.stations.push_back(station);
  }
  const MoveReport back = robot.MovePosition(RobotFrame::kEndEffector, start.pose);
  if (!back.result.ok()) {
    return StopHere(robot, "the move back to the start failed: " + back.result.message, &result);
  }
  result.completed = true;
  return result;
}

}  // namespace oal
