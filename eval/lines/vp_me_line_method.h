// ViSP 3.5's moving-edge line tracker (vpMeLine) as a compared method: one tracker per
// target edge, two per stripe (their midline), started on the first frame's targets and
// re-initialised on a target after it drifts or throws.
#pragma once

#include <memory>

#include "eval/lines/line_method.h"

namespace oal {

/// vpMe settings of the vpMeLine method and its failure rule.
struct VpMeLineOptions {
  /// Search half-length along the normal of each moving edge, pixels, [1, 100]. Lines that
  /// move further between frames are lost (ViSP's default is 4; 15 follows slow and
  /// moderate motion).
  int range_px = 15;
  /// Likelihood threshold of a moving edge (vpMe::setThreshold; ViSP 3.5 default 10000 for
  /// its 5x5 masks), > 0. 10000 keeps edges of 40+ grey levels of contrast.
  double threshold = 10000.0;
  /// Distance between moving edges along the line, pixels, [1, 100].
  double sample_step_px = 5.0;
  /// With truth, a tracker further than either bound from its truth line has failed.
  double drift_angle_deg = 5.0;
  double drift_offset_px = 10.0;

  void Check() const;
};

/// The vpMeLine method; `stripes`: each target is a stripe of two edges.
std::unique_ptr<LineMethod> MakeVpMeLineMethod(const VpMeLineOptions& options, bool stripes);

}  // namespace oal
