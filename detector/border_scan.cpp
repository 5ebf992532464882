#include "detector/border_scan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace oal {
namespace {

// Loop coordinates of the four corners: top-left, top-right, bottom-right, bottom-left.
std::array<int, 4> Corners(const BorderRect& r) {
  const int w = r.Width(), h = r.Height();
  return {0, w - 1, w + h - 2, 2 * w + h - 3};
}

double WrapLoop(double s, int perimeter) {
  s = std::fmod(s, static_cast<double>(perimeter));
  return s < 0.0 ? s + perimeter : s;
}

// A run of "on" pixels in unwrapped loop coordinates: pixels first..last (last may be >= P).
struct Run {
  int first = 0;
  int last = 0;
};

}  // namespace

BorderRect BorderAt(int width, int height, int d) {
  return BorderRect{d, d, width - 1 - d, height - 1 - d};
}

Point2d BorderRect::ToPixel(double s) const {
  const auto c = Corners(*this);
  s = WrapLoop(s, Perimeter());
  if (s <= c[1]) return {u0 + s, static_cast<double>(v0)};
  if (s <= c[2]) return {static_cast<double>(u1), v0 + (s - c[1])};
  if (s <= c[3]) return {u1 - (s - c[2]), static_cast<double>(v1)};
  return {static_cast<double>(u0), v1 - (s - c[3])};
}

std::uint8_t BorderRect::Sides(double s, double corner_px) const {
  const auto c = Corners(*this);
  const int p = Perimeter();
  s = WrapLoop(s, p);
  std::uint8_t sides = s <= c[1] ? kTop : s <= c[2] ? kRight : s <= c[3] ? kBottom : kLeft;
  // Corner k joins side k-1 (before it on the loop) and side k (after it).
  constexpr std::array<std::uint8_t, 4> kBefore = {kLeft, kTop, kRight, kBottom};
  constexpr std::array<std::uint8_t, 4> kAfter = {kTop, kRight, kBottom, kLeft};
  for (int k = 0; k < 4; ++k) {
    double distance = std::fabs(s - c[k]);
    distance = std::min(distance, p - distance);
    if (distance <= corner_px) sides |= kBefore[k] | kAfter[k];
  }
  return sides;
}

void GatherBorder(const GrayImageView& image, const BorderRect& rect,
                  std::vector<std::uint8_t>* samples) {
  samples->resize(static_cast<std::size_t>(rect.Perimeter()));
  std::uint8_t* out = samples->data();
  const std::uint8_t* top = image.data + rect.v0 * image.stride;
  std::memcpy(out, top + rect.u0, static_cast<std::size_t>(rect.Width()));
  out += rect.Width();
  for (int v = rect.v0 + 1; v <= rect.v1; ++v) *out++ = image.at(rect.u1, v);
  const std::uint8_t* bottom = image.data + rect.v1 * image.stride;
  out = std::reverse_copy(bottom + rect.u0, bottom + rect.u1, out);
  for (int v = rect.v1 - 1; v > rect.v0; --v) *out++ = image.at(rect.u0, v);
}

int OtsuThreshold(const std::vector<std::uint8_t>& samples, int* contrast) {
  // A histogram of every fourth pixel in 32 bins of 8 grey levels is plenty: the threshold
  // only has to fall between the two classes, and the sub-pixel run ends interpolate grey
  // levels anyway.
  constexpr int kBins = 32, kShift = 3;
  std::array<int, kBins> histogram{};
  for (std::size_t i = 0; i < samples.size(); i += 4) ++histogram[samples[i] >> kShift];
  std::int64_t total = 0, sum_all = 0;
  for (int b = 0; b < kBins; ++b) {
    total += histogram[b];
    sum_all += static_cast<std::int64_t>(b) * histogram[b];
  }
  // Between-class variance ∝ (sum_all·w_low − sum_low·total)² / (w_low·w_high); candidates
  // are compared by cross-multiplication, so the loop has no division.
  double best_numerator = -1.0, best_denominator = 1.0;
  std::int64_t weight_low = 0, sum_low = 0, best_weight_low = 0, best_sum_low = 0;
  int best = kBins / 2;
  for (int b = 0; b + 1 < kBins; ++b) {
    weight_low += histogram[b];
    sum_low += static_cast<std::int64_t>(b) * histogram[b];
    const std::int64_t weight_high = total - weight_low;
    if (weight_low == 0 || weight_high == 0) continue;
    const double spread = static_cast<double>(sum_all * weight_low - sum_low * total);
    const double numerator = spread * spread;
    const double denominator = static_cast<double>(weight_low) * static_cast<double>(weight_high);
    if (numerator * best_denominator > best_numerator * denominator) {
      best_numerator = numerator;
      best_denominator = denominator;
      best = b + 1;  // bins < best are the low class
      best_weight_low = weight_low;
      best_sum_low = sum_low;
    }
  }
  if (contrast) {
    *contrast = 0;
    if (best_weight_low > 0 && best_weight_low < total) {
      const double gap = static_cast<double>(sum_all - best_sum_low) / (total - best_weight_low) -
                         static_cast<double>(best_sum_low) / best_weight_low;
      *contrast = static_cast<int>(gap * (1 << kShift));
    }
  }
  return best << kShift;
}

namespace {

// True if no pixel of s[0, 16) is on the line side of the threshold: the common case, so it
// is tested 16 pixels at a time (GCC/Clang vector extensions: SSE2 on x86-64, NEON on ARM).
template <bool kLight>
bool BlockIsBackground(const std::uint8_t* s, int threshold) {
#if defined(__GNUC__)
  typedef std::uint8_t Bytes16 __attribute__((vector_size(16)));
  typedef std::uint64_t Words2 __attribute__((vector_size(16)));
  Bytes16 block;
  std::memcpy(&block, s, sizeof(block));
  const auto t = static_cast<std::uint8_t>(std::clamp(threshold, 0, 255));
  // A threshold of 0 (dark) or 255 (light) can mark no pixel.
  if (kLight ? threshold >= 255 : threshold <= 0) return true;
  const Bytes16 on = kLight ? (block > t) : (block < t);
  Words2 words;
  std::memcpy(&words, &on, sizeof(words));
  return (words[0] | words[1]) == 0;
#else
  for (int k = 0; k < 16; ++k) {
    if (kLight ? s[k] > threshold : s[k] < threshold) return false;
  }
  return true;
#endif
}

// Runs of line pixels in s[0, p), in order, bridging gaps narrower than min_gap.
template <bool kLight>
int ScanRuns(const std::uint8_t* s, int p, int threshold, int min_gap, Run* runs, int max_runs) {
  auto on = [&](int i) { return kLight ? s[i] > threshold : s[i] < threshold; };
  int count = 0;
  int i = 0;
  while (i < p) {
    if (i + 16 <= p && BlockIsBackground<kLight>(s + i, threshold)) {
      i += 16;
      continue;
    }
    if (!on(i)) {
      ++i;
      continue;
    }
    int j = i;
    while (j + 1 < p && on(j + 1)) ++j;
    if (count > 0 && i - runs[count - 1].last - 1 < min_gap) {
      runs[count - 1].last = j;
    } else if (count < max_runs) {
      runs[count++] = Run{i, j};
    }
    i = j + 1;
  }
  return count;
}

}  // namespace

int FindBorderPoints(const std::vector<std::uint8_t>& samples, const BorderRect& rect,
                     int threshold, const DetectorOptions& options,
                     std::vector<BorderPoint>* points) {
  const int p = static_cast<int>(samples.size());
  if (p < 4) return 0;
  const bool light = options.polarity == Polarity::kLightLines;
  // f > 0 marks a pixel of a line (or of the dark side of an edge); |f| is its contrast.
  auto f = [&](int i) {
    const int value = samples[static_cast<std::size_t>(i < 0 ? i + p : i >= p ? i - p : i)];
    return light ? static_cast<double>(value - threshold) : static_cast<double>(threshold - value);
  };

  const int min_gap = static_cast<int>(std::ceil(options.min_width_px));
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

  const auto corners = Corners(rect);
  const double max_run =
      options.max_width_px / std::sin(options.min_crossing_angle_deg * kPi / 180.0);
  const bool edges = options.polarity == Polarity::kEdges;
  int added = 0;
  auto push = [&](const BorderPoint& point) {
    if (added >= options.max_points_per_border) return false;
    points->push_back(point);
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
    const double length = s_b - s_a;
    if (length < options.min_width_px) continue;

    if (edges) {
      if (length >= p - options.min_width_px) continue;
      if (!push({rect.ToPixel(s_a), 0.0, rect.Sides(s_a), true})) break;
      if (!push({rect.ToPixel(s_b), 0.0, rect.Sides(s_b), true})) break;
      continue;
    }
    if (length > max_run) continue;

    bool straight = true;
    for (int c : corners) {
      for (int shift : {-p, 0, p}) {
        if (run.first < c + shift && c + shift < run.last) straight = false;
      }
    }
    BorderPoint point;
    point.run_px = length;
    point.straight = straight;
    if (straight) {
      double weight_sum = 0.0, weighted = 0.0;
      for (int i = run.first; i <= run.last; ++i) {
        const double weight = std::max(0.0, f(i));
        weight_sum += weight;
        weighted += weight * i;
      }
      const double centre = weight_sum > 0.0 ? weighted / weight_sum : 0.5 * (s_a + s_b);
      point.pixel = rect.ToPixel(centre);
      point.sides = rect.Sides(centre);
    } else {
      const Point2d a = rect.ToPixel(s_a), b = rect.ToPixel(s_b);
      point.pixel = Point2d{0.5 * (a.u + b.u), 0.5 * (a.v + b.v)};
      point.sides = rect.Sides(s_a) | rect.Sides(s_b);
    }
    if (!push(point)) break;
  }
  return added;
}

}  // namespace oal
