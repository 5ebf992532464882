// The ordered-accumulator-list (OAL) line detector of ../shared/paper/ordered-list-hough.md,
// sections 2 and 3, with the remedies of ../shared/paper/NOTES.md behind switches
// (DetectorOptions::Paper() turns them off; the lens correction follows the camera given).
//
//   for each border d = start, start + step, ... until the centre:
//     1. scan the border, feature points = middles of line runs     (border_scan.h)
//     2. every pair of the border's points -> a line (rho, theta)
//     3. vote into the ordered accumulator list, Eq. 1 and 2        (accumulator_list.h)
//     4. count, reorder by weight - count/2 (Eq. 3)
//     5. cull entries with weight - count/2 < 0 beyond max_lines (Eq. 4)
//   6. read off the best lines, dropping near-duplicates          (line_fit.h for the refit)
//
// Where the paper is vague, the choices made here:
//   - Borders: d = start, start + step, ... while the rectangle is at least 2 x 2 pixels; a
//     centre border that degenerates to a line or a point is not scanned.
//   - Step 1's threshold: Otsu's per border (or a fixed one); a border whose two classes differ
//     by less than min_contrast, or than min_relative_contrast of the light class's level
//     where that is less (a dim frame's ink differs from its paper by a fraction of the paper),
//     gives no point.
//   - Step 2: pairs of points on the same side of a border are skipped when
//     skip_same_side_pairs (they cannot belong to a line crossing the rectangle).
//   - Step 3: "weighted by the number of votes prior to this iteration" is read per vote (the
//     entry's weight before this vote), so the entry is the running mean of its votes. The
//     thresholds are decided on the list's float copies of the parameters (about 7
//     significant digits of the double values that are averaged). The list holds at most
//     max_lines + the pairs of one border (memory bounded); a vote matching nothing while it
//     is full is dropped.
//   - Step 4: every entry's count grows, the one created on this border included ("the count
//     on all the lines"); the sort is stable. The paper's "renormalise the vote counts" is not
//     done: Eq. 4 compares absolute weights and counts, which a renormalisation would change.
//   - Step 5: entries with a negative score are culled from the bottom only until max_lines
//     remain ("lines will only be removed if there are more than 20").
//   - Step 6: "close parameters" are within duplicate_angle_deg and duplicate_r_px, rho taken
//     from the image centre (NearDuplicate, line.h). anglechange 2 deg, rchange 4 px and these
//     thresholds are ours (the paper gives no values), set on the accuracy evaluation
//     (oalservo detect-accuracy, docs/BENCHMARKS.md).
//
// Lines are reported in the convention of line.h. With a camera that has distortion, the
// feature points are undistorted before step 2 and the lines are in undistorted pixel
// coordinates (the pixels an ideal pinhole camera with the same intrinsics would see).
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "detector/accumulator_list.h"
#include "detector/border_scan.h"
#include "detector/image_view.h"
#include "detector/lens.h"
#include "detector/line.h"
#include "detector/line_fit.h"
#include "detector/options.h"
#include "detector/region.h"

namespace oal {

struct DetectedLine {
  LineParams line;        ///< rho, theta (line.h); undistorted if Undistorts()
  int votes = 0;          ///< OAL weight
  int count = 0;          ///< OAL count (borders counted since the entry was created)
  int borders = 0;        ///< borders with at least one feature point on the line
  int support = 0;        ///< feature points of all borders within support_tolerance_px
  double width_px = 0.0;  ///< mean line thickness across the line (0 for edges)
  /// Where the line meets the image border, or the region's outline when a region was
  /// scanned (the undistorted one when correcting).
  Point2d end_a, end_b;
  /// The first and last supporting feature point along the line, projected onto it: the
  /// part of the line that was seen.
  Point2d support_a, support_b;
  int seed_id = -1;  ///< the LineSeed whose entry collected this line's votes, or -1
};

/// A line expected in the next frame, e.g. a tracked line, in the coordinates of the
/// detector's output (line.h; undistorted if Undistorts()).
struct LineSeed {
  int id = 0;
  LineParams line;
};

class OalDetector {
 public:
  /// Throws std::invalid_argument if `options` fail DetectorOptions::Check().
  explicit OalDetector(const DetectorOptions& options = DetectorOptions());
  /// As above; feature points are undistorted with `camera`'s kdu when its model has
  /// distortion.
  OalDetector(const DetectorOptions& options, const Lens& camera);

  /// Detects the lines of `image`, best first. The returned reference stays valid until the
  /// next call. An image smaller than the first border gives no line; an empty view throws
  /// std::invalid_argument. After the first frame of a given size nothing is allocated.
  const std::vector<DetectedLine>& Detect(const GrayImageView& image) { return Detect(image, {}); }
  const std::vector<DetectedLine>& Detect(const vpImage<unsigned char>& image) {
    return Detect(ViewOf(image), {});
  }
  /// As above, with the accumulator list seeded by `seeds` before the first border
  /// (OrderedAccumulatorList::Seed): a line that moved less than anglechange and rchange
  /// from its seed collects its votes in the seed's entry and comes out with its seed_id.
  const std::vector<DetectedLine>& Detect(const GrayImageView& image,
                                          const std::vector<LineSeed>& seeds);
  /// As above, scanning the concentric borders of `region` (region.h) instead of the
  /// image's: border d is the region moved inward by d = start_px, start_px + step_px, ...
  /// (the image's edges too, where the region leaves the image); the list's rho is measured
  /// from the region's centroid. An empty region scans the whole image. Throws
  /// std::invalid_argument for a region failing ScanRegion::Check().
  const std::vector<DetectedLine>& Detect(const GrayImageView& image,
                                          const std::vector<LineSeed>& seeds,
                                          const ScanRegion& region);
  /// As above with the borders given one by one (region.h: ScanBorders; border k clipped to
  /// the image moved inward by start_px + k step_px), e.g. rectangles concentric on a planar
  /// target. The list's origin is the centroid of the first border inside the image; lines
  /// end on its outline.
  /// No borders scans the whole image. Throws std::invalid_argument for a polygon failing
  /// ScanRegion::Check().
  const std::vector<DetectedLine>& Detect(const GrayImageView& image,
                                          const std::vector<LineSeed>& seeds,
                                          const ScanBorders& borders);

  bool Undistorts() const { return undistorter_.has_value(); }
  const DetectorOptions& options() const { return options_; }
  /// The feature points of the last frame, border by border (for display and diagnosis).
  const std::vector<FramePoint>& feature_points() const { return frame_points_; }
  /// The accumulator list as the last frame left it.
  const OrderedAccumulatorList& accumulator_list() const { return oal_; }
  /// The borders the last frame's region was scanned on, outermost first, in image pixels
  /// (count() 0 when the whole image was scanned).
  const RegionBorders& region_borders() const { return region_borders_; }

 private:
  /// A border's outline (detector.cpp: RectangleOutline, or a region border's vertices) in
  /// working coordinates centred on the list's origin, as fixed-size arrays padded by
  /// repeating the last point, so that Crossed is a short loop, unrolled and two points at a
  /// time with SSE2. kPoints is even: Crossed takes two at a time.
  template <std::size_t kPoints>
  struct BorderOutline {
    std::array<double, kPoints> u, v;

    explicit BorderOutline(const std::vector<Point2d>& outline);  // outline not empty
    /// Whether the entry's line crosses the outline: some point strictly on each side.
    bool Crossed(const OalEntry& entry) const;
  };

  void PrepareFor(int width, int height);
  /// The working state of region_borders_ once they are built: origin, outlines, where lines
  /// end.
  void PrepareRegion();
  const std::vector<DetectedLine>& DetectInRegion(const GrayImageView& image,
                                                  const std::vector<LineSeed>& seeds);
  void ScanBorder(const GrayImageView& image, int border);
  void ScanRegionBorder(const GrayImageView& image, int border);
  /// Step 1's threshold for a border's samples; false when the border has no contrast.
  bool BorderThreshold(const std::vector<std::uint8_t>& samples, int* threshold) const;
  /// Appends border_points_ to the frame's points (working coordinates) and votes their pairs.
  void AddBorderPoints(int border);
  void VotePairs(int border, std::size_t first_point);
  /// The pair width test of DetectorOptions::max_pair_width_ratio for the chord from a to b,
  /// (du, dv) = b - a, length_sq = du² + dv².
  bool WidthsAgree(const FramePoint& a, const FramePoint& b, double du, double dv,
                   double length_sq) const;
  void ReadOff(int width, int height, bool in_region);
  Point2d ToWorking(const Point2d& pixel) const;

  DetectorOptions options_;
  std::optional<PointUndistorter> undistorter_;
  OrderedAccumulatorList oal_;

  // Working memory, sized once per image size (no allocation per frame after that).
  int width_ = 0, height_ = 0;
  double centre_u_ = 0.0, centre_v_ = 0.0;
  /// The list's rho origin this frame: the image centre, or the region's centroid.
  double origin_u_ = 0.0, origin_v_ = 0.0;
  BorderLoops loops_;
  std::vector<BorderPoint> border_points_;
  std::vector<FramePoint> frame_points_;
  std::vector<BorderOutline<8>> outlines_;  ///< per border
  std::vector<Point2d> image_outline_;      ///< the image border in working coordinates
  /// max_width_px as a pair's widths are measured (on the ideal image when correcting).
  double pair_max_width_px_ = 0.0;
  // A region's borders (the last region's; rebuilt for each frame with a region).
  bool in_region_ = false;       ///< the next DetectInRegion scans region_borders_
  bool scanned_region_ = false;  ///< the last frame was scanned in a region
  RegionBorders region_borders_;
  // A region border has at most 12 vertices; most have 8 or fewer (a quadrilateral, clipped
  // by the image), whose test is half as long.
  std::vector<BorderOutline<8>> region_outlines_;
  std::vector<BorderOutline<16>> region_outlines_long_;
  std::vector<Point2d> region_outline_;  ///< the region (inside the image), working coordinates
  std::vector<Point2d> outline_scratch_;
  std::vector<std::uint8_t> region_samples_;
  std::vector<DetectedLine> candidates_;
  std::vector<DetectedLine> lines_;
};

}  // namespace oal
