#include "scene/lived_in.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "base/check.h"
#include "base/random.h"
#include "detector/line.h"  // kPi

namespace oal {
namespace {

// Streams of a frame's draws: each condition has its own, so that turning one on or off
// leaves the others' draws as they were.
enum Stream : std::uint64_t {
  kOccluderStream = 1,
  kGlareStream,
  kExposureStream,
  kMotionBlurStream,
  kJpegStream,
};

// Uniform draws in [0, 1) of one stream of one frame (std::mt19937_64 is specified exactly,
// unlike the standard distributions, so the scenes are the same on every platform).
class Draws {
 public:
  Draws(std::uint64_t seed, int frame, Stream stream)
      : gen_(SplitMix64(SplitMix64(seed ^ 0x6c6976656420696eull) +
                        static_cast<std::uint64_t>(frame) * 131u + stream)) {}
  double operator()() { return static_cast<double>(gen_() >> 11) * 0x1.0p-53; }
  double In(const DrawRange& range) { return range.lo + (range.hi - range.lo) * (*this)(); }

 private:
  std::mt19937_64 gen_;
};

struct Vec {
  double x = 0.0, y = 0.0;
};
Vec operator+(Vec a, Vec b) {
  return {a.x + b.x, a.y + b.y};
}
Vec operator*(double k, Vec a) {
  return {k * a.x, k * a.y};
}
Vec Direction(double angle) {
  return {std::cos(angle), std::sin(angle)};
}

void AddCapsule(PlaneOccluder* o, Vec a, Vec b, double radius) {
  o->capsules.push_back({a.x, a.y, b.x, b.y, radius});
}

// A hand whose palm lies within 5 cm of the board, fingers pointing inwards, the forearm
// reaching out away from the board's centre; left or right, a little larger or smaller.
void MakeHand(const LineTarget& target, const std::function<double()>& u, PlaneOccluder* o) {
  const double hw = 0.5 * target.board_width_m + 0.05, hh = 0.5 * target.board_height_m + 0.05;
  const Vec palm{hw * (2.0 * u() - 1.0), hh * (2.0 * u() - 1.0)};
  const double outward = std::atan2(palm.y, palm.x) + (u() - 0.5) * kPi / 2.0;
  const double scale = 0.9 + 0.25 * u();
  const Vec forward = Direction(outward + kPi);  // towards the fingertips
  const double side = u() < 0.5 ? 1.0 : -1.0;    // which side the thumb is on
  const Vec across = side * Vec{-forward.y, forward.x};
  o->ellipses.push_back({palm.x, palm.y, 0.05 * scale, 0.043 * scale, outward});
  const double offsets[4] = {-0.027, -0.009, 0.009, 0.027};
  const double lengths[4] = {0.062, 0.075, 0.08, 0.072};
  for (int f = 0; f < 4; ++f) {
    const double spread = (f - 1.5) * 0.08 + (u() - 0.5) * 0.15;
    const Vec direction = Direction(outward + kPi + side * spread);
    const Vec base = palm + (0.035 * scale) * forward + (offsets[f] * scale) * across;
    const double length = lengths[f] * scale * (0.6 + 0.4 * u());  // curled a little, or not
    AddCapsule(o, base, base + length * direction, 0.0085 * scale);
  }
  const Vec thumb_base = palm + (0.035 * scale) * across + (-0.01 * scale) * forward;
  const Vec thumb = Direction(outward + kPi + side * (0.9 + 0.4 * u()));
  AddCapsule(o, thumb_base, thumb_base + (0.055 * scale) * thumb, 0.0105 * scale);
  const Vec wrist = palm + (-0.045 * scale) * forward;
  const Vec elbow = palm + (-0.40 * scale) * forward;
  AddCapsule(o, wrist, palm + (-0.12 * scale) * forward, 0.028 * scale);
  AddCapsule(o, palm + (-0.12 * scale) * forward, elbow, 0.04 * scale);
}

// A pen anywhere on the board, at any angle.
void MakePen(const LineTarget& target, const std::function<double()>& u, PlaneOccluder* o) {
  const Vec centre{0.5 * target.board_width_m * (2.0 * u() - 1.0),
                   0.5 * target.board_height_m * (2.0 * u() - 1.0)};
  const Vec direction = Direction(kPi * u());
  const double half = 0.5 * (0.12 + 0.05 * u());
  AddCapsule(o, centre + (-half) * direction, centre + half * direction, 0.004 + 0.003 * u());
}

// A cable winding across the board: from a point beyond it, towards a point on it, turning a
// little at each of its segments.
void MakeCable(const LineTarget& target, const std::function<double()>& u, PlaneOccluder* o) {
  const double diagonal = std::hypot(target.board_width_m, target.board_height_m);
  const Vec aim{0.25 * target.board_width_m * (2.0 * u() - 1.0),
                0.25 * target.board_height_m * (2.0 * u() - 1.0)};
  const double from_angle = 2.0 * kPi * u();
  Vec point = aim + (0.75 * diagonal) * Direction(from_angle);
  double heading = from_angle + kPi;
  constexpr int kSegments = 16;
  const double segment = 1.5 * diagonal / kSegments, radius = 0.002 + 0.002 * u();
  double turn = 0.0;
  for (int i = 0; i < kSegments; ++i) {
    turn = 0.7 * turn + (u() - 0.5) * 0.16;
    heading += turn;
    const Vec next = point + segment * Direction(heading);
    AddCapsule(o, point, next, radius);
    point = next;
  }
}

// A tool held over or lying on the board: a bar (a ruler, a screwdriver) or a block (a phone,
// a multimeter) with rounded ends.
void MakeTool(const LineTarget& target, const std::function<double()>& u, PlaneOccluder* o) {
  const Vec centre{0.5 * target.board_width_m * (2.0 * u() - 1.0),
                   0.5 * target.board_height_m * (2.0 * u() - 1.0)};
  const Vec direction = Direction(kPi * u());
  const bool bar = u() < 0.5;
  const double half = bar ? 0.5 * (0.12 + 0.12 * u()) : 0.5 * (0.05 + 0.04 * u());
  const double radius = bar ? 0.008 + 0.01 * u() : 0.03 + 0.015 * u();
  AddCapsule(o, centre + (-half) * direction, centre + half * direction, radius);
}

void CheckRange(const DrawRange& range, double lo, double hi, const std::string& field) {
  RequireOption(range.lo >= lo && range.lo <= range.hi && range.hi <= hi,
                "LivedInOptions::" + field,
                "[" + std::to_string(range.lo) + ", " + std::to_string(range.hi) + "]",
                std::to_string(lo) + " <= lo <= hi <= " + std::to_string(hi));
}

void CheckFraction(double fraction, const std::string& field) {
  RequireOption(fraction >= 0.0 && fraction <= 1.0, "LivedInOptions::" + field, fraction,
                "0 <= " + field + " <= 1");
}

}  // namespace

std::string ToString(OccluderKind kind) {
  switch (kind) {
    case OccluderKind::kHand:
      return "hand";
    case OccluderKind::kPen:
      return "pen";
    case OccluderKind::kCable:
      return "cable";
    case OccluderKind::kTool:
      return "tool";
  }
  return "unknown";
}

OccluderKind OccluderKindFromString(const std::string& text) {
  for (const OccluderKind kind :
       {OccluderKind::kHand, OccluderKind::kPen, OccluderKind::kCable, OccluderKind::kTool}) {
    if (text == ToString(kind)) return kind;
  }
  throw std::invalid_argument("occluder kind '" + text + "' is not one of: hand, pen, cable, tool");
}

bool LivedInOptions::Any() const {
  return occluders.fraction > 0.0 || glare.fraction > 0.0 || exposure.fraction > 0.0 ||
         motion_blur.fraction > 0.0 || jpeg.fraction > 0.0;
}

void LivedInOptions::Check() const {
  CheckFraction(occluders.fraction, "occluders.fraction");
  RequireOption(!occluders.kinds.empty(), "LivedInOptions::occluders.kinds", "empty",
                "at least one kind");
  CheckRange(occluders.grey, 0.0, 255.0, "occluders.grey");
  RequireOption(occluders.texture_grey >= 0.0 && occluders.texture_grey <= 100.0,
                "LivedInOptions::occluders.texture_grey", occluders.texture_grey,
                "0 <= texture_grey <= 100");
  RequireOption(occluders.shadow_darkness >= 0.0 && occluders.shadow_darkness <= 0.95,
                "LivedInOptions::occluders.shadow_darkness", occluders.shadow_darkness,
                "0 <= shadow_darkness <= 0.95");
  CheckFraction(glare.fraction, "glare.fraction");
  CheckRange(glare.sigma_m, 1e-6, 1.0, "glare.sigma_m");
  CheckRange(glare.peak_grey, 0.0, 2000.0, "glare.peak_grey");
  CheckFraction(exposure.fraction, "exposure.fraction");
  RequireOption(
      exposure.gain.lo >= 0.05 && exposure.gain.lo <= 1.0 && exposure.gain.hi >= 1.0 &&
          exposure.gain.hi <= 4.0,
      "LivedInOptions::exposure.gain",
      "[" + std::to_string(exposure.gain.lo) + ", " + std::to_string(exposure.gain.hi) + "]",
      "0.05 <= lo <= 1 <= hi <= 4");
  CheckFraction(motion_blur.fraction, "motion_blur.fraction");
  CheckRange(motion_blur.length_px, 0.0, 200.0, "motion_blur.length_px");
  CheckFraction(jpeg.fraction, "jpeg.fraction");
  CheckRange(jpeg.quality, 1.0, 100.0, "jpeg.quality");
}

PlaneOccluder MakeOccluder(OccluderKind kind, const LineTarget& target, int grey,
                           double texture_grey, double shadow_darkness,
                           const std::function<double()>& uniform) {
  PlaneOccluder o;
  o.label = ToString(kind);
  o.grey = grey;
  o.texture_grey = texture_grey;
  o.texture_seed = static_cast<std::uint64_t>(uniform() * 0x1.0p53);
  switch (kind) {
    case OccluderKind::kHand:
      MakeHand(target, uniform, &o);
      break;
    case OccluderKind::kPen:
      MakePen(target, uniform, &o);
      break;
    case OccluderKind::kCable:
      MakeCable(target, uniform, &o);
      break;
    case OccluderKind::kTool:
      MakeTool(target, uniform, &o);
      break;
  }
  // Held above the sheet, a hand or a tool casts a soft shadow beside itself.
  if (kind == OccluderKind::kHand || kind == OccluderKind::kTool) {
    o.shadow_darkness = shadow_darkness;
    o.shadow_offset_m = 0.01 + 0.03 * uniform();
    o.shadow_angle_rad = 2.0 * kPi * uniform();
    o.shadow_softness_m = 0.01 + 0.02 * uniform();
  }
  return o;
}

void DrawLivedIn(const LivedInOptions& options, const LineTarget& target, std::uint64_t seed,
                 int frame, FrameEffects* effects) {
  const double hw = 0.5 * target.board_width_m, hh = 0.5 * target.board_height_m;
  if (Draws draw(seed, frame, kOccluderStream); draw() < options.occluders.fraction) {
    const std::size_t pick = std::min(
        options.occluders.kinds.size() - 1,
        static_cast<std::size_t>(draw() * static_cast<double>(options.occluders.kinds.size())));
    const int grey = static_cast<int>(std::lround(draw.In(options.occluders.grey)));
    effects->plane_occluders.push_back(
        MakeOccluder(options.occluders.kinds[pick], target, grey, options.occluders.texture_grey,
                     options.occluders.shadow_darkness, [&draw] { return draw(); }));
  }
  if (Draws draw(seed, frame, kGlareStream); draw() < options.glare.fraction) {
    Glare glare;
    glare.x_m = hw * (2.0 * draw() - 1.0);
    glare.y_m = hh * (2.0 * draw() - 1.0);
    glare.sigma_m = draw.In(options.glare.sigma_m);
    glare.peak_grey = draw.In(options.glare.peak_grey);
    effects->glares.push_back(glare);
  }
  if (Draws draw(seed, frame, kExposureStream); draw() < options.exposure.fraction) {
    const DrawRange& gain = options.exposure.gain;
    const DrawRange dim{gain.lo, 0.5 * (1.0 + gain.lo)}, bright{0.5 * (1.0 + gain.hi), gain.hi};
    effects->gain *= draw() < 0.5 ? draw.In(dim) : draw.In(bright);
  }
  if (Draws draw(seed, frame, kMotionBlurStream); draw() < options.motion_blur.fraction) {
    effects->motion_blur_px = draw.In(options.motion_blur.length_px);
    effects->motion_blur_angle_rad = kPi * draw();
  }
  if (Draws draw(seed, frame, kJpegStream); draw() < options.jpeg.fraction) {
    effects->jpeg_quality = static_cast<int>(std::lround(draw.In(options.jpeg.quality)));
  }
}

}  // namespace oal
