// The two YAML camera files users already have, read and written with the full lens:
//
// - OpenCV's calibration YAML (what OpenCV's calibration sample and cv::FileStorage write):
//   `camera_matrix` and `distortion_coefficients` as `!!opencv-matrix` {rows, cols, dt, data},
//   `image_width`, `image_height`; 4, 5 or 8 coefficients in calib3d's order (more only when
//   the thin-prism and tilt terms are zero).
// - ROS's camera_info YAML (camera_calibration_parsers): `camera_name`, `image_width`,
//   `image_height`, `camera_matrix` {rows, cols, data}, `distortion_model` (plumb_bob or
//   rational_polynomial), `distortion_coefficients`, `rectification_matrix`,
//   `projection_matrix`.
//
// Read with yaml-cpp, so every error names the file, the line and the key.
#pragma once

#include <string>
#include <vector>

#include "detector/lens.h"

namespace oal {

struct YamlCamera {
  Lens lens;
  std::string name;  ///< ROS's camera_name; empty in OpenCV's files
  unsigned int width = 0, height = 0;
  bool ros = false;  ///< ROS's camera_info, else OpenCV's calibration YAML
};

/// Reads OpenCV's calibration YAML or ROS's camera_info from `path` (told apart by ROS's
/// `distortion_model`); throws std::runtime_error naming the file, line and key.
YamlCamera ReadYamlCamera(const std::string& path);

/// The text of OpenCV's calibration YAML of `lens` (a lens in OpenCV's model or the
/// pinhole), each of `comments` a `#` line after the header.
std::string OpenCvYamlText(const Lens& lens, unsigned int width, unsigned int height,
                           const std::vector<std::string>& comments);

/// The text of ROS's camera_info of `lens` (OpenCV's model or the pinhole): plumb_bob, or
/// rational_polynomial when k4-k6 are set; identity rectification, projection [K | 0].
std::string RosCameraInfoText(const Lens& lens, const std::string& name, unsigned int width,
                              unsigned int height, const std::vector<std::string>& comments);

}  // namespace oal
