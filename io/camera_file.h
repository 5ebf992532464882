// Camera files: ViSP's camera XML (what vpXmlParserCamera reads and writes), OpenCV's
// calibration YAML and ROS's camera_info.
//
// ViSP's XML: vpXmlParserCamera::parse(cam, file, name, model, width, height) accepts a <camera>
// only if its <name> equals `name` exactly (an empty name matches only unnamed cameras), its image
// size is within 15 px of width x height (0 = any) and it has a <model> of type `model`; it
// fails unless exactly one camera matches. To pick "the first camera" when the user names
// none, the file is listed first (libxml2), then the chosen camera is parsed by ViSP with its
// own name and size.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "detector/lens.h"

namespace oal {

/// The camera files users have: ViSP's camera XML (one radial term each way, kud and kdu),
/// OpenCV's calibration YAML and ROS's camera_info YAML (OpenCV's model, io/camera_yaml.h).
enum class CameraFileFormat { kViSPXml, kOpenCvYaml, kRosCameraInfo };

/// "ViSP's camera XML", "OpenCV's calibration YAML", "ROS's camera_info YAML".
std::string CameraFileFormatName(CameraFileFormat format);

/// The format a camera file written to `path` takes, from its extension: .xml is ViSP's XML,
/// .yaml and .yml OpenCV's calibration YAML, or ROS's camera_info when `ros`. Throws
/// std::invalid_argument naming the file for any other extension.
CameraFileFormat CameraFileFormatFor(const std::string& path, bool ros);

struct CameraFile {
  Lens camera;
  std::string name;         ///< <name> or camera_name, may be empty
  unsigned int width = 0;   ///< image width, 0 if absent
  unsigned int height = 0;  ///< image height, 0 if absent
  CameraFileFormat format = CameraFileFormat::kViSPXml;
};

/// A warning when `camera` was calibrated for another image size than width x height of the
/// frame `source`; nothing when the sizes agree or the file gives none.
std::optional<std::string> CameraSizeMismatch(const CameraFile& camera, int width, int height,
                                              const std::string& source);

/// Reads a camera file, its format told by its extension: .xml ViSP's camera XML (camera
/// `camera_name`, or the file's first camera when the name is empty; the model
/// perspectiveProjWithDistortion when the camera has one), .yaml or .yml OpenCV's calibration
/// YAML or ROS's camera_info (told apart by ROS's distortion_model; a name given must be ROS's
/// camera_name). Throws std::runtime_error naming the file (and the line and key where it
/// can) when it is missing, malformed, or holds no usable camera.
CameraFile LoadCameraFile(const std::string& path, const std::string& camera_name = "");

/// Writes `camera` to `path` in `format`, atomically (replacing `path`), each of `comments`
/// as a comment. A lens the format cannot hold exactly (OpenCV's model in ViSP's XML, ViSP's
/// kdu in a YAML file) is written as its best approximation over the width x height image
/// (the image the principal point centres when no size is given), and the returned note says
/// so and by how much it misses; nothing when the file holds the lens exactly.
std::optional<std::string> SaveCameraFile(const std::string& path, const Lens& camera,
                                          const std::string& name, unsigned int width,
                                          unsigned int height, CameraFileFormat format,
                                          const std::vector<std::string>& comments);
/// The same in the format the extension names (CameraFileFormatFor(path, false)), no comments.
std::optional<std::string> SaveCameraFile(const std::string& path, const Lens& camera,
                                          const std::string& name, unsigned int width,
                                          unsigned int height);

}  // namespace oal
