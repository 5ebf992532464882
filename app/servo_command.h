// `oalservo servo [--config FILE] [--out DIR] [--mode LAW] [--display auto|on|off]`: visual
// servoing to a goal pose with the camera in the loop (loop/servo_loop.h, run from a configuration
// by app/servo_run.h). With no --config it runs the built-in default, equal to
// config/servo-sim.yaml: a simulated free-flying camera, the exponential law, delta 0.8. Prints one
// row per iteration in the form of the paper's Table 3 (iteration, X, Y, Z mm, pitch, roll deg of
// the camera in the base frame, translation error mm, rotation error deg, status), then the
// outcome, and writes into the output directory (config output.directory, or --out) servo.csv,
// servo-error.png and, without a window, the annotated frames (app/servo_output.h), each
// atomically. A vpDisplayX window shows the frames when a display exists (output.display; with
// auto, an X display that cannot be reached gives a warning and no window). Ctrl-C, SIGTERM,
// SIGHUP, or a click in the window, stops the robot (SafeRobot::RequestEmergencyStop) and ends the
// run with status interrupted, the outputs written as for any other end. Before the source and the
// robot are opened the output directory is checked writable and a window opened; an earlier run's
// outputs are replaced only once the robot is connected (a run that cannot connect writes nothing).
// Exit status: 0 converged (or a replay played to its end), 1 any other outcome or an error,
// 2 a bad command line.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/config.h"
#include "app/servo_run.h"

namespace oal {

struct ServoCommandOptions {
  std::string config_path;  ///< YAML configuration; empty: the built-in default
  /// Further files applied after it, in order (e.g. a hand-eye file after the robot's).
  std::vector<std::string> more_config_paths;
  /// Overrides of the configuration; empty: as configured.
  std::string out_dir;  ///< output.directory (created if missing)
  std::string mode;     ///< servo.mode: point-and-go, exponential, velocity
  std::string display;  ///< output.display: auto, on, off
};

/// The built-in default configuration (config/servo-sim.yaml, embedded at build time).
ServoAppConfig DefaultServoConfig();
/// The configuration `options` selects: each --config applied in turn over the built-in
/// default (keys and sections a file leaves out keep the values before it), or the built-in
/// itself,
/// then the command line's overrides. Throws std::runtime_error / std::invalid_argument for a
/// bad file or override.
ServoAppConfig LoadServoConfig(const ServoCommandOptions& options);

/// The configuration's files as the run's first line names them: "a.yaml + b.yaml", or the
/// built-in default's name.
std::string ConfigNames(const ServoCommandOptions& options);

/// Requests the emergency stop of the robot registered by StopSignalHooks()' on_robot (the
/// StopSignalScope's callback: async-signal-safe; a no-op when none is registered).
void StopRobotOnSignal();
/// The hooks `oalservo servo` runs with: `signals`' flag interrupts the loop and its signal
/// names the reason; the robot is registered for StopRobotOnSignal() (on_robot(nullptr)
/// unregisters it and returns once no handler is still using it). `signals` must outlive
/// the run.
ServoRunHooks StopSignalHooks(const StopSignalScope& signals);

/// In a simulation (the rows know the true error), the console's line on where the camera truly
/// ended, with a plain warning when the estimate says converged while the truth lies well
/// outside the law's tolerances (a biased pose: e.g. a camera model that does not match the
/// lens); nullopt without a truth.
std::optional<std::string> TrueErrorLine(const ServoRunReport& report, const ServoOptions& law);

/// Loads the configuration, runs the loop (rows to `out`) and writes the outputs.
ServoRunReport RunServoCommand(const ServoCommandOptions& options, std::ostream& out,
                               const ServoRunHooks& hooks = ServoRunHooks());
/// Runs the loop on `config` (rows to `out`, the first line naming `config_name`) and writes
/// the outputs into config.output.directory; `directory_what` names that setting in errors
/// (e.g. "output directory (--out)").
ServoRunReport RunServoWithOutputs(const ServoAppConfig& config, const std::string& config_name,
                                   const std::string& directory_what, std::ostream& out,
                                   const ServoRunHooks& hooks = ServoRunHooks());

int RunServoMain(int argc, char** argv);

}  // namespace oal
