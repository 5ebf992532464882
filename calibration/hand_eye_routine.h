// The automatic hand-eye routine: the arm visits stations around where it stands (the camera
// turned about the target, HandEyeStations()), and at each, once it stands still, a pair is
// taken: the end effector's pose from the robot, the target's from the camera. Every move goes
// through the safety runner; a station it would refuse (outside the workspace box, out of
// reach) is skipped with the reason before anything moves. At the end the arm goes back to
// where it started.
//
// The frames and the pose estimate come from the caller (MeasureTarget): this library knows
// the robot interface, not images.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calibration/hand_eye.h"
#include "robots/safe_robot.h"

namespace oal {

/// Takes a frame and estimates the target's pose in it: cMo, or nullopt with `why` set ("the
/// target is not in view").
using MeasureTarget = std::function<std::optional<vpHomogeneousMatrix>(std::string* why)>;

struct HandEyeRoutineOptions {
  HandEyeStationOptions stations;
  /// The arm stands still when two successive poses of the target agree within these: mm ...
  double still_mm = 0.5;
  /// ... and degrees.
  double still_deg = 0.1;
  /// Frames to wait at a station for the target to stand still. Range [2, 1000].
  int max_frames_per_station = 10;

  void Check() const;
};

struct HandEyeStation {
  vpHomogeneousMatrix wMe_planned;
  bool taken = false;
  std::string skipped;  ///< why no pair was taken here (empty when taken)
};

struct HandEyeRoutineResult {
  std::vector<HandEyePair> pairs;
  std::vector<HandEyeStation> stations;
  /// Every station visited (or skipped) and the arm back at the start. When false, `stopped`
  /// says why the routine ended early; the robot is stopped then.
  bool completed = false;
  std::string stopped;
};

/// Runs the routine on a connected, enabled `robot`. `eMc_guess`: the mounting as the user
/// believes it, to plan the stations (it does not enter the pairs). `progress` receives one
/// line per station (may be empty). `interrupt`, when set, stops the arm at the next frame or
/// poll and ends the routine. A first frame with no pose ends it before anything moves.
HandEyeRoutineResult RunHandEyeRoutine(SafeRobot& robot, const vpHomogeneousMatrix& eMc_guess,
                                       const MeasureTarget& measure,
                                       const HandEyeRoutineOptions& options,
                                       const std::function<void(const std::string&)>& progress,
                                       const std::atomic<bool>* interrupt = nullptr);

}  // namespace oal
