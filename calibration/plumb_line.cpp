#include "calibration/plumb_line.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "base/check.h"
#include "base/format.h"
#include "base/statistics.h"
#include "detector/lens.h"  // FitKud

namespace oal {
namespace {

// A point in distorted normalised coordinates.
struct Normalised {
  double x = 0.0, y = 0.0;
};

// The ideal point of a distorted one under ViSP's correction x_u = x_d (1 + kdu r_d^2), and
// its derivative along itself with respect to kdu: d x_u / d kdu = slope * x_u.
struct Ideal {
  double x = 0.0, y = 0.0, slope = 0.0;
};

Ideal Undistort(const Normalised& p, double kdu) {
  const double r2 = p.x * p.x + p.y * p.y, factor = 1.0 + kdu * r2;
  return {p.x * factor, p.y * factor, r2 / factor};
}

struct Line {
  std::vector<Normalised> points;
  std::vector<bool> inlier;
  double nx = 0.0, ny = 0.0, c = 0.0;  // n . p_u = c, |n| = 1
};

// Total least squares on the inliers' ideal points: the centroid and the direction of least
// spread.
void FitLine(double kdu, Line* line) {
  std::vector<Ideal> ideal;
  double sx = 0, sy = 0;
  for (std::size_t i = 0; i < line->points.size(); ++i) {
    if (!line->inlier[i]) continue;
    ideal.push_back(Undistort(line->points[i], kdu));
    sx += ideal.back().x, sy += ideal.back().y;
  }
  const double mx = sx / ideal.size(), my = sy / ideal.size();
  double sxx = 0, sxy = 0, syy = 0;
  for (const Ideal& p : ideal) {
    const double dx = p.x - mx, dy = p.y - my;
    sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
  }
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);  // direction of the line
  line->nx = -std::sin(angle);
  line->ny = std::cos(angle);
  line->c = line->nx * mx + line->ny * my;
}

double Residual(const Line& line, const Normalised& p, double kdu) {
  const Ideal u = Undistort(p, kdu);
  return line.nx * u.x + line.ny * u.y - line.c;
}

// Points further from their line than four robust standard deviations (and than `floor`,
// normalised) are left out; the others are taken back.
void CutOutliers(double kdu, double floor, std::vector<Line>* lines) {
  std::vector<double> magnitudes;
  for (const Line& line : *lines) {
    for (const Normalised& p : line.points) magnitudes.push_back(std::fabs(Residual(line, p, kdu)));
  }
  const double limit = std::max(floor, 4.0 * 1.4826 * MedianInPlace(&magnitudes));
  for (Line& line : *lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      line.inlier[i] = std::fabs(Residual(line, line.points[i], kdu)) <= limit;
    }
  }
}

struct KduStep {
  double kdu = 0.0, information = 0.0, rss = 0.0;
  int used = 0;
};

// With the lines fixed, one Gauss-Newton step in kdu: e_i + J_i dk = 0 in least squares.
KduStep StepKdu(const std::vector<Line>& lines, double kdu) {
  double ej = 0, jj = 0, ee = 0;
  int used = 0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const Ideal u = Undistort(line.points[i], kdu);
      const double along_normal = line.nx * u.x + line.ny * u.y;
      const double e = along_normal - line.c, j = along_normal * u.slope;
      ej += e * j, jj += j * j, ee += e * e, ++used;
    }
  }
  return {jj > 0 ? kdu - ej / jj : kdu, jj, ee, used};
}

// The information on kdu left once each line's offset and direction have taken their share:
// the part of each point's d e / d kdu that a line's shift and turn (1, along) cannot mimic.
double KduInformation(const std::vector<Line>& lines, double kdu) {
  double information = 0.0;
  for (const Line& line : lines) {
    double n = 0, st = 0, stt = 0, sj = 0, stj = 0, sjj = 0;
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const Ideal u = Undistort(line.points[i], kdu);
      const double t = -line.ny * u.x + line.nx * u.y;  // along the line
      const double j = (line.nx * u.x + line.ny * u.y) * u.slope;
      n += 1, st += t, stt += t * t, sj += j, stj += t * j, sjj += j * j;
    }
    if (n < 3) continue;
    // Residual sum of squares of j regressed on (1, t).
    const double det = n * stt - st * st;
    if (!(det > 0)) continue;
    const double a = (stt * sj - st * stj) / det, b = (n * stj - st * sj) / det;
    information += std::max(0.0, sjj - a * sj - b * stj);
  }
  return information;
}

double RmsPx(const std::vector<Line>& lines, double kdu, double scale_px) {
  double sum = 0;
  int n = 0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const double e = Residual(line, line.points[i], kdu) * scale_px;
      sum += e * e, ++n;
    }
  }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

}  // namespace

void PlumbLineOptions::Check() const {
  RequireOption(min_lines >= 1 && min_lines <= 100000, "PlumbLineOptions::min_lines", min_lines,
                "1 <= min_lines <= 100000");
  RequireOption(min_points_per_line >= 3 && min_points_per_line <= 1000000,
                "PlumbLineOptions::min_points_per_line", min_points_per_line,
                "3 <= min_points_per_line <= 1000000");
  RequireOption(kdu_min < kdu_max, "PlumbLineOptions::kdu_min", kdu_min, "kdu_min < kdu_max");
  RequireOption(width > 0 && height > 0, "PlumbLineOptions::width", width,
                "width > 0 and height > 0");
}

PlumbLineResult EstimateRadialDistortion(const std::vector<std::vector<Point2d>>& pixels, double px,
                                         double py, double u0, double v0,
                                         const PlumbLineOptions& options) {
  options.Check();
  std::vector<Line> lines;
  for (const std::vector<Point2d>& points : pixels) {
    if (static_cast<int>(points.size()) < options.min_points_per_line) continue;
    Line line;
    for (const Point2d& p : points) {
      line.points.push_back({(p.u - u0) / px, (p.v - v0) / py});
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
  KduStep step;
  for (int round = 0; round < 4; ++round) {
    if (round > 0) CutOutliers(step.kdu, 0.5 / scale_px, &lines);
    for (int iteration = 0; iteration < 1000; ++iteration) {
      for (Line& line : lines) FitLine(step.kdu, &line);
      const double before = step.kdu;
      step = StepKdu(lines, step.kdu);
      if (iteration > 0 && std::fabs(step.kdu - before) < 1e-12) break;
    }
  }
  // How far kdu is pinned: the residuals' spread (kdu and each line's two parameters fitted)
  // through what the lines leave of its information. The step's own information, with the
  // lines held, made kdu look ten times surer than ten frames' scatter showed it to be.
  const int dof = step.used - 1 - 2 * static_cast<int>(lines.size());
  const double sigma2 = dof > 0 ? step.rss / dof : 0.0;
  const double information = KduInformation(lines, step.kdu);
  result.kdu_sd = information > 0 ? std::sqrt(sigma2 / information) : HUGE_VAL;
  if (!(information > 0) || !(result.kdu_sd < 0.05)) {
    throw std::runtime_error(
        "the lines pass too near the image's centre to show the lens (kdu +- " +
        Number(result.kdu_sd, 3) + "): view the target off-centre, its stripes reaching the edges");
  }
  if (step.kdu < options.kdu_min || step.kdu > options.kdu_max) {
    throw std::runtime_error("kdu came out at " + Number(step.kdu, 3) + ", outside [" +
                             Number(options.kdu_min, 3) + ", " + Number(options.kdu_max, 3) +
                             "]: the points are not of straight lines through this camera");
  }
  result.kdu = step.kdu;
  result.points = step.used;
  result.rms_after_px = RmsPx(lines, step.kdu, scale_px);
  Lens camera = Lens::WithKudKdu(px, py, u0, v0, 0.0, step.kdu);
  result.kud = FitKud(camera, options.width, options.height);
  return result;
}

}  // namespace oal
