// Step 1 of the paper: scan one concentric border of the image and turn its line crossings
// into sub-pixel feature points.
//
// The border at distance d is the closed rectangle of pixels with u in {d, W-1-d} or
// v in {d, H-1-d}. It is walked clockwise as one loop (top row left to right, right column
// down, bottom row right to left, left column up), so a run that wraps around a corner of
// the rectangle stays one run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "detector/image_view.h"
#include "detector/line.h"
#include "detector/options.h"
#include "detector/region.h"

namespace oal {

/// Bits naming the sides of a border rectangle a point lies on (a corner lies on two).
enum BorderSide : std::uint8_t { kTop = 1, kRight = 2, kBottom = 4, kLeft = 8 };

struct BorderRect {
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;  ///< inclusive pixel bounds

  int Width() const { return u1 - u0 + 1; }
  int Height() const { return v1 - v0 + 1; }
  bool Valid() const { return Width() >= 2 && Height() >= 2; }
  /// Number of pixels on the loop.
  int Perimeter() const { return 2 * Width() + 2 * Height() - 4; }

  /// Pixel position of loop coordinate s (pixel i of the loop is at s = i; fractional s
  /// interpolates along the loop, wrapping at Perimeter()).
  Point2d ToPixel(double s) const;
  /// Sides holding loop coordinate s; within `corner_px` (at most 1, the shortest side) of a
  /// corner both sides are set.
  std::uint8_t Sides(double s, double corner_px = 0.5) const;
  /// ToPixel and Sides at once: returns Sides(s, corner_px) and sets *pixel to ToPixel(s).
  std::uint8_t Locate(double s, Point2d* pixel, double corner_px = 0.5) const;
};

/// The border at distance d from the edges of a width x height image (may be invalid).
BorderRect BorderAt(int width, int height, int d);

/// A feature point found on a border.
struct BorderPoint {
  Point2d pixel;            ///< sub-pixel image position
  double run_px = 0.0;      ///< length of the run along the loop, pixels (0 for edges)
  std::uint16_t sides = 0;  ///< BorderSide bits (a rectangle), or 1 << edge (a polygon)
  bool straight = true;     ///< the run lies on one side (its width can be measured)
  /// Unit direction of the side the run lies on; (0, 0) when it is not on one side only.
  Point2d along;
  /// How much lighter one side of the run is than the other (beside it, two samples each),
  /// over the run's depth below the lighter: 0 on even paper; a glare's slope or a shadow's
  /// edge beside a stripe moves its middle. 0 when unknown (edges, runs round a corner).
  float background_step = 0.0f;
};

/// Copies the loop's pixels, in loop order, into `samples` (resized; no allocation once it
/// has the capacity).
void GatherBorder(const GrayImageView& image, const BorderRect& rect,
                  std::vector<std::uint8_t>* samples);

/// The loops of a frame's concentric borders d = first_px, first_px + step_px, ... (while
/// valid), each in GatherBorder's order. Their left and right columns are read in one pass
/// over the image's rows, straight into the loops: read column by column, every pixel would
/// cost a cache line for one border; read row by row, one cache line serves the columns of
/// all the borders that cross it (about 64 / step_px of them).
class BorderLoops {
 public:
  /// Sizes the loops for width x height images; allocates only when the size changes.
  void Prepare(int width, int height, int first_px, int step_px);
  /// Reads the inner rows (all but the top and bottom one) of every border's two columns.
  /// `image` must have the size given to Prepare.
  void Read(const GrayImageView& image);
  /// Border k's loop (0 = outermost), as GatherBorder writes it: its top and bottom rows are
  /// copied now, its columns were taken by the last Read.
  const std::vector<std::uint8_t>& Gather(const GrayImageView& image, int k);
  /// Number of borders.
  int count() const { return static_cast<int>(loops_.size()); }
  /// The rectangle of border k.
  BorderRect Rect(int k) const { return BorderAt(width_, height_, first_px_ + k * step_px_); }

 private:
  int width_ = 0, height_ = 0, first_px_ = 0, step_px_ = 1;
  std::vector<std::vector<std::uint8_t>> loops_;
  std::vector<std::uint8_t*> right_at_, left_at_;  ///< Read's working memory
};

/// Otsu's threshold of `samples`; `contrast` receives the difference of the two class means
/// and `light`, when given, the light class's mean.
int OtsuThreshold(const std::vector<std::uint8_t>& samples, int* contrast, int* light = nullptr);

/// Finds the feature points of one border's samples (as GatherBorder wrote them) and appends
/// them to `points`, at most options.max_points_per_border. Returns the number appended.
/// Runs shorter than min_width_px are dropped and light gaps shorter than min_width_px are
/// bridged, so dead pixels and noise give no point. A straight run's point is its
/// intensity-weighted centroid; a run that wraps a corner gives the midpoint of its two
/// sub-pixel ends, which lies on the centre line of a stripe with parallel edges.
int FindBorderPoints(const std::vector<std::uint8_t>& samples, const BorderRect& rect,
                     int threshold, const DetectorOptions& options,
                     std::vector<BorderPoint>* points);
/// The same for a border of a region (region.h), as PolygonLoop::Gather wrote its samples.
/// A loop read every few pixels (PolygonLoop::SampleStep() > 1) finds its runs on its
/// samples; with `image` (the one it was gathered from) each straight run is read again at
/// every pixel to place its ends and centre (a sharp stripe edge between samples three pixels
/// apart would move its point by up to half a pixel).
int FindBorderPoints(const std::vector<std::uint8_t>& samples, const PolygonLoop& loop,
                     int threshold, const DetectorOptions& options,
                     std::vector<BorderPoint>* points, const GrayImageView* image = nullptr);

}  // namespace oal
