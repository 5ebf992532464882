// Internal to servo/'s pose: the geometry of a '#' target (pose.h) as step 1 and vpPose need
// it, the pixel -> metre conversion, and step 1 on a checked target.
#pragma once

#include <visp3/core/vpRotationMatrix.h>

#include <array>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "servo/pose.h"
#include "target/line_target.h"

namespace oal::pose_internal {

struct Vec2 {
  double x = 0.0, y = 0.0;
};

struct HashTarget {
  /// corner[k] = lines[k] ∩ lines[(k + 1) % 4], board plane, metres.
  std::array<Vec2, 4> corner;
  /// Unit direction of each line (from its first to its second point) and unit normal
  /// (direction turned by +90 deg), board plane.
  std::array<Vec2, 4> direction, normal;
  std::array<double, 4> width_m{};
};

/// Throws std::invalid_argument unless `target` has 4 lines with 1 ∥ 3, 2 ∥ 4 and 1, 2
/// crossing at 10 deg or more, each of positive length and width.
HashTarget HashTargetFrom(const LineTarget& target);

/// A point in the lines' pixels to normalised metres (PoseOptions::lines_undistorted).
void PixelToMetre(const Lens& camera, bool undistorted, const Point2d& p, double* x, double* y);

/// Step 1 (IdentifyTargetLines) without the checks; `previous_cRo` (may be null) keeps the
/// identity of lines 1-4 consistent with the previous pose (PoseOptions::previous_max_deg).
PoseResult Identify(const std::vector<DetectedLine>& lines, const HashTarget& target,
                    const PoseOptions& options, const vpRotationMatrix* previous_cRo);

}  // namespace oal::pose_internal
