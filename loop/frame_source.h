// Where the servo loop's frames come from: the target rendered from the camera's true pose (a
// simulation), or the frames of a camera or a recording (io/image_source.h).
#pragma once

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <cstdint>
#include <exception>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/image_source.h"
#include "scene/lived_in.h"
#include "scene/scene.h"
#include "target/line_target.h"

namespace oal {

/// A frame as the loop asks for it.
struct Capture {
  vpHomogeneousMatrix true_cMo;  ///< the camera's true pose when it is taken (a simulation)
  int iteration = 0;
  double time_s = 0.0;  ///< the loop's clock when it is taken, s
  /// The camera's twist while it is exposed (camera frame, m/s and rad/s; empty: still).
  vpColVector velocity;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The frame `capture` asks for: seen from its true pose (simulation) or the next one of
  /// the source; false at the end of a recording. Throws std::runtime_error when a frame cannot
  /// be read.
  virtual bool Grab(const Capture& capture, cv::Mat* gray) = 0;
  /// True when a recording has no frame left (the next Grab() would return false); a camera
  /// never ends.
  virtual bool AtEnd() { return false; }
  virtual std::string Name() const = 0;
  /// The frames are rendered from the true pose: the loop knows its true error.
  virtual bool KnowsTruth() const { return false; }
  /// How long before it is delivered a frame is taken, s: the loop asks for the scene at
  /// that earlier time and predicts from where the robot was then.
  virtual double LatencyS() const { return 0.0; }
  /// When the last frame handed out was taken, s on the monotonic clock (steady_clock), when
  /// the source says (a V4L2 camera's buffer timestamps); the loop then predicts from where the
  /// robot was at that moment.
  virtual std::optional<double> TakenAt() const { return std::nullopt; }
};

/// What the simulated camera sees besides the bench: a lived-in scene's conditions
/// (scene/lived_in.h: a hand or a tool over the sheet, a glare, an exposure change, ...)
/// drawn once for each episode of the run's clock and held through it, and the smear of its
/// own motion over its exposure.
struct SimulatedCameraScene {
  LivedInOptions lived_in;
  /// Each episode lasts a time drawn in this range, s, 0 < lo <= hi <= 3600.
  DrawRange episode_s{0.2, 1.0};
  std::uint64_t seed = 1;   ///< of the episodes and what they hold
  double exposure_s = 0.0;  ///< the camera's motion blurs each frame over this long, [0, 1]
  double latency_s = 0.0;   ///< a frame is delivered this long after it is taken, s, [0, 1]

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// The simulated camera: `target` rendered from the true pose with `render`'s lens, noise,
/// blur and scene, each iteration's noise its own (seeded by the iteration), and `scene`'s
/// episodes and motion blur.
class RenderedFrames : public FrameSource {
 public:
  RenderedFrames(const LineTarget& target, const RenderOptions& render,
                 const SimulatedCameraScene& scene = SimulatedCameraScene());
  bool Grab(const Capture& capture, cv::Mat* gray) override;
  std::string Name() const override { return "the simulated camera"; }
  bool KnowsTruth() const override { return true; }
  double LatencyS() const override { return scene_.latency_s; }

 private:
  /// The episode the clock is in at `time_s` (0 first).
  int EpisodeAt(double time_s);

  LineTarget target_;
  SimulatedCameraScene scene_;
  SceneRenderer renderer_;
  RenderedFrame frame_;
  std::vector<double> episode_ends_;  ///< drawn as the clock reaches them
};

/// A V4L2 camera or a recording: the source's frames in turn, whatever the pose.
class RecordedFrames : public FrameSource {
 public:
  explicit RecordedFrames(std::unique_ptr<ImageSource> source);
  bool Grab(const Capture& capture, cv::Mat* gray) override;
  /// Reads the next frame ahead (Grab() then hands it out); an unreadable one is not the end,
  /// and the next Grab() throws its error.
  bool AtEnd() override;
  std::string Name() const override { return source_->Name(); }
  std::optional<double> TakenAt() const override { return taken_s_; }

 private:
  std::unique_ptr<ImageSource> source_;
  std::optional<double> taken_s_;
  Frame frame_;
  bool peeked_ = false;              // frame_ holds the next frame already (AtEnd())
  bool peeked_frame_ = false;        // ... and there was one
  std::exception_ptr peeked_error_;  // ... or it could not be read
};

}  // namespace oal
