#include "app/lens_estimate.h"

#include <utility>

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

PlumbLineResult StripeCollector::Estimate(const vpCameraParameters& pinhole, int width,
                                          int height) const {
  PlumbLineOptions options;
  options.width = width;
  options.height = height;
  return EstimateRadialDistortion(stripes_, pinhole.get_px(), pinhole.get_py(), pinhole.get_u0(),
                                  pinhole.get_v0(), options);
}

vpCameraParameters WithLens(const vpCameraParameters& pinhole, const PlumbLineResult& lens) {
  vpCameraParameters camera;
  camera.initPersProjWithDistortion(pinhole.get_px(), pinhole.get_py(), pinhole.get_u0(),
                                    pinhole.get_v0(), lens.kud, lens.kdu);
  return camera;
}

}  // namespace oal
