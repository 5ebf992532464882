// The lens told from the target's stripes (calibration/plumb_line.h) over the first frames a
// pinhole tracker finds the target in: what `pose --estimate-distortion`, `pose-accuracy
// --estimate-distortion` and the servo loop's camera.estimate_distortion share.
#pragma once

#include <visp3/core/vpCameraParameters.h>

#include <vector>

#include "calibration/plumb_line.h"
#include "detector/line.h"
#include "servo/target_tracker.h"

namespace oal {

class StripeCollector {
 public:
  /// The stripes of the tracker's last frame, when it has a pose.
  void Add(const TargetPoseTracker& tracker);
  /// Frames added with a pose.
  int frames() const { return frames_; }
  /// kud and kdu from the stripes collected, through `pinhole`'s px, py, u0, v0, in a width x
  /// height image. Throws std::runtime_error saying why when they cannot tell the lens.
  PlumbLineResult Estimate(const vpCameraParameters& pinhole, int width, int height) const;

 private:
  std::vector<std::vector<Point2d>> stripes_;
  int frames_ = 0;
};

/// `pinhole` with the estimated lens (kud and kdu).
vpCameraParameters WithLens(const vpCameraParameters& pinhole, const PlumbLineResult& lens);

}  // namespace oal
