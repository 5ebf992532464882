#include "io/annotate.h"

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
cv::Rect2d UndistortedBounds(int width, int height, const Lens& camera) {
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
                                                 const Lens& camera) {
  const cv::Rect2d box = UndistortedBounds(width, height, camera);
  Point2d a, b;
  if (!ClipToRect(line, box.x, box.y, box.x + box.width, box.y + box.height, &a, &b)) return {};
  const double length = std::hypot(b.u - a.u, b.v - a.v);
  const int samples = std::max(2, static_cast<int>(std::ceil(length / kSampleStepPx)) + 1);
  std::vector<std::vector<cv::Point2d>> runs(1);
  for (int i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / (samples - 1);
    const double u = a.u + t * (b.u - a.u), v = a.v + t * (b.v - a.v);
    const Point2d d =
        camera.Pixel((u - camera.u0()) / camera.px(), (v - camera.v0()) / camera.py());
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
cv::Point2d FramePixel(const Lens& camera, double x, double y) {
  const Point2d p = camera.Pixel(x, y);
  return cv::Point2d(p.u, p.v);
}

void DrawText(cv::Mat& image, const std::string& text, const cv::Point& origin,
              const cv::Scalar& colour, double scale) {
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// Where the labels of lines 1-4 keep away from: the target's crossings, as their centre and
// the radius that holds them (else the image's centre, and no radius).
struct LabelAnchor {
  cv::Point2d centre;
  double radius_px = 0.0;
};

LabelAnchor AnchorOf(const PoseResult& pose, const Lens& camera, int width, int height) {
  std::vector<cv::Point2d> corners;
  for (const vpColVector& corner : pose.corners_m) {
    if (corner.size() < 2) continue;
    const cv::Point2d p = FramePixel(camera, corner[0], corner[1]);
    if (std::isfinite(p.x) && std::isfinite(p.y)) corners.push_back(p);
  }
  if (corners.size() != 4) return {cv::Point2d(0.5 * (width - 1), 0.5 * (height - 1)), 0.0};
  LabelAnchor anchor{(corners[0] + corners[1] + corners[2] + corners[3]) / 4.0, 0.0};
  for (const cv::Point2d& p : corners) {
    anchor.radius_px = std::max(anchor.radius_px, cv::norm(p - anchor.centre));
  }
  return anchor;
}

// A point of the drawn line for its label: along it from where it passes nearest the
// crossings' centre, past the crossings (beyond the anchor's radius, not on them), inside the
// image and clear of the status text at its top and bottom edges.
cv::Point2d LabelPoint(const std::vector<cv::Point2d>& drawn, const LabelAnchor& anchor, int width,
                       int height) {
  const double label_offset_px = anchor.radius_px + 25.0;
  // A straight line is drawn from its two ends: points every few pixels to walk along.
  std::vector<cv::Point2d> run = {drawn.front()};
  for (std::size_t i = 1; i < drawn.size(); ++i) {
    const int steps = std::max(1, static_cast<int>(cv::norm(drawn[i] - drawn[i - 1]) / 4.0));
    for (int j = 1; j <= steps; ++j) {
      run.push_back(drawn[i - 1] + (drawn[i] - drawn[i - 1]) * (static_cast<double>(j) / steps));
    }
  }
  constexpr double kTopPx = 28.0, kBottomPx = 34.0, kSidePx = 12.0;
  const auto usable = [&](const cv::Point2d& p) {
    return p.x >= kSidePx && p.x <= width - 1 - kSidePx - 10.0 && p.y >= kTopPx &&
           p.y <= height - 1 - kBottomPx;
  };
  std::size_t nearest = 0;
  for (std::size_t i = 1; i < run.size(); ++i) {
    if (cv::norm(run[i] - anchor.centre) < cv::norm(run[nearest] - anchor.centre)) nearest = i;
  }
  // Walk both ways from the nearest point; the first side to reach the offset inside the
  // usable part of the image wins, else the farthest usable point seen.
  cv::Point2d best = run[nearest];
  double best_walked = -1.0;
  for (const int step : {1, -1}) {
    double walked = 0.0;
    for (std::size_t i = nearest; i + step < run.size() && (step > 0 || i > 0);) {
      const std::size_t next = static_cast<std::size_t>(static_cast<long>(i) + step);
      walked += cv::norm(run[next] - run[i]);
      i = next;
      if (!usable(run[i])) break;
      if (walked > best_walked) {
        best = run[i];
        best_walked = walked;
      }
      if (walked >= label_offset_px) return run[i];
    }
  }
  return best;
}

}  // namespace

std::vector<std::vector<cv::Point2d>> LineInFrame(const LineParams& line, int width, int height,
                                                  const std::optional<Lens>& undistorted_by) {
  if (undistorted_by) return CurvedLine(line, width, height, *undistorted_by);
  Point2d a, b;
  if (!ClipToRect(line, 0.0, 0.0, width - 1.0, height - 1.0, &a, &b)) return {};
  return {{cv::Point2d(a.u, a.v), cv::Point2d(b.u, b.v)}};
}

cv::Mat AnnotateLines(const cv::Mat& frame, const std::vector<DetectedLine>& lines,
                      const std::optional<Lens>& undistorted_by) {
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

// Target lines 1-4, in every drawing of them (BGR).
const cv::Scalar kLineColours[4] = {{0, 200, 255}, {255, 0, 200}, {255, 255, 0}, {0, 128, 255}};

// The frame with the identified lines labelled 1-4, the corners, the target frame's axes
// (x red, y green, z blue, kAxisLengthM long) when the pose is ok, and the status.
cv::Mat AnnotatePose(const cv::Mat& gray, const std::vector<DetectedLine>& lines,
                     const PoseResult& pose, const Lens& camera,
                     const std::optional<Lens>& undistorted_by,
                     const std::vector<Point2d>& region) {
  cv::Mat image;
  cv::cvtColor(gray, image, cv::COLOR_GRAY2BGR);
  const int w = gray.cols, h = gray.rows;
  if (region.size() >= 3) {  // the outermost border scanned, thin
    std::vector<cv::Point2d> outline;
    for (const Point2d& p : region) outline.emplace_back(p.u, p.v);
    const std::vector<std::vector<cv::Point>> polygon = {Fixed(outline)};
    cv::polylines(image, polygon, true, cv::Scalar(120, 200, 120), 1, cv::LINE_AA, kShift);
  }
  const LabelAnchor anchor = AnchorOf(pose, camera, w, h);
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
    const cv::Point2d at = LabelPoint(runs.front(), anchor, w, h);
    DrawText(image, std::to_string(k + 1), cv::Point(cvRound(at.x) + 5, cvRound(at.y) - 5),
             kLineColours[k], 0.6);
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

void DrawGoalLines(cv::Mat* image, const LineTarget& target, const vpHomogeneousMatrix& cdMo,
                   const Lens& camera) {
  constexpr double kDashPx = 8.0;
  for (std::size_t k = 0; k < target.lines.size() && k < 4; ++k) {
    const TargetLine& line = target.lines[k];
    // The printed centre line seen from the goal, through the lens, in short steps: dashes.
    auto pixel_at = [&](double t) {
      vpColVector o(4);
      o[0] = line.x1_m + t * (line.x2_m - line.x1_m);
      o[1] = line.y1_m + t * (line.y2_m - line.y1_m);
      o[2] = 0.0;
      o[3] = 1.0;
      const vpColVector c = cdMo * o;
      if (!(c[2] > 1e-6)) return cv::Point2d(NAN, NAN);
      return FramePixel(camera, c[0] / c[2], c[1] / c[2]);
    };
    const cv::Point2d a = pixel_at(0.0), b = pixel_at(1.0);
    if (!std::isfinite(a.x) || !std::isfinite(b.x)) continue;
    const int steps = std::clamp(static_cast<int>(cv::norm(b - a) / kDashPx), 2, 2000);
    cv::Point2d previous = a;
    for (int i = 1; i <= steps; ++i) {
      const cv::Point2d next = pixel_at(static_cast<double>(i) / steps);
      if (i % 2 == 1 && std::isfinite(next.x) && std::isfinite(previous.x)) {
        cv::line(*image, previous, next, kLineColours[k], 1, cv::LINE_AA);
      }
      previous = next;
    }
  }
}

}  // namespace oal
