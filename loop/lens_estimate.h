// The lens told from the target's stripes (calibration/plumb_line.h) over the first frames a
// pinhole tracker finds the target in: what `pose --estimate-distortion`, `pose-accuracy
// --estimate-distortion` and the servo loop's camera.estimate_distortion share; and what the
// commands say when the lens check finds a camera file that misses the lens.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calibration/plumb_line.h"
#include "detector/image_view.h"
#include "detector/lens.h"
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
  PlumbLineResult Estimate(const Lens& pinhole, int width, int height) const;

 private:
  std::vector<std::vector<Point2d>> stripes_;
  int frames_ = 0;
};

/// Frames with the target that tell the lens, and how many frames are read at most to find
/// them. Ten tell kdu within about 1 % (one standard deviation), which costs a pose up to
/// twice its translation error; thirty, within about 0.6 %, leave it as with the true kdu
/// (docs/BENCHMARKS.md).
constexpr int kLensFrames = 30;
constexpr int kMaxLensFramesRead = 300;

/// The next frame: `view` set (valid until the next call) and true, or false at the end.
using NextFrame = std::function<bool(GrayImageView* view)>;

struct ToldLens {
  std::optional<PlumbLineResult> lens;  ///< when the stripes told it
  std::string why;                      ///< why they did not
  int frames = 0;                       ///< frames that showed the target
};

/// Tracks frames from `next`, each on its own, with `tracker` (a pinhole camera's), until
/// `frames` show the target or `max_read` have been read, and tells the lens from their stripes
/// through `pinhole`. Every view is scanned on all its borders (TargetPoseTracker::
/// set_quick_scan); the tracker is reset after. What `next` throws goes through.
ToldLens TellLensFromStripes(TargetPoseTracker& tracker, const Lens& pinhole, const NextFrame& next,
                             int frames = kLensFrames, int max_read = kMaxLensFramesRead);

/// The lens check's warning: "lines 1-4 still bend after `corrected_by` corrects them, as if
/// the lens's kdu were the camera's +0.10 ... `remedy`".
std::string LensMismatchWarning(const LensCheck& lens, const std::string& corrected_by,
                                const std::string& remedy);

/// `pinhole` with the estimated lens (kud and kdu).
Lens WithLens(const Lens& pinhole, const PlumbLineResult& lens);

}  // namespace oal
