#include "detector/region.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "detector/options.h"

namespace oal {
namespace {

double Cross(const Point2d& o, const Point2d& a, const Point2d& b) {
  return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
}

// Writes into *out (cleared) the part of the convex polygon where `inside(p) >= 0` (inside
// is affine in p).
template <typename Inside>
void ClipByHalfPlane(const std::vector<Point2d>& polygon, Inside inside,
                     std::vector<Point2d>* out) {
  out->clear();
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2d& p = polygon[i];
    const Point2d& q = polygon[(i + 1) % n];
    const double fp = inside(p), fq = inside(q);
    if (fp >= 0.0) out->push_back(p);
    if ((fp >= 0.0) != (fq >= 0.0)) {
      const double t = fp / (fp - fq);
      out->push_back(Point2d{p.u + t * (q.u - p.u), p.v + t * (q.v - p.v)});
    }
  }
}

double DistanceSquared(const Point2d& a, const Point2d& b) {
  return (a.u - b.u) * (a.u - b.u) + (a.v - b.v) * (a.v - b.v);
}

// Drops, in place, consecutive vertices closer than `eps` and vertices on a straight run.
void Simplify(std::vector<Point2d>* polygon, double eps = 1e-6) {
  std::vector<Point2d>& out = *polygon;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (kept > 0 && DistanceSquared(out[i], out[kept - 1]) < eps * eps) continue;
    out[kept++] = out[i];
  }
  out.resize(kept);
  while (out.size() > 1 && DistanceSquared(out.front(), out.back()) < eps * eps) out.pop_back();
  bool changed = true;
  while (changed && out.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < out.size() && out.size() >= 3; ++i) {
      const Point2d& a = out[(i + out.size() - 1) % out.size()];
      const Point2d& b = out[i];
      const Point2d& c = out[(i + 1) % out.size()];
      const double cross = Cross(a, b, c);
      if (cross * cross <= eps * eps * std::max(DistanceSquared(a, c), 1.0)) {
        out.erase(out.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }
}

// The smallest width of a convex polygon: over its edges, the largest distance of a vertex
// from the edge's line.
double MinimumWidth(const std::vector<Point2d>& polygon) {
  double width = HUGE_VAL;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2d& a = polygon[i];
    const Point2d& b = polygon[(i + 1) % n];
    const double length = std::hypot(b.u - a.u, b.v - a.v);
    if (!(length > 0.0)) continue;
    double farthest = 0.0;
    for (const Point2d& p : polygon) farthest = std::max(farthest, std::fabs(Cross(a, b, p)));
    width = std::min(width, farthest / length);
  }
  return width;
}

}  // namespace

void ScanRegion::Check() const {
  const int n = static_cast<int>(vertices.size());
  RequireOption(n >= 3 && n <= kMaxVertices, "region.vertices", n,
                "3 to " + std::to_string(kMaxVertices) + " vertices");
  auto vertex_text = [](const Point2d& p) {
    return "(" + std::to_string(p.u) + ", " + std::to_string(p.v) + ")";
  };
  for (const Point2d& p : vertices) {
    if (!(std::isfinite(p.u) && std::isfinite(p.v))) {
      RequireOption(false, "region.vertex", vertex_text(p), "finite");
    }
  }
  const double area = SignedArea(vertices);
  RequireOption(std::fabs(area) > 1.0, "region.area", std::fabs(area), "area > 1 px^2");
  for (int i = 0; i < n; ++i) {
    const double turn = Cross(vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n]);
    if (!(turn * area >= -1e-9 * std::fabs(area))) {
      RequireOption(false, "region.vertex " + std::to_string((i + 1) % n + 1),
                    vertex_text(vertices[(i + 1) % n]), "a convex polygon");
    }
  }
}

void ScanBorders::Check() const {
  RequireOption(image_margin_px >= 0, "ScanBorders::image_margin_px", image_margin_px, ">= 0");
  RequireOption(image_margin_step_px >= 0, "ScanBorders::image_margin_step_px",
                image_margin_step_px, ">= 0");
  for (const std::vector<Point2d>& polygon : polygons) ScanRegion{polygon}.Check();
}

double SignedArea(const std::vector<Point2d>& polygon) {
  double twice = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2d& p = polygon[i];
    const Point2d& q = polygon[(i + 1) % n];
    twice += p.u * q.v - q.u * p.v;
  }
  return 0.5 * twice;
}

Point2d Centroid(const std::vector<Point2d>& polygon) {
  if (polygon.empty()) return Point2d{};
  const double area = SignedArea(polygon);
  if (!(std::fabs(area) > 1e-12)) return polygon.front();
  double cu = 0.0, cv = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2d& p = polygon[i];
    const Point2d& q = polygon[(i + 1) % n];
    const double w = p.u * q.v - q.u * p.v;
    cu += (p.u + q.u) * w;
    cv += (p.v + q.v) * w;
  }
  return Point2d{cu / (6.0 * area), cv / (6.0 * area)};
}

std::vector<Point2d> ConvexHull(std::vector<Point2d> points) {
  std::sort(points.begin(), points.end(), [](const Point2d& a, const Point2d& b) {
    return a.u < b.u || (a.u == b.u && a.v < b.v);
  });
  points.erase(
      std::unique(points.begin(), points.end(),
                  [](const Point2d& a, const Point2d& b) { return a.u == b.u && a.v == b.v; }),
      points.end());
  if (points.size() < 3) return points;
  // Lower and upper chains, counter-clockwise in a y-up frame, which is the image borders'
  // turning sense in image coordinates (v down).
  std::vector<Point2d> hull(2 * points.size());
  std::size_t k = 0;
  for (const Point2d& p : points) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], p) <= 0.0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  if (SignedArea(hull) < 0.0) std::reverse(hull.begin(), hull.end());
  return hull;
}

std::vector<Point2d> InsetRegion(const ScanRegion& region, double inset_px, int width, int height,
                                 double min_extent_px) {
  const double lo_u = inset_px, hi_u = width - 1.0 - inset_px;
  const double lo_v = inset_px, hi_v = height - 1.0 - inset_px;
  if (!(hi_u - lo_u >= min_extent_px && hi_v - lo_v >= min_extent_px)) return {};
  std::vector<Point2d> polygon = {{lo_u, lo_v}, {hi_u, lo_v}, {hi_u, hi_v}, {lo_u, hi_v}};
  std::vector<Point2d> clipped;
  std::vector<Point2d> outline = region.vertices;
  if (SignedArea(outline) < 0.0) std::reverse(outline.begin(), outline.end());
  for (std::size_t i = 0; i < outline.size() && polygon.size() >= 3; ++i) {
    const Point2d a = outline[i];
    const Point2d b = outline[(i + 1) % outline.size()];
    const double length = std::hypot(b.u - a.u, b.v - a.v);
    if (!(length > 0.0)) continue;
    ClipByHalfPlane(
        polygon, [&](const Point2d& p) { return Cross(a, b, p) / length - inset_px; }, &clipped);
    polygon.swap(clipped);
  }
  Simplify(&polygon);
  if (polygon.size() < 3 || !(MinimumWidth(polygon) >= min_extent_px)) return {};
  return polygon;
}

std::vector<Point2d> GrowPolygon(const std::vector<Point2d>& polygon, double grow_px) {
  std::vector<Point2d> outline = polygon;
  if (outline.size() < 3) return outline;
  if (SignedArea(outline) < 0.0) std::reverse(outline.begin(), outline.end());
  const std::size_t n = outline.size();
  std::vector<Point2d> grown;
  for (std::size_t i = 0; i < n; ++i) {
    // The vertex between edge (prev -> p) and edge (p -> next), both moved outward.
    const Point2d& prev = outline[(i + n - 1) % n];
    const Point2d& p = outline[i];
    const Point2d& next = outline[(i + 1) % n];
    const double l1 = std::hypot(p.u - prev.u, p.v - prev.v);
    const double l2 = std::hypot(next.u - p.u, next.v - p.v);
    if (!(l1 > 0.0 && l2 > 0.0)) continue;
    // Outward normals of a positively turning polygon in image coordinates.
    const Point2d n1{(p.v - prev.v) / l1, -(p.u - prev.u) / l1};
    const Point2d n2{(next.v - p.v) / l2, -(next.u - p.u) / l2};
    const double dot = n1.u * n2.u + n1.v * n2.v;
    const double scale = grow_px / std::max(1.0 + dot, 1e-3);
    grown.push_back(Point2d{p.u + (n1.u + n2.u) * scale, p.v + (n1.v + n2.v) * scale});
  }
  return grown;
}

bool Contains(const std::vector<Point2d>& polygon, const Point2d& p) {
  const std::size_t n = polygon.size();
  if (n < 3) return false;
  const double sense = SignedArea(polygon) >= 0.0 ? 1.0 : -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (sense * Cross(polygon[i], polygon[(i + 1) % n], p) < 0.0) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------

void PolygonLoop::AddEdge(const Point2d& a, const Point2d& b) {
  const double du = b.u - a.u, dv = b.v - a.v;
  const double length = std::sqrt(du * du + dv * dv);
  Edge edge;
  edge.first = perimeter_;
  edge.direction = length > 0.0 ? Point2d{du / length, dv / length} : Point2d{1.0, 0.0};
  edge.mostly_horizontal = std::fabs(du) >= std::fabs(dv);
  // Samples at every sample_step_-th integer coordinate of the longer axis in [a, b), in its
  // direction.
  const double from = edge.mostly_horizontal ? a.u : a.v;
  const double to = edge.mostly_horizontal ? b.u : b.v;
  const double delta = to - from;
  if (delta != 0.0) {
    const double sign = delta > 0.0 ? 1.0 : -1.0;
    const double first = sign > 0.0 ? std::ceil(from) : std::floor(from);
    const double last = sign > 0.0 ? std::ceil(to) - 1.0 : std::floor(to) + 1.0;
    const long pixels = std::lround((last - first) * sign);
    edge.count = pixels < 0 ? 0 : static_cast<int>(pixels / sample_step_) + 1;
    const double slope = (edge.mostly_horizontal ? dv : du) / std::fabs(delta);
    const double t = (first - from) * sign;  // along the longer axis from a
    const double step = sign * sample_step_, step_across = slope * sample_step_;
    if (edge.mostly_horizontal) {
      edge.start = Point2d{first, a.v + t * slope};
      edge.step = Point2d{step, step_across};
    } else {
      edge.start = Point2d{a.u + t * slope, first};
      edge.step = Point2d{step_across, step};
    }
  }
  edge.spacing = std::hypot(edge.step.u, edge.step.v);
  perimeter_ += edge.count;
  edges_.push_back(edge);
}

void PolygonLoop::Assign(const std::vector<Point2d>& polygon, int sample_step) {
  sample_step_ = std::max(1, sample_step);
  vertices_.assign(polygon.begin(), polygon.end());
  edges_.clear();
  perimeter_ = 0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) AddEdge(polygon[i], polygon[(i + 1) % n]);
}

namespace {

// How many rows ahead an edge down the image asks for its pixels: each of its samples is on
// a row of its own, a cache line the hardware would fetch only when it is read.
constexpr std::ptrdiff_t kRowsAhead = 8;

// Samples `count` pixels stepping by `major_step` bytes along the longer axis, interpolated
// between the pixel and its neighbour `minor_step` bytes away across it, at the 16.16
// fixed-point coordinate across = start_fx + k step_fx (the pixel's offset across in whole
// pixels and its fraction). `origin` is the pixel at across = 0 of the first sample. The
// caller keeps every sample and its neighbour inside the image.
template <bool kPrefetch>
void SampleEdge(const std::uint8_t* origin, std::ptrdiff_t major_step, std::ptrdiff_t minor_step,
                std::int64_t start_fx, std::int64_t step_fx, int count, std::uint8_t* out) {
  std::int64_t across_fx = start_fx;
  for (int k = 0; k < count; ++k, across_fx += step_fx) {
    const std::ptrdiff_t whole = static_cast<std::ptrdiff_t>(across_fx >> 16);
    const int f = static_cast<int>((across_fx >> 8) & 255);
    const std::uint8_t* p = origin + k * major_step + whole * minor_step;
    if (kPrefetch) __builtin_prefetch(p + kRowsAhead * major_step);
    const int a = p[0];
    out[k] = static_cast<std::uint8_t>(a + (((p[minor_step] - a) * f + 128) >> 8));
  }
}

}  // namespace

bool PolygonLoop::SampleStretch(const GrayImageView& image, const Edge& edge, int offset_px,
                                int pixels_apart, int count, bool clamp, std::uint8_t* out) const {
  // The coordinate across the edge's longer axis in 16.16 fixed point; along it the samples
  // step by whole pixels.
  constexpr double kOne = 65536.0;
  const bool horizontal = edge.mostly_horizontal;
  const double start_across = horizontal ? edge.start.v : edge.start.u;
  const double sample_across = horizontal ? edge.step.v : edge.step.u;  // one sample_step_'s
  const double step_across =
      pixels_apart == sample_step_ ? sample_across : sample_across / sample_step_ * pixels_apart;
  const int limit = (horizontal ? image.height : image.width) - 2;  // last pixel with a neighbour
  const auto start_fx = static_cast<std::int64_t>(std::llround(
      (offset_px == 0 ? start_across : start_across + offset_px * (sample_across / sample_step_)) *
      kOne));
  const auto step_fx = static_cast<std::int64_t>(std::llround(step_across * kOne));
  const std::int64_t end_fx = start_fx + step_fx * (count - 1);
  const int sign = (horizontal ? edge.step.u : edge.step.v) > 0.0 ? 1 : -1;
  const int along =
      static_cast<int>(std::lround(horizontal ? edge.start.u : edge.start.v)) + sign * offset_px;
  const std::ptrdiff_t stride = image.stride;
  const std::ptrdiff_t major = horizontal ? sign * pixels_apart : sign * pixels_apart * stride;
  const std::ptrdiff_t minor = horizontal ? stride : 1;
  const std::uint8_t* origin = image.data + (horizontal ? along : along * stride);
  if (std::min(start_fx, end_fx) >= 0 && (std::max(start_fx, end_fx) >> 16) <= limit) {
    if (!clamp) {
      const int along_end = along + sign * pixels_apart * (count - 1);
      const int along_limit = (horizontal ? image.width : image.height) - 1;
      if (std::min(along, along_end) < 0 || std::max(along, along_end) > along_limit) {
        return false;
      }
    }
    if (horizontal) {
      SampleEdge<false>(origin, major, minor, start_fx, step_fx, count, out);
    } else {
      SampleEdge<true>(origin, major, minor, start_fx, step_fx, count, out);
    }
    return true;
  }
  if (!clamp) return false;
  // Where the last pixel row (column) would need its neighbour beyond the image, the
  // fraction is moved to the pixel before it.
  for (int k = 0; k < count; ++k) {
    const std::int64_t across_fx = start_fx + step_fx * k;
    std::ptrdiff_t whole = static_cast<std::ptrdiff_t>(across_fx >> 16);
    int f = static_cast<int>((across_fx >> 8) & 255);
    if (whole < 0) whole = 0, f = 0;
    if (whole > limit) whole = limit, f = 256;
    const std::uint8_t* p = origin + k * major + whole * minor;
    const int a = p[0];
    *out++ = static_cast<std::uint8_t>(a + (((p[minor] - a) * f + 128) >> 8));
  }
  return true;
}

void PolygonLoop::Gather(const GrayImageView& image, std::vector<std::uint8_t>* samples) const {
  samples->resize(static_cast<std::size_t>(perimeter_));
  std::uint8_t* out = samples->data();
  for (const Edge& edge : edges_) {
    if (edge.count == 0) continue;
    SampleStretch(image, edge, 0, sample_step_, edge.count, true, out);
    out += edge.count;
  }
}

int PolygonLoop::EdgeAt(double s) const {
  // The last edge with samples whose first sample is at or before s.
  int found = -1;
  for (int e = 0; e < static_cast<int>(edges_.size()); ++e) {
    const Edge& edge = edges_[static_cast<std::size_t>(e)];
    if (edge.count > 0 && edge.first <= s) found = e;
  }
  if (found < 0) {  // before the first edge with samples: the gap at the seam, the last one's
    for (int e = static_cast<int>(edges_.size()) - 1; e >= 0; --e) {
      if (edges_[static_cast<std::size_t>(e)].count > 0) return e;
    }
    return 0;
  }
  return found;
}

Point2d PolygonLoop::SampleAt(int k) const {
  k = ((k % perimeter_) + perimeter_) % perimeter_;
  const Edge& edge = edges_[static_cast<std::size_t>(EdgeAt(k))];
  const double j = k - edge.first;
  return Point2d{edge.start.u + j * edge.step.u, edge.start.v + j * edge.step.v};
}

bool PolygonLoop::GatherPixels(const GrayImageView& image, int first, int count,
                               std::uint8_t* out) const {
  if (first < 0 || count <= 0 || first >= perimeter_) return false;
  const Edge& edge = edges_[static_cast<std::size_t>(EdgeAt(first))];
  const int j = first - edge.first;  // the edge's sample
  if (j < 0 || j * sample_step_ + count - 1 > (edge.count - 1) * sample_step_) return false;
  return SampleStretch(image, edge, j * sample_step_, 1, count, false, out);
}

std::uint16_t PolygonLoop::Locate(double s, Point2d* pixel, double corner_px) const {
  if (perimeter_ <= 0) {
    *pixel = vertices_.empty() ? Point2d{} : vertices_.front();
    return 0;
  }
  s = std::fmod(s, static_cast<double>(perimeter_));
  if (s < 0.0) s += perimeter_;
  const int e = EdgeAt(s);
  const Edge& edge = edges_[static_cast<std::size_t>(e)];
  const double last = edge.first + edge.count - 1;
  if (s <= last) {
    const double j = s - edge.first;
    *pixel = Point2d{edge.start.u + j * edge.step.u, edge.start.v + j * edge.step.v};
  } else {  // in the gap after the edge's last sample: towards the next edge's first
    const Point2d a = SampleAt(static_cast<int>(last));
    const Point2d b = SampleAt(static_cast<int>(last) + 1);
    const double t = s - last;
    *pixel = Point2d{a.u + t * (b.u - a.u), a.v + t * (b.v - a.v)};
  }
  std::uint16_t sides = static_cast<std::uint16_t>(1u << e);
  // The vertex after this edge sits half a sample after its last sample, the one before it
  // half a sample before its first (the next / previous edge with samples).
  const int n = static_cast<int>(edges_.size());
  auto next_with_samples = [&](int from, int direction) {
    for (int k = 1; k <= n; ++k) {
      const int i = ((from + direction * k) % n + n) % n;
      if (edges_[static_cast<std::size_t>(i)].count > 0) return i;
    }
    return from;
  };
  if (s - (edge.first - 0.5) <= corner_px || s + perimeter_ - (edge.first - 0.5) <= corner_px) {
    sides |= static_cast<std::uint16_t>(1u << next_with_samples(e, -1));
  }
  if ((last + 0.5) - s <= corner_px) {
    sides |= static_cast<std::uint16_t>(1u << next_with_samples(e, 1));
  }
  return sides;
}

Point2d PolygonLoop::Direction(double s) const {
  if (perimeter_ <= 0) return Point2d{1.0, 0.0};
  s = std::fmod(s, static_cast<double>(perimeter_));
  if (s < 0.0) s += perimeter_;
  return edges_[static_cast<std::size_t>(EdgeAt(s))].direction;
}

double PolygonLoop::Spacing(double s) const {
  if (perimeter_ <= 0) return 1.0;
  s = std::fmod(s, static_cast<double>(perimeter_));
  if (s < 0.0) s += perimeter_;
  return edges_[static_cast<std::size_t>(EdgeAt(s))].spacing;
}

bool PolygonLoop::HasCornerInside(double first, double last) const {
  for (const Edge& edge : edges_) {
    if (edge.count == 0) continue;
    // The vertex before this edge's first sample.
    const double corner = edge.first - 0.5;
    for (const double c : {corner, corner + perimeter_, corner - perimeter_}) {
      if (first < c && c < last) return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------

bool RegionBorders::Inset(double d, int width, int height, double min_extent_px,
                          std::vector<Point2d>* out) {
  const double lo_u = d, hi_u = width - 1.0 - d, lo_v = d, hi_v = height - 1.0 - d;
  out->clear();
  if (!(hi_u - lo_u >= min_extent_px && hi_v - lo_v >= min_extent_px)) return false;
  // Sutherland-Hodgman on fixed arrays: the rectangle clipped by each edge's half-plane adds
  // at most one vertex per plane.
  constexpr std::size_t kMax = 4 + 2 * ScanRegion::kMaxVertices;
  std::array<Point2d, kMax> buffers[2];
  std::size_t n = 4;
  buffers[0][0] = {lo_u, lo_v};
  buffers[0][1] = {hi_u, lo_v};
  buffers[0][2] = {hi_u, hi_v};
  buffers[0][3] = {lo_u, hi_v};
  int current = 0;
  for (const HalfPlane& h : planes_) {
    const std::array<Point2d, kMax>& in = buffers[current];
    std::array<Point2d, kMax>& clipped = buffers[1 - current];
    std::size_t m = 0;
    double fp = h.nu * in[n - 1].u + h.nv * in[n - 1].v - h.c - d;
    for (std::size_t i = 0; i < n; ++i) {  // edge from in[i - 1] to in[i]
      const Point2d& p = in[(i + n - 1) % n];
      const Point2d& q = in[i];
      const double fq = h.nu * q.u + h.nv * q.v - h.c - d;
      if ((fp >= 0.0) != (fq >= 0.0) && m < kMax) {
        const double t = fp / (fp - fq);
        clipped[m++] = Point2d{p.u + t * (q.u - p.u), p.v + t * (q.v - p.v)};
      }
      if (fq >= 0.0 && m < kMax) clipped[m++] = q;
      fp = fq;
    }
    n = m;
    current = 1 - current;
    if (n < 3) return false;
  }
  // Consecutive vertices that coincide (a corner of the rectangle on an edge's line) once.
  const std::array<Point2d, kMax>& result = buffers[current];
  constexpr double kEps2 = 1e-12;
  for (std::size_t i = 0; i < n; ++i) {
    if (!out->empty() && DistanceSquared(result[i], out->back()) < kEps2) continue;
    out->push_back(result[i]);
  }
  while (out->size() > 1 && DistanceSquared(out->front(), out->back()) < kEps2) out->pop_back();
  if (out->size() < 3) return false;
  return min_extent_px <= 0.0 || MinimumWidth(*out) >= min_extent_px;
}

void RegionBorders::SetPlanes(const std::vector<Point2d>& polygon) {
  planes_.clear();
  const std::size_t n = polygon.size();
  const double sense = SignedArea(polygon) >= 0.0 ? 1.0 : -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2d& a = polygon[i];
    const Point2d& b = polygon[(i + 1) % n];
    const double length = std::hypot(b.u - a.u, b.v - a.v);
    if (!(length > 0.0)) continue;
    // Inside: sense * cross(b - a, p - a) >= 0, i.e. n . p >= n . a with n = sense (-dv, du).
    const double nu = -sense * (b.v - a.v) / length, nv = sense * (b.u - a.u) / length;
    planes_.push_back(HalfPlane{nu, nv, nu * a.u + nv * a.v});
  }
}

bool RegionBorders::Append(const std::vector<Point2d>& polygon) {
  const std::size_t i = static_cast<std::size_t>(count_);
  if (polygons_.size() <= i) {
    polygons_.emplace_back();
    loops_.emplace_back();
  }
  polygons_[i].assign(polygon.begin(), polygon.end());
  loops_[i].Assign(polygons_[i], sample_step_);
  if (loops_[i].Perimeter() < 4) return false;
  ++count_;
  return true;
}

void RegionBorders::Assign(const ScanBorders& borders, int width, int height, int first_px,
                           int step_px) {
  count_ = 0;
  inside_.clear();
  for (std::size_t k = 0; k < borders.polygons.size(); ++k) {
    SetPlanes(borders.polygons[k]);
    if (count_ == 0) Inset(0.0, width, height, 0.0, &inside_);
    // The image's edges at this border's distance; the polygon's own edges as given.
    const double d = first_px + static_cast<double>(k) * step_px;
    for (HalfPlane& h : planes_) h.c -= d;  // Inset() moves every plane by d: undo it here
    if (Inset(d, width, height, 2.0, &probe_)) Append(probe_);
  }
}

void RegionBorders::Build(const ScanRegion& region, int width, int height, int first_px,
                          int step_px, int max_borders) {
  SetPlanes(region.vertices);
  Inset(0.0, width, height, 0.0, &inside_);
  // How deep the borders go at step_px (total borders, found by bisection on the border
  // index: an inset is empty beyond the region's inradius), then the spacing that keeps them
  // to max_borders, evenly spread over the same depth.
  auto exists = [&](int k) {
    return Inset(first_px + static_cast<double>(k) * step_px, width, height, 2.0, &probe_);
  };
  int total = 0;
  if (exists(0)) {
    int lo = 0, hi = 1;  // exists(lo), !exists(hi) once found
    while (exists(hi)) {
      lo = hi;
      hi *= 2;
    }
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      (exists(mid) ? lo : hi) = mid;
    }
    total = lo + 1;
  }
  double spacing = step_px;
  if (max_borders > 1 && total > max_borders) {
    spacing = static_cast<double>(step_px) * (total - 1) / (max_borders - 1);
  }
  count_ = 0;
  for (int k = 0; k < total; ++k) {
    const double d = first_px + k * spacing;
    if (d > first_px + (total - 1.0) * step_px + 1e-9) break;
    // d is within the depth found above, so the border exists: no width check.
    if (!Inset(d, width, height, 0.0, &probe_) || !Append(probe_)) break;
  }
}

}  // namespace oal
