#include "app/servo_command.h"

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <iostream>

#include "app/atomic_file.h"
#include "app/command_line.h"
#include "app/servo_default_config.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

// Ctrl-C: the handler only stores to lock-free atomics (async-signal-safe).
std::atomic<bool> g_interrupt{false};
std::atomic<SafeRobot*> g_robot{nullptr};
static_assert(std::atomic<SafeRobot*>::is_always_lock_free, "the robot pointer must be lock-free");

extern "C" void OnSigint(int /*signal*/) {
  g_interrupt.store(true);
  if (SafeRobot* robot = g_robot.load()) robot->RequestEmergencyStop();
}

// Installs the handler for the lifetime of the run and restores the previous one.
class SigintScope {
 public:
  SigintScope() { previous_ = std::signal(SIGINT, &OnSigint); }
  ~SigintScope() { std::signal(SIGINT, previous_); }
  SigintScope(const SigintScope&) = delete;
  SigintScope& operator=(const SigintScope&) = delete;

 private:
  void (*previous_)(int) = SIG_DFL;
};

}  // namespace

ServoAppConfig DefaultServoConfig() {
  return ParseConfig(kDefaultServoConfigYaml, kDefaultServoConfigName);
}

ServoAppConfig LoadServoConfig(const ServoCommandOptions& options) {
  if (options.config_path.empty()) return DefaultServoConfig();
  return LoadConfig(options.config_path);
}

ServoRunReport RunServoCommand(const ServoCommandOptions& options, std::ostream& out,
                               const ServoRunHooks& hooks) {
  const ServoAppConfig config = LoadServoConfig(options);
  const fs::path csv = fs::path(options.out_dir) / "servo.csv";
  if (!options.out_dir.empty()) {
    fs::create_directories(options.out_dir);
    CheckOutputFile(csv);
  }
  out << "oalservo servo: "
      << (options.config_path.empty() ? kDefaultServoConfigName : options.config_path) << ", "
      << ToString(config.servo.law.mode) << " law\n";
  const ServoRunReport report = RunServo(config, out, hooks);
  out << "oalservo servo: " << ToString(report.status) << ": " << report.message << '\n';
  if (!options.out_dir.empty()) {
    AtomicFile file(csv);
    WriteServoCsv(report, file.stream());
    file.Commit();
    out << "oalservo servo: wrote " << csv.string() << '\n';
  }
  return report;
}

int RunServoMain(int argc, char** argv) {
  ServoCommandOptions options;
  CLI::App cli(
      "Visual servoing to a goal pose with the camera in the loop: render (simulated camera), "
      "detect, estimate the pose, move the robot; one row per iteration in the form of the "
      "paper's Table 3, and DIR/servo.csv.",
      "oalservo servo");
  cli.add_option("--config", options.config_path,
                 "YAML configuration: camera, robot, servo, goal, target_pose (and detector, "
                 "target, pose) sections; default: the built-in config/servo-sim.yaml");
  cli.add_option("--out", options.out_dir, "output directory for servo.csv (created if missing)")
      ->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo servo\n"
      "  oalservo servo --config config/table3-sim.yaml --out out/table3");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  g_interrupt.store(false);
  SigintScope sigint;
  ServoRunHooks hooks;
  hooks.interrupt = &g_interrupt;
  hooks.on_robot = [](SafeRobot* robot) { g_robot.store(robot); };
  const ServoRunReport report = RunServoCommand(options, std::cout, hooks);
  return report.status == ServoRunStatus::kConverged ? kExitOk : kExitError;
}

}  // namespace oal
