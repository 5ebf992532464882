// Ground truth files: target lines and the camera pose per frame, in the renderer's
// frame_NNNN.json (`oalservo render` writes it, FrameTruthJson) or in one CSV file.
//
// Truth CSV (docs/EVALUATE.md): one row per line and frame, and at most one pose row per
// frame, in any order:
//
//   frame,line,rho,theta                       a target line (the format of oalservo compare)
//   frame,pose,tx,ty,tz,tux,tuy,tuz            the pose cMo: translation (metres) and
//                                              theta-u rotation (radians) of the target frame
//                                              in the camera frame (ViSP's vpHomogeneousMatrix)
//
//   frame  the number in the frame's file name, its last run of digits (image.0001.pgm -> 1,
//          frame_0007.png -> 7), or for a video its 0-based index (FrameNumber)
//   line   an integer >= 0 identifying the line across frames (the target line's index for
//          the four-line target: 0-3 are lines 1-4)
//   rho, theta   pixels and radians, u·cosθ + v·sinθ = ρ (detector/line.h), image
//          (distorted) coordinates; theta in [-2 pi, 2 pi] (normalised to [0, pi): our
//          [0, pi), atan2's (-pi, pi] and ViSP's [0, 2 pi) all work; a larger value is
//          rejected, most likely degrees)
//
// A header row starting with "frame", blank lines and lines starting with '#' are skipped.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "detector/lens.h"
#include "detector/line.h"
#include "io/json_io.h"
#include "scene/scene.h"  // RenderedFrame

namespace oal {

/// One target line in one frame: what scoring and a user re-initialising a tracker see.
struct TargetLineTruth {
  int id = 0;             ///< the line's identity across frames (target index, CSV `line`)
  LineParams image_line;  ///< image (distorted) coordinates: distorted_fit or the CSV line
  LineParams ideal_line;  ///< undistorted pixels (JSON `ideal`); = image_line for CSV
  Point2d end_a, end_b;   ///< ends of the visible chord, image pixels
  double width_px = 0.0;  ///< stripe width, pixels (0: an edge or unknown)
};

/// The frame number a truth CSV row names for the frame read from `source` at 0-based
/// `position` in its input: the last run of digits in the file name (image.0001.pgm -> 1,
/// frame_0007.png -> 7, video.avi#12 -> 12), else `position`.
int FrameNumber(const std::string& source, int position);

/// The line rows of a truth CSV (file comment): frame number -> its lines. Throws
/// std::runtime_error "FILE:LINE: ..." for a missing file or a malformed row. Chord ends are
/// left at zero (set per frame from the image size).
std::map<int, std::vector<TargetLineTruth>> LoadTruthCsv(const std::string& path);

/// The visible target lines of a frame_NNNN.json truth file (oalservo render). Throws
/// std::runtime_error naming the file if it is missing or malformed.
std::vector<TargetLineTruth> LoadTruthJson(const std::string& path);

struct TruthCsv {
  std::map<int, std::vector<TargetLineTruth>> lines;  ///< frame number -> its lines
  std::map<int, vpHomogeneousMatrix> poses;           ///< frame number -> cMo
};

/// Reads a truth CSV with line and pose rows (file comment). Throws std::runtime_error
/// "FILE:LINE: ..." for a missing file or a malformed row (wrong field count, a field that is
/// not a number, a negative or fractional frame or line, theta outside [-2 pi, 2 pi], a line
/// or pose given twice).
TruthCsv LoadTruthCsvWithPoses(const std::string& path);

/// The pose cMo of a frame_NNNN.json truth file (oalservo render); nothing if it has none.
/// Throws std::runtime_error naming the file if it is missing or malformed.
std::optional<vpHomogeneousMatrix> LoadTruthPoseJson(const std::string& path);

/// The renderer's truth of one frame, the frame_NNNN.json that LoadTruthJson and
/// LoadTruthPoseJson read: {frame, image, target, seed, noise_seed, camera, cMo, lines}.
/// `image`: the frame's file name; `seed`: the data set's; `noise_seed`: the frame's.
Json FrameTruthJson(const RenderedFrame& frame, int index, const std::string& image,
                    const std::string& target, std::uint64_t seed, std::uint64_t noise_seed,
                    const Lens& camera, int width, int height);

}  // namespace oal
