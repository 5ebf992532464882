// Lines of a planar target in a calibration view: on the plane and in the image, and the
// homography their crossings give. Shared by the solver (calibrate.cpp) and the sheet's views
// (sheet_view.cpp); not installed.
#pragma once

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "calibration/calibrate.h"

namespace oal::plane_lines {

// A line of a view on the target's plane, with a unit direction.
struct PlaneLine {
  cv::Point2d point, direction;
};

inline PlaneLine OnPlane(const CalibrationLine& line) {
  const double length = std::hypot(line.dx, line.dy);
  return PlaneLine{{line.x, line.y}, {line.dx / length, line.dy / length}};
}

inline cv::Point2d Snap(const PlaneLine& line, const cv::Point2d& q) {
  return line.point + line.direction * (q - line.point).dot(line.direction);
}

// Where two plane lines cross, when they are more than 20 deg apart.
inline std::optional<cv::Point2d> Crossing(const PlaneLine& a, const PlaneLine& b) {
  const double sine = a.direction.cross(b.direction);
  if (std::fabs(sine) < std::sin(20.0 * 3.14159265358979323846 / 180.0)) return std::nullopt;
  const double t = (b.point - a.point).cross(b.direction) / sine;
  return a.point + a.direction * t;
}

// The straight image line through a line's seen points, homogeneous (a, b, c): a u + b v + c = 0.
inline cv::Vec3d ImageLine(const std::vector<Point2d>& seen) {
  std::vector<cv::Point2f> points;
  for (const Point2d& p : seen)
    points.emplace_back(static_cast<float>(p.u), static_cast<float>(p.v));
  cv::Vec4f fit;
  cv::fitLine(points, fit, cv::DIST_L2, 0, 0.01, 0.01);
  return cv::Vec3d(fit[1], -fit[0], fit[0] * fit[3] - fit[1] * fit[2]);
}

// The view's homography from its plane to its image (lens ignored), from its known points and
// the crossings of its lines; empty with fewer than four of them.
inline std::optional<cv::Matx33d> FirstHomography(const CalibrationView& view) {
  std::vector<cv::Point2d> plane, image;
  for (const CalibrationPoint& point : view.points) {
    plane.emplace_back(point.x, point.y);
    image.emplace_back(point.u, point.v);
  }
  for (std::size_t i = 0; i < view.lines.size(); ++i) {
    for (std::size_t j = i + 1; j < view.lines.size(); ++j) {
      const std::optional<cv::Point2d> crossing =
          Crossing(OnPlane(view.lines[i]), OnPlane(view.lines[j]));
      if (!crossing || view.lines[i].seen.size() < 2 || view.lines[j].seen.size() < 2) continue;
      const cv::Vec3d seen = ImageLine(view.lines[i].seen).cross(ImageLine(view.lines[j].seen));
      if (std::fabs(seen[2]) < 1e-12) continue;
      plane.push_back(*crossing);
      image.emplace_back(seen[0] / seen[2], seen[1] / seen[2]);
    }
  }
  if (plane.size() < 4) return std::nullopt;
  const cv::Mat h = cv::findHomography(plane, image, 0);
  if (h.empty()) return std::nullopt;
  return cv::Matx33d(h);
}

}  // namespace oal::plane_lines
