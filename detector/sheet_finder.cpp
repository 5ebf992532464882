#include "detector/sheet_finder.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "detector/options.h"
#include "detector/region.h"
#include "detector/simd.h"

namespace oal {
namespace {

// A quadrilateral is kept only when its cells fill at least this much of it.
constexpr double kMinFill = 0.6;
// Refinement: points probed along each side, and how far along the normal, in cells.
constexpr int kEdgePoints = 9;
constexpr std::size_t kMinEdgePoints = 4;
constexpr double kEdgeSearchCells = 2.5;
constexpr double kEdgeTolerancePx = 1.5;
// A side's edge is a stripe's ink against the cell's paper, a tenth of its grey level or
// less: it differs by min_contrast, or by half the paper's level in a frame too dim for that
// (a grey hand's edge, a fifth darker than the paper, is no stripe's at any exposure).
constexpr double kEdgeContrastOfLight = 0.5;
// The last pass: a cell is light only when it is at least this fraction of the brightest cell
// within this many cells (a stripe under a glare stays darker than the paper beside it).
constexpr int kLocalRadiusCells = 3;
constexpr double kLocalLightRatio = 0.8;
// ... and FindFaintlyDark's: a pale hand or sleeve is a tenth darker than the paper beside it
// (paper's texture, noise and fall-off over a few cells change a cell's mean by a few per cent).
constexpr double kFaintLightRatio = 0.9;
constexpr int kSaturatedGrey = 250;
constexpr int kLocalSaturationMargin = 15;
// FindSplitAtNecks: two rooms of light cells that meet where the cells lie less than this
// fraction of the shallower room's depth from dark are split there. A washed-out crossing
// joining the middle cell to its neighbour is a third to a half as deep as the cells; along a
// room's middle the depth varies by a step or two, so one room is never split.
constexpr double kNeckDepthRatio = 0.7;
// Depths are chamfer distances to dark, in these units per step across and diagonally.
constexpr int kChamferStep = 3, kChamferDiagonal = 4;

// Otsu's threshold over the values of histogram[lo, 256): values >= the result are the
// light class; *contrast gets the two classes' mean difference and *light the light class's
// mean (both 0 when a class is empty).
int OtsuOfHistogram(const std::array<int, 256>& histogram, int lo, double* contrast,
                    double* light) {
  double total = 0.0, sum = 0.0;
  for (int g = lo; g < 256; ++g) {
    total += histogram[g];
    sum += static_cast<double>(g) * histogram[g];
  }
  *contrast = 0.0;
  *light = 0.0;
  double weight_low = 0.0, sum_low = 0.0, best = -1.0;
  int threshold = 256;
  for (int g = lo; g < 255; ++g) {
    weight_low += histogram[g];
    sum_low += static_cast<double>(g) * histogram[g];
    const double weight_high = total - weight_low;
    if (weight_low <= 0.0 || weight_high <= 0.0) continue;
    const double gap = (sum - sum_low) / weight_high - sum_low / weight_low;
    const double between = weight_low * weight_high * gap * gap;
    if (between > best) {
      best = between;
      threshold = g + 1;
      *contrast = gap;
      *light = (sum - sum_low) / weight_high;
    }
  }
  return threshold;
}

double TriangleArea(const Point2d& a, const Point2d& b, const Point2d& c) {
  return 0.5 * std::fabs((b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u));
}

// Drops the vertices of a convex polygon whose triangle with their neighbours is smallest,
// one at a time, until `count` remain (the polygon shrinks, staying inside the original).
void ReduceTo(std::vector<Point2d>* polygon, std::size_t count) {
  std::vector<Point2d>& p = *polygon;
  while (p.size() > count) {
    std::size_t best = 0;
    double smallest = HUGE_VAL;
    const std::size_t n = p.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double a = TriangleArea(p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
      if (a < smallest) {
        smallest = a;
        best = i;
      }
    }
    p.erase(p.begin() + static_cast<std::ptrdiff_t>(best));
  }
}

// Whether the probe at (u, v) lies inside the image, by a hundredth of a pixel at least (what
// ProbeSums' fixed point may drift): its pixel and its neighbours one pixel away along (du, dv)
// on both sides, nearest pixels.
bool ProbeInside(const GrayImageView& image, double u, double v, double du, double dv) {
  constexpr double kMargin = 0.01;
  for (int k = -1; k <= 1; ++k) {
    const double x = u + k * du + 0.5, y = v + k * dv + 0.5;
    if (!(x >= kMargin && y >= kMargin && x < image.width - kMargin &&
          y < image.height - kMargin)) {
      return false;
    }
  }
  return true;
}

// The sums of the grey levels of n probes at from + i step (i < n), each its pixel and its
// neighbours one pixel away along `along`, nearest pixels, into sums[i]; the first and the last
// probe must be inside the image (ProbeInside), and so all are. Positions in fixed point (16
// fractional bits): a probe lands at most n / 2^16 px off.
void ProbeSums(const GrayImageView& image, const Point2d& from, const Point2d& step,
               const Point2d& along, int n, int* sums) {
  const auto fixed = [](double x) { return static_cast<std::int64_t>(std::lround(x * 65536.0)); };
  const std::int64_t step_u = fixed(step.u), step_v = fixed(step.v);
  const std::int64_t along_u = fixed(along.u), along_v = fixed(along.v);
  std::int64_t u = fixed(from.u + 0.5), v = fixed(from.v + 0.5);
  const std::uint8_t* const data = image.data;
  const std::ptrdiff_t stride = image.stride;
  const auto pixel = [data, stride](std::int64_t fu, std::int64_t fv) {
    return static_cast<int>(data[(fv >> 16) * stride + (fu >> 16)]);
  };
  for (int i = 0; i < n; ++i, u += step_u, v += step_v) {
    sums[i] = pixel(u - along_u, v - along_v) + pixel(u, v) + pixel(u + along_u, v + along_v);
  }
}

// A side from a to b of a quadrilateral turning like the image borders: its unit direction
// and outward unit normal.
struct Side {
  Point2d a, b, direction, outward;
  double length = 0.0;

  Side(const Point2d& from, const Point2d& to) : a(from), b(to) {
    const double du = to.u - from.u, dv = to.v - from.v;
    length = std::sqrt(du * du + dv * dv);
    direction = length > 0.0 ? Point2d{du / length, dv / length} : Point2d{1.0, 0.0};
    outward = Point2d{direction.v, -direction.u};
  }
  Point2d At(double t, double s) const {
    return Point2d{a.u + t * (b.u - a.u) + s * outward.u, a.v + t * (b.v - a.v) + s * outward.v};
  }
};

// The light/dark edge nearest to the side at t along its normal, within +-search px: false
// when there is none with enough contrast.
bool EdgeAt(const GrayImageView& image, const Side& side, double t, double light, double search,
            double min_contrast, Point2d* edge) {
  const int n = static_cast<int>(2.0 * search) + 1;
  std::array<int, 512> sums;  // three pixels' sums along the normal
  if (n > static_cast<int>(sums.size())) return false;
  const Point2d& along = side.direction;
  // The probes lie on a segment: when both of its ends are inside the image, all are (one
  // outside leaves no edge to find).
  const Point2d first = side.At(t, -search), last = side.At(t, n - 1 - search);
  if (!ProbeInside(image, first.u, first.v, along.u, along.v) ||
      !ProbeInside(image, last.u, last.v, along.u, along.v)) {
    return false;
  }
  ProbeSums(image, first, side.outward, along, n, sums.data());
  const int darkest_sum = *std::min_element(sums.begin(), sums.begin() + n);
  if (light - darkest_sum / 3.0 < min_contrast) return false;
  // Halfway between the light and the darkest, in the sums' units (three grey levels).
  const double threshold = 1.5 * light + 0.5 * darkest_sum;
  double best = HUGE_VAL;
  for (int i = 0; i + 1 < n; ++i) {
    const int g0 = sums[static_cast<std::size_t>(i)], g1 = sums[static_cast<std::size_t>(i + 1)];
    if (!(g0 >= threshold && g1 < threshold)) continue;  // light to dark, outward
    const double s = i - search + (g0 - threshold) / (g0 - g1);
    if (std::fabs(s) < std::fabs(best)) best = s;
  }
  if (!std::isfinite(best)) return false;
  *edge = side.At(t, best);
  return true;
}

// The side moved onto the light/dark edge: a line through the edge points found along it
// (at least 4 of kEdgePoints, those more than 1.5 px off the first fit dropped).
bool RefineSide(const GrayImageView& image, const Side& side, double light, double search,
                double min_contrast, LineParams* line) {
  std::vector<Point2d> points;
  for (int k = 0; k < kEdgePoints; ++k) {
    const double t = 0.1 + 0.8 * k / (kEdgePoints - 1.0);
    Point2d edge;
    if (EdgeAt(image, side, t, light, search, min_contrast, &edge)) points.push_back(edge);
  }
  if (points.size() < kMinEdgePoints) return false;
  // The line through two of the points that most of the others lie on (a hand or a pen over
  // part of the side puts its own edge in a few of them); distances by the cross product, no
  // angles, as this runs for every pair (the pair's length once, not once a point).
  struct Pair {
    Point2d from;
    double du = 0.0, dv = 0.0, tolerance = 0.0;
    bool Holds(const Point2d& p) const {
      return tolerance > 0.0 && std::fabs((p.u - from.u) * dv - (p.v - from.v) * du) <= tolerance;
    }
  };
  const auto pair_of = [&points](std::size_t i, std::size_t j) {
    const double du = points[j].u - points[i].u, dv = points[j].v - points[i].v;
    // A chord of tens of pixels: hypot's care for overflow is not needed, its cost is.
    return Pair{points[i], du, dv, kEdgeTolerancePx * std::sqrt(du * du + dv * dv)};
  };
  std::size_t most = 0;
  Pair best;
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); ++j) {
      const Pair pair = pair_of(i, j);
      const auto on = static_cast<std::size_t>(std::count_if(
          points.begin(), points.end(), [&pair](const Point2d& p) { return pair.Holds(p); }));
      if (on > most) {
        most = on;
        best = pair;
      }
    }
  }
  if (most < kMinEdgePoints) return false;
  std::vector<Point2d> kept;
  for (const Point2d& p : points) {
    if (best.Holds(p)) kept.push_back(p);
  }
  points.swap(kept);
  *line = FitLine(points);
  return true;
}

// out[i]: the brightest (take_brightest) or the darkest of `in` over the (2 radius + 1)^2
// cells around cell i of a w x h grid, clipped to the grid (separable: rows, then columns);
// *rows is working memory.
void ExtremeAround(const std::vector<std::uint8_t>& in, int w, int h, int radius,
                   bool take_brightest, std::vector<std::uint8_t>* rows,
                   std::vector<std::uint8_t>* out) {
  const auto extreme = [take_brightest](std::uint8_t a, std::uint8_t b) {
    return take_brightest ? std::max(a, b) : std::min(a, b);
  };
  rows->resize(in.size());
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = in.data() + static_cast<std::size_t>(y) * w;
    std::uint8_t* row_out = rows->data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      std::uint8_t value = row[x];
      for (int k = std::max(0, x - radius); k <= std::min(w - 1, x + radius); ++k) {
        value = extreme(value, row[k]);
      }
      row_out[x] = value;
    }
  }
  out->resize(in.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t value = (*rows)[static_cast<std::size_t>(y) * w + x];
      for (int k = std::max(0, y - radius); k <= std::min(h - 1, y + radius); ++k) {
        value = extreme(value, (*rows)[static_cast<std::size_t>(k) * w + x]);
      }
      (*out)[static_cast<std::size_t>(y) * w + x] = value;
    }
  }
}

// Each light cell's chamfer distance (3 a step, 4 a diagonal one) to the nearest dark cell
// of the grid; beyond the grid counts as light (a sheet running out of view is not narrowed
// at the image's edge). Dark cells get 0.
void DistanceToDark(const std::vector<std::uint8_t>& grid, int w, int h, int threshold,
                    std::vector<int>* distance) {
  constexpr int kFar = 1 << 20;
  distance->resize(grid.size());
  std::vector<int>& d = *distance;
  for (std::size_t i = 0; i < grid.size(); ++i) d[i] = grid[i] >= threshold ? kFar : 0;
  const auto relax = [&](int x, int y, int dx, int dy, int step) {
    const int nx = x + dx, ny = y + dy;
    if (nx < 0 || ny < 0 || nx >= w || ny >= h) return;
    int& here = d[static_cast<std::size_t>(y) * w + x];
    here = std::min(here, d[static_cast<std::size_t>(ny) * w + nx] + step);
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      relax(x, y, -1, 0, kChamferStep);
      relax(x, y, 0, -1, kChamferStep);
      relax(x, y, -1, -1, kChamferDiagonal);
      relax(x, y, 1, -1, kChamferDiagonal);
    }
  }
  for (int y = h - 1; y >= 0; --y) {
    for (int x = w - 1; x >= 0; --x) {
      relax(x, y, 1, 0, kChamferStep);
      relax(x, y, 0, 1, kChamferStep);
      relax(x, y, 1, 1, kChamferDiagonal);
      relax(x, y, -1, 1, kChamferDiagonal);
    }
  }
}

// Bit i of words (64 cells a word) set when cells[i] >= threshold, i < n; the bits past n are 0.
void LightMask(const std::uint8_t* cells, int n, int threshold, std::uint64_t* words) {
  const int word_count = (n + 63) / 64;
  std::fill(words, words + word_count, 0u);
  int i = 0;
#if OAL_HAVE_SSE2
  // cells >= threshold  <=>  max(cells, threshold) == cells, 16 cells a step.
  const __m128i level = _mm_set1_epi8(static_cast<char>(threshold));
  for (; i + 16 <= n; i += 16) {
    const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(cells + i));
    const auto bits = static_cast<std::uint64_t>(
        static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(c, level), c))));
    words[i >> 6] |= bits << (i & 63);  // i is a multiple of 16: the 16 bits stay in one word
  }
#endif
  for (; i < n; ++i) {
    words[i >> 6] |= static_cast<std::uint64_t>(cells[i] >= threshold) << (i & 63);
  }
}

// The first i >= from whose bit is `set` (set: 1, else 0); words.size() * 64 when there is none.
int NextBit(const std::vector<std::uint64_t>& words, int from, bool set) {
  const int count = static_cast<int>(words.size());
  int w = from >> 6;
  if (w >= count) return count * 64;
  std::uint64_t word =
      (set ? words[static_cast<std::size_t>(w)] : ~words[static_cast<std::size_t>(w)]) &
      (~std::uint64_t{0} << (from & 63));
  while (word == 0) {
    if (++w >= count) return count * 64;
    word = set ? words[static_cast<std::size_t>(w)] : ~words[static_cast<std::size_t>(w)];
  }
  return w * 64 + __builtin_ctzll(word);
}

}  // namespace

int LightQuad::ClosedSideCount() const {
  int count = 0;
  for (int k = 0; k < 4; ++k) count += (closed_sides >> k) & 1;
  return count;
}

void SheetFinderOptions::Check() const {
  RequireOption(cell_px >= 2 && cell_px <= 64, "SheetFinderOptions::cell_px", cell_px,
                "2 <= cell_px <= 64");
  RequireOption(min_area_fraction > 0.0 && min_area_fraction <= 1.0,
                "SheetFinderOptions::min_area_fraction", min_area_fraction,
                "0 < min_area_fraction <= 1");
  RequireOption(min_contrast >= 0 && min_contrast <= 255, "SheetFinderOptions::min_contrast",
                min_contrast, "0 <= min_contrast <= 255");
  RequireOption(min_relative_contrast >= 0.0 && min_relative_contrast <= 1.0,
                "SheetFinderOptions::min_relative_contrast", min_relative_contrast,
                "0 <= min_relative_contrast <= 1");
  RequireOption(max_candidates >= 1 && max_candidates <= 16, "SheetFinderOptions::max_candidates",
                max_candidates, "1 <= max_candidates <= 16");
}

double SheetFinderOptions::ContrastNeededAt(double light) const {
  return ContrastNeeded(min_contrast, min_relative_contrast, light);
}

SheetFinderOptions SheetFinderOptions::ScaledBy(double scale) const {
  RequireOption(scale > 0.0 && scale <= 100.0, "SheetFinderOptions::ScaledBy scale", scale,
                "0 < scale <= 100");
  SheetFinderOptions scaled = *this;
  scaled.cell_px = std::clamp(static_cast<int>(std::lround(cell_px * scale)), 2, 64);
  return scaled;
}

SheetFinder::SheetFinder(const SheetFinderOptions& options)
    : options_((options.Check(), options)) {}

void SheetFinder::ComputeCells(const GrayImageView& image) {
  const int c = options_.cell_px;
  grid_width_ = image.width / c;
  grid_height_ = image.height / c;
  cells_.assign(static_cast<std::size_t>(grid_width_) * grid_height_, 0);
  std::vector<std::uint32_t> sums(static_cast<std::size_t>(grid_width_));
  // Two rows of each cell (every fourth row of a small one) and at most sixteen pixels of each
  // row, in the cell's middle: the mean of a few dozen pixels is plenty to tell paper from ink,
  // and a frame's cost follows its cells, not its area (the cells grow with the image).
  const int first_row = std::min(1, c - 1);
  const int row_step = std::max(4, c / 2);
  const int rows_used = (c - first_row + row_step - 1) / row_step;
  const int window = c >= 16 ? 16 : (c >= 8 ? 8 : c);
  const int offset = (c - window) / 2;
  const std::uint32_t count = static_cast<std::uint32_t>(rows_used * window);
  // Dividing by `count` as a multiply (a division per cell is most of this function's time):
  // ceil(2^32 / count) gives the exact quotient for numerators below 2^32 / count, and a
  // cell's rounded sum is below 256 count + count.
  const std::uint64_t reciprocal = ((std::uint64_t{1} << 32) + count - 1) / count;
  for (int gy = 0; gy < grid_height_; ++gy) {
    std::fill(sums.begin(), sums.end(), 0u);
    for (int r = first_row; r < c; r += row_step) {
      const int y = gy * c + r;
      const std::uint8_t* row = image.data + static_cast<std::ptrdiff_t>(y) * image.stride;
      // The next row used, asked for now: a frame just out of memory costs more to wait for
      // than to sum, and the rows used are too far apart for the hardware to guess.
      if (y + row_step < image.height) {
        const std::uint8_t* ahead = row + row_step * static_cast<std::ptrdiff_t>(image.stride);
        for (int x = 0; x < image.width; x += 64) __builtin_prefetch(ahead + x);
      }
      int gx = 0;
#if OAL_HAVE_SSE2
      const __m128i zero = _mm_setzero_si128();
      if (c == 8) {  // one psadbw sums two cells' eight pixels
        for (; gx + 1 < grid_width_; gx += 2) {
          const __m128i pixels = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + gx * 8));
          const __m128i sad = _mm_sad_epu8(pixels, zero);
          sums[static_cast<std::size_t>(gx)] += static_cast<std::uint32_t>(_mm_cvtsi128_si32(sad));
          sums[static_cast<std::size_t>(gx) + 1] +=
              static_cast<std::uint32_t>(_mm_extract_epi16(sad, 4));
        }
      } else if (window == 16) {  // one psadbw sums a cell's sixteen, in two halves
        for (; gx < grid_width_; ++gx) {
          const __m128i pixels =
              _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + gx * c + offset));
          const __m128i sad = _mm_sad_epu8(pixels, zero);
          sums[static_cast<std::size_t>(gx)] +=
              static_cast<std::uint32_t>(_mm_cvtsi128_si32(sad) + _mm_extract_epi16(sad, 4));
        }
      } else if (window == 8) {
        for (; gx < grid_width_; ++gx) {
          const __m128i pixels =
              _mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + gx * c + offset));
          sums[static_cast<std::size_t>(gx)] +=
              static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_sad_epu8(pixels, zero)));
        }
      }
#endif
      for (; gx < grid_width_; ++gx) {
        const std::uint8_t* p = row + gx * c + offset;
        std::uint32_t s = 0;
        for (int k = 0; k < window; ++k) s += p[k];
        sums[static_cast<std::size_t>(gx)] += s;
      }
    }
    std::uint8_t* out = cells_.data() + static_cast<std::size_t>(gy) * grid_width_;
    for (int gx = 0; gx < grid_width_; ++gx) {
      const std::uint64_t rounded = sums[static_cast<std::size_t>(gx)] + count / 2;
      out[gx] = static_cast<std::uint8_t>((rounded * reciprocal) >> 32);
    }
  }
}

bool SheetFinder::Describe(const GrayImageView& image, const std::uint8_t* grid, int threshold,
                           const std::vector<CellRun>& runs, LightQuad* quad) const {
  const int c = options_.cell_px;
  // Cell edges in pixel coordinates (pixel centres at integers), clamped to the image.
  const double max_u = image.width - 1.0, max_v = image.height - 1.0;
  auto edge_u = [&](int gx) { return std::clamp(gx * c - 0.5, 0.0, max_u); };
  auto edge_v = [&](int gy) { return std::clamp(gy * c - 0.5, 0.0, max_v); };
  // Each grid row's leftmost and rightmost cell is enough for the convex hull.
  double light_sum = 0.0, cells = 0.0;
  std::vector<Point2d> corners;
  for (std::size_t i = 0; i < runs.size();) {
    const int row = runs[i].row;
    int left = runs[i].first, right = runs[i].last;
    for (; i < runs.size() && runs[i].row == row; ++i) {
      const CellRun& run = runs[i];
      left = std::min(left, run.first);
      right = std::max(right, run.last);
      const std::uint32_t* sums =
          row_sums_.data() + static_cast<std::size_t>(row) * (grid_width_ + 1);
      light_sum += sums[run.last + 1] - sums[run.first];
      cells += run.last - run.first + 1;
    }
    if (row == 0 || row == grid_height_ - 1 || left == 0 || right == grid_width_ - 1) {
      quad->touches_border = true;
    }
    // The row's top and bottom edges; a bottom edge is the next row's top edge, so only the
    // extremes of both are kept.
    const double u0 = edge_u(left), u1 = edge_u(right + 1), top = edge_v(row);
    if (!corners.empty() && corners.back().v == top) {
      corners[corners.size() - 2].u = std::min(corners[corners.size() - 2].u, u0);
      corners.back().u = std::max(corners.back().u, u1);
    } else {
      corners.push_back({u0, top});
      corners.push_back({u1, top});
    }
    corners.push_back({u0, edge_v(row + 1)});
    corners.push_back({u1, edge_v(row + 1)});
  }
  std::vector<Point2d> hull = ConvexHull(corners);
  if (hull.size() < 4) return false;
  ReduceTo(&hull, 4);
  const double n = cells;
  const double quad_cells = std::fabs(SignedArea(hull)) / (c * c);
  quad->fill = quad_cells > 0.0 ? std::min(1.0, n / quad_cells) : 0.0;
  if (quad->fill < kMinFill) return false;
  for (int k = 0; k < 4; ++k)
    quad->corners[static_cast<std::size_t>(k)] = hull[static_cast<std::size_t>(k)];
  quad->threshold = threshold;
  quad->light = static_cast<int>(std::lround(light_sum / n));
  quad->area_fraction = n * c * c / (static_cast<double>(image.width) * image.height);

  // Which sides are closed in by a dark band with light beyond (the stripes round a '#'s
  // middle cell).
  std::array<Side, 4> sides{Side(hull[0], hull[1]), Side(hull[1], hull[2]), Side(hull[2], hull[3]),
                            Side(hull[3], hull[0])};
  double shortest = HUGE_VAL;
  for (const Side& side : sides) shortest = std::min(shortest, side.length);
  const double reach = 0.5 * shortest;
  // Two of three probes decide a side; once two sides are open the cell cannot be a grid's
  // middle one, and the rest is not probed. The probes step through the grid's cells: the
  // dark band around a component is dark at its threshold by construction, and light cells
  // beyond it belong to another component.
  quad->closed_sides = 0;
  int open = 0;
  for (int k = 0; k < 4 && open < 2; ++k) {
    const Side& side = sides[static_cast<std::size_t>(k)];
    auto closed_at = [&](double t) {
      return ClosedInCells(grid, side.At(t, 0.0), side.outward, threshold, reach);
    };
    const int first_two = closed_at(0.3) + closed_at(0.7);
    const bool closed = first_two == 2 || (first_two == 1 && closed_at(0.5));
    if (closed) {
      quad->closed_sides |= static_cast<std::uint8_t>(1u << k);
    } else {
      ++open;
    }
  }

  quad->score = 10.0 * quad->ClosedSideCount() + 5.0 * quad->fill + quad->area_fraction;
  return true;
}

bool SheetFinder::Refine(const GrayImageView& image, LightQuad* quad) const {
  if (quad->refined) return true;
  const int c = options_.cell_px;
  const std::array<Point2d, 4>& q = quad->corners;
  const std::array<Side, 4> sides{Side(q[0], q[1]), Side(q[1], q[2]), Side(q[2], q[3]),
                                  Side(q[3], q[0])};
  // A side whose edge is not found (a hand over it) stays where the cells put it: the other
  // three still place the corners better than the cells do.
  std::array<LineParams, 4> lines;
  int unmoved = 0;
  const double edge_contrast =
      std::min(static_cast<double>(options_.min_contrast), kEdgeContrastOfLight * quad->light);
  for (std::size_t k = 0; k < 4; ++k) {
    if (!RefineSide(image, sides[k], quad->light, kEdgeSearchCells * c, edge_contrast, &lines[k])) {
      lines[k] = LineThrough(sides[k].a, sides[k].b);
      if (++unmoved > 1) return false;
    }
  }
  std::array<Point2d, 4> refined{};
  for (int k = 0; k < 4; ++k) {
    if (!Intersect(lines[static_cast<std::size_t>((k + 3) % 4)], lines[static_cast<std::size_t>(k)],
                   &refined[static_cast<std::size_t>(k)], 0.05)) {
      return false;
    }
  }
  // Each side moved by at most the search window; the corners of a sharp cell can move
  // further (the cells cut them off), so the check is on the shape: convex, and of an area
  // near the cells'.
  const std::vector<Point2d> coarse(q.begin(), q.end()), check(refined.begin(), refined.end());
  const double coarse_area = SignedArea(coarse), refined_area = SignedArea(check);
  if (ConvexHull(check).size() == 4 && refined_area > 0.8 * coarse_area &&
      refined_area < 1.6 * coarse_area) {
    quad->corners = refined;
    quad->refined = true;
  }
  return quad->refined;
}

bool SheetFinder::GlareSaturates() const {
  return first_light_ < kSaturatedGrey - kLocalSaturationMargin;
}

void SheetFinder::MarkLocallyDark(double light_ratio, bool clipped_is_glare) {
  // The brightest over (2 kLocalRadiusCells + 1)^2 cells, then the cells darker than
  // light_ratio of it set to 0.
  // Where the paper itself is not saturated, a saturated cell is a glare's core, over ink and
  // paper alike: it tells nothing, and taken as light it would join the cells around it.
  const bool glare_saturates = clipped_is_glare && GlareSaturates();
  ExtremeAround(cells_, grid_width_, grid_height_, kLocalRadiusCells, true, &rows_, &brightest_);
  local_.resize(cells_.size());
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const bool light = cells_[i] >= light_ratio * brightest_[i] &&
                       !(glare_saturates && cells_[i] >= kSaturatedGrey);
    local_[i] = light ? cells_[i] : 0;
  }
}

int SheetFinder::Root(int run) {
  while (runs_[static_cast<std::size_t>(run)].parent != run) {
    CellRun& r = runs_[static_cast<std::size_t>(run)];
    r.parent = runs_[static_cast<std::size_t>(r.parent)].parent;  // path halving
    run = r.parent;
  }
  return run;
}

bool SheetFinder::ClosedInCells(const std::uint8_t* grid, const Point2d& from,
                                const Point2d& outward, int threshold, double reach) const {
  const double c = options_.cell_px;
  const int steps = static_cast<int>(reach / c) + 1;
  int dark = 0;
  for (int s = 0; s <= steps; ++s) {
    const Point2d p{from.u + s * c * outward.u, from.v + s * c * outward.v};
    const int gx = static_cast<int>(std::floor((p.u + 0.5) / c));
    const int gy = static_cast<int>(std::floor((p.v + 0.5) / c));
    if (gx < 0 || gy < 0 || gx >= grid_width_ || gy >= grid_height_) return false;
    const bool light = grid[static_cast<std::size_t>(gy) * grid_width_ + gx] >= threshold;
    if (!light) {
      ++dark;
    } else if (dark > 0) {
      return true;  // light, dark, light again
    }
  }
  return false;
}

void SheetFinder::AddComponents(const GrayImageView& image, const std::uint8_t* grid,
                                int threshold) {
  // Runs of light cells row by row, each joined to the runs of the row above that it touches
  // (4-connectivity: overlapping columns). A row's light cells are found as a bit mask and its
  // runs by counting zeros: on a textured bench, a branch per cell mispredicts at every run.
  runs_.clear();
  const int words = (grid_width_ + 63) / 64;
  light_bits_.resize(static_cast<std::size_t>(words));
  std::size_t above_begin = 0, above_end = 0;
  for (int gy = 0; gy < grid_height_; ++gy) {
    LightMask(grid + static_cast<std::size_t>(gy) * grid_width_, grid_width_, threshold,
              light_bits_.data());
    const std::size_t row_begin = runs_.size();
    std::size_t above = above_begin;  // the first run above that may touch this row's next run
    for (int gx = NextBit(light_bits_, 0, true); gx < grid_width_;
         gx = NextBit(light_bits_, gx, true)) {
      const int first = gx;
      gx = std::min(NextBit(light_bits_, gx, false), grid_width_);
      const int last = gx - 1;
      const int index = static_cast<int>(runs_.size());
      runs_.push_back(CellRun{gy, first, last, index});
      while (above < above_end && runs_[above].last < first) ++above;
      for (std::size_t a = above; a < above_end && runs_[a].first <= last; ++a) {
        const int ra = Root(static_cast<int>(a)), rb = Root(index);
        if (ra != rb) runs_[static_cast<std::size_t>(std::max(ra, rb))].parent = std::min(ra, rb);
      }
    }
    above_begin = row_begin;
    above_end = runs_.size();
  }
  // The runs grouped by component, in row order within each (a counting sort by root: the
  // runs are already in row order).
  const std::size_t n_runs = runs_.size();
  starts_.assign(n_runs + 1, 0);
  for (std::size_t i = 0; i < n_runs; ++i) {
    runs_[i].parent = Root(static_cast<int>(i));
    ++starts_[static_cast<std::size_t>(runs_[i].parent) + 1];
  }
  for (std::size_t i = 0; i < n_runs; ++i) starts_[i + 1] += starts_[i];
  order_.resize(n_runs);
  for (std::size_t i = 0; i < n_runs; ++i) {
    order_[static_cast<std::size_t>(starts_[static_cast<std::size_t>(runs_[i].parent)]++)] =
        static_cast<int>(i);
  }
  const int c = options_.cell_px;
  const int total = grid_width_ * grid_height_;
  const int min_cells =
      std::max(4, static_cast<int>(std::ceil(options_.min_area_fraction * image.width *
                                             image.height / (c * c))));
  for (std::size_t i = 0; i < order_.size();) {
    const int root = runs_[static_cast<std::size_t>(order_[i])].parent;
    component_.clear();
    int cells = 0;
    for (; i < order_.size() && runs_[static_cast<std::size_t>(order_[i])].parent == root; ++i) {
      const CellRun& run = runs_[static_cast<std::size_t>(order_[i])];
      component_.push_back(run);
      cells += run.last - run.first + 1;
    }
    // Too small, or most of the image (the bench, not a cell of a printed grid).
    if (cells < min_cells || 2 * cells > total) continue;
    // A quadrilateral fills at least half its bounding box (a square turned by 45 degrees);
    // a grid's middle cell lies inside the image, its crossings in view.
    int left = grid_width_, right = -1;
    for (const CellRun& run : component_) {
      left = std::min(left, run.first);
      right = std::max(right, run.last);
    }
    const int rows = component_.back().row - component_.front().row + 1;
    const bool at_edge = left == 0 || right == grid_width_ - 1 || component_.front().row == 0 ||
                         component_.back().row == grid_height_ - 1;
    if (at_edge || 2.2 * cells < static_cast<double>(rows) * (right - left + 1)) continue;
    // The same component found at another threshold (its cell box within a cell) is kept
    // once: as first found, unless it is found again closed in on more sides (a hand over a
    // crossing leaves a side open at one threshold and closed at the last pass's).
    const std::array<int, 4> box{left, component_.front().row, right, component_.back().row};
    const auto seen = std::find_if(seen_.begin(), seen_.end(), [&](const SeenComponent& s) {
      for (std::size_t k = 0; k < 4; ++k) {
        if (std::abs(s.box[k] - box[k]) > 1) return false;
      }
      return true;
    });
    if (seen != seen_.end() && seen->closed_sides == 4) continue;
    LightQuad quad;
    if (!Describe(image, grid, threshold, component_, &quad)) continue;
    if (seen == seen_.end()) {
      seen_.push_back({box, quad.ClosedSideCount(), static_cast<int>(candidates_.size())});
      candidates_.push_back(quad);
    } else if (quad.ClosedSideCount() > seen->closed_sides) {
      seen->closed_sides = quad.ClosedSideCount();
      if (seen->candidate >= 0) {  // returned by this call: replaced
        candidates_[static_cast<std::size_t>(seen->candidate)] = quad;
      } else {
        seen->candidate = static_cast<int>(candidates_.size());
        candidates_.push_back(quad);
      }
    }
  }
}

const std::vector<LightQuad>& SheetFinder::Find(const GrayImageView& image) {
  if (image.empty() || image.stride < image.width) {
    throw std::invalid_argument("SheetFinder::Find: empty image or stride < width");
  }
  candidates_.clear();
  seen_.clear();
  ComputeCells(image);
  if (grid_width_ < 2 || grid_height_ < 2) return candidates_;
  std::array<int, 256> histogram{};
  for (const std::uint8_t value : cells_) ++histogram[value];
  row_sums_.assign(static_cast<std::size_t>(grid_height_) * (grid_width_ + 1), 0u);
  for (int gy = 0; gy < grid_height_; ++gy) {
    std::uint32_t* sums = row_sums_.data() + static_cast<std::size_t>(gy) * (grid_width_ + 1);
    const std::uint8_t* row = cells_.data() + static_cast<std::size_t>(gy) * grid_width_;
    for (int gx = 0; gx < grid_width_; ++gx) sums[gx + 1] = sums[gx] + row[gx];
  }
  // Light against dark, then the light class split again (a light bench, a bright photo),
  // until a cell closed in on all four sides (a '#'s middle cell) is found: the splits are
  // for a sheet the first threshold merged with the bench, and cost a labelling each.
  first_threshold_ = -1;
  first_light_ = 0.0;
  local_done_ = false;
  int lo = 0;
  bool closed = false;
  for (int level = 0; level < 3 && !closed; ++level) {
    double contrast = 0.0, light = 0.0;
    const int threshold = OtsuOfHistogram(histogram, lo, &contrast, &light);
    if (threshold > 255 || contrast < options_.ContrastNeededAt(light)) break;
    AddComponents(image, cells_.data(), threshold);
    lo = threshold;
    if (first_threshold_ < 0) {
      first_threshold_ = threshold;
      first_light_ = light;
    }
    closed = std::any_of(candidates_.begin(), candidates_.end(),
                         [](const LightQuad& quad) { return quad.ClosedSideCount() == 4; });
  }
  if (!closed) AddLocallyLight(image, kLocalLightRatio);
  KeepBest();
  return candidates_;
}

const std::vector<LightQuad>& SheetFinder::FindLocallyLight(const GrayImageView& image) {
  if (local_done_) {
    candidates_.clear();
    return candidates_;
  }
  return LookAgainLocally(image, kLocalLightRatio);
}

const std::vector<LightQuad>& SheetFinder::FindFaintlyDark(const GrayImageView& image) {
  return LookAgainLocally(image, kFaintLightRatio);
}

const std::vector<LightQuad>& SheetFinder::FindNarrowed(const GrayImageView& image) {
  candidates_.clear();
  if (first_threshold_ >= 0 && OnTheLastGrid(image)) {
    MarkLocallyDark(kLocalLightRatio);
    ExtremeAround(local_, grid_width_, grid_height_, 1, false, &rows_, &narrowed_);
    AddComponents(image, narrowed_.data(), first_threshold_);
    KeepBest();
  }
  return candidates_;
}

const std::vector<LightQuad>& SheetFinder::FindSplitAtNecks(const GrayImageView& image) {
  candidates_.clear();
  if (first_threshold_ >= 0 && OnTheLastGrid(image)) {
    MarkLocallyDark(kLocalLightRatio);
    SplitAtNecks(local_, first_threshold_, &split_);
    AddComponents(image, split_.data(), first_threshold_);
    KeepBest();
  }
  return candidates_;
}

const std::vector<LightQuad>& SheetFinder::FindClippedAsPaper(const GrayImageView& image) {
  candidates_.clear();
  if (first_threshold_ >= 0 && GlareSaturates() && OnTheLastGrid(image)) {
    MarkLocallyDark(kLocalLightRatio, false);
    AddComponents(image, local_.data(), first_threshold_);
    SplitAtNecks(local_, first_threshold_, &split_);
    AddComponents(image, split_.data(), first_threshold_);
    KeepBest();
  }
  return candidates_;
}

void SheetFinder::SplitAtNecks(const std::vector<std::uint8_t>& grid, int threshold,
                               std::vector<std::uint8_t>* out) {
  // A watershed of the distances to dark: the light cells taken from the deepest up, each
  // joining the room of its neighbours; where two rooms meet, they are one when the meeting
  // cell is nearly as deep as the shallower room's deepest, else the cell is their neck, set
  // dark.
  DistanceToDark(grid, grid_width_, grid_height_, threshold, &depth_);
  order_.clear();
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (depth_[i] > 0) order_.push_back(static_cast<int>(i));
  }
  std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) {
    return depth_[static_cast<std::size_t>(a)] > depth_[static_cast<std::size_t>(b)];
  });
  room_.assign(grid.size(), -1);
  room_parent_.clear();
  room_peak_.clear();
  const auto parent = [&](int r) -> int& { return room_parent_[static_cast<std::size_t>(r)]; };
  const auto root = [&](int r) {
    while (parent(r) != r) {
      parent(r) = parent(parent(r));  // path halving
      r = parent(r);
    }
    return r;
  };
  *out = grid;
  constexpr std::array<std::array<int, 2>, 4> kSteps{{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
  for (const int cell : order_) {
    const std::size_t i = static_cast<std::size_t>(cell);
    const int x = cell % grid_width_, y = cell / grid_width_;
    const int depth = depth_[i];
    int joined = -1;
    bool neck = false;
    for (const auto& step : kSteps) {
      const int nx = x + step[0], ny = y + step[1];
      if (nx < 0 || ny < 0 || nx >= grid_width_ || ny >= grid_height_) continue;
      const int other = room_[static_cast<std::size_t>(ny) * grid_width_ + nx];
      if (other < 0) continue;
      const int r = root(other);
      if (joined < 0 || r == joined) {
        joined = r;
        continue;
      }
      const int shallower = std::min(room_peak_[static_cast<std::size_t>(r)],
                                     room_peak_[static_cast<std::size_t>(joined)]);
      if (depth >= kNeckDepthRatio * shallower) {
        parent(r) = joined;
        room_peak_[static_cast<std::size_t>(joined)] = std::max(
            room_peak_[static_cast<std::size_t>(joined)], room_peak_[static_cast<std::size_t>(r)]);
      } else {
        neck = true;
      }
    }
    if (neck) {
      (*out)[i] = 0;
    } else if (joined >= 0) {
      room_[i] = joined;
    } else {
      room_[i] = static_cast<int>(room_parent_.size());
      room_parent_.push_back(room_[i]);
      room_peak_.push_back(depth);
    }
  }
}

bool SheetFinder::OnTheLastGrid(const GrayImageView& image) const {
  return image.width / options_.cell_px == grid_width_ &&
         image.height / options_.cell_px == grid_height_;
}

const std::vector<LightQuad>& SheetFinder::LookAgainLocally(const GrayImageView& image,
                                                            double light_ratio) {
  candidates_.clear();
  if (OnTheLastGrid(image)) {
    AddLocallyLight(image, light_ratio);
    KeepBest();
  }
  return candidates_;
}

void SheetFinder::AddLocallyLight(const GrayImageView& image, double light_ratio) {
  local_done_ = true;
  if (first_threshold_ < 0) return;
  MarkLocallyDark(light_ratio);
  AddComponents(image, local_.data(), first_threshold_);
}

void SheetFinder::KeepBest() {
  for (SeenComponent& seen : seen_) seen.candidate = -1;  // candidates_ reordered, then cleared
  std::stable_sort(candidates_.begin(), candidates_.end(),
                   [](const LightQuad& a, const LightQuad& b) { return a.score > b.score; });
  if (static_cast<int>(candidates_.size()) > options_.max_candidates) {
    candidates_.resize(static_cast<std::size_t>(options_.max_candidates));
  }
}

}  // namespace oal
