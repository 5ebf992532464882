// Where `oalservo detect` gets its frames. One spec names one source:
//
//   x.png                 one image (any format OpenCV decodes)
//   frames/               the images of a directory, sorted by file name; other files are
//                         skipped with a warning, but for the known companion files
//                         (IsCompanionFile: camera.xml, truth JSON and CSV)
//   frames/img%04d.png    a printf pattern: indices from 0 (or 1 if there is no 0) until the
//                         first missing file (a warning names the gap when files exist in
//                         the 100 indices after it); only one %d conversion (with optional 0
//                         and width)
//   x.avi, x.mp4, ...     a video (cv::VideoCapture)
//   /dev/videoN           a V4L2 camera (vpV4l2Grabber), until stopped
//
// Frames come out as 8-bit grey cv::Mat, viewed by the detector without a copy.
#pragma once

#include <visp3/core/vpImage.h>

#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "detector/image_view.h"
#include "io/v4l2_modes.h"

namespace oal {

/// The detector's view of an 8-bit grey cv::Mat (CV_8UC1), without a copy.
inline GrayImageView ViewOf(const cv::Mat& gray) {
  return GrayImageView{gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)};
}

struct Frame {
  cv::Mat gray;        ///< CV_8UC1; may share memory with the source until its next Next()
  std::string source;  ///< image path, or "<video or device>#<index in that source>"
  /// When the camera took it, s on the monotonic clock (std::chrono::steady_clock's, as the
  /// V4L2 driver's buffer timestamps); unset when the source cannot tell (files, videos).
  std::optional<double> taken_s;

  GrayImageView view() const { return ViewOf(gray); }
};

class ImageSource {
 public:
  virtual ~ImageSource() = default;
  /// Reads the next frame into `frame`; false at the end of the source. Throws
  /// std::runtime_error naming the file when a frame cannot be read or decoded (a JPEG or
  /// PNG cut short included); frame->source then names that file (a list of images) or is
  /// left as it was (a caller clears it first to tell). A list of images has then moved
  /// past that file, so a caller may skip it and call Next() again.
  virtual bool Next(Frame* frame) = 0;
  /// Frames the source announces (files listed, the container's frame count); -1: unknown
  /// (a camera, a video without a count).
  virtual int ExpectedFrames() const { return -1; }
  /// What is being read, for messages, e.g. "directory 'frames'".
  virtual std::string Name() const = 0;
};

/// Opens the source named by `spec` (see the file comment). Throws std::runtime_error with
/// the reason for a missing file, an undecodable image ("cannot decode image 'x.png'"), a
/// video without frames, a missing device and an unsupported input. Files skipped in a
/// directory, and files after the gap that ends a printf pattern, are reported in
/// `warnings` (if given).
/// True for a V4L2 device path (/dev/videoN, /dev/v4l/...).
bool IsDevicePath(const std::string& spec);

std::unique_ptr<ImageSource> OpenImageSource(const std::string& spec,
                                             std::vector<std::string>* warnings = nullptr);

/// What to ask of a V4L2 camera: CameraRequest (io/v4l2_modes.h), the format, size and rate;
/// 0 leaves a value to the mode chosen.
using V4l2Settings = CameraRequest;

/// Opens the V4L2 camera `device` (e.g. /dev/video0) in the mode ChooseCameraMode picks for
/// `settings` among the modes the device lists: an MJPEG mode, or a rate other than 25 or 50,
/// through OpenCV's V4L2 backend (which decodes MJPEG), else through vpV4l2Grabber; a device
/// that lists no modes through vpV4l2Grabber as asked. Frames carry the driver's capture
/// timestamps. Throws std::runtime_error saying so when the device does not exist, cannot be
/// opened, gives no mode as asked (listing those that come nearest), or this build cannot
/// read it.
std::unique_ptr<ImageSource> OpenV4l2Source(const std::string& device,
                                            const V4l2Settings& settings = V4l2Settings());

/// An image file's bytes decoded to 8-bit grey, as every source decodes them (a PNG or JPEG
/// cut short is refused before the decoder sees it). Throws std::runtime_error naming `name`.
cv::Mat DecodeGrayImage(const std::vector<unsigned char>& bytes, const std::string& name);
/// One image file decoded to 8-bit grey as the sources decode it. Throws std::runtime_error
/// naming the file when it is missing, cut short or not an image.
cv::Mat ReadGrayImageFile(const std::string& path);
/// The same as a shared vpImage (e.g. a renderer's background, scene/scene.h).
std::shared_ptr<const vpImage<unsigned char>> ReadGrayImage(const std::string& path);

/// True if `path` has the extension of an image format OpenCV reads (case-insensitive).
bool HasImageExtension(const std::string& path);
/// True if `path` names a file expected next to images or videos that is no frame: a
/// camera.xml, target.yaml, a JSON file (`oalservo render`'s frame truth and sequence.json) or a
/// <video>.truth.csv. Directories skip these without a warning.
bool IsCompanionFile(const std::string& path);
/// True if `path` has the extension of a video container.
bool HasVideoExtension(const std::string& path);

/// Expands a printf pattern with one %d conversion ("img%04d.png", 7 -> "img0007.png").
/// Throws std::runtime_error if `pattern` has no such conversion or more than one.
std::string ExpandPattern(const std::string& pattern, int index);

}  // namespace oal
