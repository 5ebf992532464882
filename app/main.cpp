// oalservo: one executable, one subcommand per task (like colmap's exe). This file is only
// the command table, --help and --version; each command lives in app/<name>_command.cpp,
// whose Run* function parses its arguments and calls a plain function that tests call
// directly. To add a command: include its header and add one row to kCommands.
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iomanip>
#include <iostream>
#include <opencv2/core/utils/logger.hpp>
#include <string>

#include "app/calibrate_accuracy_command.h"
#include "app/calibrate_command.h"
#include "app/camera_command.h"
#include "app/cameras_command.h"
#include "app/command_line.h"
#include "app/compare_command.h"
#include "app/demo_command.h"
#include "app/detect_command.h"
#include "app/detector_accuracy_command.h"
#include "app/edge_reference_command.h"
#include "app/evaluate_command.h"
#include "app/hand_eye_command.h"
#include "app/pose_accuracy_command.h"
#include "app/pose_command.h"
#include "app/render_command.h"
#include "app/scorbot_sim_command.h"
#include "app/servo_accuracy_command.h"
#include "app/servo_command.h"
#include "app/target_command.h"
#include "io/quiet_stderr.h"

#ifndef OAL_VERSION
#define OAL_VERSION "unknown"
#endif

namespace {

constexpr oal::Command kCommands[] = {
    {"detect", &oal::RunDetect, "detect lines in images, a directory, a video or a V4L2 camera"},
    {"detect-accuracy", &oal::RunDetectAccuracy,
     "accuracy of the detector on rendered frames, against the paper and OpenCV"},
    {"edge-reference", &oal::RunEdgeReference,
     "independent reference lines for a sequence with one straight edge (truth CSV)"},
    {"pose-accuracy", &oal::RunPoseAccuracy,
     "accuracy of the camera pose from the four-line target on rendered frames"},
    {"pose", &oal::RunPose, "camera pose from the four-line target in every frame"},
    {"servo", &oal::RunServoMain,
     "visual servoing to a goal pose, camera in the loop (default: simulated robot)"},
    {"servo-accuracy", &oal::RunServoAccuracy,
     "servo convergence from many random start poses, for each law"},
    {"render", &oal::RunRender, "render a synthetic data set with ground truth"},
    {"compare", &oal::RunCompare,
     "our detector, vpMeLine and OpenCV line detectors against ground truth"},
    {"evaluate", &oal::RunEvaluate,
     "evaluate the tracker and the pose on recorded videos: JSON, annotated video, HTML report"},
    {"demo", &oal::RunDemo, "render, detect and compare one frame of a cheap camera"},
    {"calibrate", &oal::RunCalibrate,
     "camera intrinsics and distortion from views of the printed target or a chessboard, as a "
     "ViSP camera file"},
    {"calibrate-accuracy", &oal::RunCalibrateAccuracy,
     "accuracy of calibrate from the printed target on rendered views of known cameras"},
    {"hand-eye", &oal::RunHandEye,
     "the camera's mounting on the arm (eMc): move through stations, or from recorded pairs"},
    {"camera", &oal::RunCamera,
     "show a camera file's lens; write it as ViSP's XML, OpenCV's YAML or ROS's camera_info"},
    {"cameras", &oal::RunCameras, "list the V4L2 cameras and their modes (format, size, rate)"},
    {"target", &oal::RunTarget, "write a printable, true-scale PDF or SVG of the line target"},
    {"scorbot-sim", &oal::RunScorbotSim,
     "Scorbot ER-VII controller simulator (ACL) on a pseudo-terminal; --measure: link budget"},
};

void PrintUsage(std::ostream& out) {
  out << "oalservo " << OAL_VERSION << ": OAL Hough line detection and visual servoing\n\n"
      << "Usage: oalservo <command> [options]\n"
      << "       oalservo --help | --version\n\nCommands:\n";
  std::size_t width = 0;  // the longest name and two spaces: every name stands apart
  for (const oal::Command& command : kCommands)
    width = std::max(width, std::strlen(command.name) + 2);
  for (const oal::Command& command : kCommands) {
    out << "  " << std::left << std::setw(static_cast<int>(width)) << command.name << command.help
        << '\n';
  }
  out << "\nRun 'oalservo <command> --help' for the options of a command.\n";
}

const oal::Command* FindCommand(const std::string& name) {
  for (const oal::Command& command : kCommands) {
    if (name == command.name) return &command;
  }
  return nullptr;
}

int RunCommand(const oal::Command& command, int argc, char** argv) {
  try {
    return command.run(argc, argv);
  } catch (const oal::UsageError& error) {
    std::cerr << "oalservo " << command.name << ": error: " << error.what() << '\n';
    return oal::kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << "oalservo " << command.name << ": error: " << error.what() << '\n';
    return oal::kExitError;
  } catch (...) {
    std::cerr << "oalservo " << command.name << ": error: unknown exception\n";
    return oal::kExitError;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // OpenCV's own log ("imread_(...): can't open/read file", the GStreamer and CAP_IMAGES
  // backends' errors when a video will not open) would repeat our errors, less clearly:
  // every failure it logs reaches the user as our own message.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  // Likewise FFmpeg's ("moov atom not found"), which OpenCV's FFmpeg backend lets through at
  // its error level unless OPENCV_FFMPEG_LOGLEVEL says otherwise (left to the user if set:
  // e.g. 24 for FFmpeg's warnings). -8 is AV_LOG_QUIET.
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", /*overwrite=*/0);
  // Before any thread: compare and evaluate silence ViSP's messages on their own thread only.
  oal::InstallQuietableStderr();
  if (argc < 2) {
    PrintUsage(std::cerr);
    return oal::kExitUsage;
  }
  const std::string first = argv[1];
  if (first == "--help" || first == "-h" || first == "help") {
    PrintUsage(std::cout);
    return oal::kExitOk;
  }
  if (first == "--version") {
    std::cout << "oalservo " << OAL_VERSION << '\n';
    return oal::kExitOk;
  }
  const oal::Command* command = FindCommand(first);
  if (command == nullptr) {
    std::cerr << "oalservo: error: unknown command '" << first << "' (run 'oalservo --help')\n";
    return oal::kExitUsage;
  }
  return RunCommand(*command, argc - 1, argv + 1);
}
