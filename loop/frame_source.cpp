#include "loop/frame_source.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "base/check.h"
#include "base/random.h"
#include "detector/lens.h"

namespace oal {
namespace {

constexpr std::uint64_t kNoiseSeed = 20240605;

// The smear of the camera's twist over `exposure_s` where the target's origin is seen: its
// image moves by (du, dv) = exposure * d(px X/Z, py Y/Z)/dt, the point moving by
// -v - w x P in the camera frame.
void MotionBlurOf(const Capture& capture, const Lens& camera, double exposure_s,
                  FrameEffects* effects) {
  if (exposure_s <= 0.0 || capture.velocity.size() != 6) return;
  const vpColVector& twist = capture.velocity;
  const double X = capture.true_cMo[0][3], Y = capture.true_cMo[1][3], Z = capture.true_cMo[2][3];
  if (!(Z > 1e-6)) return;
  const double dX = -twist[0] - (twist[4] * Z - twist[5] * Y);
  const double dY = -twist[1] - (twist[5] * X - twist[3] * Z);
  const double dZ = -twist[2] - (twist[3] * Y - twist[4] * X);
  const double du = exposure_s * camera.px() * (dX / Z - X * dZ / (Z * Z));
  const double dv = exposure_s * camera.py() * (dY / Z - Y * dZ / (Z * Z));
  const double length = std::min(std::hypot(du, dv), 200.0);
  if (length > effects->motion_blur_px) {
    effects->motion_blur_px = length;
    effects->motion_blur_angle_rad = std::atan2(dv, du);
  }
}

}  // namespace

void SimulatedCameraScene::Check() const {
  lived_in.Check();
  RequireOption(episode_s.lo > 0.0 && episode_s.lo <= episode_s.hi && episode_s.hi <= 3600.0,
                "SimulatedCameraScene::episode_s", episode_s.lo,
                "0 < episode_s[0] <= episode_s[1] <= 3600");
  RequireOption(exposure_s >= 0.0 && exposure_s <= 1.0, "SimulatedCameraScene::exposure_s",
                exposure_s, "0 <= exposure_s <= 1");
  RequireOption(latency_s >= 0.0 && latency_s <= 1.0, "SimulatedCameraScene::latency_s", latency_s,
                "0 <= latency_s <= 1");
}

RenderedFrames::RenderedFrames(const LineTarget& target, const RenderOptions& render,
                               const SimulatedCameraScene& scene)
    : target_(target), scene_((scene.Check(), scene)), renderer_(target, render) {}

int RenderedFrames::EpisodeAt(double time_s) {
  // Each episode's length from its own draw: the same episodes whatever the frames asked.
  while (episode_ends_.empty() || episode_ends_.back() <= time_s) {
    const auto index = static_cast<std::uint64_t>(episode_ends_.size());
    const double uniform = UnitInterval(
        SplitMix64(scene_.seed * 0x9E3779B97F4A7C15ULL + index * 0xBF58476D1CE4E5B9ULL + 1));
    const double length =
        scene_.episode_s.lo + uniform * (scene_.episode_s.hi - scene_.episode_s.lo);
    episode_ends_.push_back((episode_ends_.empty() ? 0.0 : episode_ends_.back()) + length);
  }
  return static_cast<int>(std::upper_bound(episode_ends_.begin(), episode_ends_.end(), time_s) -
                          episode_ends_.begin());
}

bool RenderedFrames::Grab(const Capture& capture, cv::Mat* gray) {
  FrameEffects effects;
  if (scene_.lived_in.Any()) {
    DrawLivedIn(scene_.lived_in, target_, scene_.seed, EpisodeAt(capture.time_s), &effects);
  }
  MotionBlurOf(capture, renderer_.options().camera, scene_.exposure_s, &effects);
  frame_ = renderer_.Render(capture.true_cMo,
                            kNoiseSeed + static_cast<std::uint64_t>(capture.iteration), effects);
  *gray = cv::Mat(static_cast<int>(frame_.image.getHeight()),
                  static_cast<int>(frame_.image.getWidth()), CV_8UC1, frame_.image.bitmap);
  return true;
}

RecordedFrames::RecordedFrames(std::unique_ptr<ImageSource> source) : source_(std::move(source)) {}

bool RecordedFrames::Grab(const Capture& /*capture*/, cv::Mat* gray) {
  if (peeked_ && peeked_error_) {
    // The frame AtEnd() read ahead could not be read: reported here, where it is taken.
    peeked_ = false;
    std::rethrow_exception(std::exchange(peeked_error_, nullptr));
  }
  const bool have_frame = peeked_ ? peeked_frame_ : source_->Next(&frame_);
  peeked_ = false;
  if (!have_frame) return false;
  *gray = frame_.gray;
  taken_s_ = frame_.taken_s;
  return true;
}

bool RecordedFrames::AtEnd() {
  if (!peeked_) {
    try {
      peeked_frame_ = source_->Next(&frame_);
    } catch (const std::exception&) {
      peeked_error_ = std::current_exception();
    }
    peeked_ = true;
  }
  return !peeked_error_ && !peeked_frame_;
}

}  // namespace oal
