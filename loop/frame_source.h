// Where the servo loop's frames come from: the target rendered from the camera's true pose (a
// simulation), or the frames of a camera or a recording (io/image_source.h).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <exception>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>

#include "io/image_source.h"
#include "scene/scene.h"
#include "target/line_target.h"

namespace oal {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The frame of iteration `iteration`: seen from `true_cMo` (simulation) or the next one of
  /// the source; false at the end of a recording. Throws std::runtime_error when a frame cannot
  /// be read.
  virtual bool Grab(const vpHomogeneousMatrix& true_cMo, int iteration, cv::Mat* gray) = 0;
  /// True when a recording has no frame left (the next Grab() would return false); a camera
  /// never ends.
  virtual bool AtEnd() { return false; }
  virtual std::string Name() const = 0;
  /// The frames are rendered from the true pose: the loop knows its true error.
  virtual bool KnowsTruth() const { return false; }
};

/// The simulated camera: `target` rendered from the true pose with `render`'s lens, noise,
/// blur and scene, each iteration's noise its own (seeded by the iteration).
class RenderedFrames : public FrameSource {
 public:
  RenderedFrames(const LineTarget& target, const RenderOptions& render);
  bool Grab(const vpHomogeneousMatrix& true_cMo, int iteration, cv::Mat* gray) override;
  std::string Name() const override { return "the simulated camera"; }
  bool KnowsTruth() const override { return true; }

 private:
  SceneRenderer renderer_;
  RenderedFrame frame_;
};

/// A V4L2 camera or a recording: the source's frames in turn, whatever the pose.
class RecordedFrames : public FrameSource {
 public:
  explicit RecordedFrames(std::unique_ptr<ImageSource> source);
  bool Grab(const vpHomogeneousMatrix& true_cMo, int iteration, cv::Mat* gray) override;
  /// Reads the next frame ahead (Grab() then hands it out); an unreadable one is not the end,
  /// and the next Grab() throws its error.
  bool AtEnd() override;
  std::string Name() const override { return source_->Name(); }

 private:
  std::unique_ptr<ImageSource> source_;
  Frame frame_;
  bool peeked_ = false;              // frame_ holds the next frame already (AtEnd())
  bool peeked_frame_ = false;        // ... and there was one
  std::exception_ptr peeked_error_;  // ... or it could not be read
};

}  // namespace oal
