// A region of interest for the border scans: a convex polygon of the image, e.g. the printed
// sheet that carries the target when it does not fill the view.
//
// The paper scans concentric borders of the whole image, which suits lines that traverse the
// image, and says any batch sampling that suits the feature will do. A sheet on a bench is a
// convex quadrilateral in the image (clipped by the image where it leaves the view); its
// concentric borders are crossed twice by every stripe printed across it, as the image's are
// by lines that traverse the image. So the border at distance d is the region's polygon moved
// inward by d (each edge shifted along its normal, the image's own edges included where the
// region leaves the image), walked as one loop from the polygon's first vertex in the same
// turning sense as the image borders (top row left to right, then down the right side).
//
// Sampling: along an edge one sample per pixel of its longer axis, or every sample_step
// pixels (integer columns for an edge nearer the horizontal, integer rows otherwise: where
// the lines are many pixels wide, fewer samples place them as well), each linearly
// interpolated across the
// other axis, so the samples lie exactly on the edge and a run's centre maps back to the
// edge without the half-pixel staircase of nearest-pixel sampling.
#pragma once

#include <cstdint>
#include <vector>

#include "detector/image_view.h"
#include "detector/line.h"

namespace oal {

/// A convex polygon in image pixels (the conventions of line.h).
struct ScanRegion {
  /// Vertices in order, either turning sense; at least 3 and at most kMaxVertices, convex.
  std::vector<Point2d> vertices;

  static constexpr int kMaxVertices = 8;

  bool empty() const { return vertices.empty(); }
  /// Throws std::invalid_argument when the polygon has too few or too many vertices, a
  /// vertex that is not finite, or is not convex with a positive area.
  void Check() const;
};

/// Borders given one by one, e.g. the images of rectangles concentric on a planar target
/// (servo/target_layout.h), instead of a region's insets.
struct ScanBorders {
  /// Outermost first; each a convex polygon in image pixels (either turning sense, at most
  /// ScanRegion::kMaxVertices vertices), which may leave the image: border k is clipped to
  /// the image moved inward by image_margin_px + k image_margin_step_px. The clipped parts
  /// follow the image's edge, so that a line leaving the image still crosses every border
  /// twice (once on the edge); one pixel apart, they do not repeat each other's points, and
  /// they stay in a narrow band at the edge: spread as deep as the image borders' step_px
  /// would take them (16 borders: 85 px), they would run along a stripe that lies near and
  /// parallel to the edge, which then no border crosses.
  std::vector<std::vector<Point2d>> polygons;
  int image_margin_px = 3;       ///< >= 0
  int image_margin_step_px = 1;  ///< >= 0

  bool empty() const { return polygons.empty(); }
  /// Throws std::invalid_argument unless every polygon passes ScanRegion::Check().
  void Check() const;
};

/// The polygon's area, pixels² (positive for the image borders' turning sense).
double SignedArea(const std::vector<Point2d>& polygon);
/// The centroid of the polygon's area (its first vertex if the area is 0).
Point2d Centroid(const std::vector<Point2d>& polygon);

/// The convex hull of `points` in the image borders' turning sense, collinear points
/// dropped (Andrew's monotone chain). Fewer than 3 distinct points give what remains.
std::vector<Point2d> ConvexHull(std::vector<Point2d> points);

/// The region moved inward by `inset_px`, intersected with the image rectangle moved inward
/// by the same amount ([d, W-1-d] x [d, H-1-d]); the image borders' turning sense. Empty when
/// nothing of at least `min_extent_px` across remains.
std::vector<Point2d> InsetRegion(const ScanRegion& region, double inset_px, int width, int height,
                                 double min_extent_px = 2.0);

/// The polygon moved outward by `grow_px` (each edge along its normal).
std::vector<Point2d> GrowPolygon(const std::vector<Point2d>& polygon, double grow_px);

/// True when `p` lies inside or on the convex polygon (either turning sense).
bool Contains(const std::vector<Point2d>& polygon, const Point2d& p);

/// One border of a region (an inset polygon) as a loop of samples. Loop coordinate k is the
/// k-th sample; fractional coordinates interpolate between samples, wrapping at Perimeter().
class PolygonLoop {
 public:
  PolygonLoop() = default;
  /// `polygon`: convex, the image borders' turning sense, at most 16 vertices, inside
  /// [0, width-1] x [0, height-1] of the image it will be read from. `sample_step`: a sample
  /// every this many pixels of an edge's longer axis, >= 1.
  explicit PolygonLoop(const std::vector<Point2d>& polygon, int sample_step = 1) {
    Assign(polygon, sample_step);
  }
  /// Makes this the loop of `polygon`, reusing the memory it holds.
  void Assign(const std::vector<Point2d>& polygon, int sample_step = 1);

  int Perimeter() const { return perimeter_; }
  int SampleStep() const { return sample_step_; }
  int Edges() const { return static_cast<int>(edges_.size()); }
  /// Reads the loop's samples from `image` into `samples` (resized).
  void Gather(const GrayImageView& image, std::vector<std::uint8_t>* samples) const;
  /// Reads `count` pixels from the whole loop coordinate `first` on, one at every pixel of
  /// the edge's longer axis (SampleStep() of them between samples), as Gather reads its
  /// samples. False (nothing read) unless they all lie on one edge, inside the image.
  bool GatherPixels(const GrayImageView& image, int first, int count, std::uint8_t* out) const;

  /// Position of loop coordinate s and the bits (1 << edge) of the edges holding it; within
  /// `corner_px` samples of a vertex both of its edges are set.
  std::uint16_t Locate(double s, Point2d* pixel, double corner_px = 0.5) const;
  /// Unit direction of the edge holding s (the loop's direction).
  Point2d Direction(double s) const;
  /// Pixels between consecutive samples of the edge holding s (1 to sqrt 2 times the
  /// sample step).
  double Spacing(double s) const;
  /// Whether a vertex lies strictly inside the loop interval (first, last); first may be
  /// negative (a run across the loop's seam), last < Perimeter() + first.
  bool HasCornerInside(double first, double last) const;
  /// The polygon's vertices.
  const std::vector<Point2d>& vertices() const { return vertices_; }

 private:
  struct Edge {
    int first = 0;         ///< loop coordinate of its first sample
    int count = 0;         ///< samples (may be 0 for an edge shorter than a pixel)
    Point2d start;         ///< position of its first sample
    Point2d step;          ///< from one sample to the next
    double spacing = 0.0;  ///< |step|, pixels (asked for at every run found on the edge)
    Point2d direction;     ///< unit direction
    bool mostly_horizontal = true;
  };
  void AddEdge(const Point2d& a, const Point2d& b);
  /// The edge whose samples, or the gap after them, hold s (s in [0, perimeter)).
  int EdgeAt(double s) const;
  Point2d SampleAt(int k) const;
  /// Reads `count` pixels of `edge`, the first `offset_px` pixels of its longer axis from its
  /// first sample, then every `pixels_apart` pixels, each interpolated across the axis. Where
  /// one would need a pixel beyond the image: with `clamp`, the fraction is moved to the
  /// pixel before it (an edge along the image's own border); without, nothing is read and
  /// false returned.
  bool SampleStretch(const GrayImageView& image, const Edge& edge, int offset_px, int pixels_apart,
                     int count, bool clamp, std::uint8_t* out) const;

  std::vector<Point2d> vertices_;
  std::vector<Edge> edges_;
  int perimeter_ = 0;
  int sample_step_ = 1;
};

/// The concentric borders of a region, rebuilt for every frame in memory kept from frame to
/// frame (nothing is allocated once the borders of a frame fit in what earlier frames used).
class RegionBorders {
 public:
  /// The borders at d = first_px, first_px + step_px, ... while at least 2 px across
  /// remains, each InsetRegion(region, d, width, height); when that gives more than
  /// `max_borders` (0: no limit), `max_borders` borders evenly spread over the same depth
  /// instead (spacing (n - 1) step_px / (max_borders - 1) for n borders at step_px).
  void Build(const ScanRegion& region, int width, int height, int first_px, int step_px,
             int max_borders);
  /// The given borders, border k clipped to the image moved inward by first_px + k step_px;
  /// a border with nothing of 2 px across left is dropped. inside() is the first one clipped
  /// to the image.
  void Assign(const ScanBorders& borders, int width, int height, int first_px, int step_px);

  /// The borders built from now on are read every `step` pixels along (PolygonLoop), >= 1.
  void set_sample_step(int step) { sample_step_ = step; }

  int count() const { return count_; }
  /// Border k's polygon (0 = outermost) and loop.
  const std::vector<Point2d>& Polygon(int k) const {
    return polygons_[static_cast<std::size_t>(k)];
  }
  const PolygonLoop& Loop(int k) const { return loops_[static_cast<std::size_t>(k)]; }
  /// The region inside the image (InsetRegion with d = 0).
  const std::vector<Point2d>& inside() const { return inside_; }

 private:
  /// The inward unit normal (nu, nv) and offset c of a region edge: inside where
  /// nu u + nv v >= c.
  struct HalfPlane {
    double nu = 0.0, nv = 0.0, c = 0.0;
  };
  /// Writes the region moved inward by d into *out (cleared); false when nothing of 2 px
  /// across is left (min_extent_px as InsetRegion).
  bool Inset(double d, int width, int height, double min_extent_px, std::vector<Point2d>* out);
  /// planes_ from a convex polygon.
  void SetPlanes(const std::vector<Point2d>& polygon);
  /// Appends polygon as the next border (count_), reusing memory; false if its loop is too
  /// short.
  bool Append(const std::vector<Point2d>& polygon);

  std::vector<HalfPlane> planes_;
  std::vector<Point2d> scratch_, probe_;
  std::vector<std::vector<Point2d>> polygons_;
  std::vector<PolygonLoop> loops_;
  int sample_step_ = 1;
  std::vector<Point2d> inside_;
  int count_ = 0;
};

}  // namespace oal
