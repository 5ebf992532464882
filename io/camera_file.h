// ViSP camera XML files (what vpXmlParserCamera reads and writes).
//
// vpXmlParserCamera::parse(cam, file, name, model, width, height) accepts a <camera> only if
// its <name> equals `name` exactly (an empty name matches only unnamed cameras), its image
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

struct CameraFile {
  Lens camera;
  std::string name;         ///< <name>, may be empty
  unsigned int width = 0;   ///< <image_width>, 0 if absent
  unsigned int height = 0;  ///< <image_height>, 0 if absent
};

/// A warning when `camera` was calibrated for another image size than width x height of the
/// frame `source`; nothing when the sizes agree or the file gives none.
std::optional<std::string> CameraSizeMismatch(const CameraFile& camera, int width, int height,
                                              const std::string& source);

/// Reads camera `camera_name` from `path`, or the first camera of the file when the name is
/// empty. The model perspectiveProjWithDistortion is used when the camera has one, else
/// perspectiveProjWithoutDistortion. Throws std::runtime_error naming the file when it is
/// missing, is not XML, or holds no usable camera.
CameraFile LoadCameraFile(const std::string& path, const std::string& camera_name = "");

/// Writes `camera` with vpXmlParserCamera::save to `path`, atomically (replacing `path`).
void SaveCameraFile(const std::string& path, const Lens& camera, const std::string& name,
                    unsigned int width, unsigned int height);

}  // namespace oal
