// What the commands over image sources (`oalservo detect`, `oalservo pose`) share: their
// inputs and outputs, opened and written the same way.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "io/v4l2_modes.h"

namespace CLI {
class App;
}  // namespace CLI

namespace oal {

class ImageSource;
class LiveView;

/// The inputs and outputs of a command over image sources; each command adds its own options.
struct FrameCommandOptions {
  /// Image, directory, printf pattern, video or /dev/videoN (io/image_source.h); read one
  /// after the other.
  std::vector<std::string> inputs;
  /// A /dev/videoN input's mode, as ParseCameraRequest reads it ("mjpeg:1280x720@30");
  /// empty: the camera's largest at its highest rate.
  std::string camera_mode;
  /// Camera to read from the command's camera file; empty: the first camera of the file.
  std::string camera_name;
  /// JSON Lines output, written atomically; empty: the stream passed to the command's function.
  std::string out_path;
  /// Directory for one annotated PNG per frame (<prefix>_0000.png...); empty: none.
  std::string annotate_dir;
  /// Stop after this many frames (for cameras); 0: all. Range [0, inf).
  int max_frames = 0;
  /// A live window (app/live_window.h) shows each annotated frame; a click or a key stops.
  bool display = false;
  /// Frames from files are shown at most this many a second (a camera's as they come).
  /// Range (0, 1000].
  double display_fps = 30.0;
};

/// The folder where `oalservo render` leaves its companion files for `inputs`: the first
/// input if it is a directory, else the first input's directory ("." for a bare name).
std::string CompanionDirectory(const std::vector<std::string>& inputs);
/// The file `name` (e.g. "camera.xml", "target.yaml") in CompanionDirectory(inputs), if it
/// exists.
std::optional<std::string> CompanionFile(const std::vector<std::string>& inputs,
                                         const std::string& name);

/// Opens every input of `options` in order; files skipped in a directory go to `warnings`.
std::vector<std::unique_ptr<ImageSource>> OpenInputs(const FrameCommandOptions& options,
                                                     std::vector<std::string>* warnings);

/// Where frame `frame`'s annotated PNG goes: annotate_dir / "<prefix>_0007.png".
std::filesystem::path AnnotationPath(const FrameCommandOptions& options, const std::string& prefix,
                                     int frame);

/// Creates annotate_dir if set, then WriteToFileOrConsole(out_path, console, write).
template <typename Write>
void WriteFrameRecords(const FrameCommandOptions& options, std::ostream& console, Write write) {
  if (!options.annotate_dir.empty()) std::filesystem::create_directories(options.annotate_dir);
  WriteToFileOrConsole(options.out_path, console, write);
}

/// The camera mode `options.camera_mode` asks for. Throws std::invalid_argument naming
/// --camera-mode and what is wrong.
CameraRequest CameraModeRequest(const FrameCommandOptions& options);

/// Adds the INPUT argument (required) and --camera-mode to a command's command line.
void AddInputsArgument(CLI::App& cli, FrameCommandOptions* options);

/// Throws std::invalid_argument for a display_fps out of its range (with display).
void CheckDisplayOptions(const FrameCommandOptions& options);

/// The live window of a command with --display (frames from files shown at `display_fps`),
/// open: throws std::runtime_error saying why none can be opened (naming $DISPLAY) and what to
/// do instead.
std::unique_ptr<LiveView> OpenLiveView(const std::string& title, double display_fps);

/// Adds --display and --display-fps.
void AddDisplayOptions(CLI::App& cli, FrameCommandOptions* options);

/// Adds --out, --annotate (described by `annotate_help`) and --max-frames.
void AddOutputOptions(CLI::App& cli, FrameCommandOptions* options,
                      const std::string& annotate_help);

}  // namespace oal
