// A view of a printed line target (the four-line sheet or board) as a calibration view: each
// stripe's centre line on the target's plane with the points seen along it.
#pragma once

#include <string>
#include <vector>

#include "calibration/calibrate.h"
#include "detector/line.h"
#include "target/line_target.h"

namespace oal {

struct SheetViewOptions {
  /// A point nearer than this (metres) to another stripe's edge is left out: where two stripes
  /// cross, the middle of a dark run is neither's. Range [0, 0.1].
  double clear_of_other_stripes_m = 0.008;
  /// A point farther than this (metres) outside its own stripe's edges or ends is left out
  /// (a speck beside it). The view's homography is found with the lens ignored, so it is
  /// loose by a few pixels. Range [0, 0.1].
  double off_own_stripe_m = 0.004;
  int min_points_per_stripe = 8;  ///< fewer: the stripe is left out. Range [2, 100000].

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// `seen[k]` are distorted pixels of points along `target.lines[k]` (e.g. the middles of the
/// stripe's dark runs). The view has those of them that stay clear of the other stripes and
/// on their own, judged on the plane through the homography of the stripes' crossings; with
/// fewer than four crossings seen it has no lines (Calibrate then says why). `runs`, when
/// given, holds each seen point's run across its stripe (CalibrationLine::runs): the points
/// are the runs' middles, which Calibrate moves onto the centre line through the lens.
CalibrationView SheetView(const LineTarget& target, const std::vector<std::vector<Point2d>>& seen,
                          std::string name, const SheetViewOptions& options = SheetViewOptions(),
                          const std::vector<std::vector<Point2d>>& runs = {});

}  // namespace oal
