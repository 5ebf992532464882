// Points of the target's plane projected through a lens (servo/target_layout.h): the pixel
// PlaneProjector gives maps back, through ViSP's own pixel-to-metre conversion, to the ideal
// point the homography gives, for barrel and pincushion lenses, near and far from the centre;
// the edge and corner cells of an A3 sheet and the homographies from them as a finder sees them.
#include "servo/target_layout.h"

#include <gtest/gtest.h>
#include <visp3/core/vpPixelMeterConversion.h>
#include <visp3/core/vpRxyzVector.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "detector/lens.h"    // CameraWithKdu
#include "detector/region.h"  // SignedArea

namespace oal {
namespace {

TEST(PlaneProjector, ItsPixelsAreViSPsDistortedProjection) {
  // A plane tilted 25 and 15 degrees, 0.45 m away: its points reach normalised radii of 0.9.
  const vpHomogeneousMatrix cMo(vpTranslationVector(0.03, -0.02, 0.45),
                                vpRotationMatrix(vpRxyzVector(0.44, -0.26, 0.7)));
  const vpHomography plane_to_image = PlaneToImage(cMo);
  for (const double kdu : {-0.3, -0.12, 0.0, 0.05, 0.15, 0.4, 1.2}) {
    const Lens camera = Lens::WithKdu(600.0, 610.0, 319.5, 239.5, kdu, 640, 480);
    const PlaneProjector projector(plane_to_image, camera);
    int projected = 0;
    for (double X = -0.3; X <= 0.3; X += 0.025) {
      for (double Y = -0.3; Y <= 0.3; Y += 0.025) {
        const double w = cMo[2][0] * X + cMo[2][1] * Y + cMo[2][3];
        const double x = (cMo[0][0] * X + cMo[0][1] * Y + cMo[0][3]) / w;
        const double y = (cMo[1][0] * X + cMo[1][1] * Y + cMo[1][3]) / w;
        Point2d pixel;
        if (!projector.Project({X, Y}, &pixel)) {
          // Only a pincushion lens has ideal radii no pixel reaches: beyond its turning point.
          EXPECT_LT(kdu, 0.0);
          EXPECT_GT(x * x + y * y, -4.0 / (27.0 * kdu)) << "X " << X << " Y " << Y;
          continue;
        }
        ++projected;
        double x_back = 0.0, y_back = 0.0;
        vpPixelMeterConversion::convertPoint(camera.ViSPCamera(640, 480), pixel.u, pixel.v, x_back,
                                             y_back);
        EXPECT_NEAR(x_back, x, 1e-9) << "kdu " << kdu << " X " << X << " Y " << Y;
        EXPECT_NEAR(y_back, y, 1e-9) << "kdu " << kdu << " X " << X << " Y " << Y;
      }
    }
    EXPECT_GT(projected, 300) << "kdu " << kdu;
  }
}

}  // namespace
}  // namespace oal

namespace oal {
namespace {

// The quadrilateral a sheet finder sees at a cell's corners (`cell`, on the target plane)
// through `truth`, its corners turned so that the cell's corner `plane_first` is its corner
// `quad_first`.
LightQuad QuadSeenAt(const std::array<Point2d, 4>& cell, int plane_first, int quad_first,
                     const vpHomography& truth, const Lens& camera) {
  LightQuad quad;
  for (int k = 0; k < 4; ++k) {
    const Point2d& plane = cell[static_cast<std::size_t>((k + plane_first - quad_first + 4) % 4)];
    EXPECT_TRUE(
        ProjectPlanePoint(truth, camera, plane, &quad.corners[static_cast<std::size_t>(k)]));
  }
  return quad;
}

// `found` puts the middle cell's corners where the pose's homography `truth` does.
void ExpectMapsAsThePose(const std::optional<vpHomography>& found, const vpHomography& truth,
                         const TargetLayout& layout, const Lens& camera) {
  ASSERT_TRUE(found.has_value());
  for (const Point2d& plane : layout.middle_cell) {
    Point2d a, b;
    ASSERT_TRUE(ProjectPlanePoint(*found, camera, plane, &a));
    ASSERT_TRUE(ProjectPlanePoint(truth, camera, plane, &b));
    EXPECT_NEAR(a.u, b.u, 1e-6);
    EXPECT_NEAR(a.v, b.v, 1e-6);
  }
}

// An A3 sheet's edge cells: between two stripes' inner edges, from the stripe they cross out to
// the sheet's edge; a quadrilateral seen at their corners, its open side on the sheet's edge,
// maps the plane as the pose does.
TEST(TargetLayout, EdgeCellsReachTheSheetsEdgeAndMapBackThroughTheirOpenSide) {
  const LineTarget target = FourLineA3Target();
  const TargetLayout layout = TargetLayout::Of(target);
  // [0] beyond line 2 (y = -0.062, 12 mm), between lines 1 and 3's inner edges; [1] beyond
  // line 1 (x = -0.090, 24 mm), between lines 2 and 4's inner edges.
  const TargetLayout::EdgeCell& above = layout.edge_cells[0];
  const TargetLayout::EdgeCell& left = layout.edge_cells[1];
  double min_y = HUGE_VAL, max_y = -HUGE_VAL, min_x = HUGE_VAL;
  for (const Point2d& c : above.corners) {
    min_y = std::min(min_y, c.v);
    max_y = std::max(max_y, c.v);
  }
  for (const Point2d& c : left.corners) min_x = std::min(min_x, c.u);
  EXPECT_NEAR(min_y, -0.1485, 1e-9);         // the sheet's edge
  EXPECT_NEAR(max_y, -0.062 - 0.006, 1e-9);  // line 2's outer edge
  EXPECT_NEAR(min_x, -0.21, 1e-9);
  const vpCameraParameters camera(600.0, 600.0, 319.5, 239.5);
  const vpHomogeneousMatrix cMo(0.01, 0.02, 0.5, 0.2, -0.1, 0.7);
  const vpHomography truth = PlaneToImage(cMo);
  for (const TargetLayout::EdgeCell& edge : layout.edge_cells) {
    for (int open_at = 0; open_at < 4; ++open_at) {
      // The quadrilateral as a finder would give it, its corners turned to start anywhere.
      LightQuad quad = QuadSeenAt(edge.corners, edge.outer, open_at, truth, camera);
      quad.closed_sides = static_cast<std::uint8_t>(0xF & ~(1u << open_at));
      ExpectMapsAsThePose(PlaneToImageFromEdgeCell(edge, quad, camera), truth, layout, camera);
    }
  }
  LightQuad closed;
  closed.closed_sides = 0xF;
  EXPECT_FALSE(PlaneToImageFromEdgeCell(above, closed, camera).has_value());
}

// An A3 sheet's corner cells: each from the outer edges of one stripe of each pair, where they
// meet, out to one of the sheet's corners, clear of every stripe; a quadrilateral seen at a
// cell's corners, starting anywhere, maps the plane as the pose does when its corner where the
// closed sides meet is laid on the cell's inner one.
TEST(TargetLayout, CornerCellsReachTheSheetsCornersAndMapBackFromTheirClosedCorner) {
  const LineTarget target = FourLineA3Target();
  const TargetLayout layout = TargetLayout::Of(target);
  std::vector<std::pair<double, double>> sheet_corners;
  for (const TargetLayout::CornerCell& cell : layout.corner_cells) {
    const Point2d& inner = cell.corners[static_cast<std::size_t>(cell.inner)];
    // Lines 1 (x = -0.09, 24 mm) and 3 (x = 0.09, 16 mm); 2 (y = -0.062, 12 mm), 4 (y = 0.062,
    // 14 mm): the inner corner at the outer edges of one of each.
    EXPECT_NEAR(std::fabs(inner.u), inner.u < 0.0 ? 0.102 : 0.098, 1e-9);
    EXPECT_NEAR(std::fabs(inner.v), inner.v < 0.0 ? 0.068 : 0.069, 1e-9);
    const Point2d& far = cell.corners[static_cast<std::size_t>((cell.inner + 2) % 4)];
    EXPECT_NEAR(std::fabs(far.u), 0.21, 1e-9);
    EXPECT_NEAR(std::fabs(far.v), 0.1485, 1e-9);
    EXPECT_GT(far.u * inner.u, 0.0);
    EXPECT_GT(far.v * inner.v, 0.0);
    sheet_corners.emplace_back(far.u, far.v);
    // In the middle cell's turning sense.
    EXPECT_GT(SignedArea({cell.corners.begin(), cell.corners.end()}) *
                  SignedArea({layout.middle_cell.begin(), layout.middle_cell.end()}),
              0.0);
  }
  std::sort(sheet_corners.begin(), sheet_corners.end());
  EXPECT_EQ(std::unique(sheet_corners.begin(), sheet_corners.end()), sheet_corners.end());

  const vpCameraParameters camera(600.0, 600.0, 319.5, 239.5);
  const vpHomogeneousMatrix cMo(0.01, 0.02, 0.5, 0.2, -0.1, 0.7);
  const vpHomography truth = PlaneToImage(cMo);
  for (const TargetLayout::CornerCell& cell : layout.corner_cells) {
    for (int inner_at = 0; inner_at < 4; ++inner_at) {
      const LightQuad quad = QuadSeenAt(cell.corners, cell.inner, inner_at, truth, camera);
      ExpectMapsAsThePose(PlaneToImageFromCorners(cell.corners, cell.inner, quad, inner_at, camera),
                          truth, layout, camera);
    }
  }
}

// The A3 sheet's middle cell seen face on (its image an exact scaling of it), a tool lying
// across it parallel to one side: the cell the sheet finder sees ends at the tool's edge. Taken
// as cut there, its two sides beside the cut are lengthened back to the whole cell.
TEST(TargetLayout, AMiddleCellCutByAToolIsLengthenedBackToItsShape) {
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  constexpr double kPxPerMetre = 1000.0;
  LightQuad whole;
  for (std::size_t k = 0; k < 4; ++k) {
    whole.corners[k] = Point2d{320.0 + kPxPerMetre * layout.middle_cell[k].u,
                               240.0 + kPxPerMetre * layout.middle_cell[k].v};
  }
  for (int cut = 0; cut < 4; ++cut) {
    // The corners cut and cut + 1 moved 40 % of the way towards the opposite side's.
    LightQuad seen = whole;
    const auto towards = [](const Point2d& a, const Point2d& b) {
      return Point2d{a.u + 0.4 * (b.u - a.u), a.v + 0.4 * (b.v - a.v)};
    };
    seen.corners[static_cast<std::size_t>(cut)] =
        towards(whole.corners[static_cast<std::size_t>(cut)],
                whole.corners[static_cast<std::size_t>((cut + 3) % 4)]);
    seen.corners[static_cast<std::size_t>((cut + 1) % 4)] =
        towards(whole.corners[static_cast<std::size_t>((cut + 1) % 4)],
                whole.corners[static_cast<std::size_t>((cut + 2) % 4)]);
    const std::vector<LightQuad> uncut = UncutCells(layout, seen, cut);
    ASSERT_FALSE(uncut.empty()) << "cut " << cut;
    double best = HUGE_VAL;
    for (const LightQuad& cell : uncut) {
      double worst = 0.0;
      for (std::size_t k = 0; k < 4; ++k) {
        worst = std::max(worst, std::hypot(cell.corners[k].u - whole.corners[k].u,
                                           cell.corners[k].v - whole.corners[k].v));
      }
      best = std::min(best, worst);
    }
    EXPECT_LT(best, 1e-6) << "cut " << cut;
    // The whole cell is not lengthened the right way round: only the other aspect, if at all.
    for (const LightQuad& cell : UncutCells(layout, whole, cut)) {
      EXPECT_GT(std::hypot(cell.corners[static_cast<std::size_t>(cut)].u -
                               whole.corners[static_cast<std::size_t>(cut)].u,
                           cell.corners[static_cast<std::size_t>(cut)].v -
                               whole.corners[static_cast<std::size_t>(cut)].v),
                1.0);
    }
  }
}

// Whether the segment a-b crosses the segment c-d.
bool Crosses(const Point2d& a, const Point2d& b, const Point2d& c, const Point2d& d) {
  const auto side = [](const Point2d& p, const Point2d& q, const Point2d& r) {
    return (q.u - p.u) * (r.v - p.v) - (q.v - p.v) * (r.u - p.u);
  };
  return side(a, b, c) * side(a, b, d) < 0.0 && side(c, d, a) * side(c, d, b) < 0.0;
}

// The borders across the stripes' middles, seen straight on (1000 px a metre): four across
// lines 1 and 3, four across lines 2 and 4, each crossed twice by each stripe of its pair
// between the crossings and never by the other pair.
TEST(TargetLayout, MiddleBordersCrossOnePairOfStripesBetweenTheCrossings) {
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const Lens camera = Lens::Pinhole(1000.0, 1000.0, 0.0, 0.0);
  const vpHomography plane_to_image = PlaneToImage(vpHomogeneousMatrix(0, 0, 1, 0, 0, 0));
  ScanBorders borders;
  AddMiddleBorders(layout, plane_to_image, camera, 4, &borders);
  ASSERT_EQ(borders.polygons.size(), 8u);
  for (std::size_t i = 0; i < borders.polygons.size(); ++i) {
    const std::vector<Point2d>& polygon = borders.polygons[i];
    ASSERT_EQ(polygon.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      const StripeSpan& stripe = layout.stripes[static_cast<std::size_t>(k)];
      const Point2d from = layout.OnStripe(k, stripe.along.lo, 0.0);
      const Point2d to = layout.OnStripe(k, stripe.along.hi, 0.0);
      const Point2d a{1000.0 * from.u, 1000.0 * from.v}, b{1000.0 * to.u, 1000.0 * to.v};
      int crossings = 0;
      for (std::size_t c = 0; c < 4; ++c) {
        crossings += Crosses(a, b, polygon[c], polygon[(c + 1) % 4]);
      }
      const bool of_pair = (k % 2 == 0) == (i < 4);
      EXPECT_EQ(crossings, of_pair ? 2 : 0) << "border " << i << ", line " << k + 1;
    }
  }
}

}  // namespace
}  // namespace oal
