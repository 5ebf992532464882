#include "app/fault_campaign.h"

#include <stdexcept>
#include <string>

#include "app/servo_command.h"
#include "app/servo_rig.h"

namespace oal {
namespace {

// The campaign drives simulators only, and judges with the simulation's truth.
void CheckCampaignConfig(const ServoAppConfig& config) {
  config.robot.Check();
  config.source.Check();
  if (config.source.type != SourceType::kSimulated) {
    throw std::invalid_argument(
        "the fault campaign renders its frames: source.type must be "
        "simulated, not " +
        ToString(config.source.type));
  }
  if (config.robot.type == RobotType::kScorbot && config.robot.scorbot.port != "simulator") {
    const std::string origin = config.Origin("robot.scorbot.port");
    throw std::invalid_argument(
        "the fault campaign drives the Controller-A simulator, never an arm: " +
        (origin.empty() ? std::string() : origin + ": ") + "robot.scorbot.port is '" +
        config.robot.scorbot.port + "', not simulator");
  }
}

}  // namespace

FaultedRobot FaultedRobotOf(RobotType type) {
  return type == RobotType::kScorbot ? FaultedRobot::kScorbot : FaultedRobot::kSimulated;
}

FaultCampaignReport RunFaultCampaign(const ServoAppConfig& config,
                                     const FaultCampaignOptions& options,
                                     const std::function<void(int, int)>& progress) {
  options.Check();
  CheckCampaignConfig(config);
  FaultCampaignSetup setup;
  setup.robot = FaultedRobotOf(config.robot.type);
  if (setup.robot == FaultedRobot::kScorbot) setup.controller = ControllerSimOptions(config);
  setup.outcome_prefix = "oalservo servo: ";  // RunServoWithOutputs' outcome line
  setup.max_lost_frames = config.servo.max_lost_frames;
  setup.run = [&config](const FaultRunRequest& request, std::ostream& log) {
    ServoAppConfig run = config;
    run.output.directory = request.output_dir;
    run.output.display = DisplayMode::kOff;
    if (!request.controller_port.empty()) {
      run.robot.scorbot.port = request.controller_port;
      run.robot.scorbot.xonxoff = true;  // as the manual specifies: XOFF holds our output
    }
    ServoRunHooks hooks;
    static_cast<ServoLoopHooks&>(hooks) = request.hooks;
    hooks.wrap_driver = request.wrap_driver;
    return RunServoWithOutputs(run, "the fault campaign's configuration",
                               "the campaign's folder (--work-dir)", log, hooks);
  };
  return RunFaultCampaign(setup, options, progress);
}

}  // namespace oal
