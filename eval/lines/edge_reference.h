// Independent reference lines for real image sequences (for `compare` on ViSP's
// line/ sequence): a documented sub-pixel edge fit that shares no code with detector/
// (only the line convention of detector/line.h).
//
// Method, per frame:
//  1. Gaussian smoothing, standard deviation `smoothing_sigma_px` (separable, kernel radius
//     ceil(3 sigma), borders replicated; edge points closer than radius + 2 px to the image
//     border are not used, since there the smoothing is one-sided).
//  2. Gradient by central differences: gu = (I(u+1) - I(u-1)) / 2, gv likewise.
//  3. Edge points along the dominant direction: where |gu| >= |gv| (edge closer to vertical)
//     the pixel is a candidate of its row, otherwise of its column. A candidate is a local
//     maximum of |gu| along the row (|gv| along the column) with |g| >= `min_gradient`; its
//     sub-pixel position along the row (column) is the vertex of the parabola through the
//     logarithms of the three magnitudes (exact for a Gaussian profile; a plain parabola when
//     a neighbour is 0), clamped to +-0.5 px. Each point keeps its gradient (gu, gv).
//  4. RANSAC (`ransac_trials`, fixed `seed`): the line through two random points; its
//     support counts points within `inlier_px` whose gradient is within
//     `max_normal_angle_deg` of the line's normal, all with one sign (one polarity: an edge
//     is dark on one side, light on the other). With a prior line (tracking a sequence) only
//     points within `search_band_px` of it, with a gradient within `max_prior_angle_deg` of its
//     normal, take part.
//  5. Total least squares (centroid + principal direction) on the support, repeated with the
//     support recomputed from the refined line until it no longer changes (at most 20 times).
//  The result: the line in our convention (u·cosθ + v·sinθ = ρ, image pixels: no lens model),
//  its polarity, and the RMS and maximum distance of its support points from it.
//
// Sequences: frame 1 is searched over the whole image (the longest straight edge wins); each
// later frame uses the previous reference as its prior and keeps the first frame's polarity,
// so one physical edge is followed. A frame whose edge is not found keeps the last prior.
//
// Truth CSV (for `oalservo compare --truth`): a header line `frame,line,rho,theta`, then
// one row per frame and reference line:
//     frame  the frame number of the file name (image.0001.pgm -> 1),
//     line   the line's index within the frame, from 0 (always 0 here: one edge per frame),
//     rho    pixels, theta radians in [0, pi), our convention, image (distorted) pixels,
// written with 10 significant digits; frames without a reference have no row.
#pragma once

#include <visp3/core/vpImage.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "detector/line.h"

namespace oal {

/// Which side of an edge is the bright one, relative to the line's normal (cosθ, sinθ).
enum class EdgePolarity {
  kAny,               ///< as an option: either; never a result
  kBrighterPositive,  ///< brighter where u·cosθ + v·sinθ > ρ
  kBrighterNegative,  ///< brighter where u·cosθ + v·sinθ < ρ
};
/// "any", "brighter-positive", "brighter-negative".
std::string ToString(EdgePolarity polarity);

struct EdgeReferenceOptions {
  double smoothing_sigma_px = 1.5;     ///< Gaussian smoothing, pixels, [0.5, 10]
  double min_gradient = 8.0;           ///< grey levels per pixel after smoothing, > 0
  double inlier_px = 1.0;              ///< support distance from the line, pixels, (0, 10]
  double max_normal_angle_deg = 25.0;  ///< point gradient vs line normal, degrees, (0, 90)
  int ransac_trials = 500;             ///< [1, 1000000]
  std::uint64_t seed = 1;              ///< RANSAC's random draws
  int min_points = 20;                 ///< fewer support points: no reference, >= 2
  double search_band_px = 20.0;        ///< with a prior: max distance from it, pixels, > 0
  double max_prior_angle_deg = 15.0;   ///< with a prior: max gradient angle to its normal, (0, 90)
  EdgePolarity polarity = EdgePolarity::kAny;  ///< restricts the edges searched

  /// Throws std::invalid_argument naming the field, the value and the violated constraint.
  void Check() const;
};

enum class EdgeReferenceStatus {
  kFound,
  kTooFewPoints,  ///< no line with min_points support points
};

struct EdgeReference {
  EdgeReferenceStatus status = EdgeReferenceStatus::kTooFewPoints;
  std::string message;                         ///< why, when not found
  LineParams line;                             ///< image pixels, line.h convention
  EdgePolarity polarity = EdgePolarity::kAny;  ///< the bright side (kAny only if not found)
  int points = 0;                              ///< support points of the final fit
  double rms_residual_px = 0.0;                ///< RMS distance of the support points from the line
  double max_residual_px = 0.0;                ///< largest distance of a support point
  Point2d end_a, end_b;                        ///< extreme support points projected on the line
};

/// The strongest straight edge of `image` (or the one near `prior`). Throws
/// std::invalid_argument if `options` fail Check() or the image is smaller than 16 x 16.
EdgeReference FitEdgeReference(const vpImage<unsigned char>& image,
                               const EdgeReferenceOptions& options,
                               const std::optional<LineParams>& prior = std::nullopt);

struct FrameReference {
  int frame = 0;  ///< frame number of the file name
  EdgeReference reference;
};

/// The file name of frame `frame` of `pattern`: a printf pattern with exactly one %d
/// conversion (optionally zero-padded with a width, "%04d"; "%%" for a '%'). Throws
/// std::invalid_argument naming the pattern when it has no such conversion (a single image or
/// a directory is not a sequence) or more than one.
std::string SequenceFramePath(const std::string& pattern, int frame);

/// The last frame of the run of consecutive existing files of `pattern` that starts at
/// frame `first` (>= 0). Throws std::invalid_argument for a bad pattern or `first` < 0, and
/// std::runtime_error naming the file when frame `first` does not exist.
int LastSequenceFrame(const std::string& pattern, int first);

/// Follows one edge through the files `pattern` (SequenceFramePath) numbered first..last, as
/// the file comment says. Throws std::invalid_argument for a bad pattern or range (first < 0
/// or first > last), and std::runtime_error naming the file if one cannot be read or is
/// smaller than FitEdgeReference accepts.
std::vector<FrameReference> FitEdgeSequence(const std::string& pattern, int first, int last,
                                            const EdgeReferenceOptions& options);

/// The truth CSV of the file comment (found references only).
void WriteTruthCsv(const std::vector<FrameReference>& references, std::ostream& out);
/// The same, written atomically to `path`.
void WriteTruthCsv(const std::vector<FrameReference>& references,
                   const std::filesystem::path& path);

}  // namespace oal
