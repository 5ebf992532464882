#include "eval/lines/oal_methods.h"

#include <algorithm>

#include "detector/lens.h"
#include "detector/tracker.h"

namespace oal {
namespace {

// The target tracker (servo/target_tracker.h): the four lines of the pose it accepts, in the
// order of the target's lines; nothing in a frame without an accepted pose (a wrong pose is
// refused, not scored). Its failures are the frames without a pose.
class OalTargetMethod : public LineMethod {
 public:
  OalTargetMethod(const TrackerSetup& setup, const LineTarget& target, const Lens& camera)
      : tracker_(target, camera, setup.detector, PoseOf(setup), setup.tracking) {}
  std::string Name() const override { return "oal-target"; }
  bool Undistorted() const override { return tracker_.detector().Undistorts(); }
  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    const TargetFrame& frame = tracker_.Track(ViewOf(image));
    lines->clear();
    if (frame.status != TargetStatus::kOk) {
      ++failures_;
      return;
    }
    for (const int index : frame.pose.line_index) {
      lines->push_back(tracker_.lines()[static_cast<std::size_t>(index)].line);
    }
  }
  int failures() const override { return failures_; }
  int reinitialisations() const override { return 0; }

 private:
  // The tracker sets the camera and each frame's size itself; scoring needs no covariance.
  static PoseOptions PoseOf(const TrackerSetup& setup) {
    PoseOptions pose = setup.pose;
    pose.compute_covariance = false;
    return pose;
  }

  TargetPoseTracker tracker_;
  int failures_ = 0;
};

// Our temporal tracker: the lines it holds in each frame (lost ones excluded), best
// supported first, as the detector ranks them. A user never re-initialises it; its
// failures are the tracks it lost.
class OalTrackerMethod : public LineMethod {
 public:
  OalTrackerMethod(const DetectorOptions& options, const std::optional<CameraFile>& camera)
      : tracker_(Options(options), camera ? camera->camera : vpCameraParameters()) {}
  std::string Name() const override { return "oal-tracker"; }
  bool Undistorted() const override { return tracker_.detector().Undistorts(); }
  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    tracker_.track(image);
    held_.clear();
    for (const TrackedLine& track : tracker_.getLines()) {
      if (track.status != TrackStatus::kLost) held_.push_back(&track.line);
    }
    std::stable_sort(held_.begin(), held_.end(), [](const DetectedLine* a, const DetectedLine* b) {
      return a->support > b->support;
    });
    lines->clear();
    for (const DetectedLine* line : held_) lines->push_back(line->line);
  }
  void AfterFrame(const vpImage<unsigned char>& /*image*/,
                  const std::vector<TargetLineTruth>& /*targets*/, bool /*from_truth*/) override {
    for (const TrackedLine& track : tracker_.getLines()) {
      failures_ += track.status == TrackStatus::kLost && track.frames_lost == 1;
    }
  }
  int failures() const override { return failures_; }
  int reinitialisations() const override { return 0; }

 private:
  static TrackerOptions Options(const DetectorOptions& detector) {
    TrackerOptions options;
    options.detector = detector;
    return options;
  }

  OalLineTracker tracker_;
  std::vector<const DetectedLine*> held_;
  int failures_ = 0;
};

}  // namespace

std::unique_ptr<LineMethod> MakeOalTrackerMethod(const DetectorOptions& options,
                                                 const std::optional<CameraFile>& camera) {
  return std::make_unique<OalTrackerMethod>(options, camera);
}

std::unique_ptr<LineMethod> MakeOalTargetMethod(const TrackerSetup& setup, const LineTarget& target,
                                                const Lens& camera) {
  return std::make_unique<OalTargetMethod>(setup, target, camera);
}

}  // namespace oal
