// The automatic hand-eye routine: the arm visits stations around where it stands (the camera
// turned about the target, HandEyeStations()), and at each, once it stands still, a pair is
// taken: the end effector's pose from the robot, the target's from the camera. Every move goes
// through the safety runner; a station it would refuse (outside the workspace box, out of
// reach) or where the target would leave the view (predicted through the guessed mounting) is
// tried turned the other way and at half the turn, then skipped with the reason, before
// anything moves. At the end the arm goes back to
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

/// Whether the target would be seen well from a camera at `cMo`: "" when it would, else why
/// not ("a crossing would be 12 px from the image's edge").
using TargetInView = std::function<std::string(const vpHomogeneousMatrix& cMo)>;

struct HandEyeRoutineOptions {
  HandEyeStationOptions stations;
  /// The arm stands still when two successive poses of the target agree within these: mm ...
  double still_mm = 0.5;
  /// ... and degrees.
  double still_deg = 0.1;
  /// A pair's cMo is the mean of this many successive frames that agree (each within still_mm
  /// and still_deg of the one before). Range [2, 100].
  int frames_averaged = 4;
  /// Frames to wait at a station for them. Range [frames_averaged, 1000].
  int max_frames_per_station = 12;

  void Check() const;
};

struct HandEyeStation {
  /// Where the end effector was sent: the planned station, or, when the runner would refuse
  /// it, the same turn the other way or half of it.
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
/// line per station (may be empty). `in_view` (may be empty: not checked) judges each
/// station's view before the arm goes there, through the guess. `interrupt`, when set, stops the
/// arm at the next frame or poll and ends the routine. A first frame with no pose ends it before
/// anything moves.
HandEyeRoutineResult RunHandEyeRoutine(SafeRobot& robot, const vpHomogeneousMatrix& eMc_guess,
                                       const MeasureTarget& measure,
                                       const HandEyeRoutineOptions& options,
                                       const std::function<void(const std::string&)>& progress,
                                       const TargetInView& in_view = nullptr,
                                       const std::atomic<bool>* interrupt = nullptr);

}  // namespace oal
