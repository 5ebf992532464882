#include "eval/recordings/annotated_output.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "detector/lens.h"
#include "io/annotate.h"
#include "io/atomic_file.h"

namespace oal {
namespace {

constexpr int kThumbnailWidth = 320;
constexpr double kVideoFps = 25.0;
constexpr double kVideoQuality = 75.0;  // JPEG quality of the MJPG video, [0, 100]

// The `capacity` worst frames, at least kThumbnailSpacingFrames frames apart, chosen as frames
// stream by: the same frames in the same order give the same choice.
class WorstFrames {
 public:
  explicit WorstFrames(std::size_t capacity) : capacity_(capacity) {}

  bool Wants(int frame, double badness) const {
    if (capacity_ == 0 || badness <= 0.0) return false;
    double near = -1.0;
    for (const Thumbnail& kept : kept_) {
      if (std::abs(kept.frame - frame) < kThumbnailSpacingFrames) {
        near = std::max(near, badness_.at(kept.frame));
      }
    }
    if (near >= 0.0) return badness > near;
    return kept_.size() < capacity_ || badness > Weakest()->second;
  }
  void Add(Thumbnail thumbnail, double badness) {
    const int frame = thumbnail.frame;
    kept_.erase(std::remove_if(kept_.begin(), kept_.end(),
                               [&](const Thumbnail& kept) {
                                 return std::abs(kept.frame - frame) < kThumbnailSpacingFrames;
                               }),
                kept_.end());
    if (kept_.size() >= capacity_) {
      const int weakest = Weakest()->first;
      kept_.erase(std::remove_if(kept_.begin(), kept_.end(),
                                 [&](const Thumbnail& kept) { return kept.frame == weakest; }),
                  kept_.end());
    }
    badness_[frame] = badness;
    kept_.push_back(std::move(thumbnail));
  }
  /// Worst first (ties: earlier frame first).
  std::vector<Thumbnail> Sorted() const {
    std::vector<Thumbnail> sorted = kept_;
    std::sort(sorted.begin(), sorted.end(), [&](const Thumbnail& a, const Thumbnail& b) {
      const double ba = badness_.at(a.frame), bb = badness_.at(b.frame);
      return ba != bb ? ba > bb : a.frame < b.frame;
    });
    return sorted;
  }
  double BadnessOf(int frame) const { return badness_.at(frame); }

 private:
  // The kept frame with the least badness (the latest of equals), as (frame, badness).
  std::optional<std::pair<int, double>> Weakest() const {
    std::optional<std::pair<int, double>> weakest;
    for (const Thumbnail& kept : kept_) {
      const double b = badness_.at(kept.frame);
      if (!weakest || b < weakest->second ||
          (b == weakest->second && kept.frame > weakest->first)) {
        weakest = std::make_pair(kept.frame, b);
      }
    }
    return weakest;
  }

  std::size_t capacity_;
  std::vector<Thumbnail> kept_;
  std::map<int, double> badness_;
};

const cv::Scalar kTrackColours[] = {{80, 80, 255},  {80, 255, 80},  {255, 160, 80}, {255, 80, 255},
                                    {80, 255, 255}, {255, 255, 80}, {160, 80, 255}, {80, 160, 255}};

// Pixel coordinates of a frame scaled by (sx, sy): pixel centres at integers on both sides,
// u' = sx (u + 0.5) - 0.5. Lines and cameras are moved into the scaled frame so that the
// drawing is done at the output size (a quarter of the pixels at 0.5), not drawn at full
// size and scaled.
struct PixelScale {
  double sx = 1.0, sy = 1.0;

  // u cos + v sin = rho  ->  a u' + b v' = rho + (cos + sin) / 2 - (a + b) / 2.
  LineParams Line(const LineParams& line) const {
    const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
    const double a = c / sx, b = s / sy, n = std::hypot(a, b);
    return LineParams{(line.rho_px + 0.5 * (c + s) - 0.5 * (a + b)) / n, std::atan2(b, a)};
  }
  // The distortion coefficients are in normalised coordinates: unchanged.
  Lens Camera(const Lens& camera) const {
    const double u0 = sx * (camera.u0() + 0.5) - 0.5, v0 = sy * (camera.v0() + 0.5) - 0.5;
    return camera.WithIntrinsics(sx * camera.px(), sy * camera.py(), u0, v0);
  }
};

// The frame at `size` with every held track (thin, labelled #id), lines 1-4 and the target
// frame's axes (AnnotatePose), and the frame number, drawn at that size.
cv::Mat Annotate(const TrackedFrame& frame, const std::optional<CameraFile>& camera,
                 const std::optional<Lens>& undistorted_by, const cv::Size& size) {
  const bool scaled = size != frame.gray.size();
  const PixelScale scale{static_cast<double>(size.width) / frame.gray.cols,
                         static_cast<double>(size.height) / frame.gray.rows};
  cv::Mat gray = frame.gray;
  std::vector<DetectedLine> held = frame.held;
  std::optional<Lens> undistorted = undistorted_by;
  if (scaled) {
    cv::resize(frame.gray, gray, size, 0.0, 0.0, cv::INTER_AREA);
    for (DetectedLine& line : held) line.line = scale.Line(line.line);
    if (undistorted) undistorted = scale.Camera(*undistorted);
  }
  cv::Mat image;
  if (camera && frame.pose) {
    image = AnnotatePose(gray, held, *frame.pose,
                         scaled ? scale.Camera(camera->camera) : camera->camera, undistorted);
  } else {
    cv::cvtColor(gray, image, cv::COLOR_GRAY2BGR);
  }
  for (std::size_t i = 0; i < held.size(); ++i) {
    const cv::Scalar& colour = kTrackColours[static_cast<std::size_t>(frame.ids[i]) % 8];
    const auto runs = LineInFrame(held[i].line, image.cols, image.rows, undistorted);
    for (const auto& run : runs) {
      for (std::size_t k = 1; k < run.size(); ++k) {
        cv::line(image, run[k - 1], run[k], colour, 1, cv::LINE_AA);
      }
    }
    if (runs.empty() || runs.front().empty()) continue;
    const cv::Point2d at = runs.front()[runs.front().size() * 2 / 3];
    cv::putText(image, "#" + std::to_string(frame.ids[i]),
                cv::Point(cvRound(at.x) + 3, cvRound(at.y) + 12), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                colour, 1, cv::LINE_AA);
  }
  // White on a black outline: readable on a bright frame as on a dark one.
  const cv::Point caption(4, image.rows - 6);
  const std::string text = "frame " + std::to_string(frame.index);
  cv::putText(image, text, caption, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, caption, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return image;
}

// The thumbnail's size: kThumbnailWidth wide at most.
cv::Size ThumbnailSize(const cv::Size& image) {
  const double scale = std::min(1.0, static_cast<double>(kThumbnailWidth) / image.width);
  return cv::Size(std::max(1, cvRound(scale * image.width)),
                  std::max(1, cvRound(scale * image.height)));
}

std::vector<unsigned char> ThumbnailJpeg(const cv::Mat& annotated) {
  cv::Mat small = annotated;
  const cv::Size size = ThumbnailSize(annotated.size());
  if (size != annotated.size()) cv::resize(annotated, small, size, 0.0, 0.0, cv::INTER_AREA);
  std::vector<unsigned char> jpeg;
  if (!cv::imencode(".jpg", small, jpeg, {cv::IMWRITE_JPEG_QUALITY, 85})) {
    throw std::runtime_error("cannot encode a thumbnail");
  }
  return jpeg;
}

}  // namespace

cv::Size VideoSize(const cv::Size& frame, double scale) {
  return cv::Size(std::max(2, 2 * cvRound(0.5 * scale * frame.width)),
                  std::max(2, 2 * cvRound(0.5 * scale * frame.height)));
}

AnnotatedVideo::AnnotatedVideo(std::filesystem::path target, double scale, std::string codec,
                               std::string codec_word)
    : scale_(scale),
      codec_(std::move(codec)),
      codec_word_(std::move(codec_word)),
      target_(std::move(target)),
      temp_(target_.parent_path() /
            (target_.stem().string() + ".tmp-" + std::to_string(::getpid()) + ".avi")) {}

AnnotatedVideo::~AnnotatedVideo() {
  writer_.release();
  if (!committed_) RemoveQuietly(temp_);
}

void AnnotatedVideo::Write(const cv::Mat& image) {
  if (!writer_.isOpened()) {
    // XVID: libavcodec's MPEG-4 part 2 encoder (OpenCV's FFmpeg backend), ~3x faster than
    // MJPG on noisy frames and ~5x smaller; MJPG: OpenCV's own encoder, every frame a
    // key frame (docs/EVALUATE.md, figures).
    const bool xvid = codec_ == "xvid";
    const bool opened = xvid ? writer_.open(temp_.string(), cv::CAP_FFMPEG,
                                            cv::VideoWriter::fourcc('X', 'V', 'I', 'D'), kVideoFps,
                                            image.size(), true)
                             : writer_.open(temp_.string(), cv::CAP_OPENCV_MJPEG,
                                            cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), kVideoFps,
                                            image.size(), true);
    if (!opened) {
      throw std::runtime_error(
          "cannot write the video " + temp_.string() +
          (xvid ? " with XVID (OpenCV's FFmpeg backend); try " + codec_word_ + " mjpg"
                : std::string()));
    }
    if (!xvid) writer_.set(cv::VIDEOWRITER_PROP_QUALITY, kVideoQuality);
    size_ = image.size();
  }
  if (image.size() == size_) {
    writer_.write(image);
  } else {  // a sequence whose images change size: the video keeps the first one's
    cv::Mat resized;
    cv::resize(image, resized, size_, 0.0, 0.0, cv::INTER_AREA);
    writer_.write(resized);
  }
}

void AnnotatedVideo::Commit() {
  if (!writer_.isOpened()) return;  // no frame
  writer_.release();
  std::filesystem::rename(temp_, target_);
  committed_ = true;
}

void WriteFrames(BoundedQueue<TrackedFrame>* queue, AnnotatedVideo* video, std::size_t thumbnails,
                 const std::optional<CameraFile>& camera, const std::optional<Lens>& undistorted_by,
                 WriterResult* result,
                 const std::function<bool(const cv::Mat&, const std::string&)>& viewer,
                 std::atomic<bool>* stop) {
  WorstFrames worst(thumbnails);
  try {
    while (std::optional<TrackedFrame> frame = queue->Pop()) {
      if (viewer && !(stop != nullptr && stop->load())) {
        const std::string caption =
            "frame " + std::to_string(frame->index) + (frame->why.empty() ? "" : ": " + frame->why);
        if (!viewer(Annotate(*frame, camera, undistorted_by, frame->gray.size()), caption) &&
            stop != nullptr) {
          stop->store(true);
        }
      }
      const StageClock::time_point start = StageClock::now();
      const bool wanted = worst.Wants(frame->index, frame->badness);
      if (video != nullptr || wanted) {
        // Drawn at the video's size, or at the thumbnail's without a video.
        const cv::Size size =
            video != nullptr ? video->Size(frame->gray.size()) : ThumbnailSize(frame->gray.size());
        const cv::Mat annotated = Annotate(*frame, camera, undistorted_by, size);
        ++result->annotated;
        const StageClock::time_point drawn = StageClock::now();
        result->annotate_us += Microseconds(drawn - start);
        if (video != nullptr) video->Write(annotated);
        const StageClock::time_point encoded = StageClock::now();
        result->encode_us += Microseconds(encoded - drawn);
        if (wanted) {
          worst.Add({frame->index, frame->why, ThumbnailJpeg(annotated)}, frame->badness);
          result->thumbnail_us += Microseconds(StageClock::now() - encoded);
        }
      }
      result->busy_us += Microseconds(StageClock::now() - start);
    }
  } catch (const std::exception& error) {
    result->error = error.what();
    queue->Close();
  }
  result->thumbnails = worst.Sorted();
}

}  // namespace oal
