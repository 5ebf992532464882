#include "app/scorbot_sim_command.h"

#include <visp3/core/vpMath.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "app/command_line.h"
#include "app/servo_command.h"
#include "app/servo_rig.h"
#include "app/servo_run.h"
#include "base/check.h"
#include "robots/safe_robot.h"
#include "robots/scorbot_controller_sim.h"
#include "robots/scorbot_robot.h"

namespace oal {
namespace {

using Clock = std::chrono::steady_clock;

// The simulator: at HOME, or (--config) as the servo loop starts it, at the configuration's
// robot.start; the command line's pacing and link on top.
ScorbotSimOptions SimOptions(const ScorbotSimCommandOptions& options) {
  ScorbotSimOptions sim;
  if (!options.config_path.empty()) {
    ServoCommandOptions servo;
    servo.config_path = options.config_path;
    const ServoAppConfig config = LoadServoConfig(servo);
    if (config.robot.type != RobotType::kScorbot) {
      throw std::invalid_argument("--config " + options.config_path + ": robot.type is '" +
                                  ToString(config.robot.type) +
                                  "', not scorbot: it has no Scorbot start to take");
    }
    sim = ControllerSimOptions(config);
  }
  sim.time_scale = options.time_scale;
  sim.throttle_to_baud = options.throttle;
  sim.baud = options.baud;
  sim.link_path = options.port_link;
  return sim;
}

}  // namespace

void ScorbotSimCommandOptions::Check() const {
  RequireOption(time_scale >= 0.01 && time_scale <= 1000.0, "--time-scale", time_scale,
                "0.01 <= --time-scale <= 1000");
  RequireOption(measure_iterations >= 0 && measure_iterations <= 100000, "--measure",
                measure_iterations, "0 <= --measure <= 100000 (0: serve)");
  RequireOption(step_mm >= 0.0 && step_mm <= 50.0, "--step-mm", step_mm, "0 <= --step-mm <= 50");
  RequireOption(step_deg >= 0.0 && step_deg <= 10.0, "--step-deg", step_deg,
                "0 <= --step-deg <= 10");
  RequireOption(speed_percent >= 1 && speed_percent <= 100, "--speed", speed_percent,
                "1 <= --speed <= 100");
}

int RunScorbotSimServer(const ScorbotSimCommandOptions& options, std::ostream& out,
                        const std::atomic<bool>* interrupt) {
  const ScorbotSimOptions started = SimOptions(options);
  ScorbotControllerSim sim(started);
  sim.Start();
  out << "oalservo scorbot-sim: Controller-A simulator on " << sim.DevicePath();
  if (!options.port_link.empty()) out << " (link " << options.port_link << ")";
  out << "\noalservo scorbot-sim: the arm starts at "
      << (options.config_path.empty() ? std::string("HOME")
                                      : "robot.start of " + options.config_path)
      << " (joints";
  std::ostringstream joints;
  joints << std::fixed << std::setprecision(1);
  for (const double joint : started.start_deg) joints << ' ' << joint;
  out << joints.str() << " deg)";
  if (options.config_path.empty()) {
    out << "; --config config/scorbot-sim.yaml starts it where that file's camera sees the target";
  }
  out << "\noalservo scorbot-sim: connect at " << options.baud << " baud 8N1, e.g. "
      << "robot: {type: scorbot, scorbot: {port: " << sim.ConnectPath() << "}}"
      << "\noalservo scorbot-sim: time scale " << options.time_scale << ", "
      << (options.throttle ? "paced at the baud rate" : "not paced") << "; Ctrl-C to stop\n"
      << std::flush;
  while (interrupt == nullptr || !interrupt->load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const ScorbotSimStats stats = sim.stats();
  sim.Stop();
  out << "oalservo scorbot-sim: stopped after " << stats.commands << " commands, "
      << stats.bytes_received << " bytes received, " << stats.bytes_sent << " bytes sent, "
      << stats.moves_completed << " moves\n";
  return kExitOk;
}

ScorbotLinkMeasurement MeasureScorbotLink(const ScorbotSimCommandOptions& options,
                                          std::ostream& out) {
  ScorbotSimCommandOptions sim_options = options;
  sim_options.port_link.clear();
  ScorbotControllerSim sim(SimOptions(sim_options));
  sim.Start();
  ScorbotOptions robot_options;
  robot_options.port = sim.DevicePath();
  robot_options.baud = options.baud;
  robot_options.echo = options.echo;
  robot_options.speed_percent = options.speed_percent;
  robot_options.sampling_time_s = 0.01;  // polls as fast as the link allows
  robot_options.reply_timeout_s = 5.0;
  // A camera 5 cm along the tool axis.
  robot_options.eMc = vpHomogeneousMatrix(0, 0, 0.05, 0, 0, 0);
  ScorbotRobot robot(robot_options);
  SafetyOptions safety;
  safety.workspace_enabled = false;
  SafeRobot safe(robot, safety);
  if (RobotResult r = safe.Connect(); !r.ok()) throw std::runtime_error(r.message);
  if (RobotResult r = safe.Enable(); !r.ok()) throw std::runtime_error(r.message);

  // One LISTPV POSITION exchange on its own, for the breakdown.
  const AclStats before_listpv = robot.link_stats();
  if (const ScorbotJointReading j = robot.GetJoints(); !j.result.ok()) {
    throw std::runtime_error(j.result.message);
  }
  const AclStats after_listpv = robot.link_stats();
  const auto listpv_out = after_listpv.link.bytes_written - before_listpv.link.bytes_written;
  const auto listpv_in = after_listpv.link.bytes_read - before_listpv.link.bytes_read;

  out << "oalservo scorbot-sim --measure: " << options.measure_iterations
      << " position-move iterations at " << options.baud << " baud, echo "
      << (options.echo ? "on" : "off") << ", SPEED " << options.speed_percent << ", step "
      << options.step_mm << " mm + " << options.step_deg << " deg\n"
      << " iter  bytes_out  bytes_in  commands  polls  wall_ms  link_only_ms\n";
  const double step_m = options.step_mm * 1e-3;
  const double step_rad = vpMath::rad(options.step_deg);
  ScorbotLinkMeasurement m;
  for (int k = 0; k < options.measure_iterations; ++k) {
    const AclStats before = robot.link_stats();
    const Clock::time_point t0 = Clock::now();
    const RobotPose pose = safe.GetPosition(RobotFrame::kCamera);
    if (!pose.result.ok()) throw std::runtime_error(pose.result.message);
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    const vpHomogeneousMatrix step(sign * step_m, 0.5 * sign * step_m, 0, 0, sign * step_rad, 0);
    const MoveReport move = safe.MovePosition(RobotFrame::kCamera, pose.pose * step);
    if (!move.result.ok()) throw std::runtime_error(move.result.message);
    const double wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
    const AclStats after = robot.link_stats();
    const double bytes_out =
        static_cast<double>(after.link.bytes_written - before.link.bytes_written);
    const double bytes_in = static_cast<double>(after.link.bytes_read - before.link.bytes_read);
    const double commands = static_cast<double>(after.commands - before.commands);
    const double link_only_s = (bytes_out + bytes_in) * 10.0 / options.baud;
    out << std::setw(5) << k + 1 << std::setw(11) << bytes_out << std::setw(10) << bytes_in
        << std::setw(10) << commands << std::setw(7) << move.polls << std::setw(9) << std::fixed
        << std::setprecision(1) << wall_s * 1e3 << std::setw(14) << link_only_s * 1e3 << '\n'
        << std::defaultfloat << std::setprecision(6);
    m.bytes_to_controller += bytes_out;
    m.bytes_from_controller += bytes_in;
    m.commands += commands;
    m.polls += move.polls;
    m.wall_s += wall_s;
    m.link_only_s += link_only_s;
    ++m.iterations;
  }
  const double n = m.iterations;
  m.bytes_to_controller /= n;
  m.bytes_from_controller /= n;
  m.commands /= n;
  m.polls /= n;
  m.wall_s /= n;
  m.link_only_s /= n;
  m.max_loop_hz = 1.0 / m.wall_s;
  safe.Disable();
  out << std::fixed << std::setprecision(1) << "mean per iteration: " << m.bytes_to_controller
      << " bytes to the controller, " << m.bytes_from_controller << " bytes from it, " << m.commands
      << " commands, " << m.polls << " polls; " << m.wall_s * 1e3 << " ms measured ("
      << m.link_only_s * 1e3 << " ms of serial time at " << options.baud << " baud, 10 bits/byte)\n"
      << "one LISTPV POSITION exchange: " << listpv_out << " bytes out, " << listpv_in
      << " bytes in\n"
      << std::setprecision(2) << "maximum loop rate: " << m.max_loop_hz
      << " Hz (position law through the ACL link)\n"
      << std::defaultfloat << std::setprecision(6);
  return m;
}

int RunScorbotSim(int argc, char** argv) {
  ScorbotSimCommandOptions options;
  CLI::App cli(
      "Scorbot ER-VII Controller-A simulator (ACL over a pseudo-terminal): prints the device "
      "to connect to and serves until Ctrl-C; or, with --measure, the bytes and time per servo "
      "iteration over the link.",
      "oalservo scorbot-sim");
  cli.add_option("--port-link", options.port_link,
                 "also create this symlink to the pty slave (a stable path for configs)");
  cli.add_option("--config", options.config_path,
                 "start the arm at this servo configuration's robot.start (e.g. "
                 "config/scorbot-sim.yaml; default: at HOME)")
      ->check(CLI::ExistingFile);
  cli.add_option("--time-scale", options.time_scale,
                 "simulated seconds per wall-clock second (motion only; the link is real time), "
                 "[0.01, 1000]")
      ->capture_default_str();
  cli.add_flag("!--no-throttle", options.throttle,
               "do not pace the bytes at the baud rate (instant replies)");
  cli.add_option("--baud", options.baud, "baud rate for the pacing (and --measure's driver)")
      ->capture_default_str()
      ->check(CLI::IsMember({1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200}));
  cli.add_option("--measure", options.measure_iterations,
                 "measure the link budget over N servo iterations of a position move, then exit, "
                 "[1, 100000]");
  cli.add_option("--step-mm", options.step_mm, "--measure: camera step per iteration, mm, [0, 50]")
      ->capture_default_str();
  cli.add_option("--step-deg", options.step_deg,
                 "--measure: camera rotation per iteration, deg, [0, 10]")
      ->capture_default_str();
  cli.add_flag("!--noecho", options.echo, "--measure: switch the controller's echo off");
  cli.add_option("--speed", options.speed_percent, "--measure: SPEED, %, [1, 100]")
      ->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo scorbot-sim --port-link /tmp/scorbot\n"
      "  oalservo scorbot-sim --config config/scorbot-sim.yaml --port-link /tmp/scorbot\n"
      "  oalservo scorbot-sim --measure 20\n"
      "  oalservo scorbot-sim --measure 20 --noecho");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  options.Check();
  if (options.measure_iterations > 0) {
    MeasureScorbotLink(options, std::cout);
    return kExitOk;
  }
  const StopSignalScope sigint;
  return RunScorbotSimServer(options, std::cout, sigint.interrupted());
}

}  // namespace oal
