// Which frames of a live camera (or a video) become calibration views: one is taken when the
// target has held still for a few frames, so that it is sharp, and when it stands apart from
// every view already taken, so that each view adds a new pose rather than a copy.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "calibration/calibrate.h"
#include "detector/line.h"

namespace oal {

struct ViewSelectorOptions {
  /// Frames in a row the target must hold still before a view is taken. Range [1, 1000].
  int still_frames = 5;
  /// The most the target may move between two frames that count as still, pixels: each known
  /// point (the same point of the plane), and each line across the stretch seen in both (its
  /// points' offsets from the curve the last frame's points trace, a straight trend along
  /// it, at its two ends, the offsets far from the line's others left out: runs cut short at
  /// a stripe's printed end). Frames see different stretches of a stripe and a lens bends it:
  /// a straight fit through its points, or the outline it gives, moves when the stripe does
  /// not. Range (0, 100].
  double still_px = 1.5;
  /// A view is taken only when the corners of its outline lie, on average, at least this far
  /// from those of every view taken, as a fraction of the image's diagonal. Range [0, 1].
  double min_difference = 0.08;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// Where the target's outline is in the image: the corners of the rectangle its known points
/// and lines span on its plane, through the view's homography (lens ignored: near enough to
/// tell motion). Empty when the view does not place the target (fewer than four points and
/// crossings).
std::optional<std::array<Point2d, 4>> TargetOutline(const CalibrationView& view);

/// How far the target moved from view `from` to view `to`, pixels (ViewSelectorOptions::
/// still_px says how); infinite when fewer than a quarter of a line's points lie within
/// `reach_px` (plus the spacing of its points) of the points `from` saw along it; empty when the
/// two views share no known point and no line seen in both.
std::optional<double> TargetMotion(const CalibrationView& from, const CalibrationView& to,
                                   double reach_px);

class ViewSelector {
 public:
  enum class Verdict {
    kNoTarget,  ///< the view does not place the target
    kMoving,    ///< the target moved within the last still_frames frames
    kTooLike,   ///< still, but too like a view already taken (similar_to())
    kTaken,     ///< still and new: take it
  };

  /// Throws std::invalid_argument for a size <= 0 or options failing their checks.
  ViewSelector(int width, int height, const ViewSelectorOptions& options = ViewSelectorOptions());

  /// The verdict on the next frame's view; a view judged kTaken counts as taken from then on.
  Verdict Offer(const CalibrationView& view);

  int taken() const { return static_cast<int>(taken_.size()); }
  /// After kTooLike: the index (from 0) of the view taken that it is too like.
  int similar_to() const { return similar_to_; }

 private:
  double diagonal_;
  ViewSelectorOptions options_;
  std::optional<CalibrationView> last_;
  int still_for_ = 0;  // frames in a row that moved no more than still_px
  int similar_to_ = -1;
  std::vector<std::array<Point2d, 4>> taken_;
};

}  // namespace oal
