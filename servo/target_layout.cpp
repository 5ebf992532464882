#include "servo/target_layout.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "detector/lens.h"  // Kdu, DistortedOverIdeal
#include "servo/pose_internal.h"

namespace oal {
namespace {

// The outer rectangle lies this far inside the stripes' printed ends (a border right at an
// end would cut the stripe's end), the inner one this far outside the crossings. Metres.
constexpr double kInsideEndsM = 0.0025;
constexpr double kOutsideCrossingsM = 0.003;
// Pixels beyond which a mapped corner is taken as "at infinity" (a border seen edge-on).
constexpr double kFarPx = 1e5;

double Cross(const Point2d& a, const Point2d& b) {
  return a.u * b.v - a.v * b.u;
}

// Whether the four points turn the same way at every corner, enclosing more than a pixel.
bool IsConvexQuadrilateral(const std::vector<Point2d>& q) {
  double first = 0.0;
  for (int k = 0; k < 4; ++k) {
    const Point2d& a = q[static_cast<std::size_t>(k)];
    const Point2d& b = q[static_cast<std::size_t>((k + 1) % 4)];
    const Point2d& c = q[static_cast<std::size_t>((k + 2) % 4)];
    const double turn = Cross(Point2d{b.u - a.u, b.v - a.v}, Point2d{c.u - b.u, c.v - b.v});
    if (k == 0) first = turn;
    if (!(turn * first > 0.0)) return false;
  }
  return std::fabs(SignedArea(q)) > 1.0;
}

// '#' coordinates (a, b) of an object-plane point.
struct HashFrame {
  Point2d origin, axis_a, axis_b;
  double det = 1.0;

  void Coordinates(double x, double y, double* a, double* b) const {
    const Point2d d{x - origin.u, y - origin.v};
    *a = Cross(d, axis_b) / det;
    *b = Cross(axis_a, d) / det;
  }
};

// The span of target line `k`, which runs along axis b (`along_b`) or axis a.
StripeSpan SpanOf(const HashFrame& frame, const TargetLine& line, bool along_b, double sin_angle) {
  double a1 = 0.0, b1 = 0.0, a2 = 0.0, b2 = 0.0;
  frame.Coordinates(line.x1_m, line.y1_m, &a1, &b1);
  frame.Coordinates(line.x2_m, line.y2_m, &a2, &b2);
  StripeSpan span;
  span.along_b = along_b;
  span.at = along_b ? 0.5 * (a1 + a2) : 0.5 * (b1 + b2);
  const double from = along_b ? b1 : a1, to = along_b ? b2 : a2;
  span.along = Interval{std::min(from, to), std::max(from, to)};
  span.half = 0.5 * line.width_m / sin_angle;
  return span;
}

// Where both stripes of a pair are printed, less the margin inside their ends.
Interval BothPrinted(const StripeSpan& s, const StripeSpan& t) {
  return Interval{std::max(s.along.lo, t.along.lo) + kInsideEndsM,
                  std::min(s.along.hi, t.along.hi) - kInsideEndsM};
}

// Just outside the pair's stripes (their outer edges plus the margin).
Interval OutsidePair(const StripeSpan& s, const StripeSpan& t) {
  return Interval{std::min(s.at - s.half, t.at - t.half) - kOutsideCrossingsM,
                  std::max(s.at + s.half, t.at + t.half) + kOutsideCrossingsM};
}

// Between the pair's inner edges.
Interval BetweenPair(const StripeSpan& s, const StripeSpan& t) {
  const StripeSpan& low = s.at <= t.at ? s : t;
  const StripeSpan& high = s.at <= t.at ? t : s;
  return Interval{low.at + low.half, high.at - high.half};
}

}  // namespace

std::optional<vpHomography> FourPointHomography(const std::array<Point2d, 4>& plane,
                                                const std::array<Point2d, 4>& image,
                                                const Point2d& origin) {
  Eigen::Matrix<double, 8, 8> a;
  Eigen::Matrix<double, 8, 1> b;
  for (int k = 0; k < 4; ++k) {
    const double X = plane[static_cast<std::size_t>(k)].u - origin.u;
    const double Y = plane[static_cast<std::size_t>(k)].v - origin.v;
    const double x = image[static_cast<std::size_t>(k)].u, y = image[static_cast<std::size_t>(k)].v;
    a.row(2 * k) << X, Y, 1.0, 0.0, 0.0, 0.0, -x * X, -x * Y;
    a.row(2 * k + 1) << 0.0, 0.0, 0.0, X, Y, 1.0, -y * X, -y * Y;
    b(2 * k) = x;
    b(2 * k + 1) = y;
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(a);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix<double, 8, 1> h = lu.solve(b);
  if (!h.allFinite()) return std::nullopt;
  // From the origin-centred plane coordinates back to the plane's: H · translate(-origin).
  const double centred[3][3] = {{h(0), h(1), h(2)}, {h(3), h(4), h(5)}, {h(6), h(7), 1.0}};
  vpHomography result;
  for (int r = 0; r < 3; ++r) {
    result[r][0] = centred[r][0];
    result[r][1] = centred[r][1];
    result[r][2] = centred[r][2] - centred[r][0] * origin.u - centred[r][1] * origin.v;
  }
  return result;
}

std::optional<vpHomogeneousMatrix> PlanePose(const vpHomography& h) {
  Eigen::Matrix3d columns;
  for (int r = 0; r < 3; ++r) columns.row(r) << h[r][0], h[r][1], h[r][2];
  const double scale = std::sqrt(columns.col(0).norm() * columns.col(1).norm());
  if (!(scale > 0.0) || !std::isfinite(scale)) return std::nullopt;
  columns /= scale;
  Eigen::Matrix3d rotation;
  rotation << columns.col(0), columns.col(1), columns.col(0).cross(columns.col(1));
  // The nearest rotation (the homography of measured points is not exactly a rigid one).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0.0) return std::nullopt;
  vpHomogeneousMatrix cMo;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) cMo[r][c] = rotation(r, c);
    cMo[r][3] = columns(r, 2);
  }
  return cMo;
}

Point2d TargetLayout::ToPlane(double a, double b) const {
  return Point2d{origin.u + a * axis_a.u + b * axis_b.u, origin.v + a * axis_a.v + b * axis_b.v};
}

Point2d TargetLayout::OnStripe(int k, double along, double across) const {
  const StripeSpan& stripe = stripes[static_cast<std::size_t>(k)];
  const double at = stripe.at + across;
  return stripe.along_b ? ToPlane(at, along) : ToPlane(along, at);
}

TargetLayout TargetLayout::Of(const LineTarget& target) {
  const pose_internal::HashTarget hash = pose_internal::HashTargetFrom(target);
  TargetLayout layout;
  for (const auto& corner : hash.corner) {
    layout.origin.u += 0.25 * corner.x;
    layout.origin.v += 0.25 * corner.y;
  }
  layout.axis_a = Point2d{hash.direction[1].x, hash.direction[1].y};
  layout.axis_b = Point2d{hash.direction[0].x, hash.direction[0].y};
  const HashFrame frame{layout.origin, layout.axis_a, layout.axis_b,
                        Cross(layout.axis_a, layout.axis_b)};
  const double sin_angle = std::fabs(frame.det);
  const StripeSpan line1 = SpanOf(frame, target.lines[0], true, sin_angle);
  const StripeSpan line3 = SpanOf(frame, target.lines[2], true, sin_angle);
  const StripeSpan line2 = SpanOf(frame, target.lines[1], false, sin_angle);
  const StripeSpan line4 = SpanOf(frame, target.lines[3], false, sin_angle);
  layout.stripes = {line1, line2, line3, line4};
  // Lines 2 and 4 run along a: their printed ends bound a; lines 1 and 3 bound b.
  layout.outer_a = BothPrinted(line2, line4);
  layout.outer_b = BothPrinted(line1, line3);
  layout.inner_a = OutsidePair(line1, line3);
  layout.inner_b = OutsidePair(line2, line4);
  if (!(layout.outer_a.lo < layout.inner_a.lo && layout.outer_a.hi > layout.inner_a.hi &&
        layout.outer_b.lo < layout.inner_b.lo && layout.outer_b.hi > layout.inner_b.hi)) {
    throw std::invalid_argument(
        "target '" + target.name +
        "': its stripes do not reach beyond the crossings on every side (each must run at least " +
        std::to_string(1000.0 * (kInsideEndsM + kOutsideCrossingsM)) +
        " mm past the stripes it crosses), so no border crosses all four");
  }
  const Interval cell_a = BetweenPair(line1, line3), cell_b = BetweenPair(line2, line4);
  layout.middle_cell = {layout.ToPlane(cell_a.lo, cell_b.lo), layout.ToPlane(cell_a.hi, cell_b.lo),
                        layout.ToPlane(cell_a.hi, cell_b.hi), layout.ToPlane(cell_a.lo, cell_b.hi)};
  std::vector<Point2d> cell(layout.middle_cell.begin(), layout.middle_cell.end());
  if (SignedArea(cell) < 0.0) std::reverse(layout.middle_cell.begin(), layout.middle_cell.end());
  const double half_w = 0.5 * target.board_width_m, half_h = 0.5 * target.board_height_m;
  // Where the board's edge is from `from` along `direction` (the board centred on the object
  // origin, its sides along x and y).
  const auto to_edge = [&](const Point2d& from, const Point2d& direction) {
    double t = HUGE_VAL;
    if (direction.u > 1e-12) t = std::min(t, (half_w - from.u) / direction.u);
    if (direction.u < -1e-12) t = std::min(t, (-half_w - from.u) / direction.u);
    if (direction.v > 1e-12) t = std::min(t, (half_h - from.v) / direction.v);
    if (direction.v < -1e-12) t = std::min(t, (-half_h - from.v) / direction.v);
    return Point2d{from.u + t * direction.u, from.v + t * direction.v};
  };
  // Beyond the lower stripe of the pair 2/4 (along -b), between lines 1 and 3; beyond the lower
  // of 1/3 (along -a), between lines 2 and 4.
  const StripeSpan& low_b = line2.at <= line4.at ? line2 : line4;
  const StripeSpan& low_a = line1.at <= line3.at ? line1 : line3;
  const double out_b = low_b.at - low_b.half, out_a = low_a.at - low_a.half;
  const Point2d minus_b{-layout.axis_b.u, -layout.axis_b.v};
  const Point2d minus_a{-layout.axis_a.u, -layout.axis_a.v};
  const std::array<std::array<Point2d, 2>, 2> inner = {
      std::array<Point2d, 2>{layout.ToPlane(cell_a.lo, out_b), layout.ToPlane(cell_a.hi, out_b)},
      std::array<Point2d, 2>{layout.ToPlane(out_a, cell_b.hi), layout.ToPlane(out_a, cell_b.lo)}};
  for (std::size_t e = 0; e < 2; ++e) {
    const Point2d& direction = e == 0 ? minus_b : minus_a;
    TargetLayout::EdgeCell& edge = layout.edge_cells[e];
    edge.corners = {inner[e][0], inner[e][1], to_edge(inner[e][1], direction),
                    to_edge(inner[e][0], direction)};
    edge.outer = 2;
    if (SignedArea({edge.corners.begin(), edge.corners.end()}) < 0.0) {
      std::reverse(edge.corners.begin(), edge.corners.end());
      edge.outer = 0;
    }
  }
  const StripeSpan& high_b = line2.at <= line4.at ? line4 : line2;
  const StripeSpan& high_a = line1.at <= line3.at ? line3 : line1;
  for (std::size_t c = 0; c < 4; ++c) {
    const bool low_side_a = c < 2, low_side_b = c % 2 == 0;
    const double a = low_side_a ? out_a : high_a.at + high_a.half;
    const double b = low_side_b ? out_b : high_b.at + high_b.half;
    const Point2d meet = layout.ToPlane(a, b);
    const Point2d along_a = to_edge(meet, low_side_a ? minus_a : layout.axis_a);
    const Point2d along_b = to_edge(meet, low_side_b ? minus_b : layout.axis_b);
    TargetLayout::CornerCell& corner = layout.corner_cells[c];
    corner.corners = {meet, along_a, to_edge(along_a, low_side_b ? minus_b : layout.axis_b),
                      along_b};
    corner.inner = 0;
    if (SignedArea({corner.corners.begin(), corner.corners.end()}) < 0.0) {
      std::reverse(corner.corners.begin(), corner.corners.end());
      corner.inner = 3;
    }
  }
  return layout;
}

vpHomography PlaneToImage(const vpHomogeneousMatrix& cMo) {
  vpHomography h;
  for (unsigned int r = 0; r < 3; ++r) {
    h[r][0] = cMo[r][0];
    h[r][1] = cMo[r][1];
    h[r][2] = cMo[r][3];
  }
  return h;
}

bool ProjectPlanePoint(const vpHomography& plane_to_image, const Lens& camera, const Point2d& plane,
                       Point2d* pixel) {
  return PlaneProjector(plane_to_image, camera).Project(plane, pixel);
}

PlaneProjector::PlaneProjector(const vpHomography& plane_to_image, const Lens& camera)
    : camera_(camera) {
  for (unsigned int r = 0; r < 3; ++r) {
    for (unsigned int c = 0; c < 3; ++c) h_[r][c] = plane_to_image[r][c];
  }
}

bool PlaneProjector::Project(const Point2d& plane, Point2d* pixel) const {
  const double w = h_[2][0] * plane.u + h_[2][1] * plane.v + h_[2][2];
  if (!(w > 1e-9)) return false;
  const double inverse_w = 1.0 / w;
  const double x = (h_[0][0] * plane.u + h_[0][1] * plane.v + h_[0][2]) * inverse_w;
  const double y = (h_[1][0] * plane.u + h_[1][1] * plane.v + h_[1][2]) * inverse_w;
  *pixel = camera_.Pixel(x, y);
  return std::isfinite(pixel->u) && std::isfinite(pixel->v) && std::fabs(pixel->u) < kFarPx &&
         std::fabs(pixel->v) < kFarPx;
}

ScanBorders TargetBorders(const TargetLayout& layout, const vpHomography& plane_to_image,
                          const Lens& camera, int count) {
  ScanBorders borders;
  TargetBorders(layout, plane_to_image, camera, count, &borders);
  return borders;
}

namespace {

// The rectangle a x b of the '#' frame mapped into the image as *polygon (its memory reused);
// false when a corner does not project or the lens folds it (a quadrilateral seen near the edge
// of the lens's reach): only convex ones are kept.
bool ProjectRectangle(const TargetLayout& layout, const PlaneProjector& projector,
                      const Interval& a, const Interval& b, std::vector<Point2d>* polygon) {
  const Point2d corners[4] = {layout.ToPlane(a.lo, b.lo), layout.ToPlane(a.hi, b.lo),
                              layout.ToPlane(a.hi, b.hi), layout.ToPlane(a.lo, b.hi)};
  polygon->resize(4);
  for (int c = 0; c < 4; ++c) {
    if (!projector.Project(corners[c], &(*polygon)[static_cast<std::size_t>(c)])) return false;
  }
  return IsConvexQuadrilateral(*polygon);
}

}  // namespace

void TargetBorders(const TargetLayout& layout, const vpHomography& plane_to_image,
                   const Lens& camera, int count, ScanBorders* out) {
  std::vector<std::vector<Point2d>>& polygons = out->polygons;
  const PlaneProjector projector(plane_to_image, camera);
  std::size_t used = 0;
  auto lerp = [](const Interval& from, const Interval& to, double f) {
    return Interval{from.lo + f * (to.lo - from.lo), from.hi + f * (to.hi - from.hi)};
  };
  for (int k = 0; k < count; ++k) {
    const double f = count > 1 ? static_cast<double>(k) / (count - 1) : 0.0;
    const Interval a = lerp(layout.outer_a, layout.inner_a, f);
    const Interval b = lerp(layout.outer_b, layout.inner_b, f);
    if (polygons.size() <= used) polygons.emplace_back();
    if (ProjectRectangle(layout, projector, a, b, &polygons[used])) ++used;
  }
  polygons.resize(used);
}

void AddMiddleBorders(const TargetLayout& layout, const vpHomography& plane_to_image,
                      const Lens& camera, int per_pair, ScanBorders* out) {
  const PlaneProjector projector(plane_to_image, camera);
  const auto& s = layout.stripes;
  const Interval cell_a = BetweenPair(s[0], s[2]), cell_b = BetweenPair(s[1], s[3]);
  for (int pair = 0; pair < 2; ++pair) {
    // Across lines 1 and 3 (pair 0): the outer rectangle's extent along a, a band of b inside
    // the middle cell; across lines 2 and 4 the same turned.
    const Interval& across = pair == 0 ? cell_b : cell_a;
    const double middle = 0.5 * (across.lo + across.hi), half = 0.5 * (across.hi - across.lo);
    for (int k = 0; k < per_pair; ++k) {
      // From near the crossing stripes' edges to near the cell's middle line.
      const double f = 0.85 - 0.6 * (per_pair > 1 ? static_cast<double>(k) / (per_pair - 1) : 0.0);
      const Interval band{middle - f * half, middle + f * half};
      const Interval a = pair == 0 ? layout.outer_a : band;
      const Interval b = pair == 0 ? band : layout.outer_b;
      std::vector<Point2d> polygon;
      if (ProjectRectangle(layout, projector, a, b, &polygon)) {
        out->polygons.push_back(std::move(polygon));
      }
    }
  }
}

std::optional<vpHomography> PlaneToImageFromCell(const TargetLayout& layout, const LightQuad& cell,
                                                 const Lens& camera) {
  std::array<Point2d, 4> image;
  for (int k = 0; k < 4; ++k) {
    const Point2d& corner = cell.corners[static_cast<std::size_t>(k)];
    Point2d& normalised = image[static_cast<std::size_t>(k)];
    normalised = camera.Normalised(corner.u, corner.v);
    if (!std::isfinite(normalised.u) || !std::isfinite(normalised.v)) return std::nullopt;
  }
  std::optional<vpHomography> best;
  double best_cost = HUGE_VAL;
  for (int shift = 0; shift < 2; ++shift) {
    std::array<Point2d, 4> plane;
    for (int k = 0; k < 4; ++k) {
      plane[static_cast<std::size_t>(k)] =
          layout.middle_cell[static_cast<std::size_t>((k + 4 - shift) % 4)];
    }
    std::optional<vpHomography> found = FourPointHomography(plane, image, layout.origin);
    if (!found) continue;
    const vpHomography& h = *found;  // the cell in front: third coordinate 1 at the origin
    const double h1[3] = {h[0][0], h[1][0], h[2][0]}, h2[3] = {h[0][1], h[1][1], h[2][1]};
    const double n1 = std::sqrt(h1[0] * h1[0] + h1[1] * h1[1] + h1[2] * h1[2]);
    const double n2 = std::sqrt(h2[0] * h2[0] + h2[1] * h2[1] + h2[2] * h2[2]);
    if (!(n1 > 0.0 && n2 > 0.0)) continue;
    const double log_ratio = std::log(n1 / n2);
    const double cosine = (h1[0] * h2[0] + h1[1] * h2[1] + h1[2] * h2[2]) / (n1 * n2);
    const double cost = log_ratio * log_ratio + cosine * cosine;
    if (cost < best_cost) {
      best_cost = cost;
      best = h;
    }
  }
  return best;
}

std::vector<LightQuad> UncutCells(const TargetLayout& layout, const LightQuad& cell, int cut) {
  constexpr double kMinLengthening = 1.1;
  const auto length = [](const Point2d& a, const Point2d& b) {
    return std::hypot(b.u - a.u, b.v - a.v);
  };
  const std::array<Point2d, 4>& plane = layout.middle_cell;
  const double side_a = length(plane[0], plane[1]), side_b = length(plane[1], plane[2]);
  const std::array<Point2d, 4>& c = cell.corners;
  const auto at = [&](int k) { return c[static_cast<std::size_t>((k % 4 + 4) % 4)]; };
  // The opposite side keeps both its corners; the sides beside the cut one run from them.
  const Point2d from_1 = at(cut + 2), from_0 = at(cut + 3);
  const Point2d to_1 = at(cut + 1), to_0 = at(cut);
  const double opposite = length(from_1, from_0);
  const double beside_1 = length(from_1, to_1), beside_0 = length(from_0, to_0);
  std::vector<LightQuad> cells;
  if (!(opposite > 0.0 && beside_1 > 0.0 && beside_0 > 0.0)) return cells;
  for (const double aspect : {side_b / side_a, side_a / side_b}) {
    const double wanted = aspect * opposite;
    if (wanted < kMinLengthening * std::max(beside_1, beside_0)) continue;
    LightQuad uncut = cell;
    uncut.corners[static_cast<std::size_t>((cut + 1) % 4)] =
        Point2d{from_1.u + (to_1.u - from_1.u) * wanted / beside_1,
                from_1.v + (to_1.v - from_1.v) * wanted / beside_1};
    uncut.corners[static_cast<std::size_t>(cut % 4)] =
        Point2d{from_0.u + (to_0.u - from_0.u) * wanted / beside_0,
                from_0.v + (to_0.v - from_0.v) * wanted / beside_0};
    const std::vector<Point2d> polygon(uncut.corners.begin(), uncut.corners.end());
    if (ConvexHull(polygon).size() == 4) cells.push_back(uncut);
  }
  std::sort(cells.begin(), cells.end(), [&](const LightQuad& a, const LightQuad& b) {
    return length(a.corners[static_cast<std::size_t>(cut % 4)], from_0) >
           length(b.corners[static_cast<std::size_t>(cut % 4)], from_0);
  });
  return cells;
}

std::optional<vpHomography> PlaneToImageFromEdgeCell(const TargetLayout::EdgeCell& edge,
                                                     const LightQuad& cell, const Lens& camera) {
  if (cell.ClosedSideCount() != 3) return std::nullopt;
  int open = 0;
  while ((cell.closed_sides >> open) & 1) ++open;
  return PlaneToImageFromEdgeCell(edge, cell, camera, open);
}

std::optional<vpHomography> PlaneToImageFromEdgeCell(const TargetLayout::EdgeCell& edge,
                                                     const LightQuad& cell, const Lens& camera,
                                                     int outer) {
  // The cell's outer side onto the quadrilateral's side `outer`.
  return PlaneToImageFromCorners(edge.corners, edge.outer, cell, outer, camera);
}

std::optional<vpHomography> PlaneToImageFromCorners(const std::array<Point2d, 4>& plane_corners,
                                                    int plane_first, const LightQuad& quad,
                                                    int quad_first, const Lens& camera) {
  std::array<Point2d, 4> image, plane;
  Point2d centre{0.0, 0.0};
  for (int k = 0; k < 4; ++k) {
    const std::size_t i = static_cast<std::size_t>((k + quad_first - plane_first + 4) % 4);
    const Point2d& corner = quad.corners[i];
    Point2d& normalised = image[static_cast<std::size_t>(k)];
    normalised = camera.Normalised(corner.u, corner.v);
    if (!std::isfinite(normalised.u) || !std::isfinite(normalised.v)) return std::nullopt;
    plane[static_cast<std::size_t>(k)] = plane_corners[static_cast<std::size_t>(k)];
    centre = Point2d{centre.u + 0.25 * plane[static_cast<std::size_t>(k)].u,
                     centre.v + 0.25 * plane[static_cast<std::size_t>(k)].v};
  }
  return FourPointHomography(plane, image, centre);
}

}  // namespace oal
