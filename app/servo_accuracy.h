// Closed-loop convergence from many random start poses (the "≥ 99 % converge" figure):
// `oalservo servo-accuracy`. Each start is a camera pose drawn with scene/'s SamplePose
// (fixed seed) and run through RunServo with the image in the loop, for each law asked.
//
// Start poses: the camera 0.3–0.8 m from the target, its optical axis at most 30° from the
// board's normal and aimed within 5 cm of the board's centre, rolled at most 30° from the
// goal's roll, every target line crossing at least 15 % of the image width (so the start can
// see the target: a start that cannot is not a servoing failure but a bad test). The goal
// and everything else come from the configuration (by default config/servo-sim.yaml).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "app/config.h"
#include "app/servo_run.h"
#include "servo/pbvs.h"

namespace oal {

struct ServoAccuracyOptions {
  int starts = 100;             ///< random start poses per law, >= 1
  std::uint64_t seed = 1;       ///< seed of the start poses
  double min_distance_m = 0.3;  ///< from the target, > 0
  double max_distance_m = 0.8;  ///< >= min_distance_m
  double max_off_deg = 30.0;    ///< tilt from the board normal and roll from the goal's
  std::vector<ServoMode> modes = {ServoMode::kPointAndGo, ServoMode::kExponential,
                                  ServoMode::kVelocity};
  /// Overrides servo.max_iterations when > 0 (the velocity law needs hundreds of periods).
  int max_iterations = 300;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// One run from one start.
struct ServoAccuracyRun {
  int start = 0;                  ///< index of the start pose
  vpHomogeneousMatrix start_wMc;  ///< the start pose (robot.start), to re-run it alone
  ServoRunStatus status = ServoRunStatus::kError;
  std::string message;
  int moves = 0;
  double start_distance_m = 0, start_off_deg = 0;  ///< the start's distance to the goal
  double final_translation_error_mm = 0;           ///< true, at the last frame
  double final_rotation_error_deg = 0;
};

struct ServoAccuracyLaw {
  ServoMode mode = ServoMode::kExponential;
  std::vector<ServoAccuracyRun> runs;
  int converged() const;
};

struct ServoAccuracyReport {
  ServoAccuracyOptions options;
  std::vector<ServoAccuracyLaw> laws;
};

/// The start poses wMc of `options` for `config` (deterministic in options.seed).
std::vector<vpHomogeneousMatrix> SampleServoStarts(const ServoAppConfig& config,
                                                   const ServoAccuracyOptions& options);

/// Runs every law from every start; `progress(done, total)` after each run.
ServoAccuracyReport EvaluateServoAccuracy(
    const ServoAppConfig& config, const ServoAccuracyOptions& options,
    const std::function<void(int done, int total)>& progress = nullptr);

}  // namespace oal
