#include "eval/rendered/detector_accuracy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "base/angles.h"
#include "base/check.h"
#include "detector/detector.h"
#include "detector/image_view.h"
#include "eval/lines/line_scoring.h"

namespace oal {
namespace {

// Scores the first N `lines` of a frame against its truth and records the result.
void Score(const std::vector<LineParams>& lines, const RenderedFrame& frame, bool undistorted,
           const PointUndistorter& undistorter, const AccuracyOptions& options, int frame_index,
           MethodAccuracy* method) {
  const std::size_t n = std::min(lines.size(), frame.truth.size());
  bool failed = lines.size() < frame.truth.size();
  for (const TruthLine& truth : frame.truth) {
    // Undistorted: the projected centre line, between the undistorted ends of its visible
    // part. Not corrected: the best straight line through the curved image of the centre
    // line, between the feet of the visible ends on it (the curve's own sag is no error of
    // a straight-line detector).
    const LineParams& reference = undistorted ? truth.ideal : truth.distorted_fit;
    const Point2d a =
        undistorted ? undistorter.Undistort(truth.end_a) : Foot(reference, truth.end_a);
    const Point2d b =
        undistorted ? undistorter.Undistort(truth.end_b) : Foot(reference, truth.end_b);
    double best_angle = 90.0, best_offset = 1e6;
    for (std::size_t i = 0; i < n; ++i) {
      const auto [angle, offset] = ErrorOf(lines[i], reference, a, b);
      if (angle / options.max_angle_deg + offset / options.max_offset_px <
          best_angle / options.max_angle_deg + best_offset / options.max_offset_px) {
        best_angle = angle;
        best_offset = offset;
      }
    }
    method->angle_error_deg.push_back(best_angle);
    method->offset_error_px.push_back(best_offset);
    failed |= best_angle > options.max_angle_deg || best_offset > options.max_offset_px;
  }
  ++method->frames;
  if (failed) {
    ++method->failed_frames;
    method->failed_frame_indices.push_back(frame_index);
  }
}

// OpenCV's HoughLines on the Otsu-thresholded image (line pixels vote, so the peaks are the
// stripes' centre lines), with the same near-duplicate suppression as our read-off.
std::vector<LineParams> OpenCvHough(const vpImage<unsigned char>& image,
                                    const DetectorOptions& detector) {
  const cv::Mat view(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()),
                     CV_8UC1, const_cast<unsigned char*>(image.bitmap));
  cv::Mat binary;
  cv::threshold(view, binary, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
  std::vector<cv::Vec3f> found;  // rho, theta, votes; sorted by votes
  cv::HoughLines(binary, found, 1.0, CV_PI / 360.0, 80);
  std::vector<LineParams> lines;
  for (const cv::Vec3f& line : found) {
    const LineParams candidate = Normalized(line[0], line[1]);
    const bool duplicate = std::any_of(lines.begin(), lines.end(), [&](const LineParams& kept) {
      return AngleBetween(kept, candidate) * kDegPerRad <= detector.duplicate_angle_deg &&
             std::fabs(RhoAlignedTo(kept, candidate) - kept.rho_px) <= detector.duplicate_r_px;
    });
    if (!duplicate) lines.push_back(candidate);
    if (static_cast<int>(lines.size()) >= detector.max_output_lines) break;
  }
  return lines;
}

// One of our detector configurations.
struct OalMethod {
  MethodAccuracy result;
  OalDetector detector;
  bool undistorted;
};

}  // namespace

void AccuracyOptions::Check() const {
  RenderedFrameOptions::Check();
  RequireOption(max_angle_deg > 0.0, "AccuracyOptions::max_angle_deg", max_angle_deg,
                "max_angle_deg > 0");
  RequireOption(max_offset_px > 0.0, "AccuracyOptions::max_offset_px", max_offset_px,
                "max_offset_px > 0");
  detector.Check();
  tracking.Check();
  sampling.Check();
  target.Check();
}

AccuracyReport EvaluateDetectorAccuracy(const AccuracyOptions& options,
                                        const std::function<void(int, int)>& progress) {
  options.Check();
  const RenderOptions render = MakeRenderOptions(options);
  const EvaluationScenes scenes(options.target, options);
  const PointUndistorter undistorter(render.camera);

  auto named = [](const char* name, const char* reference) {
    MethodAccuracy result;
    result.name = name;
    result.reference = reference;
    return result;
  };
  std::vector<OalMethod> ours;
  ours.push_back({named("oal, points undistorted", "ideal"),
                  OalDetector(options.detector, render.camera), true});
  ours.push_back({named("oal, distortion not corrected", "distorted fit"),
                  OalDetector(options.detector), false});
  ours.push_back({named("paper's algorithm, points undistorted", "ideal"),
                  OalDetector(DetectorOptions::Paper(), render.camera), true});
  ours.push_back({named("paper's algorithm (as published)", "distorted fit"),
                  OalDetector(DetectorOptions::Paper()), false});
  MethodAccuracy opencv = named("OpenCV HoughLines (Otsu binary)", "distorted fit");
  // The tracker's pose is not needed: only its lines are scored.
  std::optional<TargetPoseTracker> tracker;
  MethodAccuracy tracked =
      named("oal, target tracker (borders on the target; time with the pose)", "ideal");
  if (options.target.lines.size() == 4) {
    PoseOptions pose;
    pose.compute_covariance = false;
    tracker.emplace(options.target, render.camera, options.detector, pose, options.tracking);
  }

  std::uint64_t state = options.seed;
  std::vector<LineParams> lines;
  const int end = options.first_frame + options.frames;
  for (int frame = 0; frame < end; ++frame) {
    const SceneRenderer& renderer = scenes.For(frame);
    const vpHomogeneousMatrix cMo = SamplePose(renderer, options.sampling, &state);
    if (frame < options.first_frame) continue;
    const RenderedFrame rendered =
        renderer.Render(cMo, options.seed * 1000003ULL + frame, scenes.EffectsFor(frame));
    for (OalMethod& method : ours) {
      const auto start = std::chrono::steady_clock::now();
      const auto& detected = method.detector.Detect(rendered.image);
      const auto stop = std::chrono::steady_clock::now();
      method.result.time_us.push_back(
          std::chrono::duration<double, std::micro>(stop - start).count());
      lines.clear();
      for (const DetectedLine& line : detected) lines.push_back(line.line);
      Score(lines, rendered, method.undistorted, undistorter, options, frame, &method.result);
    }
    const auto start = std::chrono::steady_clock::now();
    lines = OpenCvHough(rendered.image, options.detector);
    const auto stop = std::chrono::steady_clock::now();
    opencv.time_us.push_back(std::chrono::duration<double, std::micro>(stop - start).count());
    Score(lines, rendered, false, undistorter, options, frame, &opencv);
    if (tracker) {
      tracker->Reset();
      const auto tracker_start = std::chrono::steady_clock::now();
      tracker->Track(ViewOf(rendered.image));
      tracked.time_us.push_back(std::chrono::duration<double, std::micro>(
                                    std::chrono::steady_clock::now() - tracker_start)
                                    .count());
      lines.clear();
      for (const DetectedLine& line : tracker->lines()) lines.push_back(line.line);
      Score(lines, rendered, true, undistorter, options, frame, &tracked);
    }
    if (progress) progress(frame + 1 - options.first_frame, options.frames);
  }

  AccuracyReport report;
  report.options = options;
  for (OalMethod& method : ours) report.methods.push_back(std::move(method.result));
  report.methods.push_back(std::move(opencv));
  if (tracker) report.methods.push_back(std::move(tracked));
  return report;
}

}  // namespace oal
