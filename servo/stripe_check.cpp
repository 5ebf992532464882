#include "servo/stripe_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "base/check.h"
#include "base/statistics.h"
#include "detector/lens.h"

namespace oal {
namespace {

// The profile reaches this far beyond each edge: a stripe's width, at least kMinBesideM.
constexpr double kMinBesideM = 0.003;
// Samples this close to a crossing stripe (beyond its half width plus its beside reach) are
// left out: the profile would run into the other stripe.
constexpr double kCrossingMarginM = 0.003;
// A profile has at most this many points, about one a pixel.
constexpr int kMaxProfile = 96;
constexpr int kMinProfile = 12;
// Grey levels at and above which a pixel is saturated (a glare).
constexpr int kSaturated = 250;
// A sheet whose paper is this close to saturation is over-exposed: a saturated profile there
// is no glare.
constexpr int kGlareMargin = 20;
// A line agreeing in fewer samples than this has not been seen.
constexpr int kMinAgreeing = 3;
// A run of contradicting samples at the rim of something covering a stripe is excused up to
// this long, or a third of the stripe's samples.
constexpr std::size_t kExcusedRun = 2;

// Whether the pixel nearest to the image point p is inside the image, a pixel's margin kept.
bool InImage(const GrayImageView& image, const Point2d& p) {
  const double u = p.u + 0.5, v = p.v + 0.5;
  return u >= 1.0 && v >= 1.0 && u < image.width - 1.0 && v < image.height - 1.0;
}

// The part of stripe k's span whose centre line is in view, to kCoarseSteps of the span (the
// whole span when both ends and the middle are; empty when no step is): a board's stripe seen
// from near shows a tenth of its length, where evenly spread samples would miss.
Interval StripeInView(const GrayImageView& image, const TargetLayout& layout,
                      const PlaneProjector& projector, int k) {
  constexpr int kCoarseSteps = 64;
  const Interval span = layout.stripes[static_cast<std::size_t>(k)].along;
  const auto seen = [&](double along) {
    Point2d pixel;
    return projector.Project(layout.OnStripe(k, along, 0.0), &pixel) && InImage(image, pixel);
  };
  if (seen(span.lo) && seen(span.hi) && seen(0.5 * (span.lo + span.hi))) return span;
  const double step = (span.hi - span.lo) / kCoarseSteps;
  int first = -1, last = -1;
  for (int i = 0; i <= kCoarseSteps; ++i) {
    if (!seen(span.lo + i * step)) continue;
    if (first < 0) first = i;
    last = i;
  }
  if (first < 0) return Interval{0.0, -1.0};
  return Interval{span.lo + first * step, span.lo + last * step};
}

enum class Verdict { kAgrees, kContradicts, kUnknown, kFlatLight };

// One profile across a stripe, where the pose puts the stripe's edges and middle on it
// (indices, fractional), and its darkest and lightest points (read with it: each profile is
// judged on them, and they cost nothing more there).
struct Profile {
  std::array<std::uint8_t, kMaxProfile> grey{};
  int n = 0;
  double spacing_px = 1.0;
  double low_edge = 0.0, centre = 0.0, high_edge = 0.0;
  int darkest = 255, darkest_at = 0, lightest = 0;
};

// Reads the profile from `from` to `to` (pixels) whose plane ends lie at depths z_from, z_to;
// the plane offsets -half, 0, +half of a profile over [-reach, reach] are placed through the
// segment's perspective (the image of the plane segment's point at s is at t = s z_to / ((1 -
// s) z_from + s z_to) of the image segment). False when part of it is out of the image.
bool ReadProfile(const GrayImageView& image, const Point2d& from, const Point2d& to, double z_from,
                 double z_to, double half, double reach, double step_px, Profile* profile) {
  // The segment lies inside the image when both its ends do.
  if (!InImage(image, from) || !InImage(image, to)) return false;
  const double du = to.u - from.u, dv = to.v - from.v;
  const double length = std::sqrt(du * du + dv * dv);  // a few pixels: hypot's care not needed
  const int n =
      std::clamp(static_cast<int>(std::ceil(length / step_px)) + 1, kMinProfile, kMaxProfile);
  profile->n = n;
  profile->spacing_px = length / (n - 1);
  // Nearest pixels along the segment, its coordinates in 16.16 fixed point.
  constexpr double kOne = 65536.0;
  const auto fixed = [](double x) {  // rounded half away from zero, as llround, inline
    const double scaled = x * kOne;
    return static_cast<std::int64_t>(scaled + (scaled >= 0.0 ? 0.5 : -0.5));
  };
  const std::int64_t step_u = fixed(du / (n - 1)), step_v = fixed(dv / (n - 1));
  std::int64_t u = fixed(from.u + 0.5), v = fixed(from.v + 0.5);
  // The image's view in locals: the profile's bytes could alias it.
  const std::uint8_t* const data = image.data;
  const std::ptrdiff_t stride = image.stride;
  std::uint8_t* const grey = profile->grey.data();
  int darkest = 256, darkest_at = 0, lightest = -1;
  for (int i = 0; i < n; ++i, u += step_u, v += step_v) {
    const int value = data[(v >> 16) * stride + (u >> 16)];
    grey[i] = static_cast<std::uint8_t>(value);
    if (value < darkest) darkest = value, darkest_at = i;
    lightest = std::max(lightest, value);
  }
  profile->darkest = darkest;
  profile->darkest_at = darkest_at;
  profile->lightest = lightest;
  const auto index = [&](double offset) {
    const double s = (offset + reach) / (2.0 * reach);
    const double t = s * z_to / ((1.0 - s) * z_from + s * z_to);
    return t * (profile->n - 1);
  };
  profile->low_edge = index(-half);
  profile->centre = index(0.0);
  profile->high_edge = index(half);
  return true;
}

// Where the profile crosses `threshold` between indices i and i + 1 (they lie on either side).
double Crossing(const Profile& p, int i, double threshold) {
  const double a = p.grey[static_cast<std::size_t>(i)], b = p.grey[static_cast<std::size_t>(i + 1)];
  return i + (a - threshold) / (a - b);
}

// A profile's light ends over its darkest point, grey levels.
int Contrast(const Profile& p) {
  const auto at = [&p](int i) { return p.grey[static_cast<std::size_t>(i)]; };
  const int n = p.n;
  const int light =
      std::min(std::max({at(0), at(1), at(2)}), std::max({at(n - 1), at(n - 2), at(n - 3)}));
  return light - p.darkest;
}

// How far both edges of a dark run lie off the stripe's the same way: the smaller offset when
// they agree in sign, else 0 (a run narrowed or widened on one side moves one edge only).
double SharedShift(double low_offset, double high_offset) {
  if (!(low_offset * high_offset > 0.0)) return 0.0;
  return low_offset > 0.0 ? std::min(low_offset, high_offset) : std::max(low_offset, high_offset);
}

// What one profile says of the pose (see the header). kFlatLight: light and flat, to be judged
// against the paper of the agreeing samples.
Verdict Judge(const Profile& p, const StripeCheckOptions& options, int min_contrast,
              int* light_level, double* shared_shift_px) {
  const auto at = [&p](int i) { return p.grey[static_cast<std::size_t>(i)]; };
  const int n = p.n;
  const int light_a = std::max({at(0), at(1), at(2)});
  const int light_b = std::max({at(n - 1), at(n - 2), at(n - 3)});
  const int light = std::min(light_a, light_b);
  const int darkest = p.darkest, darkest_at = p.darkest_at;
  *light_level = light;
  if (darkest >= kSaturated) return Verdict::kUnknown;  // a glare over it all
  if (light - darkest < min_contrast) return Verdict::kFlatLight;
  const double threshold = 0.5 * (light + darkest);
  // The dark run nearest to the stripe's middle (the one holding it, if any).
  int seed = static_cast<int>(std::lround(std::clamp(p.centre, 0.0, n - 1.0)));
  if (!(at(seed) < threshold)) {
    int best = -1;
    for (int i = 0; i < n; ++i) {
      if (at(i) < threshold && (best < 0 || std::abs(i - seed) < std::abs(best - seed))) best = i;
    }
    seed = best < 0 ? darkest_at : best;
  }
  // Each edge halfway between the darkest point and the paper on its own side: under a glare's
  // slope or a shadow's the paper is lighter on one side, and so is the ink next to it.
  const double threshold_lo = 0.5 * (light_a + darkest), threshold_hi = 0.5 * (light_b + darkest);
  int lo = seed, hi = seed;
  while (lo > 0 && at(lo - 1) < threshold_lo) --lo;
  while (hi < n - 1 && at(hi + 1) < threshold_hi) ++hi;
  if (lo == 0 || hi == n - 1) return Verdict::kUnknown;  // dark beyond the profile: covered
  const double low = Crossing(p, lo - 1, threshold_lo), high = Crossing(p, hi, threshold_hi);
  const double predicted = p.high_edge - p.low_edge;
  const double tolerance = std::max(options.centre_tolerance_px / p.spacing_px,
                                    options.centre_tolerance_fraction * predicted);
  const double ratio = (high - low) / predicted;
  if (std::fabs(0.5 * (low + high) - p.centre) <= tolerance &&
      std::fabs(ratio - 1.0) <= options.width_tolerance) {
    *shared_shift_px = SharedShift(low - p.low_edge, high - p.high_edge) * p.spacing_px;
    return Verdict::kAgrees;
  }
  // Wider: the stripe and something dark against it, one edge still the stripe's.
  if (ratio > 1.0 + options.width_tolerance &&
      (std::fabs(low - p.low_edge) <= tolerance || std::fabs(high - p.high_edge) <= tolerance)) {
    return Verdict::kAgrees;
  }
  // Narrower, inside the stripe, one edge the stripe's: something lighter than ink over the
  // rest of it (a pen or a cable across it, a tool's rim); it hides that part and tells
  // nothing.
  if ((std::fabs(low - p.low_edge) <= tolerance && high < p.high_edge - tolerance) ||
      (std::fabs(high - p.high_edge) <= tolerance && low > p.low_edge + tolerance)) {
    return Verdict::kUnknown;
  }
  return Verdict::kContradicts;
}

// Paper where the ink should be, next to a sample that agrees (through samples that tell
// nothing): something as light as the paper lying over the stripe (a pale hand, a sheet, a
// glove), not a wrong pose. A pose whose stripe agrees to a pixel at one sample is off by at
// most a few pixels at the next, its ink still inside the profile (a displaced dark run, which
// contradicts); the ink wholly out of the profile there would take a turn of the stripe by tens
// of degrees between two samples. Other flat light samples (between contradicting ones, or a
// whole stripe of them) contradict.
void ExcuseLightCover(const std::vector<std::pair<int, Profile>>& profiles,
                      std::vector<Verdict>* verdicts) {
  std::vector<Verdict>& v = *verdicts;
  const auto same_line = [&](std::size_t a, std::size_t b) {
    return profiles[a].first == profiles[b].first;
  };
  for (std::size_t first = 0; first < v.size();) {
    if (v[first] != Verdict::kFlatLight && v[first] != Verdict::kUnknown) {
      ++first;
      continue;
    }
    std::size_t end = first;
    while (end < v.size() && same_line(first, end) &&
           (v[end] == Verdict::kFlatLight || v[end] == Verdict::kUnknown)) {
      ++end;
    }
    const bool agrees_before =
        first > 0 && same_line(first - 1, first) && v[first - 1] == Verdict::kAgrees;
    const bool agrees_after = end < v.size() && same_line(end, first) && v[end] == Verdict::kAgrees;
    for (std::size_t i = first; i < end; ++i) {
      if (v[i] == Verdict::kFlatLight) {
        v[i] = agrees_before || agrees_after ? Verdict::kUnknown : Verdict::kContradicts;
      }
    }
    first = end;
  }
}

}  // namespace

void StripeCheckOptions::Check() const {
  RequireOption(samples >= 4 && samples <= 256, "StripeCheckOptions::samples", samples,
                "4 <= samples <= 256");
  RequireOption(min_contrast >= 1 && min_contrast <= 255, "StripeCheckOptions::min_contrast",
                min_contrast, "1 <= min_contrast <= 255");
  RequireOption(centre_tolerance_px > 0.0 && centre_tolerance_px <= 100.0,
                "StripeCheckOptions::centre_tolerance_px", centre_tolerance_px,
                "0 < centre_tolerance_px <= 100");
  RequireOption(centre_tolerance_fraction >= 0.0 && centre_tolerance_fraction <= 1.0,
                "StripeCheckOptions::centre_tolerance_fraction", centre_tolerance_fraction,
                "0 <= centre_tolerance_fraction <= 1");
  RequireOption(width_tolerance > 0.0 && width_tolerance <= 10.0,
                "StripeCheckOptions::width_tolerance", width_tolerance,
                "0 < width_tolerance <= 10");
  RequireOption(profile_step_px >= 0.25 && profile_step_px <= 16.0,
                "StripeCheckOptions::profile_step_px", profile_step_px,
                "0.25 <= profile_step_px <= 16");
}

double StripeAgreement::Worst() const {
  double worst = 1.0;
  for (int k = 0; k < 4; ++k) {
    const std::size_t i = static_cast<std::size_t>(k);
    if (dark[i] < kMinAgreeing) return 0.0;
    worst = std::min(worst, static_cast<double>(dark[i]) / (dark[i] + contradict[i]));
  }
  return worst;
}

int StripeAgreement::Unseen(double min_agreement) const {
  int unseen = -1;
  for (int k = 0; k < 4; ++k) {
    const std::size_t i = static_cast<std::size_t>(k);
    if (dark[i] >= kMinAgreeing) {
      if (static_cast<double>(dark[i]) / (dark[i] + contradict[i]) < min_agreement) return -1;
      continue;
    }
    if (unseen >= 0 || contradict[i] > 0) return -1;
    unseen = k;
  }
  return unseen;
}

double StripeAgreement::ShiftRms() const {
  double sum2 = 0.0;
  int agreeing = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    sum2 += dark[k] * shift_rms_px[k] * shift_rms_px[k];
    agreeing += dark[k];
  }
  return agreeing > 0 ? std::sqrt(sum2 / agreeing) : 0.0;
}

double StripeAgreement::Seen() const {
  int in_view = 0, agreeing = 0;
  for (int k = 0; k < 4; ++k) {
    in_view += samples[static_cast<std::size_t>(k)];
    agreeing += dark[static_cast<std::size_t>(k)];
  }
  return in_view > 0 ? static_cast<double>(agreeing) / in_view : 0.0;
}

StripeAgreement CheckStripes(const GrayImageView& image, const TargetLayout& layout,
                             const vpHomogeneousMatrix& cMo, const Lens& camera,
                             const StripeCheckOptions& options) {
  StripeAgreement agreement;
  const PlaneProjector projector(PlaneToImage(cMo), camera);
  const auto depth = [&cMo](const Point2d& plane) {
    return cMo[2][0] * plane.u + cMo[2][1] * plane.v + cMo[2][3];
  };
  // Every profile first: how dark the stripes are in this frame (the light, the exposure, the
  // blur) says how dark a run must be to be one, and how light the paper is.
  std::vector<std::pair<int, Profile>> profiles;  // (line, profile), in order along each line
  profiles.reserve(4 * static_cast<std::size_t>(options.samples));
  Profile profile;
  for (int k = 0; k < 4; ++k) {
    const StripeSpan& stripe = layout.stripes[static_cast<std::size_t>(k)];
    const double reach = stripe.half + std::max(2.0 * stripe.half, kMinBesideM);
    const auto near_crossing = [&](double along) {
      for (const StripeSpan& other : layout.stripes) {
        if (other.along_b != stripe.along_b &&
            std::fabs(along - other.at) <
                other.half + std::max(2.0 * other.half, kMinBesideM) + kCrossingMarginM) {
          return true;
        }
      }
      return false;
    };
    const Interval in_view = StripeInView(image, layout, projector, k);
    if (!(in_view.hi > in_view.lo)) continue;
    for (int i = 0; i < options.samples; ++i) {
      const double along = in_view.lo + (in_view.hi - in_view.lo) * (i + 0.5) / options.samples;
      if (near_crossing(along)) continue;
      // Beside a stripe running along the image's edge, a shorter profile: half a stripe's
      // width of paper either side still tells the stripe from what is not.
      const auto read = [&](double across) {
        const Point2d from_plane = layout.OnStripe(k, along, -across);
        const Point2d to_plane = layout.OnStripe(k, along, across);
        Point2d from, to;
        return projector.Project(from_plane, &from) && projector.Project(to_plane, &to) &&
               ReadProfile(image, from, to, depth(from_plane), depth(to_plane), stripe.half, across,
                           options.profile_step_px, &profile);
      };
      if (!read(reach) && !(options.short_profiles_at_edge &&
                            read(stripe.half + std::max(0.5 * stripe.half, kMinBesideM / 2.0)))) {
        continue;
      }
      ++agreement.samples[static_cast<std::size_t>(k)];
      profiles.emplace_back(k, profile);
    }
  }
  std::vector<int> contrasts;
  for (const auto& [k, p] : profiles) {
    const int contrast = Contrast(p);
    if (contrast >= options.min_contrast) contrasts.push_back(contrast);
  }
  const int min_contrast = std::max(options.min_contrast, MedianInPlace(&contrasts) / 2);
  std::vector<Verdict> verdicts;
  std::vector<int> lights, paper;
  verdicts.reserve(profiles.size());
  lights.reserve(profiles.size());
  std::array<double, 4> shift_sum2{};
  for (const auto& [k, p] : profiles) {
    int light = 0;
    double shift = 0.0;
    verdicts.push_back(Judge(p, options, min_contrast, &light, &shift));
    lights.push_back(light);
    if (verdicts.back() == Verdict::kAgrees) {
      paper.push_back(light);
      shift_sum2[static_cast<std::size_t>(k)] += shift * shift;
    }
  }
  // A light, flat profile as light as the paper beside the agreeing samples: paper where the
  // ink should be; darker, a light object over the stripe; lighter, a glare washing the stripe
  // out (paper lit more than the rest of the sheet is).
  // A profile reaching saturation where the sheet's paper does not (or lit well above that
  // paper) lies under a glare, which washes the ink out and bends its edges: it tells nothing
  // either way. (Where the whole sheet saturates, an over-exposed frame, saturation is no sign.)
  const int paper_level = MedianInPlace(&paper);
  const auto under_glare = [&](std::size_t i) {
    const Profile& p = profiles[i].second;
    return !paper.empty() &&
           (lights[i] > paper_level + min_contrast ||
            (paper_level < kSaturated - kGlareMargin && p.lightest >= kSaturated));
  };
  for (std::size_t i = 0; i < verdicts.size(); ++i) {
    if (verdicts[i] == Verdict::kContradicts && under_glare(i)) verdicts[i] = Verdict::kUnknown;
    if (verdicts[i] != Verdict::kFlatLight) continue;
    const bool as_paper =
        !paper.empty() && !under_glare(i) && lights[i] >= paper_level - min_contrast / 2;
    if (!as_paper) verdicts[i] = Verdict::kUnknown;
  }
  ExcuseLightCover(profiles, &verdicts);
  // A short run of contradicting samples that ends at a covered one, or at an end of the
  // stripe's samples, lies at the rim of something covering the stripe (a finger's edge across
  // the profile leaves a partial dark run; a pale hand over the stripe's end passes for paper):
  // excused. Two samples, or a third of the stripe's, on a line in all; a run between agreeing
  // samples is not.
  // The samples of a line follow each other along it.
  for (std::size_t first = 0; first < verdicts.size();) {
    const int k = profiles[first].first;
    const std::size_t s = static_cast<std::size_t>(k);
    std::size_t end = first;
    while (end < verdicts.size() && profiles[end].first == k) ++end;
    const std::size_t short_run = std::max<std::size_t>(kExcusedRun, (end - first) / 3);
    std::size_t excused_here = 0;  // at most one short run's worth on a line
    for (std::size_t i = first; i < end;) {
      if (verdicts[i] == Verdict::kAgrees) ++agreement.dark[s];
      if (verdicts[i] != Verdict::kContradicts) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < end && verdicts[j] == Verdict::kContradicts) ++j;
      const bool open_before = i == first || verdicts[i - 1] == Verdict::kUnknown;
      const bool open_after = j == end || verdicts[j] == Verdict::kUnknown;
      const bool whole = i == first && j == end;
      const bool excused =
          (open_before || open_after) && !whole && excused_here + (j - i) <= short_run;
      if (excused) excused_here += j - i;
      (excused ? agreement.excused[s] : agreement.contradict[s]) += static_cast<int>(j - i);
      i = j;
    }
    first = end;
  }
  // (Agreeing samples stay so through the excuses above.)
  for (std::size_t k = 0; k < 4; ++k) {
    agreement.shift_rms_px[k] =
        agreement.dark[k] > 0 ? std::sqrt(shift_sum2[k] / agreement.dark[k]) : 0.0;
  }
  return agreement;
}

}  // namespace oal
