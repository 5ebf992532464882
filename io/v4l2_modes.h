// The V4L2 cameras of this machine and the modes each offers (pixel format, size, rates), and
// the choice of a mode for what the user asked (`source: {format, width, height, fps}` in a
// configuration, --camera-mode on the command line). USB webcams give 720p and 1080p at 30
// frames a second as MJPEG only; in YUYV most give them at 5-10 or not at all.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace oal {

/// The pixel format asked of a camera; kAuto: the best the camera offers at the size and rate.
enum class CameraFormat { kAuto, kMjpeg, kYuyv, kGrey };

/// "auto", "mjpeg", "yuyv", "grey".
std::string ToString(CameraFormat format);
/// The format named (as ToString gives it, any case); nullopt for another word.
std::optional<CameraFormat> CameraFormatFromString(const std::string& name);

/// One mode a camera offers: a pixel format at a size, with the frame rates it gives there.
struct CameraMode {
  std::string fourcc;  ///< V4L2's four characters: "MJPG", "YUYV", "GREY", ...
  int width = 0, height = 0;
  std::vector<double> fps;  ///< frames a second, highest first; empty when not listed

  /// "MJPG 1280x720 at 30, 15 fps".
  std::string Describe() const;
};

/// A V4L2 capture device.
struct CameraDevice {
  std::string path;  ///< /dev/videoN
  std::string card;  ///< the driver's name for the camera ("HD Webcam C270")
  std::string bus;   ///< where it is plugged ("usb-0000:00:14.0-1")
  std::vector<CameraMode> modes;
};

/// Every /dev/video* under `dev_dir` that captures video, with its modes (metadata nodes that
/// UVC cameras also create are left out). Empty when there is none.
std::vector<CameraDevice> ListCameras(const std::string& dev_dir = "/dev");

/// The modes of the V4L2 device at `path`; empty when it cannot be opened or lists none.
std::vector<CameraMode> ModesOfDevice(const std::string& path);

/// What the user asks of a camera; 0 leaves a value to the choice.
struct CameraRequest {
  CameraFormat format = CameraFormat::kAuto;
  int width = 0, height = 0;  ///< 0: the largest the format gives at the rate
  double fps = 0.0;           ///< 0: the highest the mode gives

  /// Throws std::invalid_argument naming the field for a negative size or rate.
  void Check() const;
};

/// The mode to open for `request` among `modes` (a device's): the size asked (or the largest),
/// in the format asked, at the rate asked (or the highest there); with kAuto, among modes
/// alike, YUYV (no compression), else MJPEG, else GREY. The rate chosen is the one asked, else
/// the highest of the mode. Throws
/// std::runtime_error saying what was asked and listing the modes that come nearest (same size,
/// or same format) when none gives it.
struct ChosenMode {
  CameraMode mode;
  double fps = 0.0;  ///< 0 when the mode lists none (the driver's)
};
ChosenMode ChooseCameraMode(const std::vector<CameraMode>& modes, const CameraRequest& request);

/// "mjpeg:1280x720@30", "yuyv:640x480", "1920x1080@30", "grey" or "auto" as a request. Throws
/// std::invalid_argument saying what is wrong in `text`.
CameraRequest ParseCameraRequest(const std::string& text);

}  // namespace oal
