#include "detector/accumulator_list.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "detector/simd.h"

namespace oal {
namespace {

// Signed angle whose sine is `s`: asin's Taylor series to s^9 (error below 1e-10 rad) up to
// sin(10 deg), which covers the default anglechange (2 deg) without a library call; beyond,
// up to the 45 deg anglechange allows, std::asin.
double StepAsin(double s) {
  constexpr double kSeriesLimit = 0.17;  // ~ sin(10 deg)
  if (std::fabs(s) > kSeriesLimit) return std::asin(s);
  const double s2 = s * s;
  return s * (1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0 + s2 * 35.0 / 1152.0))));
}

// Rotates the unit vector (c, s) by the angle a. For |a| < 0.1 rad (every step of the default
// anglechange) sin/cos series good to 1e-12 and a renormalisation: the squared norm n is 1 to
// about 1e-12, so one Newton step for 1 / sqrt(n), (3 - n) / 2, is exact to double precision
// (and costs no sqrt or division). Larger steps use std::cos and std::sin.
void Rotate(double a, double* c, double* s) {
  if (std::fabs(a) >= 0.1) {
    const double cos_a = std::cos(a), sin_a = std::sin(a);
    const double new_c = *c * cos_a - *s * sin_a;
    *s = *s * cos_a + *c * sin_a;
    *c = new_c;
    return;
  }
  const double a2 = a * a;
  // Horner form with constant coefficients (x / 24.0 would be a real division).
  const double cos_a = 1.0 + a2 * (-1.0 / 2.0 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0)));
  const double sin_a = a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0))));
  const double new_c = *c * cos_a - *s * sin_a;
  const double new_s = *s * cos_a + *c * sin_a;
  const double norm = 0.5 * (3.0 - (new_c * new_c + new_s * new_s));
  *c = new_c * norm;
  *s = new_s * norm;
}

// Turns the normal half a turn (theta +- pi, -rho) when it points below the u axis, so that
// theta stays in [0, pi): sin > 0, or sin = 0 and cos > 0.
void KeepUpperHalf(double* cos_theta, double* sin_theta, double* rho_px) {
  if (*sin_theta < 0.0 || (*sin_theta == 0.0 && *cos_theta < 0.0)) {
    *cos_theta = -*cos_theta;
    *sin_theta = -*sin_theta;
    *rho_px = -*rho_px;
  }
}

// FirstMatch tests kMatchLanes entries per vector, two vectors per loop iteration; the
// match arrays are padded to whole iterations.
constexpr int kMatchLanes = 4;                // one 16-byte SIMD register of floats
constexpr int kMatchBlock = 2 * kMatchLanes;  // entries tested per loop iteration

int RoundUpToBlocks(int n) {
  return (n + kMatchBlock - 1) / kMatchBlock * kMatchBlock;
}

}  // namespace

OrderedAccumulatorList::OrderedAccumulatorList(double angle_change_rad, double r_change_px,
                                               int max_lines, int capacity)
    : cos_angle_change_(std::cos(angle_change_rad)),
      sin_angle_change_(std::sin(angle_change_rad)),
      r_change_px_(r_change_px),
      max_lines_(max_lines),
      capacity_(std::max(capacity, max_lines)) {
  const auto reserved = static_cast<std::size_t>(capacity_);
  entries_.reserve(reserved);
  order_.reserve(reserved);
  moved_.reserve(reserved);
  const auto padded = static_cast<std::size_t>(RoundUpToBlocks(capacity_));
  match_cos_.assign(padded, 0.0f);
  match_sin_.assign(padded, 0.0f);
  match_rho_.assign(padded, 0.0f);
}

void OrderedAccumulatorList::Mirror(std::size_t i) {
  match_cos_[i] = static_cast<float>(entries_[i].cos_theta);
  match_sin_[i] = static_cast<float>(entries_[i].sin_theta);
  match_rho_[i] = static_cast<float>(entries_[i].rho_px);
}

#if OAL_HAVE_VECTOR_EXTENSIONS
// The scalar loop below, kMatchBlock entries at a time (GCC/Clang vector extensions: SSE2 on
// x86-64, NEON on ARM). The lanes compute exactly the scalar loop's float expressions.
int OrderedAccumulatorList::FirstMatch(double cos_theta, double sin_theta, double rho_px) const {
  typedef float Floats __attribute__((vector_size(4 * kMatchLanes)));
  typedef std::int32_t Ints __attribute__((vector_size(4 * kMatchLanes)));
  static_assert(kMatchLanes == 4, "broadcast below lists the lanes");
  auto broadcast = [](float x) { return Floats{x, x, x, x}; };
  auto load = [](const std::vector<float>& array, int i) {
    Floats v;
    std::memcpy(&v, array.data() + i, sizeof(v));
    return v;
  };
  // fabs and sign flips as bit operations on the IEEE sign bit.
  auto bits = [](Floats v) {
    Ints b;
    std::memcpy(&b, &v, sizeof(b));
    return b;
  };
  auto floats = [](Ints b) {
    Floats v;
    std::memcpy(&v, &b, sizeof(v));
    return v;
  };
  constexpr std::int32_t kSignBit = INT32_MIN;
  const Floats c = broadcast(static_cast<float>(cos_theta));
  const Floats s = broadcast(static_cast<float>(sin_theta));
  const Ints rho = bits(broadcast(static_cast<float>(rho_px)));
  const Floats cos_limit = broadcast(static_cast<float>(cos_angle_change_));
  const Floats r_limit = broadcast(static_cast<float>(r_change_px_));
  const Floats zero = broadcast(0.0f);
  // Eq. 1 and 2 for entries [i, i + kMatchLanes): all-ones lanes match.
  auto matches = [&](int i) {
    const Floats dot = load(match_cos_, i) * c + load(match_sin_, i) * s;
    const Floats abs_dot = floats(bits(dot) & ~kSignBit);
    // A negative dot is the same line with its normal reversed: theta +- pi, -rho. (A dot
    // of -0 would flip rho where the scalar loop does not, but it fails Eq. 1 anyway.)
    const Floats aligned_rho = floats(rho ^ ((dot < zero) & kSignBit));
    const Floats rho_gap = floats(bits(aligned_rho - load(match_rho_, i)) & ~kSignBit);
    return ~(abs_dot < cos_limit) & ~(rho_gap > r_limit);
  };
  const int size = static_cast<int>(entries_.size());
  for (int i = 0; i < size; i += kMatchBlock) {
    const Ints low = matches(i), high = matches(i + kMatchLanes);
#if OAL_HAVE_SSE2
    // One bit per lane, from the lanes' sign bits.
    __m128 low_lanes, high_lanes;
    std::memcpy(&low_lanes, &low, sizeof(low_lanes));
    std::memcpy(&high_lanes, &high, sizeof(high_lanes));
    const unsigned lanes = static_cast<unsigned>(_mm_movemask_ps(low_lanes)) |
                           static_cast<unsigned>(_mm_movemask_ps(high_lanes)) << kMatchLanes;
    if (lanes == 0) continue;
    const int k = __builtin_ctz(lanes);
#else
    int k = 0;
    while (k < kMatchBlock && (k < kMatchLanes ? low[k] : high[k - kMatchLanes]) == 0) ++k;
    if (k == kMatchBlock) continue;
#endif
    // Lanes past the end hold stale values: a match there means no match.
    return i + k < size ? i + k : -1;
  }
  return -1;
}
#else
int OrderedAccumulatorList::FirstMatch(double cos_theta, double sin_theta, double rho_px) const {
  const float c = static_cast<float>(cos_theta), s = static_cast<float>(sin_theta);
  const float rho = static_cast<float>(rho_px);
  const float cos_limit = static_cast<float>(cos_angle_change_);
  const float r_limit = static_cast<float>(r_change_px_);
  const int size = static_cast<int>(entries_.size());
  for (int i = 0; i < size; ++i) {
    const float dot = match_cos_[i] * c + match_sin_[i] * s;
    if (std::fabs(dot) < cos_limit) continue;  // Eq. 1
    // A negative dot is the same line with its normal reversed: theta +- pi, -rho.
    const float aligned_rho = dot < 0.0f ? -rho : rho;
    if (std::fabs(aligned_rho - match_rho_[i]) > r_limit) continue;  // Eq. 2
    return i;
  }
  return -1;
}
#endif

LineParams OalEntry::Line() const {
  // atan2 is in [0, pi] for the upper half-plane; pi itself (sin = +0, cos < 0) is the
  // same line as theta 0.
  const double theta = std::atan2(sin_theta, cos_theta);
  return theta < kPi ? LineParams{rho_px, std::max(theta, 0.0)} : LineParams{-rho_px, 0.0};
}

int OrderedAccumulatorList::Vote(double cos_theta, double sin_theta, double rho_px, int border) {
  const int size = static_cast<int>(entries_.size());
  const int i = FirstMatch(cos_theta, sin_theta, rho_px);
  if (i >= 0) {
    OalEntry& entry = entries_[static_cast<std::size_t>(i)];
    const double sign =
        entry.cos_theta * cos_theta + entry.sin_theta * sin_theta < 0.0 ? -1.0 : 1.0;
    const double rho = sign * rho_px;
    const double c = sign * cos_theta, s = sign * sin_theta;
    const double cross = entry.cos_theta * s - entry.sin_theta * c;  // sin(theta_new - theta_old)
    const double prior = static_cast<double>(entry.weight);
    // theta moves to the vote-weighted mean of the angles: the normal turns by that step.
    const double share = 1.0 / (prior + 1.0);  // the new vote's share of the mean
    Rotate(StepAsin(cross) * share, &entry.cos_theta, &entry.sin_theta);
    entry.rho_px = (prior * entry.rho_px + rho) * share;
    KeepUpperHalf(&entry.cos_theta, &entry.sin_theta, &entry.rho_px);
    ++entry.weight;
    if (entry.last_border != border) {
      ++entry.borders;
      entry.last_border = border;
    }
    Mirror(static_cast<std::size_t>(i));
    return i;
  }
  if (size >= capacity_) return -1;
  Append(cos_theta, sin_theta, rho_px).last_border = border;
  return size;
}

int OrderedAccumulatorList::Seed(double cos_theta, double sin_theta, double rho_px, int seed_id) {
  const int size = static_cast<int>(entries_.size());
  if (size >= capacity_) return -1;
  OalEntry& entry = Append(cos_theta, sin_theta, rho_px);
  entry.borders = 0;
  entry.seed_id = seed_id;
  return size;
}

OalEntry& OrderedAccumulatorList::Append(double cos_theta, double sin_theta, double rho_px) {
  KeepUpperHalf(&cos_theta, &sin_theta, &rho_px);
  // Built in place: a local entry copied in was written field by field and read back in
  // wider moves, which stalled on store forwarding.
  entries_.emplace_back();
  OalEntry& entry = entries_.back();
  entry.cos_theta = cos_theta;
  entry.sin_theta = sin_theta;
  entry.rho_px = rho_px;
  Mirror(entries_.size() - 1);
  return entry;
}

void OrderedAccumulatorList::SortAndCull() {
  // The order is found on small keys, by a stable insertion sort: after a border the list
  // is nearly in order (the paper's argument for reordering every border), so few keys move:
  // those of the entries voted for, and of the new ones at the end, which rise past the
  // stale hypotheses. A key moves past lower scores only, so of equal scores the older entry
  // stays first. Then only the entries from the first moved place on are rewritten.
  const std::size_t size = entries_.size();
  order_.resize(size);  // within the reserved capacity
  for (std::size_t i = 0; i < size; ++i) {
    order_[i].double_score = entries_[i].DoubleScore();
    order_[i].index = static_cast<int>(i);
  }
  std::size_t first_moved = size;
  for (std::size_t i = 1; i < size; ++i) {
    const SortKey key = order_[i];
    if (key.double_score <= order_[i - 1].double_score) continue;  // in place: the common case
    std::size_t hole = i;
    do {
      order_[hole] = order_[hole - 1];
      --hole;
    } while (hole > 0 && key.double_score > order_[hole - 1].double_score);
    order_[hole] = key;
    first_moved = std::min(first_moved, hole);
  }
  // Step 5: cull from the bottom while the list is longer than max_lines.
  std::size_t keep = size;
  while (static_cast<int>(keep) > max_lines_ && order_[keep - 1].double_score < 0) --keep;
  if (first_moved < keep) {
    moved_.clear();
    for (std::size_t k = first_moved; k < keep; ++k) {
      moved_.push_back(entries_[static_cast<std::size_t>(order_[k].index)]);
    }
    std::copy(moved_.begin(), moved_.end(),
              entries_.begin() + static_cast<std::ptrdiff_t>(first_moved));
    for (std::size_t k = first_moved; k < keep; ++k) Mirror(k);
  }
  entries_.resize(keep);  // only shrinks: no allocation
}

}  // namespace oal
