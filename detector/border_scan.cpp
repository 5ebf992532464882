#include "detector/border_scan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "detector/simd.h"

namespace oal {
namespace {

// Loop coordinates of the four corners: top-left, top-right, bottom-right, bottom-left.
std::array<int, 4> Corners(const BorderRect& r) {
  const int w = r.Width(), h = r.Height();
  return {0, w - 1, w + h - 2, 2 * w + h - 3};
}

double WrapLoop(double s, int perimeter) {
  if (s >= 0.0 && s < perimeter) return s;  // the common case, without fmod
  s = std::fmod(s, static_cast<double>(perimeter));
  return s < 0.0 ? s + perimeter : s;
}

// A run of "on" pixels in unwrapped loop coordinates: pixels first..last (last may be >= P).
// (No member initialisers: FindBorderPoints keeps an array of them that is never read
// before it is written, and should not be zeroed on every border.)
struct Run {
  int first;
  int last;
};

}  // namespace

BorderRect BorderAt(int width, int height, int d) {
  return BorderRect{d, d, width - 1 - d, height - 1 - d};
}

std::uint8_t BorderRect::Locate(double s, Point2d* pixel, double corner_px) const {
  const auto c = Corners(*this);
  const int p = Perimeter();
  s = WrapLoop(s, p);
  // The side holding s runs from corner k to corner k + 1 (corner 4 is corner 0 at s = p).
  const int k = s <= c[1] ? 0 : s <= c[2] ? 1 : s <= c[3] ? 2 : 3;
  const double along = s - c[static_cast<std::size_t>(k)];
  const double u_0 = u0, v_0 = v0, u_1 = u1, v_1 = v1;
  *pixel = k == 0   ? Point2d{u_0 + along, v_0}
           : k == 1 ? Point2d{u_1, v_0 + along}
           : k == 2 ? Point2d{u_1 - along, v_1}
                    : Point2d{u_0, v_1 - along};
  // Corner k joins side k - 1 (before it on the loop) and side k (after it).
  const double side_end = k == 3 ? p : c[static_cast<std::size_t>(k + 1)];
  constexpr std::array<std::uint8_t, 4> kSide = {kTop, kRight, kBottom, kLeft};
  std::uint8_t sides = kSide[static_cast<std::size_t>(k)];
  if (along <= corner_px) sides |= kSide[static_cast<std::size_t>((k + 3) % 4)];
  if (side_end - s <= corner_px) sides |= kSide[static_cast<std::size_t>((k + 1) % 4)];
  return sides;
}

Point2d BorderRect::ToPixel(double s) const {
  Point2d pixel;
  Locate(s, &pixel);
  return pixel;
}

std::uint8_t BorderRect::Sides(double s, double corner_px) const {
  Point2d unused;
  return Locate(s, &unused, corner_px);
}

namespace {

// std::reverse_copy of [first, last) to out, eight bytes at a time: a byte swap of a
// 64-bit word reverses the bytes' memory order on any endianness.
void ReverseCopy(const std::uint8_t* first, const std::uint8_t* last, std::uint8_t* out) {
  for (; last - first >= 8; last -= 8, out += 8) {
    std::uint64_t word;
    std::memcpy(&word, last - 8, sizeof(word));
#if defined(__GNUC__)
    word = __builtin_bswap64(word);
#else
    std::uint64_t swapped = 0;
    for (int k = 0; k < 8; ++k) swapped = (swapped << 8) | ((word >> (8 * k)) & 0xFF);
    word = swapped;
#endif
    std::memcpy(out, &word, sizeof(word));
  }
  std::reverse_copy(first, last, out);
}

// Copies the rect's top and bottom rows into their places in its loop `out` (the top row
// first, left to right; the bottom row after the right column, right to left).
void CopyRows(const GrayImageView& image, const BorderRect& rect, std::uint8_t* out) {
  const int width = rect.Width(), inner_rows = rect.Height() - 2;
  const std::uint8_t* top = image.data + rect.v0 * image.stride;
  const std::uint8_t* bottom = image.data + rect.v1 * image.stride;
  std::memcpy(out, top + rect.u0, static_cast<std::size_t>(width));
  out += width + inner_rows;
  *out++ = bottom[rect.u1];  // the bottom-right corner
  ReverseCopy(bottom + rect.u0, bottom + rect.u1, out);
}

}  // namespace

void GatherBorder(const GrayImageView& image, const BorderRect& rect,
                  std::vector<std::uint8_t>* samples) {
  const int perimeter = rect.Perimeter();
  samples->resize(static_cast<std::size_t>(perimeter));
  std::uint8_t* out = samples->data();
  CopyRows(image, rect, out);
  // Both columns in one pass over the inner rows: the right column fills the loop downwards
  // after the top row, the left column fills it upwards from the end. (Locals, because the
  // byte stores could alias rect and image and would force reloads.)
  const int u0 = rect.u0, u1 = rect.u1, inner_rows = rect.Height() - 2;
  const std::ptrdiff_t stride = image.stride;
  std::uint8_t* right = out + rect.Width();
  std::uint8_t* left = out + perimeter - 1;
  const std::uint8_t* row = image.data + (rect.v0 + 1) * stride;
  for (int k = 0; k < inner_rows; ++k, row += stride) {
    *right++ = row[u1];
    *left-- = row[u0];
  }
}

void BorderLoops::Prepare(int width, int height, int first_px, int step_px) {
  if (width == width_ && height == height_ && first_px == first_px_ && step_px == step_px_) {
    return;
  }
  width_ = width;
  height_ = height;
  first_px_ = first_px;
  step_px_ = step_px;
  loops_.clear();
  for (int d = first_px; BorderAt(width, height, d).Valid(); d += step_px) {
    loops_.emplace_back(static_cast<std::size_t>(BorderAt(width, height, d).Perimeter()));
  }
  right_at_.assign(loops_.size(), nullptr);
  left_at_.assign(loops_.size(), nullptr);
}

void BorderLoops::Read(const GrayImageView& image) {
  // Loop order: top row, right column down, bottom row leftwards, left column up. Row v of
  // border k's right column is at right_at[k][v], of its left column at left_at[k][-v].
  // (Set here rather than in Prepare, as a copied object's loops are elsewhere; locals,
  // because the byte stores could alias the members and would force reloads.)
  const int count = this->count();
  for (int k = 0; k < count; ++k) {
    const BorderRect rect = Rect(k);
    std::uint8_t* loop = loops_[static_cast<std::size_t>(k)].data();
    // Row v0 + 1 is at loop index Width() on the right, Perimeter() - 1 on the left.
    right_at_[static_cast<std::size_t>(k)] = loop + rect.Width() - (rect.v0 + 1);
    left_at_[static_cast<std::size_t>(k)] = loop + rect.Perimeter() - 1 + (rect.v0 + 1);
  }
  std::uint8_t* const* right_at = right_at_.data();
  std::uint8_t* const* left_at = left_at_.data();
  const int first = first_px_, step = step_px_;
  // Rows in pairs the same distance from the top and the bottom edge (the middle row of an
  // odd height twice, harmlessly): both are inner rows of the same borders, those with
  // d < top, so one pass over those borders serves four pixels.
  for (int top = first + 1, bottom = height_ - 2 - first; top <= bottom; ++top, --bottom) {
    const int active = std::min(count, (top - first + step - 1) / step);
    const std::uint8_t* top_row = image.data + top * image.stride;
    const std::uint8_t* bottom_row = image.data + bottom * image.stride;
    int u_left = first, u_right = width_ - 1 - first;
    for (int k = 0; k < active; ++k, u_left += step, u_right -= step) {
      std::uint8_t* right = right_at[k];
      std::uint8_t* left = left_at[k];
      right[top] = top_row[u_right];
      left[-top] = top_row[u_left];
      right[bottom] = bottom_row[u_right];
      left[-bottom] = bottom_row[u_left];
    }
  }
}

const std::vector<std::uint8_t>& BorderLoops::Gather(const GrayImageView& image, int k) {
  std::vector<std::uint8_t>& loop = loops_[static_cast<std::size_t>(k)];
  CopyRows(image, Rect(k), loop.data());
  return loop;
}

namespace {

// Histogram of every fourth sample in kBins bins of 2^kShift grey levels. Eight interleaved
// partial histograms let consecutive increments of the same bin (the background's) proceed
// without waiting for each other: an increment of memory waits for the previous one's store
// to forward, about five cycles, so one histogram would take five cycles a sample.
template <int kBins, int kShift>
std::array<int, kBins> SampledHistogram(const std::vector<std::uint8_t>& samples) {
  constexpr std::size_t kPartials = 8, kStride = 4;
  // 16-bit counts (half the memory to clear): a partial counts at most one sample in 32.
  std::array<std::array<std::uint16_t, kBins>, kPartials> partial{};
  const std::uint8_t* s = samples.data();
  const std::size_t n = samples.size();
  std::size_t i = 0;
  for (; i + kPartials * kStride <= n; i += kPartials * kStride) {
    for (std::size_t k = 0; k < kPartials; ++k) ++partial[k][s[i + k * kStride] >> kShift];
  }
  for (; i < n; i += kStride) ++partial[0][s[i] >> kShift];
  std::array<int, kBins> histogram{};
  for (const auto& part : partial) {
    for (int b = 0; b < kBins; ++b) histogram[b] += part[b];
  }
  return histogram;
}

}  // namespace

int OtsuThreshold(const std::vector<std::uint8_t>& samples, int* contrast, int* light) {
  // A histogram of every fourth pixel in 32 bins of 8 grey levels is plenty: the threshold
  // only has to fall between the two classes, and the sub-pixel run ends interpolate grey
  // levels anyway.
  constexpr int kBins = 32, kShift = 3;
  const std::array<int, kBins> histogram = SampledHistogram<kBins, kShift>(samples);
  int total = 0, sum_all = 0;
  for (int b = 0; b < kBins; ++b) {
    total += histogram[b];
    sum_all += b * histogram[b];
  }
  int lowest = 0, highest = kBins - 1;  // the occupied bins (none: lowest > highest)
  while (lowest < kBins && histogram[lowest] == 0) ++lowest;
  while (highest > lowest && histogram[highest] == 0) --highest;
  // Between-class variance ∝ (sum_all·w_low − sum_low·total)² / (w_low·w_high); candidates
  // are compared by cross-multiplication, so the loop has no division. The running sums are
  // integers (a one-cycle dependency chain); the squares and products, below 2^53, are
  // exact in double.
  double best_numerator = -1.0, best_denominator = 1.0;
  int weight_low = 0, sum_low = 0, best_weight_low = 0, best_sum_low = 0;
  int best = kBins / 2;
  // Splits below the lowest or from the highest occupied bin leave a class empty.
  for (int b = lowest; b < highest; ++b) {
    weight_low += histogram[b];
    sum_low += b * histogram[b];
    const auto spread = static_cast<double>(static_cast<std::int64_t>(sum_all) * weight_low -
                                            static_cast<std::int64_t>(sum_low) * total);
    const double numerator = spread * spread;
    const auto denominator = static_cast<double>(weight_low * (total - weight_low));
    if (numerator * best_denominator > best_numerator * denominator) {
      best_numerator = numerator;
      best_denominator = denominator;
      best = b + 1;  // bins < best are the low class
      best_weight_low = weight_low;
      best_sum_low = sum_low;
    }
  }
  if (contrast) *contrast = 0;
  if (light) *light = 0;
  if (best_weight_low > 0 && best_weight_low < total) {
    const double light_mean =
        static_cast<double>(sum_all - best_sum_low) / (total - best_weight_low);
    if (contrast) {
      const double gap = light_mean - static_cast<double>(best_sum_low) / best_weight_low;
      *contrast = static_cast<int>(gap * (1 << kShift));
    }
    if (light) *light = static_cast<int>(light_mean * (1 << kShift));
  }
  return best << kShift;
}

namespace {

// Bit k of the result is set if pixel s[k] of s[0, n) is on the line side of the threshold.
template <bool kLight>
std::uint64_t LineMaskScalar(const std::uint8_t* s, int n, int threshold) {
  std::uint64_t mask = 0;
  for (int k = 0; k < n; ++k) {
    const bool on = kLight ? s[k] > threshold : s[k] < threshold;
    mask |= static_cast<std::uint64_t>(on) << k;
  }
  return mask;
}

#if OAL_HAVE_VECTOR_EXTENSIONS
typedef std::uint8_t Bytes16 __attribute__((vector_size(16)));
typedef std::int8_t ByteMasks16 __attribute__((vector_size(16)));  // comparison results

// Bit k of the result is the top bit of byte k of `on`.
std::uint32_t MoveMask(ByteMasks16 on) {
#if OAL_HAVE_SSE2
  __m128i bytes;
  std::memcpy(&bytes, &on, sizeof(bytes));
  return static_cast<std::uint32_t>(_mm_movemask_epi8(bytes));
#else
  const Bytes16 lane_bit = {1, 2, 4, 8, 16, 32, 64, 128, 1, 2, 4, 8, 16, 32, 64, 128};
  Bytes16 bits;
  std::memcpy(&bits, &on, sizeof(bits));
  bits &= lane_bit;
  // Each half holds eight distinct bits in eight bytes; multiplying by 0x0101...01 sums
  // the bytes into the top byte, whatever the byte order.
  std::uint64_t halves[2];
  std::memcpy(halves, &bits, sizeof(halves));
  constexpr std::uint64_t kSumBytes = 0x0101010101010101ULL;
  const std::uint64_t low8 = (halves[0] * kSumBytes) >> 56;
  const std::uint64_t high8 = (halves[1] * kSumBytes) >> 56;
  return static_cast<std::uint32_t>(low8 | high8 << 8);
#endif
}
#endif

// LineMaskScalar for 64 pixels, 16 at a time (GCC/Clang vector extensions: SSE2 on x86-64,
// where one instruction gathers the 16 comparison bits, NEON on ARM). Needs
// 0 <= threshold <= 255.
template <bool kLight>
std::uint64_t LineMask64(const std::uint8_t* s, int threshold) {
#if OAL_HAVE_VECTOR_EXTENSIONS
  const auto t = static_cast<std::uint8_t>(threshold);
  std::uint64_t mask = 0;
  for (int block = 0; block < 4; ++block) {
    Bytes16 pixels;
    std::memcpy(&pixels, s + 16 * block, sizeof(pixels));
    const ByteMasks16 on = kLight ? (pixels > t) : (pixels < t);
    mask |= static_cast<std::uint64_t>(MoveMask(on)) << (16 * block);
  }
  return mask;
#else
  return LineMaskScalar<kLight>(s, 64, threshold);
#endif
}

int CountTrailingZeros(std::uint64_t x) {  // x != 0
#if defined(__GNUC__)
  return __builtin_ctzll(x);
#else
  int n = 0;
  for (; (x & 1) == 0; x >>= 1) ++n;
  return n;
#endif
}

// Collects runs of line pixels in order, bridging gaps narrower than min_gap; at most
// max_runs (later runs are dropped, but may still be bridged into the last one kept).
class RunCollector {
 public:
  RunCollector(int min_gap, Run* runs, int max_runs)
      : min_gap_(min_gap), runs_(runs), max_runs_(max_runs) {}
  void Add(int first, int last) {
    if (count_ > 0 && first - runs_[count_ - 1].last - 1 < min_gap_) {
      runs_[count_ - 1].last = last;
    } else if (count_ < max_runs_) {
      runs_[count_++] = Run{first, last};
    }
  }
  int count() const { return count_; }

 private:
  int min_gap_;
  Run* runs_;
  int max_runs_;
  int count_ = 0;
};

// Runs of line pixels in s[0, p). The border is turned into 64-pixel bit masks, and run
// ends are found as the next set or clear bit, so background costs no per-pixel branch.
template <bool kLight>
int ScanRuns(const std::uint8_t* s, int p, int threshold, int min_gap, Run* runs, int max_runs) {
  RunCollector collector(min_gap, runs, max_runs);
  const bool vector_ok = threshold >= 0 && threshold <= 255;
  bool in_run = false;
  int run_first = 0;
  for (int base = 0; base < p; base += 64) {
    const int n = std::min(64, p - base);
    std::uint64_t mask = 0;
    if (!vector_ok) {
      mask = LineMaskScalar<kLight>(s + base, n, threshold);
    } else if (n == 64) {
      mask = LineMask64<kLight>(s + base, threshold);
    } else {  // the last, partial block: vectorised too, from a copy (the bits past n are masked)
      std::uint8_t tail[64] = {};
      std::memcpy(tail, s + base, static_cast<std::size_t>(n));
      mask = LineMask64<kLight>(tail, threshold);
    }
    const std::uint64_t valid = n == 64 ? ~0ULL : (1ULL << n) - 1;
    for (int k = 0; k < n;) {
      // In a run look for its end (a clear bit), outside for the next start (a set bit).
      const std::uint64_t wanted = (in_run ? ~mask : mask) & valid & (~0ULL << k);
      if (wanted == 0) break;
      k = CountTrailingZeros(wanted);
      if (in_run) {
        collector.Add(run_first, base + k - 1);
      } else {
        run_first = base + k;
      }
      in_run = !in_run;
      ++k;
    }
  }
  if (in_run) collector.Add(run_first, p - 1);
  return collector.count();
}

// Whether a corner of the loop lies strictly inside the run. Runs start in [-p, p) and end
// before p, so it is enough to compare the end with the first corner after the start
// (corners[0] = 0 comes back as p).
bool CornerInsideRun(const Run& run, const std::array<int, 4>& corners, int p) {
  const int offset = run.first < 0 ? -p : 0;
  const int start = run.first - offset;  // in [0, p)
  const int next = start < corners[1]   ? corners[1]
                   : start < corners[2] ? corners[2]
                   : start < corners[3] ? corners[3]
                                        : p;
  return next + offset < run.last;
}

// Adds the contrast weights of loop coordinates [lo, hi], stored at samples s[i + shift].
// Chunks of kChunk pixels are summed in 32-bit integers, relative to the chunk's start,
// which cannot overflow (255 * 2048 * 2047 / 2 < 2^31).
template <bool kLight>
void AddWeightsScalar(const std::uint8_t* s, int lo, int hi, int shift, int threshold,
                      std::int64_t* weight_sum, std::int64_t* weighted) {
  constexpr int kChunk = 2048;
  for (int start = lo; start <= hi; start += kChunk) {
    const std::uint8_t* chunk = s + start + shift;
    const int n = std::min(kChunk, hi - start + 1);
    std::int32_t chunk_weight = 0, chunk_weighted = 0;
    for (int k = 0; k < n; ++k) {
      const int value = chunk[k];
      const std::int32_t weight = std::max(0, kLight ? value - threshold : threshold - value);
      chunk_weight += weight;
      chunk_weighted += weight * k;
    }
    *weight_sum += chunk_weight;
    *weighted += chunk_weighted + static_cast<std::int64_t>(chunk_weight) * start;
  }
}

// AddWeightsScalar with the same integer sums, 16 samples at a time with SSE2: the weights
// are saturating byte differences, their sum one psadbw, their sum times the lane index one
// pmaddwd. The 16-sample windows stay inside s[0, n) (n >= 16, 0 <= threshold <= 255): the
// last one is moved back to end at n and its lanes already counted or outside [lo, hi] are
// zeroed. Runs are short (tens of samples), so this saves the scalar loop's per-sample cost.
template <bool kLight>
void AddWeights(const std::uint8_t* s, int n, int lo, int hi, int shift, int threshold,
                std::int64_t* weight_sum, std::int64_t* weighted) {
#if OAL_HAVE_SSE2
  if (hi < lo) return;
  if (n < 16 || threshold < 0 || threshold > 255) {
    AddWeightsScalar<kLight>(s, lo, hi, shift, threshold, weight_sum, weighted);
    return;
  }
  const __m128i t = _mm_set1_epi8(static_cast<char>(threshold));
  const __m128i zero = _mm_setzero_si128();
  const __m128i lane = _mm_setr_epi8(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m128i lane_low = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
  const __m128i lane_high = _mm_setr_epi16(8, 9, 10, 11, 12, 13, 14, 15);
  const int first = lo + shift, last = hi + shift;  // in s
  std::int64_t total = 0, indexed = 0;              // sum of w, sum of (index in s) * w
  for (int window = first; window <= last; window += 16) {
    const int start = std::min(window, n - 16);
    const __m128i pixels = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + start));
    const __m128i all = kLight ? _mm_subs_epu8(pixels, t) : _mm_subs_epu8(t, pixels);
    // Lanes before `window` (counted by the previous window) or after `last` are dropped.
    const __m128i before = _mm_cmplt_epi8(lane, _mm_set1_epi8(static_cast<char>(window - start)));
    const __m128i after =
        _mm_cmpgt_epi8(lane, _mm_set1_epi8(static_cast<char>(std::min(last - start, 15))));
    const __m128i weights = _mm_andnot_si128(_mm_or_si128(before, after), all);
    const __m128i sums = _mm_sad_epu8(weights, zero);
    const int block_weight = _mm_cvtsi128_si32(sums) + _mm_extract_epi16(sums, 4);
    __m128i products = _mm_add_epi32(_mm_madd_epi16(_mm_unpacklo_epi8(weights, zero), lane_low),
                                     _mm_madd_epi16(_mm_unpackhi_epi8(weights, zero), lane_high));
    products = _mm_add_epi32(products, _mm_shuffle_epi32(products, _MM_SHUFFLE(1, 0, 3, 2)));
    products = _mm_add_epi32(products, _mm_shuffle_epi32(products, _MM_SHUFFLE(2, 3, 0, 1)));
    total += block_weight;
    indexed += _mm_cvtsi128_si32(products) + static_cast<std::int64_t>(start) * block_weight;
  }
  *weight_sum += total;
  *weighted += indexed - static_cast<std::int64_t>(shift) * total;  // loop coordinates
#else
  (void)n;
  AddWeightsScalar<kLight>(s, lo, hi, shift, threshold, weight_sum, weighted);
#endif
}

// The contrast-weighted centre of a run in loop coordinates (its midpoint if it has no
// contrast). Weights are integers, so integer sums give the double sums exactly, faster.
// A run across the loop's seam is summed in contiguous pieces.
template <bool kLight>
double WeightedCentre(const std::uint8_t* s, int p, const Run& run, int threshold, double s_a,
                      double s_b) {
  std::int64_t weight_sum = 0, weighted = 0;
  AddWeights<kLight>(s, p, run.first, std::min(run.last, -1), p, threshold, &weight_sum, &weighted);
  AddWeights<kLight>(s, p, std::max(run.first, 0), std::min(run.last, p - 1), 0, threshold,
                     &weight_sum, &weighted);
  AddWeights<kLight>(s, p, std::max(run.first, p), run.last, -p, threshold, &weight_sum, &weighted);
  return weight_sum > 0 ? static_cast<double>(weighted) / static_cast<double>(weight_sum)
                        : 0.5 * (s_a + s_b);
}

// The loop geometry FindPoints needs, for a border rectangle and for a region's polygon.
class RectGeometry {
 public:
  explicit RectGeometry(const BorderRect& rect) : rect_(rect), corners_(Corners(rect)) {}
  bool HasCornerInside(const Run& run, int p) const { return CornerInsideRun(run, corners_, p); }
  std::uint16_t Locate(double s, Point2d* pixel) const { return rect_.Locate(s, pixel); }
  // The side's direction when the point lies on one side only (a side's width across the
  // line is then measurable).
  Point2d Along(double, std::uint16_t sides) const {
    const bool horizontal = (sides & (kTop | kBottom)) != 0;
    const bool vertical = (sides & (kRight | kLeft)) != 0;
    if (horizontal == vertical) return Point2d{};
    return horizontal ? Point2d{1.0, 0.0} : Point2d{0.0, 1.0};
  }
  double Spacing(double) const { return 1.0; }
  int Stride() const { return 1; }
  bool RereadsRuns() const { return false; }
  bool ReadPixels(int, int, std::uint8_t*) const { return false; }

 private:
  const BorderRect& rect_;
  std::array<int, 4> corners_;
};

class PolygonGeometry {
 public:
  PolygonGeometry(const PolygonLoop& loop, const GrayImageView* image)
      : loop_(loop), image_(image) {}
  bool HasCornerInside(const Run& run, int) const {
    return loop_.HasCornerInside(run.first, run.last);
  }
  std::uint16_t Locate(double s, Point2d* pixel) const { return loop_.Locate(s, pixel); }
  Point2d Along(double s, std::uint16_t sides) const {
    if ((sides & (sides - 1)) != 0) return Point2d{};  // more than one edge
    return loop_.Direction(s);
  }
  double Spacing(double s) const { return loop_.Spacing(s); }
  int Stride() const { return loop_.SampleStep(); }
  bool RereadsRuns() const { return image_ != nullptr && loop_.SampleStep() > 1; }
  // The image's pixels from loop coordinate `first` on (PolygonLoop::GatherPixels).
  bool ReadPixels(int first, int count, std::uint8_t* out) const {
    return loop_.GatherPixels(*image_, first, count, out);
  }

 private:
  const PolygonLoop& loop_;
  const GrayImageView* image_;
};

// A run of a loop read every `stride` pixels, read again at every pixel from two samples
// before it to two after: the dark stretch around its middle there, its ends where it crosses
// `threshold`, and its centre weighted by the contrast to `reference` (the paper beside it)
// over it and a pixel either side, as on the samples. Writes the centre (loop coordinates)
// and returns the length (samples); 0 when the stretch is not found (the samples' stand).
template <typename Geometry>
double RereadRun(const Geometry& geometry, const Run& run, int threshold, int reference, bool light,
                 double* centre) {
  constexpr int kMaxPixels = 1024;
  const int stride = geometry.Stride();
  const int lo = run.first - 2;
  const int n = (run.last - run.first + 4) * stride + 1;
  std::array<std::uint8_t, kMaxPixels> grey;
  if (n > kMaxPixels || !geometry.ReadPixels(lo, n, grey.data())) return 0.0;
  const auto f = [&](int i) {
    const int value = grey[static_cast<std::size_t>(i)];
    return light ? value - threshold : threshold - value;  // > 0: the run's
  };
  const int middle = static_cast<int>(std::lround((*centre - lo) * stride));
  if (middle <= 0 || middle >= n - 1 || f(middle) <= 0) return 0.0;
  int first = middle, last = middle;
  while (first > 0 && f(first - 1) > 0) --first;
  while (last < n - 1 && f(last + 1) > 0) ++last;
  if (first == 0 || last == n - 1) return 0.0;
  const double a = first - 1 + static_cast<double>(-f(first - 1)) / (f(first) - f(first - 1));
  const double b = last + static_cast<double>(f(last)) / (f(last) - f(last + 1));
  const Run weighted{first - 1, last + 1};
  const double fine = light ? WeightedCentre<true>(grey.data(), n, weighted, reference, a, b)
                            : WeightedCentre<false>(grey.data(), n, weighted, reference, a, b);
  *centre = lo + fine / stride;
  return (b - a) / stride;
}

template <typename Geometry>
int FindPoints(const std::vector<std::uint8_t>& samples, const Geometry& geometry, int threshold,
               const DetectorOptions& options, std::vector<BorderPoint>* points) {
  const int p = static_cast<int>(samples.size());
  if (p < 4) return 0;
  const bool light = options.polarity == Polarity::kLightLines;
  // f > 0 marks a pixel of a line (or of the dark side of an edge); |f| is its contrast.
  auto f = [&](int i) {
    const int value = samples[static_cast<std::size_t>(i < 0 ? i + p : i >= p ? i - p : i)];
    return light ? static_cast<double>(value - threshold) : static_cast<double>(threshold - value);
  };

  // Widths in samples: a sample every `stride` pixels along the border's longer axis.
  const double stride = geometry.Stride();
  const double min_width = options.min_width_px / stride;
  const double max_width = options.max_width_px / stride;
  const int min_gap = std::max(1, static_cast<int>(std::ceil(min_width)));
  constexpr int kMaxRuns = 2 * 64 + 2;
  Run runs[kMaxRuns];
  int run_count = light ? ScanRuns<true>(samples.data(), p, threshold, min_gap, runs, kMaxRuns)
                        : ScanRuns<false>(samples.data(), p, threshold, min_gap, runs, kMaxRuns);
  if (run_count == 0) return 0;
  if (runs[0].first == 0 && runs[run_count - 1].last == p - 1 && run_count == 1) {
    return 0;  // the whole border is dark: nothing crosses it
  }
  if (run_count > 1 && runs[0].first + p - runs[run_count - 1].last - 1 < min_gap) {
    runs[0].first = runs[run_count - 1].first - p;  // one run across the loop's seam
    --run_count;
  }

  // (Computed only for runs wider than max_width_px, which are rare: sin is not cheap.)
  auto longer_than_max_run = [&](double length) {
    return length > max_width &&
           length > max_width / std::sin(options.min_crossing_angle_deg * kPi / 180.0);
  };
  const bool edges = options.polarity == Polarity::kEdges;
  int added = 0;
  // Appends a point, built in place (copying in a just-built local point stalled on store
  // forwarding); false once the border has its maximum.
  auto push = [&](const Point2d& pixel, double run_px, std::uint16_t sides, bool straight,
                  const Point2d& along, double background_step) {
    if (added >= options.max_points_per_border) return false;
    BorderPoint& point = points->emplace_back();
    point.pixel = pixel;
    point.run_px = run_px;
    point.sides = sides;
    point.straight = straight;
    point.along = along;
    point.background_step = static_cast<float>(background_step);
    ++added;
    return true;
  };

  for (int k = 0; k < run_count; ++k) {
    const Run& run = runs[k];
    // Sub-pixel ends where f crosses zero, by linear interpolation.
    const double f_before = f(run.first - 1), f_first = f(run.first);
    const double f_last = f(run.last), f_after = f(run.last + 1);
    const double s_a = run.first - 1 + (-f_before) / (f_first - f_before);
    const double s_b = run.last + f_last / (f_last - f_after);
    double length = s_b - s_a;
    if (length < min_width) continue;

    if (edges) {
      if (length >= p - min_width) continue;
      Point2d a, b;
      const std::uint16_t sides_a = geometry.Locate(s_a, &a), sides_b = geometry.Locate(s_b, &b);
      if (!push(a, 0.0, sides_a, true, Point2d{}, 0.0)) break;
      if (!push(b, 0.0, sides_b, true, Point2d{}, 0.0)) break;
      continue;
    }
    if (longer_than_max_run(length)) continue;

    const bool straight = !geometry.HasCornerInside(run, p);
    Point2d pixel, along;
    std::uint16_t sides = 0;
    double run_px = length * stride;
    double background_step = 0.0;
    if (straight) {
      // The weights: each sample's contrast to the threshold, or (centre_from_background) to
      // the background beside the run, over the run and one sample either side, which a
      // partly covered pixel beyond the threshold's crossing still counts in: clipped at the
      // threshold, a sample grid out of phase with the stripe pulls the centre by up to a
      // quarter pixel.
      Run weighted = run;
      int reference = threshold;
      if (options.centre_from_background && run.last - run.first + 7 < p) {
        weighted = Run{run.first - 1, run.last + 1};
        const double beside =
            0.25 * (f(run.first - 3) + f(run.first - 2) + f(run.last + 2) + f(run.last + 3));
        // f is the contrast to the threshold: back to a grey level.
        reference = static_cast<int>(std::lround(light ? threshold + beside : threshold - beside));
        reference = std::clamp(reference, 0, 255);
      }
      double centre = light
                          ? WeightedCentre<true>(samples.data(), p, weighted, reference, s_a, s_b)
                          : WeightedCentre<false>(samples.data(), p, weighted, reference, s_a, s_b);
      if (geometry.RereadsRuns()) {
        const double reread_length = RereadRun(geometry, run, threshold, reference, light, &centre);
        if (reread_length > 0.0) length = reread_length;
      }
      // f < 0 beside the run: its magnitude is the background's contrast to the threshold.
      const double before = -0.5 * (f(run.first - 3) + f(run.first - 2));
      const double after = -0.5 * (f(run.last + 2) + f(run.last + 3));
      double depth = 0.0;
      for (int i = run.first; i <= run.last; ++i) depth = std::max(depth, f(i));
      const double drop = std::max(before, after) + depth;  // the lighter side to the run's ink
      if (drop > 0.0) background_step = std::fabs(before - after) / drop;
      sides = geometry.Locate(centre, &pixel);
      along = geometry.Along(centre, sides);
      run_px = length * geometry.Spacing(centre);
    } else {
      Point2d a, b;
      sides = static_cast<std::uint16_t>(geometry.Locate(s_a, &a) | geometry.Locate(s_b, &b));
      pixel = Point2d{0.5 * (a.u + b.u), 0.5 * (a.v + b.v)};
    }
    if (!push(pixel, run_px, sides, straight, along, background_step)) break;
  }
  return added;
}

}  // namespace

int FindBorderPoints(const std::vector<std::uint8_t>& samples, const BorderRect& rect,
                     int threshold, const DetectorOptions& options,
                     std::vector<BorderPoint>* points) {
  return FindPoints(samples, RectGeometry(rect), threshold, options, points);
}

int FindBorderPoints(const std::vector<std::uint8_t>& samples, const PolygonLoop& loop,
                     int threshold, const DetectorOptions& options,
                     std::vector<BorderPoint>* points, const GrayImageView* image) {
  return FindPoints(samples, PolygonGeometry(loop, image), threshold, options, points);
}

}  // namespace oal
