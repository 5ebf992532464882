// `oalservo servo-accuracy`'s runs (eval/campaigns/servo_accuracy.h) from a servo configuration:
// the starts drawn around its target and camera, each run as `oalservo servo` runs it.
#pragma once

#include <functional>
#include <vector>

#include "app/config.h"
#include "eval/campaigns/servo_accuracy.h"

namespace oal {

/// The target, its wMo and the camera of `config`.
ServoStartScene StartSceneOf(const ServoAppConfig& config);

/// SampleServoStarts in `config`'s scene.
std::vector<vpHomogeneousMatrix> SampleServoStarts(const ServoAppConfig& config,
                                                   const ServoAccuracyOptions& options);

/// EvaluateServoAccuracy with `config`'s servo run (RunServo, app/servo_run.h): its law set to
/// each mode, its robot started at each start.
ServoAccuracyReport EvaluateServoAccuracy(
    const ServoAppConfig& config, const ServoAccuracyOptions& options,
    const std::function<void(int done, int total)>& progress = nullptr);

}  // namespace oal
