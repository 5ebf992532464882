#include "detector/detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "base/angles.h"
#include "detector/lens.h"
#include "detector/simd.h"

namespace oal {
namespace {

int MaxPairs(int points) {
  return points * (points - 1) / 2;
}

// Where `line` enters and leaves the closed polygon `outline` (first and last crossing
// along the line); false if it misses it.
bool ClipToOutline(const LineParams& line, const std::vector<Point2d>& outline, Point2d* a,
                   Point2d* b) {
  const double c = std::cos(line.theta_rad), s = std::sin(line.theta_rad);
  double t_min = std::numeric_limits<double>::infinity();
  double t_max = -t_min;
  for (std::size_t i = 0; i < outline.size(); ++i) {
    const Point2d& p = outline[i];
    const Point2d& q = outline[(i + 1) % outline.size()];
    const double fp = p.u * c + p.v * s - line.rho_px;
    const double fq = q.u * c + q.v * s - line.rho_px;
    if ((fp > 0.0) == (fq > 0.0)) continue;
    const double k = fp / (fp - fq);
    const Point2d x{p.u + k * (q.u - p.u), p.v + k * (q.v - p.v)};
    const double t = -x.u * s + x.v * c;  // position along the line direction (-s, c)
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  if (t_min > t_max) return false;
  const Point2d foot{line.rho_px * c, line.rho_px * s};
  *a = Point2d{foot.u - t_min * s, foot.v + t_min * c};
  *b = Point2d{foot.u - t_max * s, foot.v + t_max * c};
  return true;
}

// A loop of points around the rectangle, `per_side` per side, clockwise from the top-left.
void RectangleOutline(const BorderRect& rect, int per_side, std::vector<Point2d>* outline) {
  outline->clear();
  const double u0 = rect.u0, v0 = rect.v0, u1 = rect.u1, v1 = rect.v1;
  const Point2d corners[4] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  for (int k = 0; k < 4; ++k) {
    const Point2d& p = corners[k];
    const Point2d& q = corners[(k + 1) % 4];
    for (int i = 0; i < per_side; ++i) {
      const double t = static_cast<double>(i) / per_side;
      outline->push_back(Point2d{p.u + t * (q.u - p.u), p.v + t * (q.v - p.v)});
    }
  }
}

}  // namespace

template <std::size_t kPoints>
OalDetector::BorderOutline<kPoints>::BorderOutline(const std::vector<Point2d>& outline) {
  for (std::size_t k = 0; k < kPoints; ++k) {
    const Point2d& p = outline[std::min(k, outline.size() - 1)];
    u[k] = p.u;
    v[k] = p.v;
  }
}

// The highest distance of a point along the line's normal is above rho and the lowest
// below: the same decisions as testing each point's sign of distance - rho.
template <std::size_t kPoints>
bool OalDetector::BorderOutline<kPoints>::Crossed(const OalEntry& entry) const {
#if OAL_HAVE_SSE2
  // Two points at a time.
  const __m128d c = _mm_set1_pd(entry.cos_theta), s = _mm_set1_pd(entry.sin_theta);
  auto distances = [&](std::size_t k) {
    return _mm_add_pd(_mm_mul_pd(_mm_loadu_pd(&u[k]), c), _mm_mul_pd(_mm_loadu_pd(&v[k]), s));
  };
  __m128d highest = distances(0), lowest = highest;
  for (std::size_t k = 2; k < kPoints; k += 2) {
    const __m128d distance = distances(k);
    highest = _mm_max_pd(highest, distance);
    lowest = _mm_min_pd(lowest, distance);
  }
  const __m128d rho = _mm_set1_pd(entry.rho_px);
  const int above = _mm_movemask_pd(_mm_cmpgt_pd(highest, rho));  // a bit per lane
  const int below = _mm_movemask_pd(_mm_cmplt_pd(lowest, rho));
  return (above != 0) & (below != 0);  // (& rather than &&: no branch)
#else
  double highest = u[0] * entry.cos_theta + v[0] * entry.sin_theta, lowest = highest;
  for (std::size_t k = 1; k < kPoints; ++k) {
    const double distance = u[k] * entry.cos_theta + v[k] * entry.sin_theta;
    highest = std::max(highest, distance);
    lowest = std::min(lowest, distance);
  }
  return highest > entry.rho_px && lowest < entry.rho_px;
#endif
}

OalDetector::OalDetector(const DetectorOptions& options)
    : options_((options.Check(), options)),
      oal_(options.angle_change_deg * kRadPerDeg, options.r_change_px, options.max_lines,
           options.max_lines + MaxPairs(options.max_points_per_border)) {}

OalDetector::OalDetector(const DetectorOptions& options, const Lens& camera)
    : OalDetector(options) {
  PointUndistorter undistorter(camera);
  if (undistorter.active()) undistorter_ = undistorter;
}

Point2d OalDetector::ToWorking(const Point2d& pixel) const {
  return undistorter_ ? undistorter_->Undistort(pixel) : pixel;
}

void OalDetector::PrepareFor(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = width;
  height_ = height;
  centre_u_ = 0.5 * (width - 1);
  centre_v_ = 0.5 * (height - 1);
  loops_.Prepare(width, height, options_.start_px, options_.step_px);
  const int borders = loops_.count();
  border_points_.reserve(static_cast<std::size_t>(options_.max_points_per_border));
  frame_points_.reserve(static_cast<std::size_t>(borders * options_.max_points_per_border));
  // Each border's outline in working coordinates, centred: its corners, and with distortion
  // also the middles of its sides, which undistortion bends outward or inward.
  outlines_.clear();
  std::vector<Point2d> outline;
  for (int border = 0; border < borders; ++border) {
    RectangleOutline(loops_.Rect(border), undistorter_ ? 2 : 1, &outline);
    for (Point2d& p : outline) {
      const Point2d working = ToWorking(p);
      p = Point2d{working.u - centre_u_, working.v - centre_v_};
    }
    outlines_.emplace_back(outline);
  }
  // The image border, where read-off lines end (undistorted when correcting).
  RectangleOutline(BorderAt(width, height, 0), 8, &image_outline_);
  // Runs are at most max_width_px wide in the image; undistorted with their points, one near
  // the image's edge is wider on the ideal image by as much as the lens stretches it there.
  double stretch = 1.0;
  for (Point2d& p : image_outline_) {
    const Point2d working = ToWorking(p);
    if (undistorter_) {
      const Point2d a = undistorter_->UndistortVector(p, working, {1.0, 0.0});
      const Point2d b = undistorter_->UndistortVector(p, working, {0.0, 1.0});
      // The larger singular value of the 2 x 2 derivative [a b].
      const double t = a.u * a.u + a.v * a.v + b.u * b.u + b.v * b.v;
      const double det = a.u * b.v - a.v * b.u;
      const double largest =
          std::sqrt(0.5 * (t + std::sqrt(std::max(0.0, t * t - 4.0 * det * det))));
      if (std::isfinite(largest)) stretch = std::max(stretch, largest);
    }
    p = working;
  }
  pair_max_width_px_ = options_.max_width_px * stretch;
  candidates_.reserve(static_cast<std::size_t>(oal_.capacity()));
  lines_.reserve(static_cast<std::size_t>(options_.max_output_lines));
}

void OalDetector::PrepareRegion() {
  // The region inside the image, where its lines end; its centroid is the list's origin.
  const std::vector<Point2d>& inside = region_borders_.inside();
  region_outline_.clear();
  for (const Point2d& p : inside) region_outline_.push_back(ToWorking(p));
  const Point2d centroid = region_borders_.count() > 0 ? Centroid(region_borders_.Polygon(0))
                                                       : Point2d{centre_u_, centre_v_};
  const Point2d origin = ToWorking(inside.empty() ? centroid : Centroid(inside));
  origin_u_ = origin.u;
  origin_v_ = origin.v;
  // The borders' outlines for the visibility counts: their vertices (at most 12: 8 of the
  // region's edges and the image's 4), undistorted, centred on the origin.
  region_outlines_.clear();
  region_outlines_long_.clear();
  std::size_t most_vertices = 0;
  for (int k = 0; k < region_borders_.count(); ++k) {
    most_vertices = std::max(most_vertices, region_borders_.Polygon(k).size());
  }
  std::vector<Point2d>& outline = outline_scratch_;
  for (int k = 0; k < region_borders_.count(); ++k) {
    outline.clear();
    for (const Point2d& p : region_borders_.Polygon(k)) {
      const Point2d working = ToWorking(p);
      outline.push_back(Point2d{working.u - origin_u_, working.v - origin_v_});
    }
    if (most_vertices <= 8) {
      region_outlines_.emplace_back(outline);
    } else {
      region_outlines_long_.emplace_back(outline);
    }
  }
}

const std::vector<DetectedLine>& OalDetector::Detect(const GrayImageView& image,
                                                     const std::vector<LineSeed>& seeds) {
  return Detect(image, seeds, ScanRegion{});
}

namespace {

void CheckView(const GrayImageView& image) {
  if (image.empty() || image.stride < image.width) {
    throw std::invalid_argument("OalDetector::Detect: empty image or stride < width");
  }
}

}  // namespace

const std::vector<DetectedLine>& OalDetector::Detect(const GrayImageView& image,
                                                     const std::vector<LineSeed>& seeds,
                                                     const ScanRegion& region) {
  CheckView(image);
  if (region.empty()) return DetectInRegion(image, seeds);
  region.Check();
  PrepareFor(image.width, image.height);
  region_borders_.set_sample_step(options_.region_sample_step);
  region_borders_.Build(region, image.width, image.height, options_.start_px, options_.step_px,
                        options_.region_max_borders);
  in_region_ = true;
  return DetectInRegion(image, seeds);
}

const std::vector<DetectedLine>& OalDetector::Detect(const GrayImageView& image,
                                                     const std::vector<LineSeed>& seeds,
                                                     const ScanBorders& borders) {
  CheckView(image);
  if (borders.empty()) return DetectInRegion(image, seeds);
  borders.Check();
  PrepareFor(image.width, image.height);
  region_borders_.set_sample_step(options_.region_sample_step);
  region_borders_.Assign(borders, image.width, image.height, borders.image_margin_px,
                         borders.image_margin_step_px);
  in_region_ = true;
  return DetectInRegion(image, seeds);
}

// The whole image when in_region_ is false (and resets it for the next call), else the
// borders region_borders_ holds.
const std::vector<DetectedLine>& OalDetector::DetectInRegion(const GrayImageView& image,
                                                             const std::vector<LineSeed>& seeds) {
  PrepareFor(image.width, image.height);
  const bool in_region = in_region_;
  in_region_ = false;
  if (in_region) {
    PrepareRegion();
  } else {
    region_borders_ = RegionBorders();
    origin_u_ = centre_u_;
    origin_v_ = centre_v_;
  }
  oal_.Clear();
  frame_points_.clear();
  lines_.clear();
  for (const LineSeed& seed : seeds) {
    // To the list's origin.
    const double c = std::cos(seed.line.theta_rad), s = std::sin(seed.line.theta_rad);
    oal_.Seed(c, s, seed.line.rho_px - origin_u_ * c - origin_v_ * s, seed.id);
  }
  scanned_region_ = in_region;
  if (in_region) {
    for (int border = 0; border < region_borders_.count(); ++border) {
      ScanRegionBorder(image, border);
    }
  } else {
    loops_.Read(image);
    for (int border = 0; border < loops_.count(); ++border) ScanBorder(image, border);
  }
  ReadOff(image.width, image.height, in_region);
  return lines_;
}

bool OalDetector::BorderThreshold(const std::vector<std::uint8_t>& samples, int* threshold) const {
  *threshold = options_.fixed_threshold;
  if (options_.threshold_mode != ThresholdMode::kOtsu) return true;
  int contrast = 0, light = 0;
  *threshold = OtsuThreshold(samples, &contrast, &light);
  // A dim frame's paper is too dark for min_contrast: its ink differs by a fraction of it.
  return contrast >= options_.ContrastNeededAt(light);
}

void OalDetector::AddBorderPoints(int border) {
  const std::size_t first_point = frame_points_.size();
  for (const BorderPoint& point : border_points_) {
    // Built in place: copying in a just-built local stalled on store forwarding.
    FramePoint& frame_point = frame_points_.emplace_back();
    const double run = point.straight ? point.run_px : 0.0;
    Point2d across{run * point.along.u, run * point.along.v};
    if (undistorter_) {
      frame_point.p = undistorter_->Undistort(point.pixel);
      if (run > 0.0) across = undistorter_->UndistortVector(point.pixel, frame_point.p, across);
    } else {
      frame_point.p = point.pixel;
    }
    frame_point.across_u = static_cast<float>(across.u);
    frame_point.across_v = static_cast<float>(across.v);
    frame_point.sides = point.sides;
    frame_point.straight = point.straight;
    frame_point.border = static_cast<std::int16_t>(border);
    frame_point.background_step = point.background_step;
  }
  VotePairs(border, first_point);
}

void OalDetector::ScanBorder(const GrayImageView& image, int border) {
  const BorderRect rect = loops_.Rect(border);
  const std::vector<std::uint8_t>& samples = loops_.Gather(image, border);
  int threshold = 0;
  if (BorderThreshold(samples, &threshold)) {
    border_points_.clear();
    FindBorderPoints(samples, rect, threshold, options_, &border_points_);
    AddBorderPoints(border);
  }

  if (!options_.count_visible_borders_only) {
    oal_.EndBorder([](const OalEntry&) { return true; });
    return;
  }
  // A local copy, captured by value: the compiler keeps it in registers across the entries
  // (it would reload member arrays after every count update, which might alias them).
  const BorderOutline<8> outline = outlines_[static_cast<std::size_t>(border)];
  oal_.EndBorder([outline](const OalEntry& entry) { return outline.Crossed(entry); });
}

void OalDetector::ScanRegionBorder(const GrayImageView& image, int border) {
  const PolygonLoop& loop = region_borders_.Loop(border);
  loop.Gather(image, &region_samples_);
  int threshold = 0;
  if (BorderThreshold(region_samples_, &threshold)) {
    border_points_.clear();
    FindBorderPoints(region_samples_, loop, threshold, options_, &border_points_, &image);
    AddBorderPoints(border);
  }
  if (!options_.count_visible_borders_only) {
    oal_.EndBorder([](const OalEntry&) { return true; });
    return;
  }
  if (region_outlines_long_.empty()) {
    const BorderOutline<8> outline = region_outlines_[static_cast<std::size_t>(border)];
    oal_.EndBorder([outline](const OalEntry& entry) { return outline.Crossed(entry); });
  } else {
    const BorderOutline<16> outline = region_outlines_long_[static_cast<std::size_t>(border)];
    oal_.EndBorder([outline](const OalEntry& entry) { return outline.Crossed(entry); });
  }
}

void OalDetector::VotePairs(int border, std::size_t first_point) {
  const std::size_t end = frame_points_.size();
  for (std::size_t i = first_point; i < end; ++i) {
    const FramePoint& a = frame_points_[i];
    for (std::size_t j = i + 1; j < end; ++j) {
      const FramePoint& b = frame_points_[j];
      if (options_.skip_same_side_pairs && (a.sides & b.sides) != 0) continue;
      const double du = b.p.u - a.p.u, dv = b.p.v - a.p.v;
      const double length_sq = du * du + dv * dv;
      if (length_sq < 1e-6) continue;
      if (!WidthsAgree(a, b, du, dv, length_sq)) continue;
      const double inverse = 1.0 / std::sqrt(length_sq);
      const double c = -dv * inverse, s = du * inverse;  // unit normal of the chord
      const double rho = c * (a.p.u - origin_u_) + s * (a.p.v - origin_v_);
      oal_.Vote(c, s, rho, border);
    }
  }
}

bool OalDetector::WidthsAgree(const FramePoint& a, const FramePoint& b, double du, double dv,
                              double length_sq) const {
  const double ratio = options_.max_pair_width_ratio;
  if (ratio == 0.0 || options_.polarity == Polarity::kEdges) return true;
  // Widths across the chord times its length (WidthAcross is linear in the normal, here the
  // chord's unnormalised normal (-dv, du)); the width limits are compared squared against
  // length_sq, so that a rejected pair costs no square root or division.
  const double width_a = WidthAcross(a, -dv, du);
  const double width_b = WidthAcross(b, -dv, du);
  if (width_a <= 0.0 || width_b <= 0.0) return true;  // a corner run: width unknown
  const double wider = std::max(width_a, width_b), narrower = std::min(width_a, width_b);
  const double max_width = pair_max_width_px_, slack = options_.min_width_px;
  if (wider * wider > max_width * max_width * length_sq) return false;
  // The min_width_px slack keeps thin lines, whose widths are a pixel or two, comparable:
  // wider <= ratio * narrower + slack, that is excess <= slack (times the length).
  const double excess = wider - ratio * narrower;
  return excess <= 0.0 || excess * excess <= slack * slack * length_sq;
}

void OalDetector::ReadOff(int width, int height, bool in_region) {
  const double tolerance = options_.support_tolerance_px;
  candidates_.clear();
  for (const OalEntry& entry : oal_.entries()) {
    if (entry.weight < options_.min_votes) continue;
    // From the list's origin to the image's top-left origin.
    const double rho = entry.rho_px + origin_u_ * entry.cos_theta + origin_v_ * entry.sin_theta;
    DetectedLine line;
    line.line = Normalized(rho, entry.Line().theta_rad);
    if (options_.refit_lines) {
      const double wide = std::max(options_.r_change_px, 2.0 * tolerance);
      // A region's borders leave the image and turn at the image's edge, often beside a
      // stripe: the runs around those corners sit off its centre line. The image's own
      // borders turn only at the image's corners, where such a run may be the line's only
      // point near that end: it is kept.
      line.line = RefitLine(line.line, frame_points_, wide, in_region);
      line.line = RefitLine(line.line, frame_points_, tolerance, in_region);
    }
    const SupportStats stats = MeasureSupport(line.line, frame_points_, tolerance);
    if (options_.rank_by_support && stats.points < options_.min_support) continue;
    line.votes = entry.weight;
    line.seed_id = entry.seed_id;
    line.count = entry.count;
    line.borders = stats.borders;
    line.support = stats.points;
    line.width_px = stats.width_px;
    line.support_a = stats.first;
    line.support_b = stats.last;
    candidates_.push_back(line);
  }
  // Best first; an insertion sort because it is stable and, unlike std::stable_sort,
  // allocates nothing.
  const bool by_support = options_.rank_by_support;
  auto better = [by_support](const DetectedLine& a, const DetectedLine& b) {
    if (by_support && a.support != b.support) return a.support > b.support;
    return a.votes > b.votes;
  };
  for (std::size_t i = 1; i < candidates_.size(); ++i) {
    const DetectedLine moving = candidates_[i];
    std::size_t j = i;
    for (; j > 0 && better(moving, candidates_[j - 1]); --j) candidates_[j] = candidates_[j - 1];
    candidates_[j] = moving;
  }

  // Near-duplicates are judged with rho from the list's origin, as the list matches lines,
  // so that the same two lines are duplicates wherever they lie in the image.
  const double duplicate_angle = options_.duplicate_angle_deg * kRadPerDeg;
  const Point2d centre{origin_u_, origin_v_};
  for (const DetectedLine& candidate : candidates_) {
    if (static_cast<int>(lines_.size()) >= options_.max_output_lines) break;
    const bool duplicate = std::any_of(lines_.begin(), lines_.end(), [&](const DetectedLine& kept) {
      return NearDuplicate(kept.line, candidate.line, centre, duplicate_angle,
                           options_.duplicate_r_px);
    });
    if (!duplicate) lines_.push_back(candidate);
  }

  // End points on the image border (the undistorted image border when correcting), or on
  // the region's outline.
  for (DetectedLine& line : lines_) {
    if (scanned_region_) {
      if (!ClipToOutline(line.line, region_outline_, &line.end_a, &line.end_b)) {
        line.end_a = line.support_a;
        line.end_b = line.support_b;
      }
    } else if (undistorter_) {
      ClipToOutline(line.line, image_outline_, &line.end_a, &line.end_b);
    } else {
      ClipToRect(line.line, 0.0, 0.0, width - 1.0, height - 1.0, &line.end_a, &line.end_b);
    }
  }
}

}  // namespace oal
