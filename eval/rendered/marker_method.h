// A marker users would print on their sheet instead of our '#' target, as the pose accuracy
// evaluation (eval/rendered/pose_accuracy.h) runs it beside ours on the same frames: what is
// printed on the sheet, and the marker's detection and pose from one frame. Each marker in its own
// file behind this interface: ViSP's AprilTag detector in apriltag_method.h, OpenCV's ChArUco board
// in charuco_method.h.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpImage.h>

#include <array>
#include <memory>
#include <string>

#include "detector/lens.h"
#include "scene/scene.h"  // PrintedPicture
#include "target/line_target.h"

namespace oal {

/// What the sheet carries: our '#' target, or a marker printed instead.
enum class SheetMarker {
  kOal,       ///< our four stripes (servo/target_tracker.h finds them)
  kAprilTag,  ///< an AprilTag 36h11 (id 0), ViSP's vpDetectorAprilTag
  kCharuco,   ///< a 10 x 7 ChArUco board, OpenCV's aruco module
};

/// "oal", "apriltag", "charuco": the one place where the markers meet strings.
std::string ToString(SheetMarker marker);
/// Throws std::invalid_argument naming the text and the accepted values.
SheetMarker SheetMarkerFromString(const std::string& text);
/// "oal, apriltag, charuco", for messages and help.
std::string SheetMarkerNameList();

/// Why a frame has no marker pose.
enum class MarkerStatus {
  kOk,        ///< found and posed
  kNotFound,  ///< the marker was not found
  kNoPose,    ///< found, but too little of it to pose (a ChArUco board's corners)
};
/// "ok", "not-found", "no-pose".
std::string ToString(MarkerStatus status);

/// One frame's result.
struct MarkerPose {
  MarkerStatus status = MarkerStatus::kNotFound;
  std::string message;      ///< why not, in the method's words; empty when kOk
  vpHomogeneousMatrix cMo;  ///< the sheet's pose (its object frame), when kOk
  double detect_us = 0.0;   ///< time to find the marker (its corners), microseconds
  double pose_us = 0.0;     ///< time to pose it from them, microseconds
};

/// What is printed on the sheet for a marker, centred on the sheet's origin.
struct MarkerPrint {
  /// The picture, for RenderOptions::printed_picture (its white texels are bare paper).
  PrintedPicture picture;
  /// The marker's outline on the sheet's plane (X, Y in metres, in order around it): all of it
  /// in the image means the whole marker is in view.
  std::array<std::array<double, 2>, 4> outline_m{};
  /// In words: "AprilTag 36h11 id 0, black square 0.250 m".
  std::string description;
};

/// A printed marker's detection and pose. Each frame is found on its own (no state carried
/// from one frame to the next).
class MarkerMethod {
 public:
  virtual ~MarkerMethod() = default;
  /// Short and printable on the sheet: "apriltag-36h11", "charuco-10x7".
  virtual std::string Name() const = 0;
  virtual const MarkerPrint& Print() const = 0;
  /// The marker and the sheet's pose in `image`, a frame of the camera the method was made
  /// for (with its lens: the image is not undistorted).
  virtual MarkerPose Find(const vpImage<unsigned char>& image) = 0;
};

/// `marker`'s method for a sheet of `sheet`'s board size seen by `camera` (ViSP's model, with
/// or without distortion) in width x height frames. Throws std::invalid_argument for
/// SheetMarker::kOal (ours is the target tracker, not a printed marker).
std::unique_ptr<MarkerMethod> MakeMarkerMethod(SheetMarker marker, const LineTarget& sheet,
                                               const Lens& camera, int width, int height);

/// `sheet`'s board, paper and ink without its stripes, named after `method`: the board a
/// marker is printed on (LineTarget::Check allows a target without lines).
LineTarget MarkerSheet(const LineTarget& sheet, const MarkerMethod& method);

}  // namespace oal
