#include "app/servo_run.h"

#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/servo_rig.h"
#include "base/format.h"

namespace oal {
namespace {

// goal.image read into the setup, with the name its messages give it ("FILE:LINE: goal.image
// 'x.png'"); throws std::runtime_error saying so when it cannot be read.
void ReadGoalImage(const ServoAppConfig& config, ServoSetup* setup) {
  setup->goal_image_name = config.goal_image_origin + ": goal.image '" + config.goal_image + "'";
  setup->goal_image = cv::imread(config.goal_image, cv::IMREAD_GRAYSCALE);
  if (setup->goal_image.empty()) {
    throw std::runtime_error(setup->goal_image_name + ": cannot read or decode the image");
  }
}

}  // namespace

vpHomogeneousMatrix TeachGoal(const ServoAppConfig& config) {
  ServoSetup setup = ServoSetupOf(config);
  ReadGoalImage(config, &setup);
  return TeachGoal(setup, setup.goal_image, setup.goal_image_name);
}

void CheckServoConfig(const ServoAppConfig& config) {
  config.camera.Check();
  config.robot.Check();
  config.servo.Check();
  config.source.Check();
  if (config.source.type == SourceType::kV4l2 && config.robot.type == RobotType::kSimulated) {
    throw std::invalid_argument(
        "source.type v4l2 needs a real robot carrying the camera (robot.type is simulated, "
        "whose motion the camera would not see); to watch a camera without moving anything use "
        "source: {type: replay, path: " +
        config.source.device + "}");
  }
  if (config.camera.estimate_distortion && !config.camera.correct_distortion) {
    throw std::invalid_argument(KeyAt(config, "camera.estimate_distortion") +
                                " tells the lens to correct it, but camera.correct_distortion "
                                "is false: give one of them");
  }
  if (config.camera.estimate_distortion && config.source.type != SourceType::kSimulated &&
      config.camera.kdu != 0.0) {
    throw std::invalid_argument(KeyAt(config, "camera.estimate_distortion") +
                                " tells the lens from the stripes, but the camera gives kdu " +
                                Number(config.camera.kdu) + " (" + KeyAt(config, "camera.kdu") +
                                "): give one of them");
  }
  if (config.camera.true_eMc && config.source.type != SourceType::kSimulated) {
    throw std::invalid_argument(KeyAt(config, "camera.true_eMc") +
                                " is the mounting of a simulated camera; source.type is " +
                                ToString(config.source.type) + ": remove it");
  }
}

ServoRunReport RunServo(const ServoAppConfig& config, std::ostream& log,
                        const ServoRunHooks& hooks) {
  CheckServoConfig(config);
  ServoSetup setup = ServoSetupOf(config);
  std::vector<std::string> source_warnings;
  const std::unique_ptr<FrameSource> frames = OpenFrames(config, &source_warnings);
  for (const std::string& warning : source_warnings) log << "warning: " << warning << '\n';

  int move_iteration = -1;  // the iteration whose move runs, for Hooks::on_move_poll
  RobotRig rig = OpenConfiguredRobot(config, [&hooks, &move_iteration](int poll) {
    if (hooks.on_move_poll) hooks.on_move_poll(move_iteration, poll);
  });
  if (hooks.wrap_driver) rig.driver = hooks.wrap_driver(std::move(rig.driver));
  if (!config.goal_image.empty()) ReadGoalImage(config, &setup);
  ServoLoopHooks loop_hooks = hooks;
  loop_hooks.on_move = [&hooks, &move_iteration](int iteration) {
    move_iteration = iteration;
    if (hooks.on_move) hooks.on_move(iteration);
  };
  return RunServoLoop(setup, *frames, rig.Loop(), log, loop_hooks);
}

}  // namespace oal
