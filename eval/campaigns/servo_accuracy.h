// Closed-loop convergence from many random start poses (the "≥ 99 % converge" figure):
// `oalservo servo-accuracy`. Each start is a camera pose drawn with scene/'s SamplePose
// (fixed seed) and run by the caller's servo run (`oalservo servo`'s, from its configuration)
// with the image in the loop, for each law asked.
//
// Start poses: the camera 0.3–0.8 m from the target, its optical axis at most 30° from the
// board's normal and aimed within 5 cm of the board's centre, rolled at most 30° from the
// goal's roll, every target line crossing at least 15 % of the image width (so the start can
// see the target: a start that cannot is not a servoing failure but a bad test). The goal
// and everything else are the caller's run's.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "detector/lens.h"
#include "loop/servo_loop.h"
#include "servo/pbvs.h"
#include "target/line_target.h"

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
  /// Motion commands the robot received after a frame the loop did not act on (-1: not
  /// audited).
  int unconfirmed_motions = -1;
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

/// Where the starts are drawn: the target, where it lies in the world, and the camera.
struct ServoStartScene {
  LineTarget target;
  vpHomogeneousMatrix wMo;  ///< the target in the world frame
  Lens camera;
  int width = 640, height = 480;  ///< the camera's image, pixels
};

/// One servo run from the camera pose `start_wMc` (the `start`-th, 0 first) with the law
/// `mode`, at most `max_iterations` (0: the run's own limit), the image in the loop; its
/// report, whose iterations carry the true errors (a simulated camera).
/// Its report, and the motion commands that reached the robot after a frame the loop did
/// not act on (eval/campaigns/motion_audit.h; -1: not audited).
struct AuditedServoRun {
  ServoRunReport report;
  int unconfirmed_motions = -1;
};
using ServoRunFrom = std::function<AuditedServoRun(const vpHomogeneousMatrix& start_wMc,
                                                   ServoMode mode, int max_iterations, int start)>;

/// The start poses wMc of `options` in `scene` (deterministic in options.seed).
std::vector<vpHomogeneousMatrix> SampleServoStarts(const ServoStartScene& scene,
                                                   const ServoAccuracyOptions& options);

/// Runs every law from every start with `run`; `progress(done, total)` after each run.
ServoAccuracyReport EvaluateServoAccuracy(
    const ServoStartScene& scene, const ServoAccuracyOptions& options, const ServoRunFrom& run,
    const std::function<void(int done, int total)>& progress = nullptr);

}  // namespace oal
