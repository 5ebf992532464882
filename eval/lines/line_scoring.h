// Lines scored against their truth, the one place every evaluation matches lines: the geometry
// a score is made of (image pixels, detector/line.h's convention) and the one-to-one matching
// of found lines with truth lines (io/truth_file.h reads the truth).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "detector/line.h"
#include "io/truth_file.h"  // TargetLineTruth

namespace oal {

/// The point of `line` nearest to `p`.
Point2d Foot(const LineParams& line, const Point2d& p);

/// Distance from `b` of the point of `a` nearest to `centre`: how far apart two nearly
/// parallel lines are where it matters (rho alone depends on where the origin is).
double DistanceAt(const LineParams& a, const LineParams& b, const Point2d& centre);

/// The line half way between two nearly parallel lines.
LineParams Midline(const LineParams& a, const LineParams& b, const Point2d& centre);

/// The angle between `line` and `truth` (degrees) and the offset: the larger distance of the
/// truth's chord ends a, b from `line` (pixels).
std::pair<double, double> ErrorOf(const LineParams& line, const LineParams& truth, const Point2d& a,
                                  const Point2d& b);

/// A reference (truth) line in the coordinates of the lines it is matched with, and the ends
/// of its visible chord.
struct ReferenceLine {
  LineParams line;
  Point2d end_a, end_b;
};

/// A matched pair: indices into the references and the lines, the angle between the two
/// lines (degrees) and the offset (ErrorOf).
struct LineMatch {
  std::size_t reference = 0, line = 0;
  double angle_deg = 0.0, offset_px = 0.0;
};

/// Matches references and lines one to one, greedily by angle / max_angle_deg + offset /
/// max_offset_px (lowest first, ties in reference then line order), among the pairs within
/// both bounds (docs/COMPARE.md's `match` metric). The matches in that order.
std::vector<LineMatch> MatchLines(const std::vector<ReferenceLine>& references,
                                  const std::vector<LineParams>& lines, double max_angle_deg,
                                  double max_offset_px);

}  // namespace oal
