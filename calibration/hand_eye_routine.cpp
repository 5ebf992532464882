#include "calibration/hand_eye_routine.h"

#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>

#include <string>
#include <utility>
#include <vector>

#include "base/check.h"
#include "base/format.h"

namespace oal {
namespace {

bool Interrupted(const std::atomic<bool>* interrupt) {
  return interrupt != nullptr && interrupt->load(std::memory_order_relaxed);
}

// The target's pose once `frames_averaged` successive frames agree, each with the one before
// (the arm and its camera stand still): their mean, which halves the pose's noise from four.
// nullopt with `why` when no pose is seen or it keeps moving.
std::optional<vpHomogeneousMatrix> StillPose(const MeasureTarget& measure,
                                             const HandEyeRoutineOptions& options,
                                             const std::atomic<bool>* interrupt, std::string* why) {
  why->clear();                            // a reason from an earlier station is not this one's
  std::vector<vpHomogeneousMatrix> still;  // successive agreeing poses
  for (int frame = 0; frame < options.max_frames_per_station; ++frame) {
    if (Interrupted(interrupt)) {
      *why = "interrupted";
      return std::nullopt;
    }
    std::optional<vpHomogeneousMatrix> cMo = measure(why);
    if (!cMo) {
      still.clear();
      continue;
    }
    if (!still.empty()) {
      const PoseDistance moved = Distance(still.back(), *cMo);
      if (moved.translation_m * 1e3 > options.still_mm ||
          vpMath::deg(moved.rotation_rad) > options.still_deg) {
        *why = "the target's pose kept changing (by " + Fixed(moved.translation_m * 1e3, 2) +
               " mm between the last two frames): the arm or the target is not still";
        still.clear();
      }
    }
    still.push_back(*cMo);
    if (static_cast<int>(still.size()) == options.frames_averaged) {
      return vpHomogeneousMatrix::mean(still);
    }
  }
  if (!still.empty() && why->empty()) {
    *why = "fewer than " + std::to_string(options.frames_averaged) + " frames showed the target";
  }
  return std::nullopt;
}

// Why the runner would refuse a move to wMe, or why the target would not be seen there
// (`in_view` on the target's pose predicted through the guess); empty: neither. The pose the
// arm would reach is judged, not the one asked: a 5-axis arm cannot turn freely, and what it
// makes of a station may look elsewhere.
std::string Refusal(SafeRobot& robot, const vpHomogeneousMatrix& wMe,
                    const vpHomogeneousMatrix& eMc_guess, const vpHomogeneousMatrix& wMo_seen,
                    const TargetInView& in_view) {
  const RobotPose reach = robot.CheckMove(RobotFrame::kEndEffector, wMe);
  if (!reach.result.ok()) return reach.result.message;
  if (!in_view) return "";
  return in_view((reach.pose * eMc_guess).inverse() * wMo_seen);
}

struct StationPlan {
  vpHomogeneousMatrix wMe;  // where to send the end effector
  std::string how;          // how it differs from the plan, for the user ("" as planned)
  std::string refusal;      // why the station is skipped; "" when it is not
};

// The station, or when it is refused (out of the box, out of reach: an arm near a joint
// limit, or the target out of view), the same turn the other way, then half of it either way,
// along the screw about the target.
StationPlan PlanStation(SafeRobot& robot, const vpHomogeneousMatrix& start,
                        const vpHomogeneousMatrix& planned, const vpHomogeneousMatrix& eMc_guess,
                        const vpHomogeneousMatrix& wMo_seen, const TargetInView& in_view) {
  StationPlan plan{planned, "", Refusal(robot, planned, eMc_guess, wMo_seen, in_view)};
  if (plan.refusal.empty()) return plan;
  const vpColVector screw = vpExponentialMap::inverse(start.inverse() * planned);
  const std::pair<double, const char*> alternatives[] = {{-1.0, "turned the other way"},
                                                         {0.5, "at half the turn"},
                                                         {-0.5, "at half the turn, the other way"}};
  for (const auto& [fraction, how] : alternatives) {
    const vpHomogeneousMatrix instead = start * vpExponentialMap::direct(fraction * screw);
    if (!Refusal(robot, instead, eMc_guess, wMo_seen, in_view).empty()) continue;
    return {instead, std::string(" ") + how + " (as planned: " + plan.refusal + ")", ""};
  }
  return plan;
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
  RequireOption(frames_averaged >= 2 && frames_averaged <= 100,
                "HandEyeRoutineOptions::frames_averaged", frames_averaged,
                "2 <= frames_averaged <= 100");
  RequireOption(max_frames_per_station >= frames_averaged && max_frames_per_station <= 1000,
                "HandEyeRoutineOptions::max_frames_per_station", max_frames_per_station,
                "frames_averaged <= max_frames_per_station <= 1000");
}

HandEyeRoutineResult RunHandEyeRoutine(SafeRobot& robot, const vpHomogeneousMatrix& eMc_guess,
                                       const MeasureTarget& measure,
                                       const HandEyeRoutineOptions& options,
                                       const std::function<void(const std::string&)>& progress,
                                       const TargetInView& in_view,
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
  // The target in the world as the guess places it: to predict where each station sees it.
  const vpHomogeneousMatrix wMo_seen = start.pose * eMc_guess * *cMo_start;
  const std::vector<vpHomogeneousMatrix> planned =
      HandEyeStations(start.pose, eMc_guess, *cMo_start, options.stations);
  const int count = static_cast<int>(planned.size());
  for (int k = 0; k < count; ++k) {
    HandEyeStation station;
    const std::string name = "station " + std::to_string(k + 1) + "/" + std::to_string(count);
    if (Interrupted(interrupt)) return StopHere(robot, "interrupted at " + name, &result);
    const StationPlan plan =
        PlanStation(robot, start.pose, planned[k], eMc_guess, wMo_seen, in_view);
    station.wMe_planned = plan.wMe;
    if (!plan.refusal.empty()) {
      station.skipped = "skipped before moving: " + plan.refusal;
      say(name + ": " + station.skipped);
      result.stations.push_back(station);
      continue;
    }
    const MoveReport move = robot.MovePosition(RobotFrame::kEndEffector, station.wMe_planned);
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
        (station.taken ? "pair " + std::to_string(result.pairs.size()) + " taken" + plan.how
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
