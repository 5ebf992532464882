#include "calibration/plumb_line.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "calibration/calibrate.h"  // FitViSPDistortion
#include "detector/options.h"       // RequireOption

namespace oal {
namespace {

// A point in distorted normalised coordinates.
struct Normalised {
  double x = 0.0, y = 0.0;
};

// The ideal point of a distorted one under x_d = x_u (1 + kud r_u^2), and the derivative of
// the ideal point along itself with respect to kud: d x_u / d kud = slope * x_u.
struct Ideal {
  double x = 0.0, y = 0.0, slope = 0.0;
};

Ideal Undistort(const Normalised& p, double kud) {
  double xu = p.x, yu = p.y;
  for (int i = 0; i < 50; ++i) {
    const double factor = 1.0 + kud * (xu * xu + yu * yu);
    const double next_x = p.x / factor, next_y = p.y / factor;
    const bool settled = std::fabs(next_x - xu) + std::fabs(next_y - yu) < 1e-15;
    xu = next_x, yu = next_y;
    if (settled) break;
  }
  const double s = xu * xu + yu * yu;
  // From x_d = x_u (1 + k s): 0 = x_u' (1 + k s) + x_u (s + 2 k x_u . x_u'), x_u' radial.
  return {xu, yu, -s / (1.0 + 3.0 * kud * s)};
}

struct Line {
  std::vector<Normalised> points;
  std::vector<bool> inlier;
  double nx = 0.0, ny = 0.0, c = 0.0;  // n . p_u = c, |n| = 1
};

// Total least squares on the inliers' ideal points: the centroid and the direction of least
// spread.
void FitLine(double kud, Line* line) {
  std::vector<Ideal> ideal;
  double sx = 0, sy = 0;
  for (std::size_t i = 0; i < line->points.size(); ++i) {
    if (!line->inlier[i]) continue;
    ideal.push_back(Undistort(line->points[i], kud));
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

double Residual(const Line& line, const Normalised& p, double kud) {
  const Ideal u = Undistort(p, kud);
  return line.nx * u.x + line.ny * u.y - line.c;
}

// Points further from their line than four robust standard deviations (and than `floor`,
// normalised) are left out; the others are taken back.
void CutOutliers(double kud, double floor, std::vector<Line>* lines) {
  std::vector<double> magnitudes;
  for (const Line& line : *lines) {
    for (const Normalised& p : line.points) magnitudes.push_back(std::fabs(Residual(line, p, kud)));
  }
  const auto middle = magnitudes.begin() + magnitudes.size() / 2;
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  const double limit = std::max(floor, 4.0 * 1.4826 * *middle);
  for (Line& line : *lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      line.inlier[i] = std::fabs(Residual(line, line.points[i], kud)) <= limit;
    }
  }
}

struct KudStep {
  double kud = 0.0, information = 0.0, rss = 0.0;
  int used = 0;
};

// With the lines fixed, one Gauss-Newton step in kud: e_i + J_i dk = 0 in least squares.
KudStep StepKud(const std::vector<Line>& lines, double kud) {
  double ej = 0, jj = 0, ee = 0;
  int used = 0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const Ideal u = Undistort(line.points[i], kud);
      const double along_normal = line.nx * u.x + line.ny * u.y;
      const double e = along_normal - line.c, j = along_normal * u.slope;
      ej += e * j, jj += j * j, ee += e * e, ++used;
    }
  }
  return {jj > 0 ? kud - ej / jj : kud, jj, ee, used};
}

double RmsPx(const std::vector<Line>& lines, double kud, double scale_px) {
  double sum = 0;
  int n = 0;
  for (const Line& line : lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      if (!line.inlier[i]) continue;
      const double e = Residual(line, line.points[i], kud) * scale_px;
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
  RequireOption(kud_min < kud_max, "PlumbLineOptions::kud_min", kud_min, "kud_min < kud_max");
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

  // Settle kud on all points, cut the points far from their lines, settle again: three times,
  // so that a first kud still far off does not cut the ends of the bent lines themselves.
  KudStep step;
  for (int round = 0; round < 4; ++round) {
    if (round > 0) CutOutliers(step.kud, 0.5 / scale_px, &lines);
    for (int iteration = 0; iteration < 1000; ++iteration) {
      for (Line& line : lines) FitLine(step.kud, &line);
      const double before = step.kud;
      step = StepKud(lines, step.kud);
      if (iteration > 0 && std::fabs(step.kud - before) < 1e-12) break;
    }
  }
  // How far kud is pinned: the residuals' spread through the step's information.
  const double sigma2 = step.used > 1 ? step.rss / (step.used - 1) : 0.0;
  result.kud_sd = step.information > 0 ? std::sqrt(sigma2 / step.information) : HUGE_VAL;
  if (!(step.information > 0) || !(result.kud_sd < 0.05)) {
    throw std::runtime_error(
        "the lines pass too near the image's centre to show the lens (kud +- " +
        Number(result.kud_sd) + "): view the target off-centre, its stripes reaching the edges");
  }
  if (step.kud < options.kud_min || step.kud > options.kud_max) {
    throw std::runtime_error("kud came out at " + Number(step.kud) + ", outside [" +
                             Number(options.kud_min) + ", " + Number(options.kud_max) +
                             "]: the points are not of straight lines through this camera");
  }
  result.kud = step.kud;
  result.points = step.used;
  result.rms_after_px = RmsPx(lines, step.kud, scale_px);
  // ViSP's other direction: the kdu that best undoes kud over the image.
  result.kdu = FitViSPDistortion(RadialDistortion{step.kud, 0.0, 0.0}, px, py, u0, v0,
                                 options.width, options.height)
                   .kdu;
  return result;
}

}  // namespace oal
