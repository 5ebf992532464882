// Calibration views of the printed line target, found before the camera is known: the target
// tracker with guessed pinhole cameras (a guess only has to be near enough to identify the
// stripes; the points it yields are the image's), each view found from scratch, and the
// stripes' feature points handed to calibration/sheet_view.h.
#pragma once

#include <memory>
#include <optional>
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

  /// From now on looks through `camera` first: a camera calibrated from the views found so far.
  /// Near the image's corners a wide lens bends a stripe past what a pinhole guess identifies;
  /// through its lens the stripes are straight. The points are the image's all the same.
  void LookThrough(const Lens& camera);

 private:
  /// The view `tracker` found in the frame it last tracked; nullopt when it found none.
  std::optional<CalibrationView> ViewOf(const TargetPoseTracker& tracker,
                                        const GrayImageView& image, const std::string& name) const;

  LineTarget target_;
  DetectorOptions detector_;
  PoseOptions pose_;
  TargetTrackerOptions tracking_;
  std::vector<TargetPoseTracker> trackers_;  // one per guessed focal length, likeliest first
  std::optional<TargetPoseTracker> calibrated_;
  Lens calibrated_camera_;
};

}  // namespace oal
