// `oalservo scorbot-sim`: the Scorbot ER-VII Controller-A simulator (robots/
// scorbot_controller_sim.h) on a pseudo-terminal, for the servo app or any terminal program to
// connect to as if it were the robot's RS-232 port.
//
//   oalservo scorbot-sim [--port-link PATH] [--time-scale X] [--no-throttle] [--baud N]
//       prints the device path (and the link) to connect to, serves until Ctrl-C, then prints
//       the bytes and commands it handled.
//   oalservo scorbot-sim --measure N [--step-mm D] [--step-deg A] [--noecho] ...
//       the link budget: N servo iterations of a position move (read the pose, define the
//       point, MOVE, poll until done) through ScorbotRobot + SafeRobot against an in-process
//       simulator paced at the baud rate in real time; prints bytes and time per iteration
//       and the resulting maximum loop rate (docs/SCORBOT.md, "Link budget").
// Exit status: 0 ok, 1 an error (a failed move in --measure), 2 a bad command line.
#pragma once

#include <atomic>
#include <iosfwd>
#include <string>

namespace oal {

struct ScorbotSimCommandOptions {
  std::string port_link;  ///< symlink to the pty slave; empty: none
  /// A servo configuration whose robot.start the arm starts at (e.g. config/scorbot-sim.yaml,
  /// so that its camera sees the target); empty: the arm starts at HOME.
  std::string config_path;
  double time_scale = 1.0;     ///< simulated s per wall s; [0.01, 1000]
  bool throttle = true;        ///< pace bytes at the baud rate (10 bits per byte)
  int baud = 9600;             ///< for the pacing and the driver in --measure
  int measure_iterations = 0;  ///< > 0: run the link measurement instead of serving
  double step_mm = 2.0;        ///< --measure: camera step per iteration, mm
  double step_deg = 0.5;       ///< --measure: camera rotation step per iteration, deg
  bool echo = true;            ///< --measure: controller echo on (false: NOECHO)
  int speed_percent = 50;      ///< --measure: SPEED

  /// Throws std::invalid_argument naming the command-line option out of range.
  void Check() const;
};

/// Figures of --measure, per servo iteration (means over the iterations).
struct ScorbotLinkMeasurement {
  int iterations = 0;
  double bytes_to_controller = 0;
  double bytes_from_controller = 0;
  double commands = 0;
  double polls = 0;
  double wall_s = 0;       ///< measured, including the motion
  double link_only_s = 0;  ///< (bytes in + bytes out) x 10 / baud: the serial time if
                           ///< nothing overlapped (half duplex, no motion)
  double max_loop_hz = 0;  ///< 1 / wall_s
};

/// Runs --measure; rows and the summary to `out`. Throws std::runtime_error if a move fails.
ScorbotLinkMeasurement MeasureScorbotLink(const ScorbotSimCommandOptions& options,
                                          std::ostream& out);

/// Serves until `*interrupt` becomes true (or forever when null); prints to `out`.
int RunScorbotSimServer(const ScorbotSimCommandOptions& options, std::ostream& out,
                        const std::atomic<bool>* interrupt);

int RunScorbotSim(int argc, char** argv);

}  // namespace oal
