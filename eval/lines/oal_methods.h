// Our methods in the comparison (eval/lines/compare.h): the OAL detector on each frame on its own,
// its temporal line tracker, and the target tracker with its pose.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "detector/options.h"
#include "eval/lines/line_method.h"
#include "io/camera_file.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"
#include "target/line_target.h"

namespace oal {

/// Our detector, target tracker and pose as an evaluation runs them: a configuration's
/// detector:, target:, pose: and tracking: sections, read by the caller.
struct TrackerSetup {
  DetectorOptions detector;
  /// The target the frames show; nothing: not known (what that means is said where a setup
  /// is taken).
  std::optional<LineTarget> target;
  /// The file that named the target (a configuration, or the target.yaml next to rendered
  /// frames), for messages; "" when none did.
  std::string target_origin;
  /// EstimatePose's tunables; its camera, lines_undistorted and image size are set per input.
  PoseOptions pose;
  TargetTrackerOptions tracking;
};

/// The OAL detector on each frame on its own ("oal"): the lines it finds, best first.
class OalMethod : public LineMethod {
 public:
  OalMethod(const DetectorOptions& options, const std::optional<CameraFile>& camera)
      : detector_(camera ? OalDetector(options, camera->camera) : OalDetector(options)) {}
  std::string Name() const override { return "oal"; }
  bool Undistorted() const override { return detector_.Undistorts(); }
  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    last_ = &detector_.Detect(image);
    lines->clear();
    for (const DetectedLine& line : *last_) lines->push_back(line.line);
  }
  const std::vector<DetectedLine>& last() const { return *last_; }

 private:
  OalDetector detector_;
  const std::vector<DetectedLine>* last_ = nullptr;
};

/// Our temporal line tracker ("oal-tracker"): the lines it holds, best supported first.
std::unique_ptr<LineMethod> MakeOalTrackerMethod(const DetectorOptions& options,
                                                 const std::optional<CameraFile>& camera);

/// The target tracker ("oal-target") of a four-line `target`: the lines of the poses it
/// accepts, in the target's order; nothing in a frame without one.
std::unique_ptr<LineMethod> MakeOalTargetMethod(const TrackerSetup& setup, const LineTarget& target,
                                                const Lens& camera);

}  // namespace oal
