// Where to look for a '#' target (pose.h) in a frame: borders concentric on the target's own
// plane, mapped into the image through a plane-to-image homography, for the detector's border
// scans (detector/region.h: ScanBorders).
//
// The paper scans concentric borders of the image, which every line crosses twice when the
// lines traverse the image. A target printed on a sheet does not fill the view, but each of its
// stripes runs the sheet's length, so every rectangle of the target plane that lies inside the
// stripes' printed ends and outside the four crossings is crossed twice by every stripe,
// wherever the camera is. The borders here are `count` such rectangles, evenly spread from
// just inside the ink's ends (outer) to just outside the crossings (inner), each mapped into
// the image; the detector clips them to the image. Rectangles in the '#'s own frame: a point
// is origin + a·axis_a + b·axis_b with axis_a along lines 2 and 4 and axis_b along lines 1 and
// 3 (oblique when the '#' is), so for the built-in targets a and b are the target's x and y.
//
// The homography comes from a pose (tracking: the previous or the predicted one) or, with no
// prior, from the target's middle cell found in the image (detector/sheet_finder.h): the
// light cell the four stripes close in, whose corners are the stripes' inner edges.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/vision/vpHomography.h>

#include <array>
#include <optional>
#include <vector>

#include "detector/lens.h"
#include "detector/line.h"
#include "detector/region.h"
#include "detector/sheet_finder.h"
#include "target/line_target.h"

namespace oal {

/// A range [lo, hi] of one of the '#' frame's coordinates, metres.
struct Interval {
  double lo = 0.0, hi = 0.0;
};

/// One stripe in the '#' frame: its centre line at `at` across it (a for lines 1 and 3, b for
/// lines 2 and 4), printed from along.lo to along.hi, `half` its half width measured along the
/// other axis.
struct StripeSpan {
  double at = 0.0;
  Interval along;
  double half = 0.0;
  bool along_b = true;  ///< lines 1 and 3 run along axis b, lines 2 and 4 along axis a
};

struct TargetLayout {
  /// The '#' frame on the target plane (object frame, metres): origin at the middle of the
  /// four crossings, unit axes along lines 2/4 (a) and lines 1/3 (b).
  Point2d origin, axis_a, axis_b;
  /// Lines 1-4.
  std::array<StripeSpan, 4> stripes{};
  /// Rectangles every stripe crosses twice: the outer one just inside the ink's ends (where
  /// all four are printed), the inner one just outside the crossings.
  Interval outer_a, outer_b, inner_a, inner_b;
  /// The middle cell, bounded by the four stripes' inner edges: corners on the target plane
  /// (object x, y in metres), in the image borders' turning sense (region.h).
  std::array<Point2d, 4> middle_cell{};
  /// The paper beyond one stripe of each pair, between the other pair's inner edges, out to
  /// the board's edge: the cells a sheet finder sees closed in on three sides (two stripes
  /// and the one they cross) when the middle cell is broken (a hand over a crossing, a glare
  /// across a stripe). [0] lies beyond line 2 or 4, [1] beyond line 1 or 3 (the ones on the
  /// lower side of their '#' coordinate; the cells beyond their partners are these turned by
  /// 180 degrees about the origin, for a '#' centred on its board). Corners as middle_cell's;
  /// `outer` is the side (from corner outer to outer + 1) on the board's edge.
  struct EdgeCell {
    std::array<Point2d, 4> corners{};
    int outer = 0;
  };
  std::array<EdgeCell, 2> edge_cells{};
  /// The paper beyond one stripe of each pair, out to the board's corner: a cell a sheet
  /// finder sees closed in on two adjacent sides (the two stripes) when the margin beyond the
  /// stripes' ends is narrower than its cells and the middle and edge cells are broken or
  /// hidden. All four, corners as middle_cell's; `inner` is the corner where the two stripes'
  /// outer edges meet.
  struct CornerCell {
    std::array<Point2d, 4> corners{};
    int inner = 0;
  };
  std::array<CornerCell, 4> corner_cells{};

  /// Object-plane point of '#' coordinates (a, b).
  Point2d ToPlane(double a, double b) const;
  /// Object-plane point at `along` on stripe k's line, `across` from its centre line.
  Point2d OnStripe(int k, double along, double across) const;

  /// The layout of a '#' target. Throws std::invalid_argument unless `target` is a '#'
  /// (pose.h) whose stripes reach beyond the crossings on every side, so that borders exist.
  static TargetLayout Of(const LineTarget& target);
};

/// The homography from the target plane (object x, y, metres) to normalised image
/// coordinates of a camera at cMo: H = [r1 r2 t].
vpHomography PlaneToImage(const vpHomogeneousMatrix& cMo);

/// The pose of a plane seen through `plane_to_image` (target plane -> normalised coordinates,
/// in front of the camera where its third coordinate is positive): its first two columns
/// scaled to the rotation's, the nearest rotation to them and their cross product. Nullopt
/// when the homography is degenerate or would put the camera behind the plane.
std::optional<vpHomogeneousMatrix> PlanePose(const vpHomography& plane_to_image);

/// The homography taking four plane points exactly onto four image points, solved with
/// Eigen's LU on its eight unknowns, the ninth fixed by h(origin) having third coordinate 1
/// (`origin` lies inside the quadrilateral, so in front of the camera); nullopt when the
/// points are degenerate (three in a line). vpHomography::DLT's SVD, meant for many points,
/// costs more than the rest of a sheet candidate.
std::optional<vpHomography> FourPointHomography(const std::array<Point2d, 4>& plane,
                                                const std::array<Point2d, 4>& image,
                                                const Point2d& origin);

/// `count` borders (>= 2) from the outer to the inner rectangle, mapped through
/// `plane_to_image` (to normalised coordinates) and `camera`'s lens into image pixels. A
/// rectangle with a corner behind the camera, too far out, or whose image is not convex is
/// left out (the borders may then be fewer; none when the target is not in front).
ScanBorders TargetBorders(const TargetLayout& layout, const vpHomography& plane_to_image,
                          const Lens& camera, int count);
/// The same into *borders, reusing the memory it holds (for a loop).
void TargetBorders(const TargetLayout& layout, const vpHomography& plane_to_image,
                   const Lens& camera, int count, ScanBorders* borders);
/// Appends `per_pair` borders across each pair of parallel stripes between the crossings,
/// where the concentric borders never look: rectangles as long as the outer border across the
/// pair, as wide as bands of the middle cell along it (from near its sides to near its middle
/// line), each crossed twice by each of the two stripes. A stripe whose arms beyond the
/// crossings are hidden (a hand over one, the image's edge cutting the other) still gives
/// points along its middle. Rectangles mapped and left out as TargetBorders' are.
void AddMiddleBorders(const TargetLayout& layout, const vpHomography& plane_to_image,
                      const Lens& camera, int per_pair, ScanBorders* out);

/// The plane-to-image homography (normalised coordinates) that maps the layout's middle cell
/// onto `cell`, a light quadrilateral of the frame: of the two ways to lay the cell's sides
/// on the quadrilateral's (a turn by 180 degrees maps the middle cell nearly onto itself and
/// changes no border), the one whose homography is nearer a rotation's first two columns.
/// Nothing when the corners cannot be undistorted or the homography is degenerate.
std::optional<vpHomography> PlaneToImageFromCell(const TargetLayout& layout, const LightQuad& cell,
                                                 const Lens& camera);

/// The plane-to-image homography (normalised coordinates) that maps `edge`, an edge cell of
/// the layout, onto `cell`, a light quadrilateral closed in on three sides: its open side on
/// the cell's outer side (the board's edge). Nothing unless exactly one side is open, or when
/// the corners cannot be undistorted or the homography is degenerate.
std::optional<vpHomography> PlaneToImageFromEdgeCell(const TargetLayout::EdgeCell& edge,
                                                     const LightQuad& cell, const Lens& camera);
/// The same with the cell's side `outer` (0-3, from corner outer to outer + 1) on the board's
/// edge, whatever was found beyond it: a cell closed in on four sides may be one beyond a
/// stripe whose fourth side is the sheet's edge with something dark and then light beyond (a
/// tool, the bench's edge, a lit surface).
std::optional<vpHomography> PlaneToImageFromEdgeCell(const TargetLayout::EdgeCell& edge,
                                                     const LightQuad& cell, const Lens& camera,
                                                     int outer);

/// The plane-to-image homography (normalised coordinates) that lays `plane` (a cell's corners
/// on the target plane, in middle_cell's turning sense) onto `quad`'s corners, the cell's
/// corner `plane_first` on the quadrilateral's corner `quad_first` (both 0-3). Nothing when the
/// corners cannot be undistorted or the homography is degenerate.
std::optional<vpHomography> PlaneToImageFromCorners(const std::array<Point2d, 4>& plane,
                                                    int plane_first, const LightQuad& quad,
                                                    int quad_first, const Lens& camera);

/// The middle cell `cell` would be if its side `cut` (from corner cut to cut + 1) were the edge
/// of something lying across the cell (a hand, a tool, a cable) rather than a stripe's: the
/// two sides beside it lengthened along their own lines, from the opposite side's corners, to
/// the length the middle cell's shape gives them beside that side (its aspect either way round,
/// as the image's foreshortening is not known). Only lengthenings by 10 % or more; none when
/// the result is not convex.
std::vector<LightQuad> UncutCells(const TargetLayout& layout, const LightQuad& cell, int cut);

/// The image of a target point seen through `plane_to_image` and the lens: distorted pixels;
/// false when it lies behind the camera or beyond the lens model's reach.
bool ProjectPlanePoint(const vpHomography& plane_to_image, const Lens& camera, const Point2d& plane,
                       Point2d* pixel);

/// ProjectPlanePoint for many points of one view: the homography and the lens are read once
/// (the model check projects a few hundred points a frame), and the lens is inverted to
/// 1e-12 of the radius, far below a pixel, rather than to the renderer's last bit.
class PlaneProjector {
 public:
  PlaneProjector(const vpHomography& plane_to_image, const Lens& camera);
  bool Project(const Point2d& plane, Point2d* pixel) const;

 private:
  double h_[3][3];
  Lens camera_;
};

}  // namespace oal
