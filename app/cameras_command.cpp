#include "app/cameras_command.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <vector>

#include "app/command_line.h"
#include "io/v4l2_modes.h"

namespace oal {

int ListCamerasTo(std::ostream& out, const std::string& dev_dir) {
  const std::vector<CameraDevice> cameras = ListCameras(dev_dir);
  if (cameras.empty()) {
    out << "no V4L2 camera: " << dev_dir
        << " has no video capture device (is the camera plugged in? in a container or a virtual "
           "machine, is /dev/videoN passed through?)\n";
    return 0;
  }
  for (const CameraDevice& camera : cameras) {
    out << camera.path << ": " << camera.card << " (" << camera.bus << ")\n";
    if (camera.modes.empty()) out << "  lists no modes\n";
    for (const CameraMode& mode : camera.modes) out << "  " << mode.Describe() << '\n';
  }
  return static_cast<int>(cameras.size());
}

int RunCameras(int argc, char** argv) {
  std::string dev_dir = "/dev";
  CLI::App cli(
      "List the V4L2 cameras of this machine and the modes each offers: the pixel format "
      "(MJPG, YUYV, GREY, ...), the size and the frame rates. A configuration's source: "
      "{device, format, width, height, fps} or --camera-mode FORMAT:WxH@FPS picks one.",
      "oalservo cameras");
  cli.add_option("--dev", dev_dir, "where to look for video devices")->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo cameras --dev /dev\n"
      "  oalservo pose /dev/video0 --camera-mode mjpeg:1280x720@30 --camera camera.yaml "
      "--display");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  ListCamerasTo(std::cout, dev_dir);
  return kExitOk;
}

}  // namespace oal
