#include "calibration/sheet_view_finder.h"

#include <algorithm>
#include <array>

#include "calibration/sheet_view.h"
#include "detector/lens.h"

namespace oal {
namespace {

// Focal lengths tried, as fractions of the image's width: a 60 deg lens first, then wider and
// narrower ones (a USB camera's lens is 50-110 deg across).
constexpr std::array<double, 4> kGuessedFocalPerWidth = {0.9, 0.65, 1.3, 1.9};
// A feature point this far from its stripe's straight line still counts: an unknown lens bends
// a stripe a few pixels away from its chord.
constexpr double kStripeTolerancePx = 6.0;

// Borders scanned on the sheet's plane: twice the tracker's default, for twice the points
// along each stripe (the focal length's deviation from 20 views falls from 0.04 % to 0.03 %).
constexpr int kCalibrationBorders = 32;

// A guessed camera's pose only identifies the stripes: the model check lets a stripe lie a
// quarter of its width off the line the guess puts it on (the unknown lens and focal length),
// and the pose is not refined on the stripes' points (the guess could not hold them rigid).
// Every view is scanned on kCalibrationBorders borders.
TargetTrackerOptions ForAGuessedCamera(TargetTrackerOptions tracking) {
  tracking.fit_stripes = false;
  tracking.stripe_tolerance_fraction = std::max(tracking.stripe_tolerance_fraction, 0.25);
  tracking.stripe_width_tolerance = std::max(tracking.stripe_width_tolerance, 0.5);
  tracking.borders = std::max(tracking.borders, kCalibrationBorders);
  // The corner cells' guesses are left out: each is tried four ways, and the loose check above
  // let one pass that threw a calibration off.
  tracking.corner_cells = false;
  return tracking;
}

}  // namespace

SheetViewFinder::SheetViewFinder(const LineTarget& target, int width, int height,
                                 const DetectorOptions& detector, const PoseOptions& pose,
                                 const TargetTrackerOptions& tracking)
    : target_(target) {
  for (const double focal_per_width : kGuessedFocalPerWidth) {
    Lens guess = Lens::Pinhole(focal_per_width * width, focal_per_width * width, 0.5 * (width - 1),
                               0.5 * (height - 1));
    trackers_.emplace_back(target, guess, detector, pose, ForAGuessedCamera(tracking));
    // Every view on all its borders: the calibration wants every point along the stripes.
    trackers_.back().set_quick_scan(false);
  }
}

CalibrationView SheetViewFinder::Find(const GrayImageView& image, const std::string& name) {
  for (TargetPoseTracker& tracker : trackers_) {
    tracker.Reset();
    tracker.Track(image);
    // The runs' middles as seen, with their runs: the calibration moves each onto the centre
    // line through the lens it solves (the guess knows no lens to do it with).
    const std::array<std::vector<FramePoint>, 4> stripes = tracker.StripeRuns(kStripeTolerancePx);
    if (stripes[0].empty()) continue;
    std::vector<std::vector<Point2d>> seen(4), runs(4);
    for (std::size_t k = 0; k < 4; ++k) {
      for (const FramePoint& point : stripes[k]) {
        seen[k].push_back(point.p);
        runs[k].push_back(Point2d{point.across_u, point.across_v});
      }
    }
    return SheetView(target_, seen, name, SheetViewOptions(), runs);
  }
  return CalibrationView{name, {}, {}};
}

}  // namespace oal
