#include "calibration/view_selector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "base/check.h"
#include "calibration/plane_lines.h"

namespace oal {
namespace {

// How far each corner of `b` lies from the same corner of `a`, pixels.
std::array<double, 4> CornerDistances(const std::array<Point2d, 4>& a,
                                      const std::array<Point2d, 4>& b) {
  std::array<double, 4> distances{};
  for (std::size_t k = 0; k < a.size(); ++k) {
    distances[k] = std::hypot(a[k].u - b[k].u, a[k].v - b[k].v);
  }
  return distances;
}

}  // namespace

void ViewSelectorOptions::Check() const {
  RequireOption(still_frames >= 1 && still_frames <= 1000, "ViewSelectorOptions::still_frames",
                still_frames, "1 <= still_frames <= 1000");
  RequireOption(still_px > 0.0 && still_px <= 100.0, "ViewSelectorOptions::still_px", still_px,
                "0 < still_px <= 100");
  RequireOption(min_difference >= 0.0 && min_difference <= 1.0,
                "ViewSelectorOptions::min_difference", min_difference, "0 <= min_difference <= 1");
}

std::optional<std::array<Point2d, 4>> TargetOutline(const CalibrationView& view) {
  const std::optional<cv::Matx33d> plane_to_image = plane_lines::FirstHomography(view);
  if (!plane_to_image) return std::nullopt;
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  const auto extend = [&](double x, double y) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  };
  for (const CalibrationPoint& point : view.points) extend(point.x, point.y);
  for (const CalibrationLine& line : view.lines) {
    extend(line.x, line.y);
    extend(line.x + line.dx, line.y + line.dy);
  }
  std::array<Point2d, 4> outline;
  const std::array<cv::Vec3d, 4> corners = {cv::Vec3d(x0, y0, 1.0), cv::Vec3d(x1, y0, 1.0),
                                            cv::Vec3d(x1, y1, 1.0), cv::Vec3d(x0, y1, 1.0)};
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const cv::Vec3d h = *plane_to_image * corners[k];
    if (std::fabs(h[2]) < 1e-12) return std::nullopt;
    outline[k] = Point2d{h[0] / h[2], h[1] / h[2]};
  }
  return outline;
}

ViewSelector::ViewSelector(int width, int height, const ViewSelectorOptions& options)
    : diagonal_(std::hypot(width, height)), options_(options) {
  options_.Check();
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("ViewSelector: the image size must be positive");
  }
}

ViewSelector::Verdict ViewSelector::Offer(const CalibrationView& view) {
  const std::optional<std::array<Point2d, 4>> outline = TargetOutline(view);
  similar_to_ = -1;
  if (!outline) {
    last_.reset();
    still_for_ = 0;
    return Verdict::kNoTarget;
  }
  const auto largest_motion = [&] {
    const std::array<double, 4> moved = CornerDistances(*last_, *outline);
    return *std::max_element(moved.begin(), moved.end());
  };
  const bool still = last_ && largest_motion() <= options_.still_px;
  still_for_ = still ? still_for_ + 1 : 0;
  last_ = outline;
  // still_frames frames in a row means still_frames - 1 steps without motion.
  if (still_for_ + 1 < options_.still_frames) return Verdict::kMoving;
  for (std::size_t k = 0; k < taken_.size(); ++k) {
    const std::array<double, 4> apart = CornerDistances(taken_[k], *outline);
    const double mean_apart =
        std::accumulate(apart.begin(), apart.end(), 0.0) / static_cast<double>(apart.size());
    if (mean_apart < options_.min_difference * diagonal_) {
      similar_to_ = static_cast<int>(k);
      return Verdict::kTooLike;
    }
  }
  taken_.push_back(*outline);
  return Verdict::kTaken;
}

}  // namespace oal
