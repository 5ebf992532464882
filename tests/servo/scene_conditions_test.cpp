// The target tracker (servo/target_tracker.h) in a lived-in scene, at a webcam's 640x480 and
// at 1920x1080 (a 70 degree webcam, its settings in pixels scaled with its focal length):
// a hand over one side of a stripe, something over a crossing, a pen across two stripes, a
// lamp's glare, a frame exposed at a third or one and a half times the right level, 12 px of
// motion blur, MJPEG at quality 40, a view tilted by up to 60 degrees, a sheet partly out of
// view, a stripe cut by the image's border next to a crossing. Each frame found on its own
// gives a right pose or none: never a wrong one.
#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpMeterPixelConversion.h>

#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "base/pose_distance.h"
#include "detector/line.h"  // kPi
#include "scene/bench_scene.h"
#include "scene/scene.h"
#include "servo/target_layout.h"
#include "servo/target_tracker.h"
#include "tests/scene/scene_image_util.h"

namespace oal {
namespace {

// A pose counted as right: within 2 % of the distance and 2 degrees (as pose-accuracy).
constexpr double kMaxTranslationFraction = 0.02;
constexpr double kMaxRotationDeg = 2.0;
constexpr int kFrames = 3;

struct Resolution {
  const char* name;
  int width, height;
  double focal_px;
};
const Resolution kResolutions[] = {{"640x480", 640, 480, 600.0}, {"1920x1080", 1920, 1080, 1371.0}};

RenderOptions BenchRender(const Resolution& resolution, std::uint64_t scene_seed) {
  RenderOptions render;
  render.camera =
      Lens::WithKdu(resolution.focal_px, resolution.focal_px, 0.5 * (resolution.width - 1),
                    0.5 * (resolution.height - 1), 0.15, resolution.width, resolution.height);
  render.width = resolution.width;
  render.height = resolution.height;
  render.noise_sigma = 3.0;
  render.blur_sigma_px = 0.8;
  render.background = testing::ReadPgm("/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm");
  DressAsBench(&render, scene_seed);
  return render;
}

// A uniform draw in [0, 1) from a 64-bit state (xorshift*).
double Uniform(std::uint64_t* state) {
  *state ^= *state >> 12;
  *state ^= *state << 25;
  *state ^= *state >> 27;
  return static_cast<double>((*state * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

// The along-coordinate of the outer crossing on stripe k's `high` side: where the
// perpendicular stripe farthest that way crosses it.
double OuterCrossing(const TargetLayout& layout, int k, bool high) {
  const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
  double outer = high ? -HUGE_VAL : HUGE_VAL;
  for (const StripeSpan& other : layout.stripes) {
    if (other.along_b == span.along_b) continue;
    outer = high ? std::max(outer, other.at + other.half) : std::min(outer, other.at - other.half);
  }
  return outer;
}

// A scene condition: frame i's pose and what happens to it.
struct Condition {
  std::string name;
  std::function<void(const SceneRenderer&, int, std::uint64_t*, vpHomogeneousMatrix*,
                     FrameEffects*)>
      draw;
};

vpHomogeneousMatrix Sheet(const SceneRenderer& renderer, std::uint64_t* state) {
  return SamplePose(renderer, SheetSampling(renderer.target()), state);
}

// Whether a corner of the sheet lies outside the image (ideal pixels).
bool SheetPartlyOut(const SceneRenderer& renderer, const vpHomogeneousMatrix& cMo) {
  const LineTarget& target = renderer.target();
  const Lens& camera = renderer.options().camera;
  for (const double x : {-0.5, 0.5}) {
    for (const double y : {-0.5, 0.5}) {
      vpColVector corner(4);
      corner[0] = x * target.board_width_m;
      corner[1] = y * target.board_height_m;
      corner[2] = 0.0;
      corner[3] = 1.0;
      const vpColVector c = cMo * corner;
      if (!(c[2] > 0.0)) return true;
      const Point2d pixel = camera.Pixel(c[0] / c[2], c[1] / c[2]);
      const double u = pixel.u, v = pixel.v;
      if (u < 0.0 || v < 0.0 || u > renderer.options().width - 1.0 ||
          v > renderer.options().height - 1.0) {
        return true;
      }
    }
  }
  return false;
}

std::vector<Condition> Conditions() {
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  std::vector<Condition> conditions;
  conditions.push_back(
      {"occluded_stripe", [layout](const SceneRenderer& renderer, int i, std::uint64_t* state,
                                   vpHomogeneousMatrix* cMo, FrameEffects* effects) {
         // A forearm along one side of stripe i % 4, from beside its outer
         // crossing to past the sheet's edge.
         *cMo = Sheet(renderer, state);
         const int k = i % 4;
         const bool high = Uniform(state) < 0.5;
         const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
         const double from = OuterCrossing(layout, k, high) + (high ? 0.02 : -0.02);
         const double to = (high ? span.along.hi + 0.15 : span.along.lo - 0.15);
         const Point2d a = layout.OnStripe(k, from, 0.0);
         const Point2d b = layout.OnStripe(k, to, 0.0);
         PlaneOccluder arm;
         arm.capsules.push_back({a.u, a.v, b.u, b.v, 0.025});
         arm.grey = 90 + static_cast<int>(100 * Uniform(state));
         arm.texture_grey = 10.0;
         arm.texture_seed = static_cast<std::uint64_t>(i);
         arm.shadow_darkness = 0.3;
         arm.shadow_offset_m = 0.01;
         effects->plane_occluders.push_back(arm);
       }});
  conditions.push_back(
      {"occluded_crossing", [layout](const SceneRenderer& renderer, int i, std::uint64_t* state,
                                     vpHomogeneousMatrix* cMo, FrameEffects* effects) {
         // A fingertip-sized blob over crossing i % 4 of the '#'.
         *cMo = Sheet(renderer, state);
         const int k = i % 4;
         const bool high = (i / 4) % 2 == 0;
         const double along = OuterCrossing(layout, k, high) +
                              (high ? -1.0 : 1.0) * layout.stripes[(k + 1) % 4].half;
         const Point2d at = layout.OnStripe(k, along, 0.0);
         PlaneOccluder blob;
         blob.ellipses.push_back({at.u, at.v, 0.035, 0.025, kPi * Uniform(state)});
         blob.grey = 80 + static_cast<int>(120 * Uniform(state));
         blob.texture_grey = 10.0;
         effects->plane_occluders.push_back(blob);
       }});
  conditions.push_back({"pen_across_two_stripes",
                        [layout](const SceneRenderer& renderer, int i, std::uint64_t* state,
                                 vpHomogeneousMatrix* cMo, FrameEffects* effects) {
                          // A dark pen across stripes k and its parallel partner, at a slant,
                          // between their crossings and their ends.
                          *cMo = Sheet(renderer, state);
                          const int k = i % 2;
                          const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
                          const StripeSpan& partner =
                              layout.stripes[static_cast<std::size_t>(k + 2)];
                          const double along =
                              0.5 * (OuterCrossing(layout, k, true) + span.along.hi);
                          const double beyond = 0.04;
                          const double lo = std::min(span.at, partner.at) - beyond;
                          const double hi = std::max(span.at, partner.at) + beyond;
                          const double slant = 0.3 * (Uniform(state) - 0.5) * (hi - lo);
                          const auto plane = [&](double along_at, double across_at) {
                            // '#' coordinates (along, across) of stripe k's family.
                            return layout.OnStripe(k, along_at, across_at - span.at);
                          };
                          const Point2d a = plane(along - slant, lo), b = plane(along + slant, hi);
                          PlaneOccluder pen;
                          pen.capsules.push_back({a.u, a.v, b.u, b.v, 0.005});
                          pen.grey = 30 + static_cast<int>(40 * Uniform(state));
                          effects->plane_occluders.push_back(pen);
                        }});
  conditions.push_back(
      {"glare", [layout](const SceneRenderer& renderer, int i, std::uint64_t* state,
                         vpHomogeneousMatrix* cMo, FrameEffects* effects) {
         // A lamp's reflection, saturated at its core, on stripe i % 4.
         *cMo = Sheet(renderer, state);
         const int k = i % 4;
         const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
         const double along = span.along.lo + (span.along.hi - span.along.lo) * Uniform(state);
         const Point2d at = layout.OnStripe(k, along, 0.0);
         effects->glares.push_back(
             {at.u, at.v, 0.01 + 0.02 * Uniform(state), 400.0 + 400.0 * Uniform(state)});
       }});
  conditions.push_back({"underexposed", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                           vpHomogeneousMatrix* cMo, FrameEffects* effects) {
                          *cMo = Sheet(renderer, state);
                          effects->gain = 1.0 / 3.0;
                        }});
  conditions.push_back({"overexposed", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                          vpHomogeneousMatrix* cMo, FrameEffects* effects) {
                          *cMo = Sheet(renderer, state);
                          effects->gain = 1.5;
                        }});
  conditions.push_back({"motion_blur", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                          vpHomogeneousMatrix* cMo, FrameEffects* effects) {
                          *cMo = Sheet(renderer, state);
                          effects->motion_blur_px = 12.0;
                          effects->motion_blur_angle_rad = 2.0 * kPi * Uniform(state);
                        }});
  conditions.push_back({"jpeg", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                   vpHomogeneousMatrix* cMo, FrameEffects* effects) {
                          *cMo = Sheet(renderer, state);
                          effects->jpeg_quality = 40;
                        }});
  conditions.push_back({"tilt_60", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                      vpHomogeneousMatrix* cMo, FrameEffects*) {
                          // Tilted by 50 to 60 degrees.
                          PoseSampling sampling = SheetSampling(renderer.target());
                          sampling.max_tilt_deg = 60.0;
                          do {
                            *cMo = SamplePose(renderer, sampling, state);
                          } while (vpMath::deg(std::acos(std::fabs((*cMo)[2][2]))) < 50.0);
                        }});
  conditions.push_back(
      {"partly_out_of_view", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                vpHomogeneousMatrix* cMo, FrameEffects*) {
         PoseSampling sampling = SheetSampling(renderer.target());
         sampling.max_offset_m = 0.25;
         do {
           *cMo = SamplePose(renderer, sampling, state);
         } while (!SheetPartlyOut(renderer, *cMo));
       }});
  conditions.push_back(
      {"stripe_cut_at_crossing", [](const SceneRenderer& renderer, int, std::uint64_t* state,
                                    vpHomogeneousMatrix* cMo, FrameEffects*) {
         // A crossing within 2 to 15 px of the image's border: the stripe
         // beyond it cut off by the border.
         PoseSampling sampling = SheetSampling(renderer.target());
         sampling.max_offset_m = 0.25;
         sampling.crossings_margin_px = 2.0;
         do {
           *cMo = SamplePose(renderer, sampling, state);
         } while (CrossingsInView(renderer, *cMo, 15.0));
       }});
  return conditions;
}

// Translation error over the distance, and rotation error in degrees.
std::pair<double, double> PoseError(const vpHomogeneousMatrix& cMo,
                                    const vpHomogeneousMatrix& cMo_true) {
  const PoseDistance d = Distance(cMo, cMo_true);
  return {d.translation_m / cMo_true.getTranslationVector().frobeniusNorm(),
          vpMath::deg(d.rotation_rad)};
}

struct Case {
  std::size_t condition;
  std::size_t resolution;
};

class SceneCondition : public ::testing::TestWithParam<Case> {};

// Every frame: a right pose or a refusal. And the tracker is not one that refuses all: at
// least one of the condition's frames is found.
TEST_P(SceneCondition, GivesARightPoseOrNone) {
  const Condition condition = Conditions()[GetParam().condition];
  const Resolution& resolution = kResolutions[GetParam().resolution];
  const std::uint64_t seed = 1000 + 17 * GetParam().condition;
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(resolution, seed));
  PoseOptions pose;
  pose.camera = renderer.options().camera;
  pose.image_width = resolution.width;
  pose.image_height = resolution.height;
  TargetPoseTracker tracker(renderer.target(), renderer.options().camera, DetectorOptions(), pose);
  std::uint64_t state = seed;
  int found = 0;
  for (int i = 0; i < kFrames; ++i) {
    vpHomogeneousMatrix cMo;
    FrameEffects effects;
    condition.draw(renderer, i, &state, &cMo, &effects);
    const RenderedFrame frame = renderer.Render(cMo, seed + static_cast<std::uint64_t>(i), effects);
    tracker.Reset();
    const TargetFrame& result = tracker.Track(ViewOf(frame.image));
    if (result.status != TargetStatus::kOk) continue;
    ++found;
    const auto [t, r] = PoseError(result.pose.cMo, cMo);
    EXPECT_LT(t, kMaxTranslationFraction) << condition.name << " frame " << i;
    EXPECT_LT(r, kMaxRotationDeg) << condition.name << " frame " << i;
  }
  RecordProperty("found", found);
  EXPECT_GE(found, 1) << condition.name << " at " << resolution.name << ": no frame found";
}

std::vector<Case> AllCases() {
  std::vector<Case> cases;
  for (std::size_t c = 0; c < Conditions().size(); ++c) {
    for (std::size_t r = 0; r < std::size(kResolutions); ++r) cases.push_back({c, r});
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(LivedIn, SceneCondition, ::testing::ValuesIn(AllCases()),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return Conditions()[param.param.condition].name + "_" +
                                  (param.param.resolution == 0 ? "640" : "1920");
                         });

}  // namespace
}  // namespace oal
