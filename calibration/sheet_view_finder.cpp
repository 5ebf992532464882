#include "calibration/sheet_view_finder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "calibration/dense_runs.h"
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

// A camera calibrated from other views: the tracker's own checks, every view on
// kCalibrationBorders borders, but a poor fit of the stripes is the lens not told yet (a view
// reaching a wide lens's corner fits 0.5-0.9 px through the lens the others gave).
TargetTrackerOptions ForACalibratedCamera(TargetTrackerOptions tracking) {
  tracking.borders = std::max(tracking.borders, kCalibrationBorders);
  tracking.check_stripes_on_poor_fit = false;
  tracking.corner_cells = false;
  return tracking;
}

// The distorted pixel of an ideal pixel of `camera`.
Point2d Distorted(const Lens& camera, double u, double v) {
  return camera.Pixel((u - camera.u0()) / camera.px(), (v - camera.v0()) / camera.py());
}

}  // namespace

SheetViewFinder::SheetViewFinder(const LineTarget& target, int width, int height,
                                 const DetectorOptions& detector, const PoseOptions& pose,
                                 const TargetTrackerOptions& tracking)
    : target_(target), detector_(detector), pose_(pose), tracking_(tracking) {
  for (const double focal_per_width : kGuessedFocalPerWidth) {
    Lens guess = Lens::Pinhole(focal_per_width * width, focal_per_width * width, 0.5 * (width - 1),
                               0.5 * (height - 1));
    trackers_.emplace_back(target, guess, detector, pose, ForAGuessedCamera(tracking));
    // Every view on all its borders: the calibration wants every point along the stripes.
    trackers_.back().set_quick_scan(false);
  }
}

void SheetViewFinder::LookThrough(const Lens& camera) {
  calibrated_camera_ = camera;
  calibrated_.emplace(target_, camera, detector_, pose_, ForACalibratedCamera(tracking_));
  calibrated_->set_quick_scan(false);
}

CalibrationView SheetViewFinder::Find(const GrayImageView& image, const std::string& name) {
  if (calibrated_) {
    calibrated_->Reset();
    calibrated_->Track(image);
    std::optional<CalibrationView> view = ViewOf(*calibrated_, image, name);
    if (view && !view->lines.empty()) return std::move(*view);
  }
  for (TargetPoseTracker& tracker : trackers_) {
    tracker.Reset();
    tracker.Track(image);
    if (std::optional<CalibrationView> view = ViewOf(tracker, image, name)) return std::move(*view);
  }
  return CalibrationView{name, {}, {}};
}

std::optional<CalibrationView> SheetViewFinder::ViewOf(const TargetPoseTracker& tracker,
                                                       const GrayImageView& image,
                                                       const std::string& name) const {
  // The runs' middles as seen, with their runs: the calibration moves each onto the centre
  // line through the lens it solves. A tracker that corrects a lens gives them on the ideal
  // image: they are taken back to the image's pixels.
  const std::array<std::vector<FramePoint>, 4> stripes = tracker.StripeRuns(kStripeTolerancePx);
  if (stripes[0].empty()) return std::nullopt;
  const bool ideal = calibrated_ && &tracker == &*calibrated_ && calibrated_camera_.distorted();
  std::vector<std::vector<Point2d>> seen(4), runs(4);
  for (std::size_t k = 0; k < 4; ++k) {
    for (const FramePoint& point : stripes[k]) {
      if (!ideal) {
        seen[k].push_back(point.p);
        runs[k].push_back(Point2d{point.across_u, point.across_v});
        continue;
      }
      const double half_u = 0.5 * point.across_u, half_v = 0.5 * point.across_v;
      const Point2d middle = Distorted(calibrated_camera_, point.p.u, point.p.v);
      const Point2d a = Distorted(calibrated_camera_, point.p.u - half_u, point.p.v - half_v);
      const Point2d b = Distorted(calibrated_camera_, point.p.u + half_u, point.p.v + half_v);
      if (!std::isfinite(middle.u + middle.v + a.u + a.v + b.u + b.v)) continue;
      seen[k].push_back(middle);
      runs[k].push_back(Point2d{b.u - a.u, b.v - a.v});
    }
    // Every column's run between the tracker's: the calibration's precision follows the
    // number of points (20 views tell the focal length to 0.05 px instead of 0.12 px).
    StripeRuns dense = DenseStripeRuns(image, StripeRuns{seen[k], runs[k]});
    seen[k] = std::move(dense.middles);
    runs[k] = std::move(dense.runs);
  }
  return SheetView(target_, seen, name, SheetViewOptions(), runs);
}

}  // namespace oal
