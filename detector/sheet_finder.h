// Where a printed grid target might be in a frame with no prior: light quadrilaterals closed
// in by dark bands, for the caller to turn into regions of interest (region.h).
//
// A '#' target printed on a sheet lying on a bench splits the paper into nine light cells;
// the middle one is closed in on all four sides by the stripes, beyond which lies paper again.
// That cell is the anchor: it is in view whenever the target's four crossings are, it is a
// clean light quadrilateral whatever lies around the sheet (a light bench, a bright photo
// beside it, a shadow), and from it the target's geometry predicts where the rest of the
// target lies. The finder works on a grid of cells (cell_px x cell_px pixel means, about 5000
// for 640 x 480, each from two rows of at most 16 of its pixels: a larger image with larger
// cells costs what a small one does):
//   1. cell means and thresholds between light and dark cells: Otsu's over the cells, then
//      Otsu's over the light class again (a light bench, a bright photo), while the classes
//      differ by at least min_contrast (less in a dim frame) and no quadrilateral closed in on all
//      four sides has been found at the thresholds before; when none is, a last pass at the first
//      threshold with the cells darker than 0.8 times the brightest within three cells taken as
//      dark, and saturated ones too where the paper is not (a stripe under a glare stays darker
//      than the paper beside it, a glare's core is no paper, a grey hand is darker than the
//      paper): this last pass is also FindLocallyLight's, for a caller none of whose
//      candidates was the target, and FindFaintlyDark's with 0.9 instead of 0.8 (a pale hand
//      or sleeve), and FindNarrowed's with each cell then the darkest of the 3 x 3 around it
//      (a bridge of light cells a cell or two wide, a stripe washed out over a short stretch),
//      and FindSplitAtNecks' with the light cells split where two rooms of them meet at a
//      neck much narrower than either (a crossing washed out over several cells), and
//      FindClippedAsPaper's, both again with the saturated cells light (paper over-exposed
//      among light things that are not);
//   2. at each threshold, the 4-connected components of light cells of at least
//      min_area_fraction of the image; each one's quadrilateral is the convex hull of its
//      cells cut down to four vertices by dropping, each time, the vertex whose triangle with
//      its neighbours is smallest (the quadrilateral stays inside the hull); a component
//      found at several thresholds is kept once, as found closed in on most sides;
//   3. each side of the quadrilateral is probed in the image at three points along the
//      outward normal, up to 3/4 of the quadrilateral's shorter side: a side is closed in
//      when dark pixels (a band of at least 2 px, min_contrast below the cell) and light ones
//      again follow;
//   4. a quadrilateral closed in on at least three sides is refined at pixel level: every
//      side is moved onto the light/dark edge found along its normal at nine points (ink
//      against paper: min_contrast, or half the paper's grey level in a frame too dim; sub-pixel;
//      the line through two of them that most others lie within 1.5 px of, then fitted to those: a
//      hand or a pen over part of a side), one side whose edge is not found left where the cells
//      put it, and the corners are the sides' crossings;
//   5. candidates are ranked by the sides closed in, how well the cells fill the
//      quadrilateral, and its area.
// The finder knows nothing of any target: which candidate is the middle cell of which target,
// and where that puts the target, is the caller's to decide (servo/target_tracker.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "detector/image_view.h"
#include "detector/line.h"

namespace oal {

struct SheetFinderOptions {
  /// Side of the grid's cells, pixels. Range [2, 64].
  int cell_px = 8;
  /// Smallest light region, as a fraction of the image's area. Range (0, 1].
  double min_area_fraction = 0.006;
  /// Light and dark must differ by at least this, grey levels, Range [0, 255] ...
  int min_contrast = 30;
  /// ... or by this fraction of the light's grey level where that is less: a frame exposed
  /// at a third of the right level keeps a third of its contrast, and the cells are means of
  /// dozens of pixels, so their noise does not grow as the frame dims. Range [0, 1].
  double min_relative_contrast = 0.14;
  /// Candidates returned at most. Range [1, 16].
  int max_candidates = 4;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
  /// The least difference between `light` (grey level) and dark that counts as contrast.
  double ContrastNeededAt(double light) const;
  /// These options for an image `scale` times as many pixels across (DetectorOptions::
  /// ScaledBy): the cells `scale` times as wide, as many of them over the sheet. `scale` in
  /// (0, 100].
  SheetFinderOptions ScaledBy(double scale) const;
};

/// A light quadrilateral of the frame.
struct LightQuad {
  /// Corners in the image borders' turning sense (region.h), image pixels; when `refined`,
  /// the crossings of its sides moved onto the light/dark edges (three of them at least, a
  /// side whose edge was not found left where the cells put it).
  std::array<Point2d, 4> corners;
  bool refined = false;
  /// Sides (0-3; side k runs from corner k to corner k+1) beyond which a dark band and light
  /// again were found, as bits 1 << k.
  std::uint8_t closed_sides = 0;
  double area_fraction = 0.0;   ///< of the image, by its light cells
  double fill = 0.0;            ///< light cells over the cells of the quadrilateral, [0, 1]
  int light = 0;                ///< mean grey level of its light cells
  int threshold = 0;            ///< the grey level that separated it
  bool touches_border = false;  ///< some of its cells lie on the image's edge
  double score = 0.0;           ///< higher is more likely a grid's middle cell

  int ClosedSideCount() const;
};

class SheetFinder {
 public:
  /// Throws std::invalid_argument for options failing Check().
  explicit SheetFinder(const SheetFinderOptions& options = SheetFinderOptions());

  /// The candidates of `image`, best first (may be none). The reference stays valid until
  /// the next call. Throws std::invalid_argument for an empty view.
  const std::vector<LightQuad>& Find(const GrayImageView& image);
  /// More candidates of the image last given to Find, for when none of its own was the
  /// target: the light cells again at its first threshold, those darker than 0.8 times the
  /// brightest cell within three cells taken as dark (a stripe under a glare stays darker than
  /// the paper beside it; a grey hand bridging the middle cell to the next is darker than the
  /// paper), quadrilaterals Find returned left out. Empty when Find made this pass itself (it
  /// does when it finds no quadrilateral closed in on four sides). Same validity as Find's.
  const std::vector<LightQuad>& FindLocallyLight(const GrayImageView& image);
  /// More candidates of the image last given to Find, for when neither Find's nor
  /// FindLocallyLight's were the target: the same last pass with the cells darker than 0.9
  /// times the brightest within three cells taken as dark (a pale hand, a sleeve or a sheet
  /// of paper a little darker than the target's paper, lying across the middle cell and its
  /// neighbours, which it joins at the coarser ratio). Same validity as Find's.
  const std::vector<LightQuad>& FindFaintlyDark(const GrayImageView& image);
  /// More candidates of the image last given to Find, for when none of the looks above found
  /// the target: the first last pass's cells (0.8 of the brightest near them), each made the
  /// darkest of itself and its eight neighbours, at the first threshold. A bridge of light
  /// cells one or two cells wide (a stripe washed out over a short stretch, a gap a blur
  /// leaves at a crossing) no longer joins the middle cell to its neighbour; the cells shrink
  /// by one on each side, which Refine takes back. Quadrilaterals found before are left out.
  /// Same validity as Find's.
  const std::vector<LightQuad>& FindNarrowed(const GrayImageView& image);
  /// More candidates of the image last given to Find, for when none of the looks above found
  /// the target: the first last pass's cells split where two rooms of light cells meet at a
  /// neck much narrower than either (a watershed of each cell's distance to dark: a glare or
  /// a blur washing out a crossing over several cells, through which the middle cell joins its
  /// neighbour or the paper beyond the sheet's edge, out of view). A room that runs out of
  /// the image is left out as in Find, the rooms inside it are not. Quadrilaterals found
  /// before are left out. Same validity as Find's.
  const std::vector<LightQuad>& FindSplitAtNecks(const GrayImageView& image);
  /// More candidates of the image last given to Find, for when none of the looks above found
  /// the target, and they took its saturated cells for a glare's core (the light cells' mean
  /// well below saturation): FindLocallyLight's and FindSplitAtNecks' cells again with the
  /// saturated cells as light as their grey. Paper over-exposed, clipped, among light things
  /// that are not (a light bench, a page, a bright photograph) is no glare: taken as dark, it
  /// leaves no middle cell. Empty when the looks above took no saturated cell for a glare.
  /// Quadrilaterals found before are left out. Same validity as Find's.
  const std::vector<LightQuad>& FindClippedAsPaper(const GrayImageView& image);
  /// Step 4 for one candidate of the same image (done on demand: a caller usually needs the
  /// first only): its sides moved onto the light/dark edges, sub-pixel. True when quad is
  /// (now) refined; its corners are unchanged otherwise.
  bool Refine(const GrayImageView& image, LightQuad* quad) const;

  const SheetFinderOptions& options() const { return options_; }
  /// The last frame's cell means, row by row (grid_width() x grid_height()).
  const std::vector<std::uint8_t>& cells() const { return cells_; }
  int grid_width() const { return grid_width_; }
  int grid_height() const { return grid_height_; }

 private:
  /// A horizontal run of light cells [first, last] of one grid row, and its component (a
  /// union-find parent index into runs_, the root is its own parent).
  struct CellRun {
    int row = 0, first = 0, last = 0;
    int parent = 0;
  };

  void ComputeCells(const GrayImageView& image);
  /// Whether, stepping from `from` along `outward` (unit) through the grid's cells, dark
  /// cells and then light ones follow within `reach` px (at `threshold`).
  bool ClosedInCells(const std::uint8_t* grid, const Point2d& from, const Point2d& outward,
                     int threshold, double reach) const;
  /// Adds the candidates of the light cells at `threshold` to candidates_.
  void AddComponents(const GrayImageView& image, const std::uint8_t* grid, int threshold);
  /// local_: the cells, those much darker than the brightest near them set to 0, and the
  /// saturated ones too when `clipped_is_glare` and GlareSaturates().
  void MarkLocallyDark(double light_ratio, bool clipped_is_glare = true);
  /// Whether a saturated cell of the last frame is taken for a glare's core: the first pass's
  /// light cells' mean is well below saturation (the paper is not clipped).
  bool GlareSaturates() const;
  /// `grid`'s light cells (>= threshold) set to 0 where two rooms meet at a neck (see
  /// FindSplitAtNecks), into *out.
  void SplitAtNecks(const std::vector<std::uint8_t>& grid, int threshold,
                    std::vector<std::uint8_t>* out);
  /// Candidates of local_ at first_threshold_ (the last pass).
  void AddLocallyLight(const GrayImageView& image, double light_ratio);
  /// The last pass again for the image last given to Find (nothing for another size), best
  /// first: FindLocallyLight's and FindFaintlyDark's.
  const std::vector<LightQuad>& LookAgainLocally(const GrayImageView& image, double light_ratio);
  /// Whether `image` has the grid of the image last given to Find (a later look's condition).
  bool OnTheLastGrid(const GrayImageView& image) const;
  /// candidates_ best first, at most max_candidates.
  void KeepBest();
  int Root(int run);
  /// One component, given as its runs (sorted by row), into a candidate; false when it is no
  /// quadrilateral.
  bool Describe(const GrayImageView& image, const std::uint8_t* grid, int threshold,
                const std::vector<CellRun>& runs, LightQuad* quad) const;

  SheetFinderOptions options_;
  int grid_width_ = 0, grid_height_ = 0;
  std::vector<std::uint8_t> cells_;
  std::vector<std::uint8_t> local_, narrowed_, split_;
  std::vector<int> depth_, room_, room_parent_, room_peak_;  ///< SplitAtNecks' working memory
  std::vector<std::uint8_t> rows_, brightest_;  ///< working memory of the cells' filters
  int first_threshold_ = -1;             ///< the first pass's threshold of the last frame; -1: none
  double first_light_ = 0.0;             ///< the mean of the cells at or above it
  bool local_done_ = false;              ///< the last pass made for the last frame
  std::vector<std::uint32_t> row_sums_;  ///< per grid row, prefix sums of the cell means
  std::vector<std::uint64_t> light_bits_;  ///< one grid row's light cells at a threshold
  std::vector<CellRun> runs_;
  std::vector<CellRun> component_;
  std::vector<int> order_, starts_;
  std::vector<LightQuad> candidates_;
  /// The components described since the last Find: their cell box (left, top, right, bottom),
  /// the most sides found closed, and where the candidate is in candidates_ (-1: not there).
  struct SeenComponent {
    std::array<int, 4> box;
    int closed_sides;
    int candidate;
  };
  std::vector<SeenComponent> seen_;
};

}  // namespace oal
