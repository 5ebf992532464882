// The third stage of `oalservo evaluate`'s pipeline (eval/recordings/evaluate.h): each tracked
// frame drawn with its tracks, lines and pose into the annotated video, and the worst frames kept
// as the report's thumbnails.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "eval/recordings/pipeline.h"
#include "eval/recordings/report.h"
#include "io/camera_file.h"
#include "servo/pose.h"

namespace oal {

/// A frame as the tracker left it, on its way to the writer.
struct TrackedFrame {
  int index = 0;
  cv::Mat gray;
  std::vector<DetectedLine> held;  ///< the lines held, best supported first
  std::vector<int> ids;            ///< their track ids
  std::optional<PoseResult> pose;  ///< none without a camera
  double badness = 0.0;            ///< worst frames first (EvaluateInput)
  std::string why;
};

/// The size of the annotated video for a frame: `scale` of it, rounded to even sizes.
cv::Size VideoSize(const cv::Size& frame, double scale);

// The annotated video, written under a temporary name ending in .avi (the writer picks the
// container from it) and renamed at Commit(). The images come at Size(frame size).
class AnnotatedVideo {
 public:
  /// `target`: the .avi to write; `scale`: the video's size relative to the frames; `codec`:
  /// "xvid" or "mjpg" (EvaluateOptions::video_codec); `codec_word`: what the user calls the
  /// codec's option, for the advice when XVID cannot be written.
  AnnotatedVideo(std::filesystem::path target, double scale, std::string codec,
                 std::string codec_word = "video_codec");
  ~AnnotatedVideo();
  AnnotatedVideo(const AnnotatedVideo&) = delete;
  AnnotatedVideo& operator=(const AnnotatedVideo&) = delete;

  cv::Size Size(const cv::Size& frame) const { return VideoSize(frame, scale_); }
  /// Opens the video at the first image's size; throws std::runtime_error when it cannot.
  void Write(const cv::Mat& image);
  /// Renames the video to its target (nothing without a frame).
  void Commit();

 private:
  double scale_;
  std::string codec_;
  std::string codec_word_;
  std::filesystem::path target_, temp_;
  cv::VideoWriter writer_;
  cv::Size size_;
  bool committed_ = false;
};

struct WriterResult {
  std::vector<Thumbnail> thumbnails;
  double busy_us = 0.0;
  double annotate_us = 0.0;   ///< scaling, colour conversion and drawing
  double encode_us = 0.0;     ///< VideoWriter::write (the encoder's colour conversion included)
  double thumbnail_us = 0.0;  ///< the thumbnails' scaling and JPEG encoding
  int annotated = 0;          ///< frames annotated
  std::string error;
};

/// The writer stage: pops tracked frames until the queue closes, draws those the video or the
/// thumbnails need (`video` may be null: thumbnails only) and keeps the `thumbnails` worst.
/// `undistorted_by`: the camera whose undistortion the tracked lines are in. An error is kept
/// in result->error and closes the queue.
/// `viewer`, when set, is shown every frame annotated at its own size with a caption; when it
/// returns false, `*stop` is set (the decoder then ends the input).
void WriteFrames(BoundedQueue<TrackedFrame>* queue, AnnotatedVideo* video, std::size_t thumbnails,
                 const std::optional<CameraFile>& camera, const std::optional<Lens>& undistorted_by,
                 WriterResult* result,
                 const std::function<bool(const cv::Mat&, const std::string&)>& viewer = {},
                 std::atomic<bool>* stop = nullptr);

}  // namespace oal
