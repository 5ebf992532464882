#include "calibration/view_selector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "base/check.h"
#include "base/statistics.h"
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

// The signed distance from q to the chord through the two points of `seen` nearest to it, the
// chord turned along `tangent`; false when the nearest lies farther than reach_px (a stretch
// `seen` does not cover).
bool OffsetFromSeen(const std::vector<Point2d>& seen, const Point2d& tangent, const Point2d& q,
                    double reach_px, double* offset) {
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::size_t first = kNone, second = kNone;
  double d_first = HUGE_VAL, d_second = HUGE_VAL;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    const double d = std::hypot(seen[i].u - q.u, seen[i].v - q.v);
    if (d < d_first) {
      second = first, d_second = d_first;
      first = i, d_first = d;
    } else if (d < d_second) {
      second = i, d_second = d;
    }
  }
  if (second == kNone || !(d_first <= reach_px)) return false;
  const Point2d& a = seen[first];
  double du = seen[second].u - a.u, dv = seen[second].v - a.v;
  const double length = std::hypot(du, dv);
  if (!(length > 1e-9)) {
    du = tangent.u, dv = tangent.v;
  } else {
    const double sign = du * tangent.u + dv * tangent.v < 0.0 ? -1.0 : 1.0;
    du *= sign / length, dv *= sign / length;
  }
  *offset = du * (q.v - a.v) - dv * (q.u - a.u);
  return true;
}

// The median distance from one of `seen`'s points to its nearest other, pixels.
double MedianSpacing(const std::vector<Point2d>& seen) {
  std::vector<double> nearest;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    double d = HUGE_VAL;
    for (std::size_t j = 0; j < seen.size(); ++j) {
      if (j != i) d = std::min(d, std::hypot(seen[i].u - seen[j].u, seen[i].v - seen[j].v));
    }
    nearest.push_back(d);
  }
  return MedianInPlace(&nearest);
}

// A line's points near those seen before needed to say how it moved.
constexpr double kMinMeasured = 3.0;
// A point whose offset lies further than this many robust deviations (and kMinOutlierPx) from
// the line's median offset is not the stripe's: a run cut short by the stripe's printed end, by
// the image's edge or by a hand has its middle pixels off the stripe's, and a view found along
// another route of scans sees such runs where the last did not.
constexpr double kOutlierScales = 4.0;
constexpr double kMinOutlierPx = 0.5;

// How far a line seen as `before` moved to `after`: the offsets of after's points from the
// curve before's points trace, as a straight trend along the line, at the ends of the stretch
// measured, the offsets far from the others left out; infinite when fewer than a quarter of
// after's points lie within reach of before's.
double LineMotion(const std::vector<Point2d>& before, const std::vector<Point2d>& after,
                  double reach_px) {
  // The line's direction: that of the straight line through the points seen before (s below
  // runs along it from that line's foot; where it starts does not change the trend's ends).
  const LineParams line = FitLine(before);
  const Point2d tangent{-std::sin(line.theta_rad), std::cos(line.theta_rad)};
  const Point2d foot{line.rho_px * std::cos(line.theta_rad),
                     line.rho_px * std::sin(line.theta_rad)};
  const double reach = reach_px + MedianSpacing(before);
  struct Measured {
    double along, offset;
  };
  std::vector<Measured> measured;
  for (const Point2d& q : after) {
    double offset = 0.0;
    if (!OffsetFromSeen(before, tangent, q, reach, &offset)) continue;
    measured.push_back({(q.u - foot.u) * tangent.u + (q.v - foot.v) * tangent.v, offset});
  }
  // A stripe moved by more than the reach leaves none of its points near those seen before; one
  // seen over another stretch, some (sliding along it shows on the lines across it).
  const auto count = static_cast<double>(measured.size());
  if (count < kMinMeasured || 4.0 * count < static_cast<double>(after.size())) return HUGE_VAL;
  std::vector<double> offsets;
  for (const Measured& m : measured) offsets.push_back(m.offset);
  const double median = MedianInPlace(&offsets);
  for (double& offset : offsets) offset = std::fabs(offset - median);
  const double keep = std::max(kMinOutlierPx, kOutlierScales * 1.4826 * MedianInPlace(&offsets));
  // Least squares of offset = a + b s over the points kept.
  double n = 0.0, ss = 0.0, sd = 0.0, sss = 0.0, ssd = 0.0, lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const auto& [along, offset] : measured) {
    if (std::fabs(offset - median) > keep) continue;
    n += 1.0, ss += along, sd += offset, sss += along * along, ssd += along * offset;
    lo = std::min(lo, along), hi = std::max(hi, along);
  }
  if (n < kMinMeasured) return HUGE_VAL;
  const double spread = sss - ss * ss / n;
  const double slope = spread > 1e-9 ? (ssd - ss * sd / n) / spread : 0.0;
  const double at_mean = sd / n, mean_s = ss / n;
  return std::max(std::fabs(at_mean + slope * (lo - mean_s)),
                  std::fabs(at_mean + slope * (hi - mean_s)));
}

}  // namespace

std::optional<double> TargetMotion(const CalibrationView& from, const CalibrationView& to,
                                   double reach_px) {
  // A line needs this many points in both views to say how it moved.
  constexpr std::size_t kMinLinePoints = 3;
  bool measured = false;
  double motion = 0.0;
  for (const CalibrationPoint& p : to.points) {
    for (const CalibrationPoint& q : from.points) {
      if (std::fabs(p.x - q.x) > 1e-9 || std::fabs(p.y - q.y) > 1e-9) continue;
      motion = std::max(motion, std::hypot(p.u - q.u, p.v - q.v));
      measured = true;
      break;
    }
  }
  const std::size_t lines = std::min(from.lines.size(), to.lines.size());
  for (std::size_t k = 0; k < lines; ++k) {
    const std::vector<Point2d>& before = from.lines[k].seen;
    const std::vector<Point2d>& after = to.lines[k].seen;
    if (before.size() < kMinLinePoints || after.size() < kMinLinePoints) continue;
    measured = true;
    motion = std::max(motion, LineMotion(before, after, reach_px));
  }
  if (!measured) return std::nullopt;
  return motion;
}

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
  // A line's point farther than a few times the stillness from what the last frame saw
  // along it lies on a stretch that frame did not see.
  const std::optional<double> motion =
      last_ ? TargetMotion(*last_, view, 4.0 * options_.still_px) : std::nullopt;
  const bool still = motion && *motion <= options_.still_px;
  still_for_ = still ? still_for_ + 1 : 0;
  last_ = view;
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
