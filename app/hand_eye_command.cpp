#include "app/hand_eye_command.h"

#include <visp3/core/vpMath.h>
#include <visp3/core/vpRxyzVector.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/config.h"
#include "app/servo_command.h"
#include "app/servo_rig.h"
#include "base/format.h"
#include "base/parse.h"
#include "calibration/hand_eye_routine.h"
#include "detector/lens.h"
#include "io/atomic_file.h"
#include "io/image_source.h"
#include "robots/safe_robot.h"
#include "servo/target_layout.h"

namespace oal {
namespace {

const char* const kColumns[12] = {"wMe_x_m",    "wMe_y_m",    "wMe_z_m",    "wMe_rx_deg",
                                  "wMe_ry_deg", "wMe_rz_deg", "cMo_x_m",    "cMo_y_m",
                                  "cMo_z_m",    "cMo_rx_deg", "cMo_ry_deg", "cMo_rz_deg"};

vpHomogeneousMatrix PoseOf(const double* v) {
  const vpRxyzVector rxyz(vpMath::rad(v[3]), vpMath::rad(v[4]), vpMath::rad(v[5]));
  return vpHomogeneousMatrix(vpTranslationVector(v[0], v[1], v[2]), vpRotationMatrix(rxyz));
}

void AppendPose(const vpHomogeneousMatrix& pose, std::ostream& out) {
  const vpTranslationVector t = pose.getTranslationVector();
  const vpRxyzVector r(pose.getRotationMatrix());
  char text[256];
  std::snprintf(text, sizeof text, "%.9f,%.9f,%.9f,%.9f,%.9f,%.9f", t[0], t[1], t[2],
                vpMath::deg(r[0]), vpMath::deg(r[1]), vpMath::deg(r[2]));
  out << text;
}

struct Settings {
  std::vector<std::string> config_paths;
  std::string pairs_path, record_path, out_path;
  HandEyeRoutineOptions routine;
};

// Registers the SafeRobot with the stop-signal handler while it lives (declared after it).
class SignalRegistration {
 public:
  SignalRegistration(const ServoRunHooks& hooks, SafeRobot* robot) : hooks_(hooks) {
    hooks_.on_robot(robot);
  }
  ~SignalRegistration() { hooks_.on_robot(nullptr); }
  SignalRegistration(const SignalRegistration&) = delete;
  SignalRegistration& operator=(const SignalRegistration&) = delete;

 private:
  const ServoRunHooks& hooks_;
};

// The target is seen well when its four crossings land inside the image, a tenth of its size
// in from the edges: the stripes then cross the scanned borders on every side.
TargetInView CrossingsInView(const LineTarget& target, const Lens& camera, int width, int height) {
  const TargetLayout layout = TargetLayout::Of(target);
  return [layout, camera, width, height](const vpHomogeneousMatrix& cMo) -> std::string {
    const vpHomography plane_to_image = PlaneToImage(cMo);
    const double margin_u = 0.1 * width, margin_v = 0.1 * height;
    for (const double a : {layout.inner_a.lo, layout.inner_a.hi}) {
      for (const double b : {layout.inner_b.lo, layout.inner_b.hi}) {
        Point2d pixel;
        if (!ProjectPlanePoint(plane_to_image, camera, layout.ToPlane(a, b), &pixel) ||
            pixel.u < margin_u || pixel.u > width - 1 - margin_u || pixel.v < margin_v ||
            pixel.v > height - 1 - margin_v) {
          return "a crossing of the target would leave the middle of the view (the arm makes "
                 "only part of the turn, or the mounting guess camera.eMc is far off)";
        }
      }
    }
    return "";
  };
}

// The files as `servo --config` takes them: the first, then each over the ones before.
ServoCommandOptions ConfigFiles(const std::vector<std::string>& paths) {
  ServoCommandOptions files;
  files.config_path = paths.front();
  files.more_config_paths.assign(paths.begin() + 1, paths.end());
  return files;
}

// The pairs taken by moving the configured arm; the configured eMc through `configured_eMc`.
std::vector<HandEyePair> TakePairs(const Settings& settings, vpHomogeneousMatrix* configured_eMc) {
  const ServoAppConfig config = LoadServoConfig(ConfigFiles(settings.config_paths));
  if (config.source.type == SourceType::kReplay) {
    throw std::runtime_error(
        KeyAt(config, "source.type") +
        " is replay: the routine needs the camera on the arm (simulated or v4l2); for pairs "
        "recorded before use --pairs");
  }
  CheckServoConfig(config);
  *configured_eMc = config.camera.eMc;
  const ServoSetup setup = ServoSetupOf(config);
  Lens model_camera = setup.camera;  // with the lens, once told
  TargetPoseTracker tracker = MakeTracker(setup);
  std::vector<std::string> warnings;
  const std::unique_ptr<FrameSource> frames = OpenFrames(config, &warnings);
  for (const std::string& warning : warnings) Warn("hand-eye", warning);
  RobotRig rig = OpenConfiguredRobot(config, nullptr);
  SafeRobot robot(*rig.driver, config.robot.safety);

  const StopSignalScope signals(&StopRobotOnSignal);
  const ServoRunHooks hooks = StopSignalHooks(signals);
  const SignalRegistration registration(hooks, &robot);
  if (RobotResult r = robot.Connect(); !r.ok()) {
    throw std::runtime_error("cannot connect the robot: " + r.message);
  }
  if (RobotResult r = robot.Enable(); !r.ok()) {
    throw std::runtime_error("cannot enable the robot: " + r.message);
  }
  std::cout << "oalservo hand-eye: " << ConfigNames(ConfigFiles(settings.config_paths)) << ", "
            << settings.routine.stations.count << " stations around the arm's pose through "
            << frames->Name() << "\n";

  if (config.camera.estimate_distortion) {
    std::string why;
    if (!TellTheLens(setup, robot, *frames, &model_camera, &tracker, std::cout, &why)) {
      throw std::runtime_error("cannot tell the lens: " + why + "; the arm did not move");
    }
  }
  int frame_count = 0;
  const MeasureTarget measure = [&](std::string* why) -> std::optional<vpHomogeneousMatrix> {
    const RobotPose camera = TrueCameraPose(robot, config.camera.true_eMc);
    cv::Mat gray;
    Capture capture;
    capture.iteration = frame_count++;
    if (camera.result.ok()) capture.true_cMo = camera.pose.inverse() * config.target_wMo;
    if (!camera.result.ok() || !frames->Grab(capture, &gray)) {
      *why = camera.result.ok() ? frames->Name() + " has no frame left"
                                : "the camera's pose cannot be read: " + camera.result.message;
      return std::nullopt;
    }
    if (gray.cols != config.camera.width || gray.rows != config.camera.height) {
      throw std::runtime_error(frames->Name() + " gives " + std::to_string(gray.cols) + "x" +
                               std::to_string(gray.rows) + " frames; the camera is " +
                               std::to_string(config.camera.width) + "x" +
                               std::to_string(config.camera.height));
    }
    const TargetFrame& tracked = tracker.Track(ViewOf(gray));
    if (tracked.status != TargetStatus::kOk) {
      *why = "no pose of the target: " + tracked.message;
      return std::nullopt;
    }
    return tracked.pose.cMo;
  };
  const HandEyeRoutineResult result = RunHandEyeRoutine(
      robot, config.camera.eMc, measure, settings.routine,
      [](const std::string& line) { std::cout << line << '\n'
                                              << std::flush; },
      CrossingsInView(config.target, model_camera, config.camera.width, config.camera.height),
      signals.interrupted());
  if (!settings.record_path.empty()) {
    std::ostringstream csv;
    WriteHandEyePairs(result.pairs, csv);
    WriteFileAtomically(settings.record_path, csv.str());
    std::cout << result.pairs.size() << " pairs written to " << settings.record_path << '\n';
  }
  if (!result.completed) {
    throw std::runtime_error("the routine stopped, the robot with it: " + result.stopped +
                             "; nothing written to " + settings.out_path);
  }
  return result.pairs;
}

void PrintResult(const HandEyeResult& result, const vpHomogeneousMatrix* configured_eMc) {
  for (std::size_t i = 0; i < result.residuals.size(); ++i) {
    std::cout << "pair " << i + 1
              << ": the target placed " + Fixed(result.residuals[i].translation_mm, 2) + " mm, " +
                     Fixed(result.residuals[i].rotation_deg, 3) + " deg from the mean\n";
  }
  std::cout << "eMc " << PoseYaml(result.eMc) << '\n'
            << "residuals RMS " << Fixed(result.rms_translation_mm, 2) << " mm, "
            << Fixed(result.rms_rotation_deg, 3) << " deg; the turns' axes up to "
            << Fixed(result.axis_spread_deg, 0) << " deg apart\n";
  if (configured_eMc != nullptr) {
    const PoseDistance d = Distance(*configured_eMc, result.eMc);
    std::cout << "the configuration's eMc differs by " << Fixed(d.translation_m * 1e3, 2) << " mm, "
              << Fixed(vpMath::deg(d.rotation_rad), 3) << " deg\n";
  }
  for (const std::string& advice : result.advice) Warn("hand-eye", advice);
}

std::string ResultYaml(const HandEyeResult& result, std::size_t pairs, const std::string& from) {
  std::ostringstream yaml;
  yaml << "# oalservo hand-eye: the camera's mounting from " << pairs << " pairs (" << from
       << ").\n# Residuals: the target placed " << Fixed(result.rms_translation_mm, 2) << " mm, "
       << Fixed(result.rms_rotation_deg, 3)
       << " deg RMS from its mean pose. Give this file after the robot's configuration:\n"
       << "#   oalservo servo --config robot.yaml --config this.yaml\n"
       << "camera:\n  eMc: " << PoseYaml(result.eMc) << '\n';
  return yaml.str();
}

}  // namespace

std::vector<HandEyePair> ReadHandEyePairs(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  std::string line;
  int number = 0;
  std::vector<HandEyePair> pairs;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::string at = path + ":" + std::to_string(number) + ": ";
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (number == 1) {
      for (int i = 0; i < 12; ++i) {
        if (cells.size() != 12 || cells[i] != kColumns[i]) {
          throw std::runtime_error(at + "the header must be the 12 columns " +
                                   std::string(kColumns[0]) + ",...," + kColumns[11] +
                                   " (oalservo hand-eye --help)");
        }
      }
      continue;
    }
    if (cells.size() != 12) {
      throw std::runtime_error(at + std::to_string(cells.size()) + " values, 12 expected");
    }
    double v[12];
    for (int i = 0; i < 12; ++i) {
      const std::optional<double> value = ParseFiniteDouble(cells[i]);
      if (!value) {
        throw std::runtime_error(at + kColumns[i] + " = '" + cells[i] + "' is not a number");
      }
      v[i] = *value;
    }
    pairs.push_back({PoseOf(v), PoseOf(v + 6)});
  }
  if (number == 0) throw std::runtime_error(path + ": empty; a header and one row a pair needed");
  return pairs;
}

void WriteHandEyePairs(const std::vector<HandEyePair>& pairs, std::ostream& out) {
  for (int i = 0; i < 12; ++i) out << (i ? "," : "") << kColumns[i];
  out << '\n';
  for (const HandEyePair& pair : pairs) {
    AppendPose(pair.wMe, out);
    out << ',';
    AppendPose(pair.cMo, out);
    out << '\n';
  }
}

int RunHandEye(int argc, char** argv) {
  CLI::App cli{
      "The hand-eye transform eMc (the camera in the end-effector frame): moves the configured "
      "arm through stations around where it stands, the camera turned about the target, takes "
      "a pair (the arm's pose, the target's pose) at each once still, and solves; or solves "
      "from pairs recorded before. Writes a configuration file with camera.eMc.",
      "oalservo hand-eye"};
  Settings settings;
  cli.add_option("--config", settings.config_paths,
                 "the robot's configuration (as for servo; given again, each file applies over "
                 "the ones before): the arm, its workspace box, the camera and the target, and "
                 "camera.eMc as you believe it, to plan the stations")
      ->check(CLI::ExistingFile);
  cli.add_option("--pairs", settings.pairs_path,
                 "solve from pairs recorded before (CSV: wMe_x_m,...,wMe_rz_deg,cMo_x_m,...,"
                 "cMo_rz_deg; metres and x-y-z Euler angles in degrees) instead of moving")
      ->check(CLI::ExistingFile);
  cli.add_option("--record", settings.record_path, "with --config: also write the pairs taken");
  cli.add_option("--out", settings.out_path, "the configuration file to write (camera.eMc)")
      ->required();
  cli.add_option("--stations", settings.routine.stations.count, "stations to visit")
      ->capture_default_str();
  cli.add_option("--tilt", settings.routine.stations.tilt_deg,
                 "largest tilt of the optical axis about the target, degrees")
      ->capture_default_str();
  cli.add_option("--roll", settings.routine.stations.roll_deg,
                 "largest turn about the optical axis, degrees")
      ->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo hand-eye --config config/scorbot-sim.yaml --record out/pairs.csv "
      "--out out/hand-eye.yaml\n"
      "  oalservo hand-eye --pairs out/pairs.csv --out out/hand-eye.yaml\n"
      "  oalservo servo --config config/scorbot-sim.yaml --config out/hand-eye.yaml\n"
      "Every move goes through the safety runner and the workspace box; a station outside it is "
      "skipped before anything moves. Ctrl-C stops the arm. The arm returns to its start.");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  if (settings.config_paths.empty() == settings.pairs_path.empty()) {
    throw UsageError(
        "give either --config (move the arm and take pairs) or --pairs (pairs "
        "recorded before), not " +
        std::string(settings.pairs_path.empty() ? "neither" : "both"));
  }
  if (!settings.record_path.empty() && settings.config_paths.empty()) {
    throw UsageError("--record writes the pairs the routine takes: it needs --config");
  }
  CheckInOptionWords([&] { settings.routine.Check(); },
                     {{"HandEyeStationOptions::count", "--stations"},
                      {"HandEyeStationOptions::tilt_deg", "--tilt"},
                      {"HandEyeStationOptions::roll_deg", "--roll"}});
  // The outputs before the work: a bad path fails before the arm moves.
  PrepareOutputFile(settings.out_path, "--out");
  if (!settings.record_path.empty()) PrepareOutputFile(settings.record_path, "--record");

  vpHomogeneousMatrix configured_eMc;
  const bool moved = !settings.config_paths.empty();
  const std::vector<HandEyePair> pairs =
      moved ? TakePairs(settings, &configured_eMc) : ReadHandEyePairs(settings.pairs_path);
  HandEyeResult result;
  try {
    result = CalibrateHandEye(pairs);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(std::string(error.what()) + "; nothing written to " +
                             settings.out_path);
  }
  PrintResult(result, moved ? &configured_eMc : nullptr);
  WriteFileAtomically(
      settings.out_path,
      ResultYaml(result, pairs.size(),
                 moved ? ConfigNames(ConfigFiles(settings.config_paths)) : settings.pairs_path));
  std::cout << "written " << settings.out_path << '\n';
  return kExitOk;
}

}  // namespace oal
