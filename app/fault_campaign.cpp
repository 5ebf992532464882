#include "app/fault_campaign.h"

#include <filesystem>
#include <fstream>
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

// The servo job's servo.csv (RunServoWithOutputs) is whole: one row per iteration of the
// loop's report, the last row the run's last; "" when it is, else what is wrong.
std::string CheckServoCsv(const std::string& dir, const ServoRunReport& report) {
  std::ifstream csv(std::filesystem::path(dir) / "servo.csv");
  if (!csv) return "servo.csv is missing";
  std::string line, last;
  int rows = -1;  // the header
  while (std::getline(csv, line)) {
    ++rows;
    last = line;
  }
  if (rows != static_cast<int>(report.iterations.size())) {
    return "servo.csv has " + std::to_string(rows) + " rows for " +
           std::to_string(report.iterations.size()) + " iterations";
  }
  if (!report.iterations.empty() &&
      last.substr(last.rfind(',') + 1) != report.iterations.back().status) {
    return "servo.csv's last row is not the run's last: " + last;
  }
  return "";
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
  setup.check_outputs = CheckServoCsv;
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
