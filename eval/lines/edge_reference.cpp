#include "eval/lines/edge_reference.h"

#include <visp3/core/vpImageConvert.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "base/angles.h"
#include "base/check.h"
#include "io/atomic_file.h"
#include "io/image_source.h"

namespace oal {
namespace {

struct EdgePoint {
  double u = 0.0, v = 0.0;    ///< sub-pixel position
  double gu = 0.0, gv = 0.0;  ///< gradient of the smoothed image, grey levels per pixel
};

// Separable Gaussian smoothing with replicated borders.
std::vector<float> Smooth(const vpImage<unsigned char>& image, double sigma, int radius) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight());
  std::vector<double> kernel(static_cast<std::size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    kernel[static_cast<std::size_t>(k + radius)] = std::exp(-0.5 * k * k / (sigma * sigma));
    sum += kernel[static_cast<std::size_t>(k + radius)];
  }
  for (double& value : kernel) value /= sum;
  std::vector<float> rows(static_cast<std::size_t>(w) * h), out(rows.size());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      double acc = 0.0;
      for (int k = -radius; k <= radius; ++k) {
        const int uu = std::clamp(u + k, 0, w - 1);
        acc += kernel[static_cast<std::size_t>(k + radius)] * image[v][uu];
      }
      rows[static_cast<std::size_t>(v) * w + u] = static_cast<float>(acc);
    }
  }
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      double acc = 0.0;
      for (int k = -radius; k <= radius; ++k) {
        const int vv = std::clamp(v + k, 0, h - 1);
        acc += kernel[static_cast<std::size_t>(k + radius)] *
               rows[static_cast<std::size_t>(vv) * w + u];
      }
      out[static_cast<std::size_t>(v) * w + u] = static_cast<float>(acc);
    }
  }
  return out;
}

// Vertex offset of the peak through (m-, m0, m+), m0 the largest: Gaussian (log) fit when
// both neighbours are positive, else a parabola; clamped to [-0.5, 0.5].
double PeakOffset(double minus, double centre, double plus) {
  double offset = 0.0;
  if (minus > 0.0 && plus > 0.0) {
    const double lm = std::log(minus), l0 = std::log(centre), lp = std::log(plus);
    const double denom = lm - 2.0 * l0 + lp;
    if (denom < 0.0) offset = 0.5 * (lm - lp) / denom;
  } else {
    const double denom = minus - 2.0 * centre + plus;
    if (denom < 0.0) offset = 0.5 * (minus - plus) / denom;
  }
  return std::clamp(offset, -0.5, 0.5);
}

// Steps 1-3 of the file comment.
std::vector<EdgePoint> EdgePoints(const vpImage<unsigned char>& image,
                                  const EdgeReferenceOptions& options) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight());
  const int radius = static_cast<int>(std::ceil(3.0 * options.smoothing_sigma_px));
  const std::vector<float> s = Smooth(image, options.smoothing_sigma_px, radius);
  auto at = [&](int u, int v) {
    return static_cast<double>(s[static_cast<std::size_t>(v) * w + u]);
  };
  auto gu = [&](int u, int v) { return 0.5 * (at(u + 1, v) - at(u - 1, v)); };
  auto gv = [&](int u, int v) { return 0.5 * (at(u, v + 1) - at(u, v - 1)); };
  const int margin = radius + 2;
  std::vector<EdgePoint> points;
  for (int v = margin; v < h - margin; ++v) {
    for (int u = margin; u < w - margin; ++u) {
      const double a = gu(u, v), b = gv(u, v);
      const double along_row = std::fabs(a), along_column = std::fabs(b);
      if (std::hypot(a, b) < options.min_gradient) continue;
      if (along_row >= along_column) {  // closer to vertical: peak along the row
        const double sign = a > 0.0 ? 1.0 : -1.0;
        const double minus = sign * gu(u - 1, v), plus = sign * gu(u + 1, v);
        if (!(along_row > minus && along_row >= plus)) continue;
        points.push_back({u + PeakOffset(minus, along_row, plus), static_cast<double>(v), a, b});
      } else {  // closer to horizontal: peak along the column
        const double sign = b > 0.0 ? 1.0 : -1.0;
        const double minus = sign * gv(u, v - 1), plus = sign * gv(u, v + 1);
        if (!(along_column > minus && along_column >= plus)) continue;
        points.push_back({static_cast<double>(u), v + PeakOffset(minus, along_column, plus), a, b});
      }
    }
  }
  return points;
}

// Points within `max_distance` of `line` whose gradient lies within the angle of
// `bright_u, bright_v` (a unit vector along the line's normal, towards the bright side)
// given by its cosine `min_cos`.
std::vector<std::size_t> Support(const std::vector<EdgePoint>& points, const LineParams& line,
                                 double bright_u, double bright_v, double max_distance,
                                 double min_cos) {
  std::vector<std::size_t> support;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const EdgePoint& p = points[k];
    if (std::fabs(line.SignedDistance(p.u, p.v)) > max_distance) continue;
    if (p.gu * bright_u + p.gv * bright_v < min_cos * std::hypot(p.gu, p.gv)) continue;
    support.push_back(k);
  }
  return support;
}

LineParams TotalLeastSquares(const std::vector<EdgePoint>& points,
                             const std::vector<std::size_t>& subset) {
  double mu = 0.0, mv = 0.0;
  for (std::size_t k : subset) {
    mu += points[k].u;
    mv += points[k].v;
  }
  mu /= static_cast<double>(subset.size());
  mv /= static_cast<double>(subset.size());
  double suu = 0.0, svv = 0.0, suv = 0.0;
  for (std::size_t k : subset) {
    const double du = points[k].u - mu, dv = points[k].v - mv;
    suu += du * du;
    svv += dv * dv;
    suv += du * dv;
  }
  const double theta = 0.5 * std::atan2(2.0 * suv, suu - svv) + kPi / 2.0;
  return Normalized(mu * std::cos(theta) + mv * std::sin(theta), theta);
}

// +1 when `polarity` asks for the bright side on the positive side of a line, -1 for the
// negative side, 0 for either.
int PolaritySign(EdgePolarity polarity) {
  return polarity == EdgePolarity::kBrighterPositive   ? 1
         : polarity == EdgePolarity::kBrighterNegative ? -1
                                                       : 0;
}

}  // namespace

std::string ToString(EdgePolarity polarity) {
  switch (polarity) {
    case EdgePolarity::kAny:
      return "any";
    case EdgePolarity::kBrighterPositive:
      return "brighter-positive";
    case EdgePolarity::kBrighterNegative:
      return "brighter-negative";
  }
  return "unknown";
}

void EdgeReferenceOptions::Check() const {
  auto reject = [](const std::string& field, double value, const std::string& constraint) {
    RequireOption(false, "EdgeReferenceOptions::" + field, value, constraint);
  };
  if (!(smoothing_sigma_px >= 0.5 && smoothing_sigma_px <= 10.0)) {
    reject("smoothing_sigma_px", smoothing_sigma_px, "0.5 <= smoothing_sigma_px <= 10");
  }
  if (!(min_gradient > 0.0)) reject("min_gradient", min_gradient, "min_gradient > 0");
  if (!(inlier_px > 0.0 && inlier_px <= 10.0))
    reject("inlier_px", inlier_px, "0 < inlier_px <= 10");
  if (!(max_normal_angle_deg > 0.0 && max_normal_angle_deg < 90.0)) {
    reject("max_normal_angle_deg", max_normal_angle_deg, "0 < max_normal_angle_deg < 90");
  }
  if (ransac_trials < 1 || ransac_trials > 1000000) {
    reject("ransac_trials", ransac_trials, "1 <= ransac_trials <= 1000000");
  }
  if (min_points < 2) reject("min_points", min_points, "min_points >= 2");
  if (!(search_band_px > 0.0)) reject("search_band_px", search_band_px, "search_band_px > 0");
  if (!(max_prior_angle_deg > 0.0 && max_prior_angle_deg < 90.0)) {
    reject("max_prior_angle_deg", max_prior_angle_deg, "0 < max_prior_angle_deg < 90");
  }
}

EdgeReference FitEdgeReference(const vpImage<unsigned char>& image,
                               const EdgeReferenceOptions& options,
                               const std::optional<LineParams>& prior) {
  options.Check();
  if (image.getWidth() < 16 || image.getHeight() < 16) {
    throw std::invalid_argument("FitEdgeReference: image of " + std::to_string(image.getWidth()) +
                                " x " + std::to_string(image.getHeight()) +
                                " px. Violated constraint: at least 16 x 16");
  }
  EdgeReference result;
  std::vector<EdgePoint> points = EdgePoints(image, options);
  const int wanted_sign = PolaritySign(options.polarity);
  if (prior) {
    const double c = std::cos(prior->theta_rad), s = std::sin(prior->theta_rad);
    const double min_cos = std::cos(options.max_prior_angle_deg * kRadPerDeg);
    points.erase(
        std::remove_if(points.begin(), points.end(),
                       [&](const EdgePoint& p) {
                         if (std::fabs(prior->SignedDistance(p.u, p.v)) > options.search_band_px) {
                           return true;
                         }
                         const double along = (p.gu * c + p.gv * s) / std::hypot(p.gu, p.gv);
                         if (std::fabs(along) < min_cos) return true;
                         return wanted_sign != 0 && along * wanted_sign < 0.0;
                       }),
        points.end());
  }
  const int n = static_cast<int>(points.size());
  if (n < options.min_points) {
    result.message = std::to_string(n) +
                     " edge points, fewer than min_points = " + std::to_string(options.min_points);
    return result;
  }

  // Step 4: RANSAC on pairs, support with one polarity.
  const double min_cos = std::cos(options.max_normal_angle_deg * kRadPerDeg);
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::size_t best_support = 0;
  LineParams best_line;
  double best_bright_u = 0.0, best_bright_v = 0.0;
  for (int trial = 0; trial < options.ransac_trials; ++trial) {
    const EdgePoint& a = points[static_cast<std::size_t>(pick(rng))];
    const EdgePoint& b = points[static_cast<std::size_t>(pick(rng))];
    if (std::hypot(a.u - b.u, a.v - b.v) < 4.0) continue;
    const LineParams line = LineThrough({a.u, a.v}, {b.u, b.v});
    const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
    for (int sign : {1, -1}) {
      if (wanted_sign != 0 && !prior && sign != wanted_sign) continue;
      const std::size_t support =
          Support(points, line, sign * c, sign * s, options.inlier_px, min_cos).size();
      if (support > best_support) {
        best_support = support;
        best_line = line;
        best_bright_u = sign * c;
        best_bright_v = sign * s;
      }
    }
  }
  if (static_cast<int>(best_support) < options.min_points) {
    result.message =
        "best line has " + std::to_string(best_support) +
        " support points, fewer than min_points = " + std::to_string(options.min_points);
    return result;
  }

  // Step 5: TLS on the support, support recomputed until it settles.
  LineParams line = best_line;
  double bright_u = best_bright_u, bright_v = best_bright_v;
  std::vector<std::size_t> support =
      Support(points, line, bright_u, bright_v, options.inlier_px, min_cos);
  for (int iteration = 0; iteration < 20; ++iteration) {
    line = TotalLeastSquares(points, support);
    const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
    const double sign = c * bright_u + s * bright_v >= 0.0 ? 1.0 : -1.0;
    bright_u = sign * c;
    bright_v = sign * s;
    std::vector<std::size_t> next =
        Support(points, line, bright_u, bright_v, options.inlier_px, min_cos);
    if (static_cast<int>(next.size()) < options.min_points) break;
    if (next == support) break;
    support = std::move(next);
  }
  if (static_cast<int>(support.size()) < options.min_points) {
    result.message = "the refined line kept " + std::to_string(support.size()) +
                     " support points, fewer than min_points";
    return result;
  }

  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  double sum2 = 0.0, max_abs = 0.0;
  double t_min = 0.0, t_max = 0.0;
  bool first = true;
  for (std::size_t k : support) {
    const EdgePoint& p = points[k];
    const double d = line.SignedDistance(p.u, p.v);
    sum2 += d * d;
    max_abs = std::max(max_abs, std::fabs(d));
    const double t = -p.u * s + p.v * c;  // position along the line
    t_min = first ? t : std::min(t_min, t);
    t_max = first ? t : std::max(t_max, t);
    first = false;
  }
  result.status = EdgeReferenceStatus::kFound;
  result.line = line;
  result.polarity = c * bright_u + s * bright_v > 0.0 ? EdgePolarity::kBrighterPositive
                                                      : EdgePolarity::kBrighterNegative;
  result.points = static_cast<int>(support.size());
  result.rms_residual_px = std::sqrt(sum2 / static_cast<double>(support.size()));
  result.max_residual_px = max_abs;
  const Point2d foot{line.rho_px * c, line.rho_px * s};
  result.end_a = Point2d{foot.u - t_min * s, foot.v + t_min * c};
  result.end_b = Point2d{foot.u - t_max * s, foot.v + t_max * c};
  return result;
}

std::string SequenceFramePath(const std::string& pattern, int frame) {
  try {
    return ExpandPattern(pattern, frame);
  } catch (const std::runtime_error& error) {
    throw std::invalid_argument(std::string(error.what()) +
                                "; edge-reference follows an edge through numbered frames, e.g. "
                                "line/image.%04d.pgm (a single image or a directory is not a "
                                "sequence)");
  }
}

int LastSequenceFrame(const std::string& pattern, int first) {
  if (first < 0) {
    throw std::invalid_argument("first frame " + std::to_string(first) +
                                ". Violated constraint: first >= 0");
  }
  const std::string first_path = SequenceFramePath(pattern, first);
  if (!std::filesystem::is_regular_file(first_path)) {
    throw std::runtime_error("image pattern \"" + pattern + "\": frame " + std::to_string(first) +
                             " (" + first_path + ") does not exist");
  }
  // Each frame number names another file (one %d conversion), so this ends.
  int last = first;
  while (last < std::numeric_limits<int>::max() &&
         std::filesystem::is_regular_file(SequenceFramePath(pattern, last + 1))) {
    ++last;
  }
  return last;
}

std::vector<FrameReference> FitEdgeSequence(const std::string& pattern, int first, int last,
                                            const EdgeReferenceOptions& options) {
  options.Check();
  SequenceFramePath(pattern, first);  // a bad pattern fails before any range error
  if (first < 0 || first > last) {
    throw std::invalid_argument("frames " + std::to_string(first) + " to " + std::to_string(last) +
                                ". Violated constraint: 0 <= first <= last");
  }
  std::vector<FrameReference> references;
  std::optional<LineParams> prior;
  EdgeReferenceOptions frame_options = options;
  for (int frame = first; frame <= last; ++frame) {
    const std::string path = SequenceFramePath(pattern, frame);
    // Through the commands' image reading, which rejects files cut short (JPEG, PNG).
    Frame decoded;
    if (!OpenImageSource(path)->Next(&decoded)) throw std::runtime_error("cannot read " + path);
    vpImage<unsigned char> image;
    vpImageConvert::convert(decoded.gray, image);
    FrameReference reference;
    reference.frame = frame;
    try {
      reference.reference = FitEdgeReference(image, frame_options, prior);
    } catch (const std::invalid_argument& e) {  // options were checked: the image size
      throw std::runtime_error(path + ": " + e.what());
    }
    if (reference.reference.status == EdgeReferenceStatus::kFound) {
      prior = reference.reference.line;
      // Keep the edge's polarity, relative to the prior's (this frame's line's) normal.
      frame_options.polarity = reference.reference.polarity;
    }
    references.push_back(std::move(reference));
  }
  return references;
}

void WriteTruthCsv(const std::vector<FrameReference>& references, std::ostream& out) {
  out << "frame,line,rho,theta\n";
  out << std::setprecision(10);
  for (const FrameReference& reference : references) {
    if (reference.reference.status != EdgeReferenceStatus::kFound) continue;
    out << reference.frame << ",0," << reference.reference.line.rho_px << ","
        << reference.reference.line.theta_rad << "\n";
  }
}

void WriteTruthCsv(const std::vector<FrameReference>& references,
                   const std::filesystem::path& path) {
  AtomicFile file(path);
  WriteTruthCsv(references, file.stream());
  file.Commit();
}

}  // namespace oal
