#include "loop/lens_estimate.h"

#include <stdexcept>
#include <utility>

#include "base/format.h"
#include "detector/lens.h"

namespace oal {
namespace {

// A feature point this far from its line still counts: a lens nobody measured bends a stripe
// a few pixels away from its chord.
constexpr double kPlumbTolerancePx = 6.0;

}  // namespace

void StripeCollector::Add(const TargetPoseTracker& tracker) {
  std::array<std::vector<Point2d>, 4> stripes = tracker.StripePoints(kPlumbTolerancePx);
  if (stripes[0].empty()) return;
  for (std::vector<Point2d>& stripe : stripes) stripes_.push_back(std::move(stripe));
  ++frames_;
}

PlumbLineResult StripeCollector::Estimate(const Lens& pinhole, int width, int height) const {
  PlumbLineOptions options;
  options.width = width;
  options.height = height;
  return EstimateRadialDistortion(stripes_, pinhole.px(), pinhole.py(), pinhole.u0(), pinhole.v0(),
                                  options);
}

ToldLens TellLensFromStripes(TargetPoseTracker& tracker, const Lens& pinhole, const NextFrame& next,
                             int frames, int max_read) {
  // Every view on all its borders: the plumb line wants every point along the stripes (on 8
  // borders instead of 16, the lens told was off by 3 % instead of 1-2 %).
  struct FullScans {
    TargetPoseTracker& tracker;
    const bool quick = tracker.quick_scan();
    explicit FullScans(TargetPoseTracker& t) : tracker(t) { tracker.set_quick_scan(false); }
    ~FullScans() {
      tracker.set_quick_scan(quick);
      tracker.Reset();
    }
    FullScans(const FullScans&) = delete;
    FullScans& operator=(const FullScans&) = delete;
  } full_scans(tracker);
  StripeCollector stripes;
  GrayImageView view;
  int read = 0;
  while (stripes.frames() < frames && read < max_read && next(&view)) {
    ++read;
    tracker.Reset();
    tracker.Track(view);
    stripes.Add(tracker);
  }
  ToldLens told;
  told.frames = stripes.frames();
  if (stripes.frames() < frames) {
    told.why = std::to_string(stripes.frames()) + " of the first " + std::to_string(read) +
               " frames show the target, " + std::to_string(frames) + " needed";
    return told;
  }
  try {
    told.lens = stripes.Estimate(pinhole, view.width, view.height);
  } catch (const std::runtime_error& error) {
    told.why = error.what();
  }
  return told;
}

std::string LensMismatchWarning(const LensCheck& lens, const std::string& corrected_by,
                                const std::string& remedy) {
  const double lens_minus_camera = -lens.median_kdu_error;
  return "lines 1-4 still bend after " + corrected_by +
         " corrects them, as if the lens's kdu were the camera's " +
         (lens_minus_camera >= 0.0 ? "+" : "") + Fixed(lens_minus_camera, 2) + " (" +
         std::to_string(lens.contradicting) + " of " + std::to_string(lens.frames) +
         " frames; median bend " + Fixed(lens.median_px, 2) +
         " px; a camera file that matches the lens leaves the kdu within 0.01): it does not "
         "describe this lens (its distortion, or the resolution it was made for), and every "
         "pose is biased. " +
         remedy;
}

Lens WithLens(const Lens& pinhole, const PlumbLineResult& lens) {
  return Lens::WithKudKdu(pinhole.px(), pinhole.py(), pinhole.u0(), pinhole.v0(), lens.kud,
                          lens.kdu);
}

}  // namespace oal
