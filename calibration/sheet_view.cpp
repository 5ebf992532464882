#include "calibration/sheet_view.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "base/check.h"
#include "calibration/plane_lines.h"

namespace oal {
namespace {

CalibrationLine CentreLine(const TargetLine& stripe) {
  CalibrationLine line;
  line.x = stripe.x1_m;
  line.y = stripe.y1_m;
  line.dx = stripe.x2_m - stripe.x1_m;
  line.dy = stripe.y2_m - stripe.y1_m;
  return line;
}

// How far `q` lies outside `stripe` (negative inside), metres on the plane: the larger of its
// distance beyond the edges and beyond the ends.
double Outside(const TargetLine& stripe, const cv::Point2d& q) {
  const cv::Point2d a(stripe.x1_m, stripe.y1_m), b(stripe.x2_m, stripe.y2_m);
  const double length = cv::norm(b - a);
  const cv::Point2d along = (b - a) / length;
  const double t = (q - a).dot(along);
  const double across = std::fabs((q - a).cross(along)) - 0.5 * stripe.width_m;
  const double beyond = std::max(-t, t - length);
  return std::max(across, beyond);
}

}  // namespace

void SheetViewOptions::Check() const {
  RequireOption(clear_of_other_stripes_m >= 0.0 && clear_of_other_stripes_m <= 0.1,
                "SheetViewOptions::clear_of_other_stripes_m", clear_of_other_stripes_m,
                "0 <= clear_of_other_stripes_m <= 0.1");
  RequireOption(off_own_stripe_m >= 0.0 && off_own_stripe_m <= 0.1,
                "SheetViewOptions::off_own_stripe_m", off_own_stripe_m,
                "0 <= off_own_stripe_m <= 0.1");
  RequireOption(min_points_per_stripe >= 2 && min_points_per_stripe <= 100000,
                "SheetViewOptions::min_points_per_stripe", min_points_per_stripe,
                "2 <= min_points_per_stripe <= 100000");
}

CalibrationView SheetView(const LineTarget& target, const std::vector<std::vector<Point2d>>& seen,
                          std::string name, const SheetViewOptions& options,
                          const std::vector<std::vector<Point2d>>& runs) {
  options.Check();
  if (!runs.empty() && runs.size() != seen.size()) {
    throw std::invalid_argument("SheetView: one list of runs per stripe");
  }
  CalibrationView all{std::move(name), {}, {}};
  std::vector<std::size_t> stripe_of;
  for (std::size_t k = 0; k < target.lines.size() && k < seen.size(); ++k) {
    if (static_cast<int>(seen[k].size()) < options.min_points_per_stripe) continue;
    CalibrationLine line = CentreLine(target.lines[k]);
    line.seen = seen[k];
    if (!runs.empty()) {
      if (runs[k].size() != seen[k].size()) {
        throw std::invalid_argument("SheetView: one run per seen point");
      }
      line.runs = runs[k];
      line.width_m = target.lines[k].width_m;
    }
    all.lines.push_back(std::move(line));
    stripe_of.push_back(k);
  }
  const std::optional<cv::Matx33d> plane_to_image = plane_lines::FirstHomography(all);
  CalibrationView view{all.name, {}, {}};
  if (!plane_to_image) return view;
  const cv::Matx33d image_to_plane = plane_to_image->inv();
  for (std::size_t l = 0; l < all.lines.size(); ++l) {
    CalibrationLine kept = all.lines[l];
    kept.seen.clear();
    kept.runs.clear();
    for (std::size_t i = 0; i < all.lines[l].seen.size(); ++i) {
      const Point2d& p = all.lines[l].seen[i];
      const cv::Vec3d h = image_to_plane * cv::Vec3d(p.u, p.v, 1.0);
      const cv::Point2d q(h[0] / h[2], h[1] / h[2]);
      bool keep = Outside(target.lines[stripe_of[l]], q) <= options.off_own_stripe_m;
      for (std::size_t other = 0; other < target.lines.size() && keep; ++other) {
        if (other == stripe_of[l]) continue;
        keep = Outside(target.lines[other], q) >= options.clear_of_other_stripes_m;
      }
      if (!keep) continue;
      kept.seen.push_back(p);
      if (!all.lines[l].runs.empty()) kept.runs.push_back(all.lines[l].runs[i]);
    }
    if (static_cast<int>(kept.seen.size()) >= options.min_points_per_stripe) {
      view.lines.push_back(std::move(kept));
    }
  }
  return view;
}

}  // namespace oal
