// Parameters of the OAL detector, with the paper's values as defaults where it gives them.
#pragma once

#include <string>

#include "base/check.h"  // RequireOption, which every Options::Check() uses

namespace oal {

/// What a feature point on a border is.
enum class Polarity {
  kDarkLines,   ///< middle of a dark run on a light background (the paper's case)
  kLightLines,  ///< middle of a light run on a dark background
  kEdges,       ///< a light/dark transition (e.g. ViSP's real `line/` sequence)
};

enum class ThresholdMode {
  kFixed,  ///< `fixed_threshold` on every border
  kOtsu,   ///< Otsu's threshold on each border's own pixels
};

/// The one place where enums meet strings ("dark", "light", "edges"; "fixed", "otsu").
std::string ToString(Polarity polarity);
std::string ToString(ThresholdMode mode);
/// Throw std::invalid_argument naming the accepted values.
Polarity PolarityFromString(const std::string& text);
ThresholdMode ThresholdModeFromString(const std::string& text);

/// The least difference from `light` (a grey level) that counts as contrast: the lesser of
/// `min_contrast` and `min_relative_contrast` times `light` (a dim frame's ink differs from its
/// paper by a fraction of the paper). The detector's borders and the sheet finder's cells both
/// judge by it.
double ContrastNeeded(int min_contrast, double min_relative_contrast, double light);

struct DetectorOptions {
  // --- Step 1: concentric border scans -------------------------------------------------
  /// Distance of the first border from the image edge, pixels. Paper: 10. Range [0, 1000].
  int start_px = 10;
  /// Distance between successive borders, pixels. Paper: 5. Range [1, 1000].
  int step_px = 5;
  Polarity polarity = Polarity::kDarkLines;
  ThresholdMode threshold_mode = ThresholdMode::kOtsu;
  /// Grey level separating line from background with kFixed. Range [1, 255].
  int fixed_threshold = 128;
  /// With kOtsu, a border whose two classes differ by fewer grey levels holds no line.
  /// Range [0, 255].
  int min_contrast = 40;
  /// ... or, where this fraction of the light class's grey level is less (a frame exposed at a
  /// third: its paper at 70-90, ink and a hand both dark), by fewer than that: at 0.35 a border
  /// whose light class is under 114 needs less than min_contrast. Range [0, 1].
  double min_relative_contrast = 0.35;
  /// The contrast a border of light class grey level `light` needs (ContrastNeeded).
  double ContrastNeededAt(double light) const;
  /// Runs narrower than this (along the border) are noise or dead pixels, pixels. Range (0, 1000].
  double min_width_px = 2.0;
  /// Widest line, measured across the line, pixels (the 2 m board's 30 mm line is 60 px wide
  /// at 0.3 m, the A3 sheet's 24 mm line 48 px). Range [min_width_px, 1000].
  double max_width_px = 80.0;
  /// A line crossing a border at angle a gives a run of width / sin(a): runs up to
  /// max_width_px / sin(min_crossing_angle_deg) are kept (NOTES 2). 90 keeps the paper's
  /// fixed maximum. Range [1, 90].
  double min_crossing_angle_deg = 15.0;
  /// Runs beyond this many on one border are ignored (a textured border). Range [2, 64].
  int max_points_per_border = 24;
  /// A run's point is its centroid weighted by each sample's contrast to the background
  /// beside the run (the mean of the two samples past each end), over the run and one sample
  /// either side; false: weighted by the contrast to the threshold over the run only.
  bool centre_from_background = true;
  /// With a region of interest (OalDetector::Detect with a ScanRegion), at most this many
  /// borders are scanned: a region so large that step_px would give more is scanned every
  /// k step_px, k the smallest that gives at most this many (a sheet filling the view costs
  /// what a smaller one does; the full-image scan always uses step_px). 0: no limit.
  /// Range [0, 1000].
  int region_max_borders = 16;
  /// A region's borders are read every this many pixels along (the whole image's every
  /// pixel): where the lines are several pixels wide, fewer samples place them as well, and
  /// a frame of a larger image costs about what a smaller one does. Range [1, 16].
  int region_sample_step = 1;

  // --- Step 2: pairwise correlation ------------------------------------------------------
  /// Two points on the same side of a border rectangle span that side, never a line that
  /// crosses the rectangle: such pairs are skipped. false correlates every pair (paper).
  bool skip_same_side_pairs = true;
  /// A pair is voted only if the widths across its chord of the two runs that gave its
  /// points agree: the larger at most this many times the smaller, plus min_width_px, and
  /// at most max_width_px. Points of two different lines rarely agree, so most of the
  /// hypotheses that the paper's list must carry and cull never enter it (NOTES 2, 4).
  /// 0 votes every pair (paper). Range 0 or [1, 100].
  double max_pair_width_ratio = 1.6;

  // --- Step 3: matching against the ordered accumulator list (Eq. 1, 2) -----------------
  /// anglechange of Eq. 1, degrees. Range (0, 45].
  double angle_change_deg = 2.0;
  /// rchange of Eq. 2, pixels; rho measured from the image centre. Range (0, 1000].
  double r_change_px = 4.0;

  // --- Step 5: culling -------------------------------------------------------------------
  /// Entries with weight - count/2 < 0 are culled only while the list is longer. Paper: 20.
  /// Range [1, 1000].
  int max_lines = 20;

  // --- Remedies for the weak points in ../shared/paper/NOTES.md (false = the paper) --------
  /// Increment `count` only on borders the line crosses (NOTES 1).
  bool count_visible_borders_only = true;
  /// Refit each read-off line to the feature points of all borders by least squares (NOTES 3).
  bool refit_lines = true;
  /// Rank read-off lines by the number of feature points on them, not by votes (NOTES 4).
  bool rank_by_support = true;
  /// A feature point within this distance of a line supports it, pixels. Range (0, 100].
  double support_tolerance_px = 1.5;

  // --- Step 6: read-off ------------------------------------------------------------------
  /// At most this many lines are returned. Range [1, 1000].
  int max_output_lines = 10;
  /// Lines with fewer votes are not returned. Range [1, 100000].
  int min_votes = 3;
  /// With rank_by_support, lines with fewer supporting points are not returned. Range [2, 100000].
  int min_support = 6;
  /// Two read-off lines closer than both of these are one line; the better one is kept.
  double duplicate_angle_deg = 3.0;  ///< Range (0, 90].
  double duplicate_r_px = 8.0;       ///< Range (0, 1000].

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;

  /// These options for an image whose lines are `scale` times as many pixels across as the
  /// ones these were set for (a camera of `scale` times the focal length): every length in
  /// pixels (the borders' start and spacing, the runs' widths, rchange, the support
  /// tolerance, the duplicates' distance) times `scale`, the spacing and the narrowest run
  /// a pixel at least; a region's borders read every whole `scale` pixels
  /// (region_sample_step); counts, angles and grey levels as they are. `scale` in (0, 100].
  DetectorOptions ScaledBy(double scale) const;

  /// The paper's algorithm: every remedy switch off (min_crossing_angle_deg 90,
  /// skip_same_side_pairs, max_pair_width_ratio, count_visible_borders_only, refit_lines,
  /// rank_by_support). What stays ours, as the paper leaves it open (detector.h lists each
  /// choice): an Otsu threshold per border with its contrast gate, intensity-weighted run
  /// centres, a run wrapping a rectangle corner taken by the midpoint of its ends, min_votes,
  /// max_points_per_border, and the list's capacity bound (a vote matching nothing while the
  /// list is full is dropped; the paper has no bound). Lens correction follows the camera
  /// given to the detector, not these options.
  static DetectorOptions Paper();
};

}  // namespace oal
