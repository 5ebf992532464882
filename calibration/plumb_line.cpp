#include "calibration/plumb_line.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "detector/options.h"  // RequireOption

namespace oal {
namespace {

// A point in normalised coordinates with its squared radius: undistorted, it is p (1 + k r2).
struct Normalised {
  double x = 0.0, y = 0.0, r2 = 0.0;
};

struct Line {
  std::vector<Normalised> points;
  std::vector<bool> inlier;
  double nx = 0.0, ny = 0.0, c = 0.0;  // n . p_u = c, |n| = 1
};

// Total least squares on the inliers undistorted by k: the centroid and the direction of
// least spread.
void FitLine(double k, Line* line) {
  double sx = 0, sy = 0, n = 0;
  for (std::size_t i = 0; i < line->points.size(); ++i) {
    if (!line->inlier[i]) continue;
    const Normalised& p = line->points[i];
    sx += p.x * (1 + k * p.r2), sy += p.y * (1 + k * p.r2), n += 1;
  }
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < line->points.size(); ++i) {
    if (!line->inlier[i]) continue;
    const Normalised& p = line->points[i];
    const double dx = p.x * (1 + k * p.r2) - mx, dy = p.y * (1 + k * p.r2) - my;
    sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
  }
  // The normal is the eigenvector of the smaller eigenvalue of [[sxx, sxy], [sxy, syy]].
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);  // direction of the line
  line->nx = -std::sin(angle);
  line->ny = std::cos(angle);
  line->c = line->nx * mx + line->ny * my;
}

double Residual(const Line& line, const Normalised& p, double k) {
  return line.nx * p.x * (1 + k * p.r2) + line.ny * p.y * (1 + k * p.r2) - line.c;
}

// Points further from their line than four robust standard deviations (and than `floor`,
// normalised) are left out; the others are taken back.
void CutOutliers(double k, double floor, std::vector<Line>* lines) {
  std::vector<double> magnitudes;
  for (const Line& line : *lines) {
    for (const Normalised& p : line.points) magnitudes.push_back(std::fabs(Residual(line, p, k)));
  }
  const auto middle = magnitudes.begin() + magnitudes.size() / 2;
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  const double limit = std::max(floor, 4.0 * 1.4826 * *middle);
  for (Line& line : *lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      line.inlier[i] = std::fabs(Residual(line, line.points[i], k)) <= limit;
    }
  }
}

struct KSolution {
  double k = 0.0, information = 0.0, rss = 0.0;
  int used = 0;
};

// With the lines fixed, e_i = a_i + k b_i: least squares in k.
KSolution SolveK(const std::vector<Line>& lines) {
  double ab = 0, bb = 0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const Normalised& p = line.points[i];
      const double along_normal = line.nx * p.x + line.ny * p.y;
      const double a = along_normal - line.c, b = along_normal * p.r2;
      ab += a * b, bb += b * b;
    }
  }
  KSolution solution;
  solution.information = bb;
  solution.k = bb > 0 ? -ab / bb : 0.0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const double e = Residual(line, line.points[i], solution.k);
      solution.rss += e * e;
      ++solution.used;
    }
  }
  return solution;
}

double RmsPx(const std::vector<Line>& lines, double k, double scale_px) {
  double sum = 0;
  int n = 0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const double e = Residual(line, line.points[i], k) * scale_px;
      sum += e * e, ++n;
    }
  }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

std::string Number(double value) {
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

}  // namespace

void PlumbLineOptions::Check() const {
  RequireOption(min_lines >= 1 && min_lines <= 100000, "PlumbLineOptions::min_lines", min_lines,
                "1 <= min_lines <= 100000");
  RequireOption(min_points_per_line >= 3 && min_points_per_line <= 1000000,
                "PlumbLineOptions::min_points_per_line", min_points_per_line,
                "3 <= min_points_per_line <= 1000000");
  RequireOption(kdu_min < kdu_max, "PlumbLineOptions::kdu_min", kdu_min, "kdu_min < kdu_max");
}

PlumbLineResult EstimateKdu(const std::vector<std::vector<Point2d>>& pixels, double px, double py,
                            double u0, double v0, const PlumbLineOptions& options) {
  options.Check();
  std::vector<Line> lines;
  for (const std::vector<Point2d>& points : pixels) {
    if (static_cast<int>(points.size()) < options.min_points_per_line) continue;
    Line line;
    for (const Point2d& p : points) {
      const double x = (p.u - u0) / px, y = (p.v - v0) / py;
      line.points.push_back({x, y, x * x + y * y});
    }
    line.inlier.assign(line.points.size(), true);
    lines.push_back(std::move(line));
  }
  if (static_cast<int>(lines.size()) < options.min_lines) {
    throw std::runtime_error(std::to_string(lines.size()) + " lines with at least " +
                             std::to_string(options.min_points_per_line) + " points, " +
                             std::to_string(options.min_lines) + " needed to tell the lens");
  }
  const double scale_px = 0.5 * (px + py);
  PlumbLineResult result;
  result.lines = static_cast<int>(lines.size());
  for (Line& line : lines) FitLine(0.0, &line);
  result.rms_before_px = RmsPx(lines, 0.0, scale_px);

  // Settle kdu on all points, cut the points far from their lines, settle again: three times,
  // so that a first kdu still far off does not cut the ends of the bent lines themselves.
  KSolution solution;
  for (int round = 0; round < 4; ++round) {
    if (round > 0) CutOutliers(solution.k, 0.5 / scale_px, &lines);
    for (int iteration = 0; iteration < 1000; ++iteration) {
      for (Line& line : lines) FitLine(solution.k, &line);
      const double before = solution.k;
      solution = SolveK(lines);
      if (iteration > 0 && std::fabs(solution.k - before) < 1e-12) break;
    }
  }
  // How far kdu is pinned: 1/sqrt(information) in units of the residuals' spread.
  const double sigma2 = solution.used > 1 ? solution.rss / (solution.used - 1) : 0.0;
  result.kdu_sd = solution.information > 0 ? std::sqrt(sigma2 / solution.information) : HUGE_VAL;
  if (!(solution.information > 0) || !(result.kdu_sd < 0.05)) {
    throw std::runtime_error(
        "the lines pass too near the image's centre to show the lens (kdu +- " +
        Number(result.kdu_sd) + "): view the target off-centre, its stripes reaching the edges");
  }
  if (solution.k < options.kdu_min || solution.k > options.kdu_max) {
    throw std::runtime_error("kdu came out at " + Number(solution.k) + ", outside [" +
                             Number(options.kdu_min) + ", " + Number(options.kdu_max) +
                             "]: the points are not of straight lines through this camera");
  }
  result.kdu = solution.k;
  result.points = solution.used;
  result.rms_after_px = RmsPx(lines, solution.k, scale_px);
  return result;
}

}  // namespace oal
