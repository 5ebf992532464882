#include "scene/sequence.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/angles.h"
#include "base/random.h"
#include "detector/lens.h"
#include "scene/geometry.h"

namespace oal {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kFocalPx = 600.0;
constexpr double kNoiseSigma = 5.0;
constexpr double kBlurSigmaPx = 1.0;
constexpr double kDistortionKdu = 0.47;
constexpr int kMaxFrames = 100000;

constexpr std::array<std::pair<SequenceKind, const char*>, 6> kNames{{
    {SequenceKind::kSlow, "slow"},
    {SequenceKind::kFast, "fast"},
    {SequenceKind::kOcclusion, "occlusion"},
    {SequenceKind::kIllumination, "illumination"},
    {SequenceKind::kLeaveReenter, "leave-reenter"},
    {SequenceKind::kDistortion, "distortion"},
}};

// Uniform in [0, 1) from 53 random bits (std::mt19937_64 is specified exactly by the
// standard, unlike the standard distributions, so sequences are the same on every platform).
double Uniform(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

// Uniform in [lo, hi).
double Uniform(std::mt19937_64& gen, double lo, double hi) {
  return lo + (hi - lo) * Uniform(gen);
}

// SplitMix64 of (seed, frame): the noise seed of one frame.
std::uint64_t FrameNoiseSeed(std::uint64_t seed, int frame) {
  return SplitMix64(seed + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(frame));
}

using scene_geometry::Cross;
using scene_geometry::Vec3;

using scene_geometry::Combine;
using scene_geometry::Unit;

// Camera with its centre at `centre` (object frame, in front of the board: z < 0) looking at
// the board point (look_x, look_y, 0), rolled by `roll_rad` about its optical axis (roll 0:
// the camera x axis is the object x axis made orthogonal to the optical axis), then panned by
// `pan_rad` about its own y axis (positive: turns right, the scene moves left in the image).
vpHomogeneousMatrix LookAt(const Vec3& centre, double look_x, double look_y, double roll_rad,
                           double pan_rad) {
  const Vec3 z0 = Unit({look_x - centre.x, look_y - centre.y, -centre.z});
  const Vec3 x0 = Unit({1.0 - z0.x * z0.x, -z0.x * z0.y, -z0.x * z0.z});
  const Vec3 y0 = Cross(z0, x0);
  const double cr = std::cos(roll_rad), sr = std::sin(roll_rad);
  const Vec3 x1 = Combine(cr, x0, sr, y0);
  const Vec3 y = Combine(-sr, x0, cr, y0);
  const double cp = std::cos(pan_rad), sp = std::sin(pan_rad);
  const Vec3 z = Combine(cp, z0, sp, x1);
  const Vec3 x = Combine(cp, x1, -sp, z0);

  return scene_geometry::PoseFromCameraAxes(x, y, z, centre);
}

// A smooth camera motion: the camera translates parallel to the board on two sinusoids
// (keeping its viewing direction), moves in and out, and rolls.
struct Motion {
  double distance_m = 0.7;            // mean distance from the board along the board normal
  double distance_amplitude_m = 0.0;  // in-and-out amplitude
  double shift_amplitude_m = 0.0;     // sideways amplitude, per axis
  double shift_rate_rad = 0.0;        // sideways angular rate, radians per frame
  double tilt_rad = 0.0;              // constant angle of the optical axis to the board normal
  double roll_amplitude_rad = 0.0;
  double roll_rate_rad = 0.0;

  // Phases and directions drawn from the seed.
  double phase_x = 0.0, phase_y = 0.0, phase_d = 0.0, phase_roll = 0.0;
  double rate_x = 1.0, rate_y = 1.0;  // factors on shift_rate_rad, so the path is a Lissajous
  double roll0_rad = 0.0, tilt_azimuth_rad = 0.0;

  void Draw(std::mt19937_64& gen, double roll0_range_rad) {
    phase_x = Uniform(gen, 0.0, 2.0 * kPi);
    phase_y = Uniform(gen, 0.0, 2.0 * kPi);
    phase_d = Uniform(gen, 0.0, 2.0 * kPi);
    phase_roll = Uniform(gen, 0.0, 2.0 * kPi);
    rate_x = Uniform(gen, 0.9, 1.1);
    rate_y = Uniform(gen, 0.7, 0.9);
    roll0_rad = Uniform(gen, -roll0_range_rad, roll0_range_rad);
    tilt_azimuth_rad = Uniform(gen, 0.0, 2.0 * kPi);
  }

  // The pose at frame t, panned by pan_rad (see LookAt).
  vpHomogeneousMatrix At(double t, double pan_rad = 0.0) const {
    const double sx = shift_amplitude_m * std::sin(rate_x * shift_rate_rad * t + phase_x);
    const double sy = shift_amplitude_m * std::sin(rate_y * shift_rate_rad * t + phase_y);
    const double d =
        distance_m + distance_amplitude_m * std::sin(0.6 * shift_rate_rad * t + phase_d);
    const double off = d * std::tan(tilt_rad);
    const Vec3 centre{sx - off * std::cos(tilt_azimuth_rad), sy - off * std::sin(tilt_azimuth_rad),
                      -d};
    const double roll = roll0_rad + roll_amplitude_rad * std::sin(roll_rate_rad * t + phase_roll);
    return LookAt(centre, sx, sy, roll, pan_rad);
  }
};

// Where the target lines 0 and 1 cross on the board (their intersection if they are not
// parallel), else the point midway between their middles; object frame, metres.
std::pair<double, double> CrossingOfFirstLines(const LineTarget& target) {
  if (target.lines.empty()) return {0.0, 0.0};
  const TargetLine& a = target.lines[0];
  const TargetLine& b = target.lines.size() > 1 ? target.lines[1] : target.lines[0];
  const double ax = a.x2_m - a.x1_m, ay = a.y2_m - a.y1_m;
  const double bx = b.x2_m - b.x1_m, by = b.y2_m - b.y1_m;
  const double det = ax * by - ay * bx;
  if (std::fabs(det) > 1e-9 * std::hypot(ax, ay) * std::hypot(bx, by)) {
    const double s = ((b.x1_m - a.x1_m) * by - (b.y1_m - a.y1_m) * bx) / det;
    return {a.x1_m + s * ax, a.y1_m + s * ay};
  }
  return {0.25 * (a.x1_m + a.x2_m + b.x1_m + b.x2_m), 0.25 * (a.y1_m + a.y2_m + b.y1_m + b.y2_m)};
}

// Distorted pixel of the board point (X, Y) seen from cMo (NaN behind the camera).
Point2d ProjectBoardPoint(const vpHomogeneousMatrix& cMo, const Lens& camera, double X, double Y) {
  const double x = cMo[0][0] * X + cMo[0][1] * Y + cMo[0][3];
  const double y = cMo[1][0] * X + cMo[1][1] * Y + cMo[1][3];
  const double z = cMo[2][0] * X + cMo[2][1] * Y + cMo[2][3];
  if (!(z > 0.0)) {
    return Point2d{std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::quiet_NaN()};
  }
  return camera.Pixel(x / z, y / z);
}

// Distance from p along `dir` to leave the image rectangle, p inside or outside it.
double DistanceToLeave(const Point2d& p, double du, double dv) {
  double t = 0.0;
  if (du > 0.0) t = std::max(t, (kWidth - 1 - p.u) / du);
  if (du < 0.0) t = std::max(t, -p.u / du);
  double tv = 0.0;
  if (dv > 0.0) tv = std::max(tv, (kHeight - 1 - p.v) / dv);
  if (dv < 0.0) tv = std::max(tv, -p.v / dv);
  // The point leaves when either coordinate does: the smaller positive exit distance.
  if (du == 0.0) return tv;
  if (dv == 0.0) return t;
  return std::min(t, tv);
}

RenderOptions BaseOptions(double kdu) {
  RenderOptions options;
  options.width = kWidth;
  options.height = kHeight;
  options.camera = Lens::WithKdu(kFocalPx, kFocalPx, 0.5 * (kWidth - 1), 0.5 * (kHeight - 1), kdu,
                                 kWidth, kHeight);
  options.noise_sigma = kNoiseSigma;
  options.blur_sigma_px = kBlurSigmaPx;
  return options;
}

// The motions of the sequences, as Motion's first fields: mean distance, in-and-out
// amplitude, sideways amplitude and rate, tilt, roll amplitude and rate.
// The slow motion is shared by slow, occlusion, illumination and leave-reenter.
Motion SlowMotion() {
  return Motion{0.7, 0.04, 0.05, 0.06, 12.0 * kRadPerDeg, 3.0 * kRadPerDeg, 0.04};
}
Motion FastMotion() {
  return Motion{0.65, 0.08, 0.13, 0.3, 12.0 * kRadPerDeg, 15.0 * kRadPerDeg, 0.35};
}
Motion DistortionMotion() {
  return Motion{0.5, 0.05, 0.08, 0.06, 10.0 * kRadPerDeg, 10.0 * kRadPerDeg, 0.05};
}

// Draws m's phases (roll0 within +-roll0_range_rad) and sets every frame's pose from it.
Motion Follow(Motion m, double roll0_range_rad, std::mt19937_64& gen, Sequence* s) {
  m.Draw(gen, roll0_range_rad);
  for (std::size_t i = 0; i < s->frames.size(); ++i) {
    s->frames[i].cMo = m.At(static_cast<double>(i));
  }
  return m;
}

std::string Common(const Sequence& s, std::size_t count) {
  std::ostringstream out;
  out << count << " frames of " << s.options.width << "x" << s.options.height
      << ", px = py = " << kFocalPx << ", target '" << s.target.name << "', noise sigma "
      << kNoiseSigma << " grey levels, blur sigma " << kBlurSigmaPx << " px";
  return out.str();
}

std::string MotionText(const Motion& m) {
  std::ostringstream out;
  out << "camera " << m.distance_m << " m +- " << m.distance_amplitude_m
      << " m from the board, optical axis tilted " << m.tilt_rad / kRadPerDeg
      << " deg, sliding parallel to the board by +- " << m.shift_amplitude_m << " m at about "
      << m.shift_rate_rad << " rad per frame, roll " << m.roll0_rad / kRadPerDeg << " +- "
      << m.roll_amplitude_rad / kRadPerDeg << " deg at " << m.roll_rate_rad << " rad per frame";
  return out.str();
}

}  // namespace

const char* ToString(SequenceKind kind) {
  for (const auto& [k, name] : kNames) {
    if (k == kind) return name;
  }
  throw std::invalid_argument("ToString: unknown SequenceKind " +
                              std::to_string(static_cast<int>(kind)));
}

SequenceKind SequenceKindFromString(const std::string& name) {
  for (const auto& [kind, text] : kNames) {
    if (name == text) return kind;
  }
  throw std::invalid_argument("sequence '" + name + "' is not one of: " + SequenceKindNames());
}

std::vector<SequenceKind> AllSequenceKinds() {
  std::vector<SequenceKind> kinds;
  for (const auto& entry : kNames) kinds.push_back(entry.first);
  return kinds;
}

std::string SequenceKindNames() {
  std::string names;
  for (const auto& entry : kNames) {
    if (!names.empty()) names += ", ";
    names += entry.second;
  }
  return names;
}

Sequence MakeSequence(SequenceKind kind, int frame_count, std::uint64_t seed,
                      const LineTarget& target) {
  if (frame_count < 1 || frame_count > kMaxFrames) {
    throw std::invalid_argument(
        "MakeSequence: frame_count = " + std::to_string(frame_count) +
        ". Violated constraint: 1 <= frame_count <= " + std::to_string(kMaxFrames));
  }
  target.Check();
  Sequence s;
  s.kind = kind;
  s.seed = seed;
  s.target = target;
  s.options = BaseOptions(kind == SequenceKind::kDistortion ? kDistortionKdu : 0.0);
  s.frames.resize(static_cast<std::size_t>(frame_count));
  for (int i = 0; i < frame_count; ++i) s.frames[i].noise_seed = FrameNoiseSeed(seed, i);

  // One generator per sequence, seeded with the kind too, so the kinds differ for one seed.
  std::mt19937_64 gen(seed ^ (0xD1B54A32D192ED03ull * (static_cast<std::uint64_t>(kind) + 1)));
  std::ostringstream text;
  text << ToString(kind) << ": " << Common(s, s.frames.size()) << ". ";
  const double last = std::max(frame_count - 1, 1);

  switch (kind) {
    case SequenceKind::kSlow: {
      const Motion m = Follow(SlowMotion(), kPi, gen, &s);
      text << "Slow smooth motion (lines move about 1-2 px per frame): " << MotionText(m) << ".";
      break;
    }
    case SequenceKind::kFast: {
      const Motion m = Follow(FastMotion(), kPi, gen, &s);
      text << "Fast shaking motion with roll (lines move 20-40 px per frame): " << MotionText(m)
           << ".";
      break;
    }
    case SequenceKind::kOcclusion: {
      const Motion m = Follow(SlowMotion(), kPi, gen, &s);
      // The occluder crosses the image on a straight line through the crossing of target
      // lines 0 and 1 as seen in the middle frame, during the middle 70 % of the frames,
      // entering and leaving just outside the image.
      Occluder occluder;
      occluder.shape = Occluder::Shape::kRectangle;
      occluder.half_width_px = 70.0;
      occluder.half_height_px = 50.0;
      occluder.grey = 128;
      const double angle = Uniform(gen, 0.0, 2.0 * kPi);
      const double du = std::cos(angle), dv = std::sin(angle);
      const double mid = 0.5 * last;
      const auto [cx, cy] = CrossingOfFirstLines(target);
      Point2d through = ProjectBoardPoint(m.At(mid), s.options.camera, cx, cy);
      if (!std::isfinite(through.u) || !std::isfinite(through.v)) {
        through = {s.options.camera.u0(), s.options.camera.v0()};
      }
      const double reach =
          std::max(DistanceToLeave(through, du, dv), DistanceToLeave(through, -du, -dv)) +
          std::hypot(occluder.half_width_px, occluder.half_height_px);
      const double begin = 0.15 * last, end = 0.85 * last;
      for (int i = 0; i < frame_count; ++i) {
        if (i < begin || i > end) continue;
        const double f = end > begin ? 2.0 * (i - begin) / (end - begin) - 1.0 : 0.0;
        Occluder o = occluder;
        o.centre_u_px = through.u + f * reach * du;
        o.centre_v_px = through.v + f * reach * dv;
        s.frames[i].effects.occluders.push_back(o);
      }
      text << "Slow motion: " << MotionText(m) << ". An opaque rectangle (grey " << occluder.grey
           << ", " << 2 * occluder.half_width_px << " x " << 2 * occluder.half_height_px
           << " px) crosses the image at constant speed in direction " << angle / kRadPerDeg
           << " deg from frame " << std::ceil(begin) << " to frame " << std::floor(end)
           << ", passing over the crossing of lines 1 and 2 at frame " << mid << ".";
      break;
    }
    case SequenceKind::kIllumination: {
      const Motion m = Follow(SlowMotion(), kPi, gen, &s);
      s.options.illumination_gradient = 0.3;
      s.options.gradient_angle_rad = Uniform(gen, 0.0, 2.0 * kPi);
      const int change = frame_count / 2;
      constexpr double kGain = 0.5, kOffset = 15.0;
      for (int i = change; i < frame_count; ++i) {
        s.frames[i].effects.gain = kGain;
        s.frames[i].effects.offset = kOffset;
      }
      text << "Slow motion: " << MotionText(m) << ". Illumination falls by 30 % across the image "
           << "towards " << s.options.gradient_angle_rad / kRadPerDeg << " deg; from frame "
           << change << " on, every grey level g becomes " << kGain << " g + " << kOffset << ".";
      break;
    }
    case SequenceKind::kLeaveReenter: {
      Motion m = SlowMotion();
      m.Draw(gen, 15.0 * kRadPerDeg);
      const double pan_rad = (Uniform(gen) < 0.5 ? -1.0 : 1.0) * 32.0 * kRadPerDeg;
      for (int i = 0; i < frame_count; ++i) {
        const double a = 0.5 * (1.0 - std::cos(2.0 * kPi * i / last));
        s.frames[i].cMo = m.At(i, pan_rad * a);
      }
      text << "Slow motion: " << MotionText(m) << ", plus a pan of " << pan_rad / kRadPerDeg
           << " deg * (1 - cos(2 pi i / " << last << ")) / 2 at frame i: the camera turns "
           << (pan_rad > 0.0 ? "right" : "left") << " and back, so the line(s) on the "
           << (pan_rad > 0.0 ? "left" : "right")
           << " leave the image in the middle of the sequence and come back.";
      break;
    }
    case SequenceKind::kDistortion: {
      const Motion m = Follow(DistortionMotion(), kPi, gen, &s);
      text << "Heavy barrel distortion, kdu = " << kDistortionKdu
           << " (kud = " << s.options.camera.kud()
           << "), moderate motion (lines move about 3-5 px per frame): " << MotionText(m) << ".";
      break;
    }
  }
  s.description = text.str();
  return s;
}

double LineDisplacementPx(const TruthLine& from, const TruthLine& to) {
  if (!from.visible || !to.visible) return std::numeric_limits<double>::quiet_NaN();
  const Point2d mid{0.5 * (from.end_a.u + from.end_b.u), 0.5 * (from.end_a.v + from.end_b.v)};
  double sum = 0.0;
  for (const Point2d& p : {from.end_a, mid, from.end_b}) {
    sum += std::fabs(to.distorted_fit.SignedDistance(p.u, p.v));
  }
  return sum / 3.0;
}

}  // namespace oal
