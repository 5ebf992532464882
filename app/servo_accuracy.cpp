#include "app/servo_accuracy.h"

#include <memory>
#include <sstream>
#include <utility>

#include "app/servo_run.h"
#include "eval/campaigns/motion_audit.h"

namespace oal {

ServoStartScene StartSceneOf(const ServoAppConfig& config) {
  ServoStartScene scene;
  scene.target = config.target;
  scene.wMo = config.target_wMo;
  scene.camera = config.camera.Camera();
  scene.width = config.camera.width;
  scene.height = config.camera.height;
  return scene;
}

std::vector<vpHomogeneousMatrix> SampleServoStarts(const ServoAppConfig& config,
                                                   const ServoAccuracyOptions& options) {
  return SampleServoStarts(StartSceneOf(config), options);
}

ServoAccuracyReport EvaluateServoAccuracy(const ServoAppConfig& config,
                                          const ServoAccuracyOptions& options,
                                          const std::function<void(int, int)>& progress) {
  const ServoRunFrom run = [&config](const vpHomogeneousMatrix& start_wMc, ServoMode mode,
                                     int max_iterations, int start) {
    ServoAppConfig run_config = config;
    // Each start its own episodes of the lived-in scene (the same for every law).
    run_config.scene.episode_seed = config.scene.episode_seed + start;
    run_config.servo.law.mode = mode;
    if (max_iterations > 0) run_config.servo.max_iterations = max_iterations;
    run_config.robot.start_wMc = start_wMc;
    std::ostringstream log;  // the per-iteration rows are not kept
    MotionAudit audit;
    ServoRunHooks hooks;
    hooks.wrap_driver = [&audit](std::unique_ptr<Robot> driver) {
      return audit.Wrap(std::move(driver));
    };
    hooks.on_grab = [&audit](int iteration, cv::Mat*) { audit.FrameTaken(iteration); };
    AuditedServoRun audited;
    audited.report = RunServo(run_config, log, hooks);
    audited.unconfirmed_motions = audit.Unconfirmed(audited.report);
    return audited;
  };
  return EvaluateServoAccuracy(StartSceneOf(config), options, run, progress);
}

}  // namespace oal
