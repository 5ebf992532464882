#include "app/frame_command.h"

#include <CLI/CLI.hpp>
#include <stdexcept>

#include "app/live_window.h"
#include "base/format.h"
#include "io/image_source.h"

namespace oal {

std::string CompanionDirectory(const std::vector<std::string>& inputs) {
  if (inputs.empty()) return ".";
  const std::filesystem::path first = inputs.front();
  const std::filesystem::path dir =
      std::filesystem::is_directory(first) ? first : first.parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

std::optional<std::string> CompanionFile(const std::vector<std::string>& inputs,
                                         const std::string& name) {
  if (inputs.empty()) return std::nullopt;
  const std::filesystem::path candidate = std::filesystem::path(CompanionDirectory(inputs)) / name;
  if (!std::filesystem::is_regular_file(candidate)) return std::nullopt;
  return candidate.string();
}

std::vector<std::unique_ptr<ImageSource>> OpenInputs(const FrameCommandOptions& options,
                                                     std::vector<std::string>* warnings) {
  std::vector<std::unique_ptr<ImageSource>> sources;
  for (const std::string& input : options.inputs) {
    if (IsDevicePath(input)) {
      sources.push_back(OpenV4l2Source(input, CameraModeRequest(options)));
    } else {
      sources.push_back(OpenImageSource(input, warnings));
    }
  }
  return sources;
}

std::filesystem::path AnnotationPath(const FrameCommandOptions& options, const std::string& prefix,
                                     int frame) {
  std::string number = std::to_string(frame);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return std::filesystem::path(options.annotate_dir) / (prefix + "_" + number + ".png");
}

CameraRequest CameraModeRequest(const FrameCommandOptions& options) {
  if (options.camera_mode.empty()) return CameraRequest();
  try {
    return ParseCameraRequest(options.camera_mode);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument("--camera-mode " + std::string(error.what()));
  }
}

void AddInputsArgument(CLI::App& cli, FrameCommandOptions* options) {
  cli.add_option("INPUT", options->inputs,
                 "image, directory of images, printf pattern (frames/img%04d.png: from index "
                 "0 or 1 up to the first missing file, with a warning if files follow the gap), "
                 "video file, or V4L2 device /dev/videoN")
      ->required();
  cli.add_option("--camera-mode", options->camera_mode,
                 "a /dev/videoN input's mode, FORMAT:WIDTHxHEIGHT@FPS, any part left out: "
                 "mjpeg:1280x720@30, yuyv:640x480, 1920x1080@30 (oalservo cameras lists the "
                 "modes; default: the largest at the highest rate, YUYV before MJPEG)");
}

void CheckDisplayOptions(const FrameCommandOptions& options) {
  if (options.display && !(options.display_fps > 0.0 && options.display_fps <= 1000.0)) {
    throw std::invalid_argument("--display-fps = " + Number(options.display_fps) +
                                ": give a rate above 0 and at most 1000 frames a second");
  }
}

std::unique_ptr<LiveView> OpenLiveView(const std::string& title, double display_fps) {
  try {
    return std::make_unique<LiveView>(title, display_fps);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error("--display: " + std::string(error.what()) +
                             "; run without --display (--annotate DIR writes the same pictures), "
                             "or where $DISPLAY names a running X server (e.g. Xvfb)");
  }
}

void AddDisplayOptions(CLI::App& cli, FrameCommandOptions* options) {
  cli.add_flag("--display", options->display,
               "show each frame annotated in a window (X11: $DISPLAY); a click or a key in it "
               "stops, the output written so far is kept");
  cli.add_option("--display-fps", options->display_fps,
                 "with --display, frames from files are shown at this rate (a camera's as they "
                 "come)")
      ->check(CLI::Range(0.1, 1000.0))
      ->capture_default_str();
}

void AddOutputOptions(CLI::App& cli, FrameCommandOptions* options,
                      const std::string& annotate_help) {
  cli.add_option("--out", options->out_path, "JSON Lines output file (written atomically)");
  cli.add_option("--annotate", options->annotate_dir, annotate_help);
  cli.add_option("--max-frames", options->max_frames, "stop after N frames (0: all)");
}

}  // namespace oal
