#include "calibration/dense_runs.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>

namespace oal {
namespace {

// A column's run kept: its length within this fraction of what its neighbours say, its middle
// within kMaxMiddleOffsetPx (or this fraction of its length) of where they put it.
constexpr double kLengthTolerance = 0.2;
constexpr double kMaxMiddleOffsetPx = 1.0;
constexpr double kMiddleOffsetFraction = 0.15;
// The paper beside a run: kPaperSamples pixels beginning this far beyond its edge (past the
// blur), flat within kPaperFlatness of the contrast (not another stripe or the sheet's edge).
constexpr double kPaperGapPx = 2.0;
constexpr double kPaperGapFraction = 0.25;
constexpr int kPaperSamples = 3;
constexpr double kPaperFlatness = 0.25;
// Less contrast than this between ink and paper, grey levels: no edge to read.
constexpr double kMinContrast = 24.0;

// A run in the scan's own coordinates: `line` the column (or row) scanned, `at` the middle
// along it, `length` along it.
struct ScanRun {
  double line = 0.0;
  double at = 0.0;
  double length = 0.0;
};

// Reads one image column (rows swapped) as a profile.
class Profile {
 public:
  Profile(const GrayImageView& image, bool columns) : image_(image), columns_(columns) {}
  int lines() const { return columns_ ? image_.width : image_.height; }
  int extent() const { return columns_ ? image_.height : image_.width; }
  double at(int line, int i) const { return columns_ ? image_.at(line, i) : image_.at(i, line); }

 private:
  const GrayImageView& image_;
  bool columns_;
};

double MeanOf(const Profile& profile, int line, int first, int count, double* spread) {
  double sum = 0.0, lo = 255.0, hi = 0.0;
  for (int i = first; i < first + count; ++i) {
    const double value = profile.at(line, i);
    sum += value;
    lo = std::min(lo, value);
    hi = std::max(hi, value);
  }
  *spread = hi - lo;
  return sum / count;
}

// The dark run across `line` near `expected`: nullopt when the profile does not show one.
std::optional<ScanRun> ReadRun(const Profile& profile, int line, const ScanRun& expected) {
  const double half = 0.5 * expected.length;
  const double gap = std::max(kPaperGapPx, kPaperGapFraction * expected.length);
  const int below = static_cast<int>(std::floor(expected.at - half - gap)) - kPaperSamples + 1;
  const int above = static_cast<int>(std::ceil(expected.at + half + gap));
  if (below < 0 || above + kPaperSamples > profile.extent()) return std::nullopt;
  double spread_below = 0.0, spread_above = 0.0;
  const double paper_below = MeanOf(profile, line, below, kPaperSamples, &spread_below);
  const double paper_above = MeanOf(profile, line, above, kPaperSamples, &spread_above);
  // The ink: the run's middle half.
  const int ink_first = static_cast<int>(std::ceil(expected.at - std::max(0.5, 0.25 * half)));
  const int ink_last = static_cast<int>(std::floor(expected.at + std::max(0.5, 0.25 * half)));
  if (ink_last < ink_first) return std::nullopt;
  double ink_spread = 0.0;
  const double ink = MeanOf(profile, line, ink_first, ink_last - ink_first + 1, &ink_spread);
  const double contrast = std::min(paper_below, paper_above) - ink;
  if (contrast < kMinContrast || spread_below > kPaperFlatness * contrast ||
      spread_above > kPaperFlatness * contrast) {
    return std::nullopt;
  }
  const double level_below = 0.5 * (ink + paper_below), level_above = 0.5 * (ink + paper_above);
  // From the middle outwards to the first sample as light as the level, on each side.
  const int middle = static_cast<int>(std::lround(expected.at));
  if (profile.at(line, middle) >= std::min(level_below, level_above)) return std::nullopt;
  int i = middle;
  while (i > below && profile.at(line, i) < level_below) --i;
  if (i <= below) return std::nullopt;
  const double a = profile.at(line, i), b = profile.at(line, i + 1);
  const double edge_below = i + (a - level_below) / (a - b);
  int j = middle;
  while (j < above && profile.at(line, j) < level_above) ++j;
  if (j >= above) return std::nullopt;
  const double c = profile.at(line, j - 1), d = profile.at(line, j);
  const double edge_above = (j - 1) + (level_above - c) / (d - c);
  ScanRun run{static_cast<double>(line), 0.5 * (edge_below + edge_above), edge_above - edge_below};
  const bool as_long =
      std::fabs(run.length - expected.length) <= kLengthTolerance * expected.length;
  const bool where_expected = std::fabs(run.at - expected.at) <=
                              std::max(kMaxMiddleOffsetPx, kMiddleOffsetFraction * expected.length);
  if (!as_long || !where_expected) return std::nullopt;
  return run;
}

// A cubic in a line's index, fitted by least squares (a quadratic or a line when too few
// points are kept for it).
class Polynomial {
 public:
  Polynomial() = default;
  Polynomial(double centre, double scale, std::vector<double> coefficients)
      : centre_(centre), scale_(scale), coefficients_(std::move(coefficients)) {}
  double operator()(double line) const {
    const double x = (line - centre_) / scale_;
    double value = 0.0;
    for (auto c = coefficients_.rbegin(); c != coefficients_.rend(); ++c) value = value * x + *c;
    return value;
  }

 private:
  double centre_ = 0.0, scale_ = 1.0;
  std::vector<double> coefficients_;
};

template <typename Value>
Polynomial FitPolynomial(const std::vector<ScanRun>& runs, const std::vector<bool>& kept,
                         Value value) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  int count = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!kept[i]) continue;
    lo = std::min(lo, runs[i].line);
    hi = std::max(hi, runs[i].line);
    ++count;
  }
  if (count == 0) return Polynomial();
  const double centre = 0.5 * (lo + hi), scale = std::max(1.0, 0.5 * (hi - lo));
  const int terms = std::min(4, std::max(1, count / 3));
  cv::Mat a(count, terms, CV_64F), b(count, 1, CV_64F);
  int row = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!kept[i]) continue;
    const double x = (runs[i].line - centre) / scale;
    double power = 1.0;
    for (int t = 0; t < terms; ++t, power *= x) a.at<double>(row, t) = power;
    b.at<double>(row, 0) = value(runs[i]);
    ++row;
  }
  cv::Mat solution;
  cv::solve(a, b, solution, cv::DECOMP_QR);
  return Polynomial(centre, scale,
                    std::vector<double>(solution.begin<double>(), solution.end<double>()));
}

}  // namespace

StripeRuns DenseStripeRuns(const GrayImageView& image, const StripeRuns& found) {
  // The stripe's direction: its two farthest-apart middles' chord.
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < found.middles.size() && i < found.runs.size(); ++i) {
    if (found.runs[i].u != 0.0 || found.runs[i].v != 0.0) usable.push_back(i);
  }
  if (usable.size() < 3 || image.empty()) return found;
  double du = 0.0, dv = 0.0, farthest = 0.0;
  for (const std::size_t i : usable) {
    for (const std::size_t j : usable) {
      const double eu = found.middles[j].u - found.middles[i].u;
      const double ev = found.middles[j].v - found.middles[i].v;
      if (eu * eu + ev * ev > farthest) {
        farthest = eu * eu + ev * ev;
        du = eu;
        dv = ev;
      }
    }
  }
  if (farthest <= 0.0) return found;
  const double norm = std::sqrt(farthest);
  du /= norm;
  dv /= norm;
  // Columns across a stripe nearer the rows, rows across one nearer the columns.
  const bool columns = std::fabs(du) >= std::fabs(dv);
  const Profile profile(image, columns);
  std::vector<ScanRun> known;
  for (const std::size_t i : usable) {
    const Point2d& m = found.middles[i];
    const Point2d& r = found.runs[i];
    const double width = std::fabs(r.u * dv - r.v * du);  // across the stripe
    const double along_scan = columns ? std::fabs(du) : std::fabs(dv);
    known.push_back(columns ? ScanRun{m.u, m.v, width / along_scan}
                            : ScanRun{m.v, m.u, width / along_scan});
  }
  // Where the stripe's middle and its run's length are at each line: polynomials through the
  // found runs (a lens bends a stripe smoothly), refitted once without the runs far off them.
  std::vector<bool> kept(known.size(), true);
  Polynomial at_line, length_at_line;
  for (int round = 0; round < 2; ++round) {
    at_line = FitPolynomial(known, kept, [](const ScanRun& r) { return r.at; });
    length_at_line = FitPolynomial(known, kept, [](const ScanRun& r) { return r.length; });
    for (std::size_t i = 0; i < known.size(); ++i) {
      kept[i] = std::fabs(at_line(known[i].line) - known[i].at) <= kMaxMiddleOffsetPx;
    }
  }
  double first = HUGE_VAL, last = -HUGE_VAL;
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (!kept[i]) continue;
    first = std::min(first, known[i].line);
    last = std::max(last, known[i].line);
  }
  StripeRuns dense;
  if (!(first < last)) return found;
  const int first_line = std::max(0, static_cast<int>(std::ceil(first)));
  const int last_line = std::min(profile.lines() - 1, static_cast<int>(std::floor(last)));
  for (int line = first_line; line <= last_line; ++line) {
    const ScanRun expected{static_cast<double>(line), at_line(line), length_at_line(line)};
    const std::optional<ScanRun> run = ReadRun(profile, line, expected);
    if (!run) continue;
    if (columns) {
      dense.middles.push_back(Point2d{run->line, run->at});
      dense.runs.push_back(Point2d{0.0, run->length});
    } else {
      dense.middles.push_back(Point2d{run->at, run->line});
      dense.runs.push_back(Point2d{run->length, 0.0});
    }
  }
  return dense.middles.size() > found.middles.size() ? dense : found;
}

}  // namespace oal
