// A stripe's runs read again at every column (or row) between those the target tracker found:
// the calibration's precision follows how many independent points each view gives, and the
// tracker's borders cross a stripe only every few tens of pixels.
#pragma once

#include <vector>

#include "detector/image_view.h"
#include "detector/line.h"

namespace oal {

/// A stripe's dark runs: each run's middle and its run (its length times its direction), both
/// in the image's pixels.
struct StripeRuns {
  std::vector<Point2d> middles;
  std::vector<Point2d> runs;
};

/// The runs of the dark stripe through `found` (runs across one stripe, in any order, each run
/// crossing it from edge to edge) read at every image column between the first and the last
/// of them when the stripe runs nearer the rows, every row otherwise. Where each column's run
/// should be and how long, cubics through the found runs say (a lens bends a stripe smoothly).
/// A column's run is kept when it is that long and there, dark in its middle, its two edges
/// crossing half the contrast between the ink and flat paper beside each: a column under a
/// hand, a pen, a glare spot or another stripe gives none. Returns `found` itself when it has
/// fewer than three runs or when fewer columns than its runs were read.
StripeRuns DenseStripeRuns(const GrayImageView& image, const StripeRuns& found);

}  // namespace oal
