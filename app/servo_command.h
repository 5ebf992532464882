// `oalservo servo [--config FILE] [--out DIR]`: visual servoing to a goal pose with the
// camera in the loop (app/servo_loop.h). With no --config it runs the built-in default, equal
// to config/servo-sim.yaml: a simulated free-flying camera, the exponential law, delta 0.8.
// Prints one row per iteration in the form of the paper's Table 3 (iteration, X, Y, Z mm,
// pitch, roll deg of the camera in the base frame, translation error mm, rotation error deg,
// status), then the outcome, and writes DIR/servo.csv (atomically). Ctrl-C stops the robot
// (SafeRobot::RequestEmergencyStop) and ends the run with status interrupted.
// Exit status: 0 converged, 1 any other outcome or an error, 2 a bad command line.
#pragma once

#include <iosfwd>
#include <string>

#include "app/config.h"
#include "app/servo_loop.h"

namespace oal {

struct ServoCommandOptions {
  std::string config_path;            ///< YAML configuration; empty: the built-in default
  std::string out_dir = "out/servo";  ///< directory for servo.csv (created if missing)
};

/// The built-in default configuration (config/servo-sim.yaml, embedded at build time).
ServoAppConfig DefaultServoConfig();
/// The configuration `options` selects: --config applied over the defaults, or the built-in.
ServoAppConfig LoadServoConfig(const ServoCommandOptions& options);

/// Loads the configuration, runs the loop (rows to `out`) and writes out_dir/servo.csv.
ServoRunReport RunServoCommand(const ServoCommandOptions& options, std::ostream& out,
                               const ServoRunHooks& hooks = ServoRunHooks());

int RunServoMain(int argc, char** argv);

}  // namespace oal
