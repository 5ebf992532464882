// Calibration views of the printed line target, found before the camera is known: the target
// tracker with guessed pinhole cameras (a guess only has to be near enough to identify the
// stripes; the points it yields are the image's), each view found from scratch, and the
// stripes' feature points handed to calibration/sheet_view.h.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "calibration/calibrate.h"
#include "detector/image_view.h"
#include "servo/target_tracker.h"

namespace oal {

class SheetViewFinder {
 public:
  /// Throws std::invalid_argument for a target that is not a four-line '#', or options failing
  /// their checks.
  SheetViewFinder(const LineTarget& target, int width, int height, const DetectorOptions& detector,
                  const PoseOptions& pose, const TargetTrackerOptions& tracking);

  /// The target's stripes in `image` as a calibration view; a view without lines when no guess
  /// found the target (Calibrate then leaves it out and says why).
  CalibrationView Find(const GrayImageView& image, const std::string& name);

 private:
  LineTarget target_;
  std::vector<TargetPoseTracker> trackers_;  // one per guessed focal length, likeliest first
};

}  // namespace oal
