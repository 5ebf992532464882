#include "eval/lines/line_scoring.h"

#include <algorithm>
#include <cmath>

#include "base/angles.h"

namespace oal {

Point2d Foot(const LineParams& line, const Point2d& p) {
  const double distance = line.SignedDistance(p.u, p.v);
  return {p.u - distance * std::cos(line.theta_rad), p.v - distance * std::sin(line.theta_rad)};
}

// Distance from `b` of the point of `a` nearest to `centre`: how far apart two nearly
// parallel lines are where it matters (rho alone depends on where the origin is).
double DistanceAt(const LineParams& a, const LineParams& b, const Point2d& centre) {
  const Point2d foot = Foot(a, centre);
  return std::fabs(b.SignedDistance(foot.u, foot.v));
}

// The line half way between two nearly parallel lines.
LineParams Midline(const LineParams& a, const LineParams& b, const Point2d& centre) {
  const Point2d fa = Foot(a, centre), fb = Foot(b, centre);
  double theta_b = b.theta_rad;
  if (theta_b - a.theta_rad > kPi / 2) theta_b -= kPi;
  if (a.theta_rad - theta_b > kPi / 2) theta_b += kPi;
  const double theta = 0.5 * (a.theta_rad + theta_b);
  const double u = 0.5 * (fa.u + fb.u), v = 0.5 * (fa.v + fb.v);
  return Normalized(u * std::cos(theta) + v * std::sin(theta), theta);
}

// Angle (degrees) and offset (larger distance of the chord ends a, b from `line`).
std::pair<double, double> ErrorOf(const LineParams& line, const LineParams& truth, const Point2d& a,
                                  const Point2d& b) {
  return {
      AngleBetween(line, truth) * kDegPerRad,
      std::max(std::fabs(line.SignedDistance(a.u, a.v)), std::fabs(line.SignedDistance(b.u, b.v)))};
}

std::vector<LineMatch> MatchLines(const std::vector<ReferenceLine>& references,
                                  const std::vector<LineParams>& lines, double max_angle_deg,
                                  double max_offset_px) {
  struct Candidate {
    double cost;
    LineMatch match;
  };
  std::vector<Candidate> candidates;
  for (std::size_t r = 0; r < references.size(); ++r) {
    const ReferenceLine& reference = references[r];
    for (std::size_t l = 0; l < lines.size(); ++l) {
      const auto [angle, offset] =
          ErrorOf(lines[l], reference.line, reference.end_a, reference.end_b);
      if (angle <= max_angle_deg && offset <= max_offset_px) {
        candidates.push_back(
            {angle / max_angle_deg + offset / max_offset_px, {r, l, angle, offset}});
      }
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
  std::vector<bool> reference_used(references.size(), false), line_used(lines.size(), false);
  std::vector<LineMatch> matches;
  for (const Candidate& c : candidates) {
    if (reference_used[c.match.reference] || line_used[c.match.line]) continue;
    reference_used[c.match.reference] = line_used[c.match.line] = true;
    matches.push_back(c.match);
  }
  return matches;
}

}  // namespace oal
