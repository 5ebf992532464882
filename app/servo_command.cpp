#include "app/servo_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "app/command_line.h"
#include "app/live_window.h"
#include "app/servo_default_config.h"
#include "app/servo_output.h"
#include "io/atomic_file.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

// A stop signal also stops the robot at once, from the signal handler (StopSignalScope's
// callback). Why globals: a handler is called with the signal number only, so the robot it
// must stop can be reached only through process-wide state, and of that a handler may touch
// lock-free atomics only (RequestEmergencyStop() stores to one).
//   g_robot: the running SafeRobot, registered by the loop's on_robot hook once it runs and
//     set back to null before it is destroyed (StopGuard in loop/servo_loop.cpp, on every path
//     out of RunServo);
//   g_stops_in_flight: handlers between their load of g_robot and their last use of it. The
//     signal may be delivered to another thread (the Controller-A simulator's) while the loop
//     unregisters the robot: unregistering waits until none is left, so that the SafeRobot is
//     not destroyed under a handler still using it.
std::atomic<SafeRobot*> g_robot{nullptr};
std::atomic<int> g_stops_in_flight{0};
static_assert(std::atomic<SafeRobot*>::is_always_lock_free, "the robot pointer must be lock-free");
static_assert(std::atomic<int>::is_always_lock_free, "the handler count must be lock-free");

void RegisterRobot(SafeRobot* robot) {
  g_robot.store(robot);
  if (robot != nullptr) return;
  // A handler that loaded the old pointer before the store is counted (sequentially
  // consistent: it counted itself before its load); one that runs on this thread meanwhile
  // loads null and returns.
  while (g_stops_in_flight.load() != 0) std::this_thread::yield();
}

}  // namespace

void StopRobotOnSignal() {
  g_stops_in_flight.fetch_add(1);
  if (SafeRobot* robot = g_robot.load()) robot->RequestEmergencyStop();
  g_stops_in_flight.fetch_sub(1);
}

ServoRunHooks StopSignalHooks(const StopSignalScope& signals) {
  ServoRunHooks hooks;
  hooks.interrupt = signals.interrupted();
  hooks.interrupt_reason = [&signals] {
    const int number = signals.signal_number();
    return number != 0 ? StopSignalName(number) : std::string("a click in the window");
  };
  hooks.on_robot = &RegisterRobot;
  return hooks;
}

ServoAppConfig DefaultServoConfig() {
  return ParseConfig(kDefaultServoConfigYaml, kDefaultServoConfigName);
}

std::string ConfigNames(const ServoCommandOptions& options) {
  std::string names = options.config_path.empty() ? kDefaultServoConfigName : options.config_path;
  for (const std::string& path : options.more_config_paths) names += " + " + path;
  return names;
}

ServoAppConfig LoadServoConfig(const ServoCommandOptions& options) {
  // A file only says what differs from the built-in default.
  ServoAppConfig config = options.config_path.empty()
                              ? DefaultServoConfig()
                              : LoadConfig(options.config_path, DefaultServoConfig());
  for (const std::string& path : options.more_config_paths) config = LoadConfig(path, config);
  if (!options.out_dir.empty()) config.output.directory = options.out_dir;
  if (!options.mode.empty()) config.servo.law.mode = ServoModeFromString(options.mode);
  if (!options.display.empty()) {
    const std::optional<DisplayMode> display = DisplayModeFromString(options.display);
    if (!display) {
      throw std::invalid_argument("--display " + options.display + ": give auto, on or off");
    }
    config.output.display = *display;
  }
  config.output.Check();
  return config;
}

namespace {

// Folders the output checks made for a run: removed again (when still empty) unless the run
// began, on every way out, so that a run that cannot start leaves nothing behind.
struct FoldersMadeForARun {
  std::vector<fs::path> folders;  ///< innermost first
  bool keep = false;
  FoldersMadeForARun() = default;
  FoldersMadeForARun(const FoldersMadeForARun&) = delete;
  FoldersMadeForARun& operator=(const FoldersMadeForARun&) = delete;
  ~FoldersMadeForARun() {
    if (keep) return;
    std::error_code ignored;  // fs::remove leaves a folder that is not empty
    for (const fs::path& folder : folders) fs::remove(folder, ignored);
  }
};

constexpr const char* kWindowTitle = "oalservo servo (click or a key to stop)";

// The window or the annotated frames, fed by the loop's on_frame hook.
class FrameOutput {
 public:
  // Opens the window now (display on: a window or an error; auto: a window if one opens, else
  // a warning and none), before the robot is touched; checks the frames directory writable.
  FrameOutput(const ServoAppConfig& config, const fs::path& frames_dir) : frames_dir_(frames_dir) {
    const OutputConfig& output = config.output;
    const int width = config.camera.width, height = config.camera.height;
    if (output.display == DisplayMode::kOn) {
      try {
        window_ = std::make_unique<LiveWindow>(width, height, kWindowTitle);
      } catch (const std::runtime_error& error) {
        throw std::runtime_error("output.display is on but " + std::string(error.what()) +
                                 "; use output.display: auto or off (--display)");
      }
    } else if (output.display == DisplayMode::kAuto && CanOpenLiveWindow()) {
      try {
        window_ = std::make_unique<LiveWindow>(width, height, kWindowTitle);
      } catch (const std::runtime_error& error) {
        Warn("servo", std::string(error.what()) + "; going on without a window (output.display " +
                          "auto; off to skip this, on to make it an error)");
      }
    }
    if (window_ == nullptr && output.save_frames && !frames_dir.empty()) {
      CheckWritableDirectory(frames_dir, "frames directory");
      save_ = true;
    }
  }

  // The run has begun: the directory shows this run only (an earlier, longer run's frames
  // would mislead).
  void Prepare() {
    if (!save_) return;
    for (const fs::directory_entry& entry : fs::directory_iterator(frames_dir_)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("iter_", 0) == 0 && entry.path().extension() == ".png") {
        RemoveQuietly(entry.path());
      }
    }
  }

  bool Active() const { return window_ != nullptr || save_; }
  LiveWindow* window() { return window_.get(); }
  bool HasWindow() const { return window_ != nullptr; }

  // Shows or writes the frame; true when the user asked to stop (a click in the window).
  bool Handle(const ServoFrame& frame) {
    const cv::Mat annotated = AnnotateServoFrame(frame);
    if (window_) {
      window_->Show(annotated);
      return window_->StopAsked();
    }
    char name[32];
    std::snprintf(name, sizeof(name), "iter_%04d.png", frame.row.iteration);
    WritePng(frames_dir_ / name, annotated);
    return false;
  }

 private:
  fs::path frames_dir_;
  std::unique_ptr<LiveWindow> window_;
  bool save_ = false;
};

}  // namespace

std::optional<std::string> TrueErrorLine(const ServoRunReport& report, const ServoOptions& law) {
  const auto last = std::find_if(
      report.iterations.rbegin(), report.iterations.rend(),
      [](const ServoIteration& row) { return std::isfinite(row.true_translation_error_mm); });
  if (last == report.iterations.rend()) return std::nullopt;
  char text[160];
  std::snprintf(text, sizeof(text), "true error (simulation): %.3f mm, %.4f deg",
                last->true_translation_error_mm, last->true_rotation_error_deg);
  std::string line = text;
  const double tolerance_mm = law.translation_tolerance_m * 1e3;
  const bool far =
      last->true_translation_error_mm > std::max(2.0 * tolerance_mm, tolerance_mm + 1.0) ||
      last->true_rotation_error_deg > 2.0 * law.rotation_tolerance_deg;
  if (report.status == ServoRunStatus::kConverged && far) {
    line +=
        "; WARNING: the estimate says converged but the camera is this far from the goal: "
        "the pose is biased (does the camera model match the lens?)";
  }
  return line;
}

ServoRunReport RunServoCommand(const ServoCommandOptions& options, std::ostream& out,
                               const ServoRunHooks& hooks) {
  return RunServoWithOutputs(
      LoadServoConfig(options), ConfigNames(options),
      options.out_dir.empty() ? "output directory (output.directory)" : "output directory (--out)",
      out, hooks);
}

ServoRunReport RunServoWithOutputs(const ServoAppConfig& config, const std::string& config_name,
                                   const std::string& directory_what, std::ostream& out,
                                   const ServoRunHooks& hooks) {
  const fs::path dir = config.output.directory;
  const fs::path csv = dir / "servo.csv", plot = dir / "servo-error.png";
  // Everything the outputs need is checked before the source and the robot are opened; what
  // an earlier run wrote is replaced only once this one has begun, and the folders the checks
  // create are removed again when it does not begin.
  const bool dir_existed = dir.empty() || fs::exists(dir);
  FoldersMadeForARun made;
  if (!dir_existed)
    made.folders = {dir / "frames", dir};
  else if (!fs::exists(dir / "frames"))
    made.folders = {dir / "frames"};
  if (!dir.empty()) {
    CheckWritableDirectory(dir, directory_what);
    CheckOutputFile(csv);
    CheckOutputFile(plot);
  }
  FrameOutput frames(config, dir.empty() ? fs::path() : dir / "frames");
  out << "oalservo servo: " << config_name << ", " << ToString(config.servo.law.mode) << " law"
      << (frames.HasWindow() ? ", live window (click to stop)" : "") << '\n';

  ServoRunHooks run_hooks = hooks;
  run_hooks.on_started = [&] {
    made.keep = true;
    frames.Prepare();
    if (hooks.on_started) hooks.on_started();
  };
  SafeRobot* robot = nullptr;
  run_hooks.on_robot = [&](SafeRobot* running) {
    robot = running;
    if (hooks.on_robot) hooks.on_robot(running);
  };
  if (frames.Active()) {
    run_hooks.on_frame = [&](const ServoFrame& frame) {
      if (hooks.on_frame) hooks.on_frame(frame);
      if (frames.Handle(frame) && robot != nullptr) robot->RequestEmergencyStop();
    };
  }
  const ServoRunReport report = RunServo(config, out, run_hooks);
  out << "oalservo servo: " << ToString(report.status) << ": " << report.message << '\n';
  if (const std::optional<std::string> truth = TrueErrorLine(report, config.servo.law)) {
    out << "oalservo servo: " << *truth << '\n';
  }
  if (!report.link_summary.empty()) out << "oalservo servo: " << report.link_summary << '\n';
  if (!dir.empty() && !report.started) {
    out << "oalservo servo: nothing written: the run did not begin ("
        << (dir_existed ? dir.string() + " keeps what an earlier run wrote" : "no folder made")
        << ")\n";
  } else if (!dir.empty()) {
    AtomicFile file(csv);
    WriteServoCsv(report, file.stream());
    file.Commit();
    try {
      WriteServoPlot(report, config.servo.law, plot);
    } catch (const std::runtime_error& error) {
      Warn("servo", error.what());  // the run and its CSV stand without the picture
    }
    out << "oalservo servo: wrote " << csv.string() << ", " << plot.string()
        << (frames.Active() && !frames.HasWindow() ? " and " + (dir / "frames").string() + "/"
                                                   : std::string())
        << '\n';
  }
  if (LiveWindow* window = frames.window(); window != nullptr && !window->StopAsked()) {
    out << "oalservo servo: click in the window to close it" << std::endl;
    window->WaitForClick(hooks.interrupt);
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
  std::vector<std::string> config_paths;
  cli.add_option("--config", config_paths,
                 "YAML configuration: camera, robot, servo, goal, target_pose (and detector, "
                 "target, pose) sections; default: the built-in config/servo-sim.yaml. Given "
                 "again, each file applies over the ones before (a hand-eye file after the "
                 "robot's)")
      ->check(CLI::ExistingFile);
  cli.add_option("--out", options.out_dir,
                 "output directory (overrides output.directory; default out/servo): servo.csv, "
                 "servo-error.png, frames/");
  cli.add_option("--mode", options.mode, "the law (overrides servo.mode)")
      ->check(CLI::IsMember({"point-and-go", "exponential", "velocity"}));
  cli.add_option("--display", options.display,
                 "live window (overrides output.display): auto = when $DISPLAY is set")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cli.footer(
      "Examples:\n"
      "  oalservo servo\n"
      "  oalservo servo --config config/table3-sim.yaml --out out/table3\n"
      "  oalservo servo --config config/table3-sim.yaml --mode point-and-go --display off\n"
      "  oalservo servo --config config/scorbot-sim.yaml --config out/hand-eye.yaml");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  if (!config_paths.empty()) {
    options.config_path = config_paths.front();
    options.more_config_paths.assign(config_paths.begin() + 1, config_paths.end());
  }
  const StopSignalScope signals(&StopRobotOnSignal);
  const ServoRunReport report = RunServoCommand(options, std::cout, StopSignalHooks(signals));
  const bool ok =
      report.status == ServoRunStatus::kConverged || report.status == ServoRunStatus::kEndOfInput;
  return ok ? kExitOk : kExitError;
}

}  // namespace oal
