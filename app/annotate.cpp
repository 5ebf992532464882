#include "app/annotate.h"

#include <visp3/core/vpMeterPixelConversion.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "detector/lens.h"
#include "scene/scene.h"

namespace oal {
namespace {

constexpr double kAxisLengthM = 0.05;  // drawn target frame axes

constexpr int kShift = 4;  // cv::polylines sub-pixel bits: coordinates in 1/16 px
constexpr double kSampleStepPx = 3.0;

// The box that holds the undistorted image of the frame (larger than the frame for barrel
// distortion), from its outline sampled every few pixels.
cv::Rect2d UndistortedBounds(int width, int height, const vpCameraParameters& camera) {
  const PointUndistorter undistorter(camera);
  double u0 = 0, v0 = 0, u1 = width - 1, v1 = height - 1;
  auto extend = [&](double u, double v) {
    const Point2d p = undistorter.Undistort(Point2d{u, v});
    u0 = std::min(u0, p.u), u1 = std::max(u1, p.u), v0 = std::min(v0, p.v), v1 = std::max(v1, p.v);
  };
  for (int u = 0; u < width; u += 4) extend(u, 0), extend(u, height - 1);
  for (int v = 0; v < height; v += 4) extend(0, v), extend(width - 1, v);
  extend(width - 1, height - 1);
  return cv::Rect2d(u0, v0, u1 - u0, v1 - v0);
}

bool Inside(const cv::Point2d& p, int width, int height) {
  return p.x >= -0.5 && p.y >= -0.5 && p.x <= width - 0.5 && p.y <= height - 0.5;
}

std::vector<std::vector<cv::Point2d>> CurvedLine(const LineParams& line, int width, int height,
                                                 const vpCameraParameters& camera) {
  const cv::Rect2d box = UndistortedBounds(width, height, camera);
  Point2d a, b;
  if (!ClipToRect(line, box.x, box.y, box.x + box.width, box.y + box.height, &a, &b)) return {};
  const double length = std::hypot(b.u - a.u, b.v - a.v);
  const int samples = std::max(2, static_cast<int>(std::ceil(length / kSampleStepPx)) + 1);
  std::vector<std::vector<cv::Point2d>> runs(1);
  for (int i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / (samples - 1);
    const double u = a.u + t * (b.u - a.u), v = a.v + t * (b.v - a.v);
    const Point2d d = DistortedPixel(camera, (u - camera.get_u0()) / camera.get_px(),
                                     (v - camera.get_v0()) / camera.get_py());
    const cv::Point2d p(d.u, d.v);
    if (Inside(p, width, height)) {
      runs.back().push_back(p);
    } else if (!runs.back().empty()) {
      runs.emplace_back();
    }
  }
  runs.erase(
      std::remove_if(runs.begin(), runs.end(), [](const auto& run) { return run.size() < 2; }),
      runs.end());
  return runs;
}

cv::Scalar ColourOf(std::size_t index) {
  static const cv::Scalar kPalette[] = {
      {0, 0, 255},   {0, 200, 0},   {255, 80, 0},  {0, 200, 255},
      {255, 0, 200}, {255, 255, 0}, {0, 128, 255}, {160, 0, 255},
  };
  return kPalette[index % (sizeof(kPalette) / sizeof(kPalette[0]))];
}

std::vector<cv::Point> Fixed(const std::vector<cv::Point2d>& run) {
  std::vector<cv::Point> points;
  points.reserve(run.size());
  for (const cv::Point2d& p : run) {
    points.emplace_back(cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift)));
  }
  return points;
}

void DrawLabel(cv::Mat& image, const std::string& text, const cv::Point2d& at,
               const cv::Scalar& colour) {
  const cv::Point origin(cvRound(at.x) + 4, cvRound(at.y) - 4);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
}

// Pixel of the normalised point (x, y) in the frame: through the kdu model (the exact inverse
// of the detector's undistortion, as LineInFrame draws lines) when the camera has
// distortion, else vpMeterPixelConversion.
cv::Point2d FramePixel(const vpCameraParameters& camera, double x, double y) {
  if (camera.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion &&
      camera.get_kdu() != 0.0) {
    const Point2d p = DistortedPixel(camera, x, y);
    return cv::Point2d(p.u, p.v);
  }
  double u = 0.0, v = 0.0;
  vpMeterPixelConversion::convertPoint(camera, x, y, u, v);
  return cv::Point2d(u, v);
}

void DrawText(cv::Mat& image, const std::string& text, const cv::Point& origin,
              const cv::Scalar& colour, double scale) {
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

}  // namespace

std::vector<std::vector<cv::Point2d>> LineInFrame(
    const LineParams& line, int width, int height,
    const std::optional<vpCameraParameters>& undistorted_by) {
  if (undistorted_by) return CurvedLine(line, width, height, *undistorted_by);
  Point2d a, b;
  if (!ClipToRect(line, 0.0, 0.0, width - 1.0, height - 1.0, &a, &b)) return {};
  return {{cv::Point2d(a.u, a.v), cv::Point2d(b.u, b.v)}};
}

cv::Mat AnnotateLines(const cv::Mat& frame, const std::vector<DetectedLine>& lines,
                      const std::optional<vpCameraParameters>& undistorted_by) {
  cv::Mat image;
  if (frame.channels() == 1) {
    cv::cvtColor(frame, image, cv::COLOR_GRAY2BGR);
  } else {
    image = frame.clone();
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto runs = LineInFrame(lines[i].line, frame.cols, frame.rows, undistorted_by);
    std::vector<std::vector<cv::Point>> polylines;
    for (const auto& run : runs) polylines.push_back(Fixed(run));
    cv::polylines(image, polylines, false, ColourOf(i), 2, cv::LINE_AA, kShift);
    if (runs.empty()) continue;
    const auto& longest = *std::max_element(
        runs.begin(), runs.end(), [](const auto& x, const auto& y) { return x.size() < y.size(); });
    DrawLabel(image, std::to_string(i), longest[longest.size() / 2], ColourOf(i));
  }
  return image;
}

// The frame with the identified lines labelled 1-4, the corners, the target frame's axes
// (x red, y green, z blue, kAxisLengthM long) when the pose is ok, and the status.
cv::Mat AnnotatePose(const cv::Mat& gray, const std::vector<DetectedLine>& lines,
                     const PoseResult& pose, const vpCameraParameters& camera,
                     const std::optional<vpCameraParameters>& undistorted_by,
                     const std::vector<Point2d>& region) {
  static const cv::Scalar kLineColours[4] = {
      {0, 200, 255}, {255, 0, 200}, {255, 255, 0}, {0, 128, 255}};
  cv::Mat image;
  cv::cvtColor(gray, image, cv::COLOR_GRAY2BGR);
  const int w = gray.cols, h = gray.rows;
  if (region.size() >= 3) {  // the outermost border scanned, thin
    std::vector<cv::Point2d> outline;
    for (const Point2d& p : region) outline.emplace_back(p.u, p.v);
    const std::vector<std::vector<cv::Point>> polygon = {Fixed(outline)};
    cv::polylines(image, polygon, true, cv::Scalar(120, 200, 120), 1, cv::LINE_AA, kShift);
  }
  for (int k = 0; k < 4; ++k) {
    const int index = pose.line_index[k];
    if (index < 0 || index >= static_cast<int>(lines.size())) continue;
    const auto runs = LineInFrame(lines[index].line, w, h, undistorted_by);
    for (const auto& run : runs) {
      for (std::size_t i = 1; i < run.size(); ++i) {
        cv::line(image, run[i - 1], run[i], kLineColours[k], 2, cv::LINE_AA);
      }
    }
    if (runs.empty() || runs.front().empty()) continue;
    const auto& run = runs.front();
    const cv::Point2d at = run[run.size() / 3];
    DrawText(image, std::to_string(k + 1), cv::Point(cvRound(at.x) + 4, cvRound(at.y) - 4),
             kLineColours[k], 0.5);
  }
  const bool ok = pose.status == PoseStatus::kOk;
  if (ok) {
    for (const vpColVector& corner : pose.corners_m) {
      cv::circle(image, FramePixel(camera, corner[0], corner[1]), 3, cv::Scalar(255, 255, 255), 1,
                 cv::LINE_AA);
    }
    // Object origin and axis ends in the camera frame, projected.
    auto project = [&](double x, double y, double z) {
      vpColVector o(4);
      o[0] = x, o[1] = y, o[2] = z, o[3] = 1.0;
      const vpColVector c = pose.cMo * o;
      return FramePixel(camera, c[0] / c[2], c[1] / c[2]);
    };
    const cv::Point2d origin = project(0.0, 0.0, 0.0);
    const std::array<cv::Point2d, 3> ends = {project(kAxisLengthM, 0.0, 0.0),
                                             project(0.0, kAxisLengthM, 0.0),
                                             project(0.0, 0.0, kAxisLengthM)};
    const cv::Scalar kAxisColours[3] = {{0, 0, 255}, {0, 200, 0}, {255, 80, 0}};
    for (int a = 0; a < 3; ++a) {
      if (std::isfinite(ends[a].x) && std::isfinite(ends[a].y) && std::isfinite(origin.x) &&
          std::isfinite(origin.y)) {
        cv::arrowedLine(image, origin, ends[a], kAxisColours[a], 2, cv::LINE_AA, 0, 0.15);
      }
    }
  }
  DrawText(image, ToString(pose.status), cv::Point(4, 16),
           ok ? cv::Scalar(0, 220, 0) : cv::Scalar(0, 0, 255), 0.45);
  return image;
}

}  // namespace oal
