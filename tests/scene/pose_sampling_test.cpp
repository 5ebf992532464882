// SamplePose: reproducible, within its bounds, facing the front of the board, the crossings in
// view when asked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/angles.h"
#include "scene/scene.h"
#include "tests/scene/scene_image_util.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::Project;

// The camera centre and optical axis in the object frame.
struct CameraInObject {
  double centre[3];
  double axis[3];
};

CameraInObject Locate(const vpHomogeneousMatrix& cMo) {
  const vpHomogeneousMatrix oMc = cMo.inverse();
  return {{oMc[0][3], oMc[1][3], oMc[2][3]}, {oMc[0][2], oMc[1][2], oMc[2][2]}};
}

bool SamePose(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (a[r][c] != b[r][c]) return false;
    }
  }
  return true;
}

TEST(SamplePose, SameStateGivesTheSameSequence) {
  const SceneRenderer renderer(FourLineTarget(), RenderOptions());
  PoseSampling sampling;
  sampling.min_visible_length_px = 150.0;
  std::uint64_t a = 12345, b = 12345;
  for (int i = 0; i < 5; ++i) {
    const vpHomogeneousMatrix pa = SamplePose(renderer, sampling, &a);
    const vpHomogeneousMatrix pb = SamplePose(renderer, sampling, &b);
    EXPECT_TRUE(SamePose(pa, pb)) << i;
    EXPECT_EQ(a, b);
  }
  std::uint64_t c = 12345;
  const vpHomogeneousMatrix first = SamplePose(renderer, sampling, &c);
  EXPECT_NE(c, 12345u);
  EXPECT_FALSE(SamePose(first, SamplePose(renderer, sampling, &c)));
  std::uint64_t d = 12346;
  EXPECT_FALSE(SamePose(first, SamplePose(renderer, sampling, &d)));
}

TEST(SamplePose, RespectsDistanceTiltOffsetAndRollBounds) {
  const SceneRenderer renderer(TwoLineTarget(), RenderOptions());
  PoseSampling sampling;
  sampling.min_distance_m = 0.5;
  sampling.max_distance_m = 0.8;
  sampling.max_tilt_deg = 20.0;
  sampling.max_offset_m = 0.04;
  sampling.any_roll = false;
  std::uint64_t state = 7;
  double max_tilt = 0.0, max_roll = 0.0, min_distance = 1e9, max_distance = 0.0;
  for (int i = 0; i < 300; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    ASSERT_TRUE(cMo.isAnHomogeneousMatrix());
    const CameraInObject cam = Locate(cMo);
    // In front of the board (object z < 0), looking towards +z.
    ASSERT_LT(cam.centre[2], 0.0);
    ASSERT_GT(cam.axis[2], 0.0);
    const double t = -cam.centre[2] / cam.axis[2];
    const double hit_x = cam.centre[0] + t * cam.axis[0], hit_y = cam.centre[1] + t * cam.axis[1];
    EXPECT_LE(std::hypot(hit_x, hit_y), sampling.max_offset_m + 1e-12);
    min_distance = std::min(min_distance, t);
    max_distance = std::max(max_distance, t);
    max_tilt = std::max(max_tilt, std::acos(cam.axis[2]));
    // Roll: the camera x axis against object x made orthogonal to the optical axis.
    const double* z = cam.axis;
    double x0[3] = {1.0 - z[0] * z[0], -z[0] * z[1], -z[0] * z[2]};
    const double norm = std::sqrt(x0[0] * x0[0] + x0[1] * x0[1] + x0[2] * x0[2]);
    const double cos_roll = (cMo[0][0] * x0[0] + cMo[0][1] * x0[1] + cMo[0][2] * x0[2]) / norm;
    max_roll = std::max(max_roll, std::acos(std::min(1.0, cos_roll)));
  }
  EXPECT_GE(min_distance, sampling.min_distance_m - 1e-12);
  EXPECT_LE(max_distance, sampling.max_distance_m + 1e-12);
  EXPECT_LT(min_distance, 0.53);  // the whole range is used
  EXPECT_GT(max_distance, 0.77);
  EXPECT_LE(max_tilt, sampling.max_tilt_deg * kRadPerDeg + 1e-9);
  EXPECT_GT(max_tilt, 0.8 * sampling.max_tilt_deg * kRadPerDeg);
  EXPECT_LE(max_roll, sampling.max_tilt_deg * kRadPerDeg + 1e-9);
  EXPECT_GT(max_roll, 0.8 * sampling.max_tilt_deg * kRadPerDeg);
}

// Views for a calibration: every one tilted between the two bounds, the whole range used.
TEST(SamplePose, TiltsBetweenTheLeastAndTheMost) {
  const SceneRenderer renderer(FourLineA3Target(), RenderOptions());
  PoseSampling sampling;
  sampling.min_tilt_deg = 30.0;
  sampling.max_tilt_deg = 45.0;
  std::uint64_t state = 11;
  double least = HUGE_VAL, most = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double tilt = std::acos(Locate(SamplePose(renderer, sampling, &state)).axis[2]);
    least = std::min(least, tilt);
    most = std::max(most, tilt);
  }
  EXPECT_GE(least, 30.0 * kRadPerDeg - 1e-9);
  EXPECT_LT(least, 31.0 * kRadPerDeg);
  EXPECT_LE(most, 45.0 * kRadPerDeg + 1e-9);
  EXPECT_GT(most, 44.0 * kRadPerDeg);
  sampling.min_tilt_deg = 50.0;
  EXPECT_THROW(SamplePose(renderer, sampling, &state), std::invalid_argument);
}

TEST(SamplePose, EveryLineIsLongEnough) {
  const SceneRenderer renderer(FourLineTarget(), RenderOptions());
  PoseSampling sampling;
  sampling.max_tilt_deg = 40.0;
  sampling.min_visible_length_px = 300.0;
  std::uint64_t state = 3;
  for (int i = 0; i < 40; ++i) {
    for (const TruthLine& line : renderer.Truth(SamplePose(renderer, sampling, &state))) {
      EXPECT_TRUE(line.visible);
      EXPECT_GE(line.visible_length_px, 300.0);
    }
  }
  sampling.min_visible_length_px = 5000.0;  // longer than the image diagonal
  EXPECT_THROW(SamplePose(renderer, sampling, &state), std::runtime_error);
}

// Poses drawn with the fields that existed before the sheet requirements (crossings in view):
// their checksums were computed from SamplePose before those were added, so data sets and
// figures made from the same seeds stay reproducible (bit-exact doubles: computed on x86-64
// Debian bookworm, the CI's platform).
TEST(SamplePose, OldFieldsGiveThePosesOfBefore) {
  const SceneRenderer board(FourLineTarget(), RenderOptions());
  PoseSampling sampling;
  std::uint64_t state = 2024, hash = 0;
  for (int i = 0; i < 50; ++i) {
    hash = testing::PoseChecksum(SamplePose(board, sampling, &state), hash);
  }
  const SceneRenderer sheet(FourLineA3Target(), RenderOptions());
  sampling.max_tilt_deg = 40.0;
  sampling.max_offset_m = 0.12;
  sampling.min_visible_length_px = 120.0;
  std::uint64_t hash2 = 0;
  for (int i = 0; i < 50; ++i) {
    hash2 = testing::PoseChecksum(SamplePose(sheet, sampling, &state), hash2);
  }
  EXPECT_EQ(hash, 0x0a95535601803ce2ull);
  EXPECT_EQ(hash2, 0x398bddfe47e78479ull);
  EXPECT_EQ(state, 146452912055701122ull);
}

// The '#' on an A3 sheet: lines 0 and 2 run along y (x fixed), lines 1 and 3 along x.
TEST(StripeCrossings, AreTheFourSquaresOfTheHash) {
  const LineTarget target = FourLineA3Target();
  const std::vector<StripeCrossing> crossings = StripeCrossings(target);
  ASSERT_EQ(crossings.size(), 4u);
  const int pairs[4][2] = {{0, 1}, {0, 3}, {1, 2}, {2, 3}};
  for (int i = 0; i < 4; ++i) {
    const StripeCrossing& c = crossings[i];
    EXPECT_EQ(c.line_a, pairs[i][0]);
    EXPECT_EQ(c.line_b, pairs[i][1]);
    const TargetLine& along_y = target.lines[c.line_a % 2 == 0 ? c.line_a : c.line_b];
    const TargetLine& along_x = target.lines[c.line_a % 2 == 0 ? c.line_b : c.line_a];
    double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
    for (const auto& corner : c.corners_m) {
      min_x = std::min(min_x, corner[0]);
      max_x = std::max(max_x, corner[0]);
      min_y = std::min(min_y, corner[1]);
      max_y = std::max(max_y, corner[1]);
      EXPECT_NEAR(std::fabs(corner[0] - along_y.x1_m), 0.5 * along_y.width_m, 1e-12);
      EXPECT_NEAR(std::fabs(corner[1] - along_x.y1_m), 0.5 * along_x.width_m, 1e-12);
    }
    EXPECT_NEAR(max_x - min_x, along_y.width_m, 1e-12);
    EXPECT_NEAR(max_y - min_y, along_x.width_m, 1e-12);
    // In order around the square: opposite corners are diagonal.
    EXPECT_NEAR(
        std::hypot(c.corners_m[2][0] - c.corners_m[0][0], c.corners_m[2][1] - c.corners_m[0][1]),
        std::hypot(along_y.width_m, along_x.width_m), 1e-12);
  }
  EXPECT_TRUE(StripeCrossings(TwoLineTarget()).empty());  // parallel stripes never cross
}

// The evaluation's A3 scenes: 0.3-0.85 m, tilt up to 30 deg, any roll, the optical axis up to
// 0.15 m from the centre (so the sheet is often partly out of view), the crossings in view.
PoseSampling SheetSampling() {
  PoseSampling sampling;
  sampling.min_distance_m = 0.3;
  sampling.max_distance_m = 0.85;
  sampling.max_tilt_deg = 30.0;
  sampling.max_offset_m = 0.15;
  sampling.crossings_in_view = true;
  sampling.crossings_margin_px = 10.0;
  return sampling;
}

bool InImage(const Point2d& p, double margin_px) {
  return p.u >= margin_px && p.u <= 639.0 - margin_px && p.v >= margin_px &&
         p.v <= 479.0 - margin_px;
}

TEST(SamplePose, CrossingsInViewPutsEveryCrossingSquareInTheImage) {
  const LineTarget target = FourLineA3Target();
  RenderOptions options;  // pinhole: ideal pixels are the image's
  const SceneRenderer renderer(target, options);
  const PoseSampling sampling = SheetSampling();
  std::uint64_t state = 99;
  int partly_out = 0;
  constexpr int kPoses = 400;
  for (int i = 0; i < kPoses; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    // The squares' corners, from the stripes: x of lines 0 and 2, y of lines 1 and 3.
    for (const int a : {0, 2}) {
      for (const int b : {1, 3}) {
        for (const double sx : {-0.5, 0.5}) {
          for (const double sy : {-0.5, 0.5}) {
            Point2d p;
            ASSERT_TRUE(Project(cMo, options.camera,
                                target.lines[a].x1_m + sx * target.lines[a].width_m,
                                target.lines[b].y1_m + sy * target.lines[b].width_m, &p))
                << "pose " << i;
            EXPECT_TRUE(InImage(p, sampling.crossings_margin_px))
                << "pose " << i << " lines " << a << ", " << b << ": " << p.u << ", " << p.v;
          }
        }
      }
    }
    bool all_corners_in = true;
    for (const double sx : {-0.5, 0.5}) {
      for (const double sy : {-0.5, 0.5}) {
        Point2d p;
        all_corners_in = all_corners_in &&
                         Project(cMo, options.camera, sx * target.board_width_m,
                                 sy * target.board_height_m, &p) &&
                         InImage(p, 0.0);
      }
    }
    partly_out += !all_corners_in;
  }
  // max_offset_m is enough to put the sheet partly out of view often.
  EXPECT_GT(partly_out, kPoses / 4);
  EXPECT_LT(partly_out, kPoses);
}

TEST(SamplePose, CrossingsInViewHoldsThroughTheLensAndInTheImage) {
  const LineTarget target = FourLineA3Target();
  RenderOptions options;
  options.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
  const SceneRenderer renderer(target, options);
  const PoseSampling sampling = SheetSampling();
  std::uint64_t state = 5;
  for (int i = 0; i < 200; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    ASSERT_TRUE(CrossingsInView(renderer, cMo, sampling.crossings_margin_px)) << "pose " << i;
    for (const StripeCrossing& crossing : StripeCrossings(target)) {
      for (const auto& corner : crossing.corners_m) {
        Point2d ideal;
        ASSERT_TRUE(Project(cMo, options.camera, corner[0], corner[1], &ideal));
        const Point2d p =
            options.camera.Pixel((ideal.u - 319.5) / 600.0, (ideal.v - 239.5) / 600.0);
        EXPECT_TRUE(InImage(p, sampling.crossings_margin_px)) << "pose " << i;
      }
    }
    if (i % 40 != 0) continue;
    // The centre of each square is dark in the rendered frame.
    const RenderedFrame frame = renderer.Render(cMo, 1);
    for (const StripeCrossing& crossing : StripeCrossings(target)) {
      Point2d ideal;
      ASSERT_TRUE(Project(cMo, options.camera,
                          0.5 * (crossing.corners_m[0][0] + crossing.corners_m[2][0]),
                          0.5 * (crossing.corners_m[0][1] + crossing.corners_m[2][1]), &ideal));
      const Point2d p = options.camera.Pixel((ideal.u - 319.5) / 600.0, (ideal.v - 239.5) / 600.0);
      EXPECT_EQ(frame.image[static_cast<int>(std::lround(p.v))][static_cast<int>(std::lround(p.u))],
                target.line_grey)
          << "pose " << i;
    }
  }
}

TEST(SamplePose, CrossingsInViewIsVacuousWithoutCrossings) {
  const SceneRenderer renderer(TwoLineTarget(), RenderOptions());
  PoseSampling plain;
  PoseSampling crossings = plain;
  crossings.crossings_in_view = true;
  std::uint64_t a = 8, b = 8;
  for (int i = 0; i < 10; ++i) {
    EXPECT_TRUE(SamePose(SamplePose(renderer, plain, &a), SamplePose(renderer, crossings, &b)));
  }
}

TEST(SamplePose, CrossingsThatCannotBeInViewThrow) {
  const SceneRenderer renderer(FourLineA3Target(), RenderOptions());
  PoseSampling sampling = SheetSampling();
  sampling.crossings_margin_px = 235.0;  // a 10 x 10 pixel window in the middle of the image
  std::uint64_t state = 1;
  try {
    SamplePose(renderer, sampling, &state);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("crossings_margin_px = 235"), std::string::npos)
        << error.what();
  }
  sampling.crossings_margin_px = -1.0;
  EXPECT_THROW(SamplePose(renderer, sampling, &state), std::invalid_argument);
}

// The camera sees the printed side, unmirrored: the stripes are dark on the light board, and
// the object x and y axes appear in the image with the same handedness as u and v.
TEST(SamplePose, CameraSeesTheFrontOfTheBoard) {
  const LineTarget target = FourLineTarget();
  RenderOptions options;
  const SceneRenderer renderer(target, options);
  PoseSampling sampling;
  sampling.min_visible_length_px = 200.0;
  std::uint64_t state = 11;
  for (int i = 0; i < 6; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    const RenderedFrame frame = renderer.Render(cMo, 1);
    Point2d origin, x_end, y_end;
    ASSERT_TRUE(Project(cMo, options.camera, 0.0, 0.0, &origin));
    ASSERT_TRUE(Project(cMo, options.camera, 0.01, 0.0, &x_end));
    ASSERT_TRUE(Project(cMo, options.camera, 0.0, 0.01, &y_end));
    const double handedness =
        (x_end.u - origin.u) * (y_end.v - origin.v) - (x_end.v - origin.v) * (y_end.u - origin.u);
    EXPECT_GT(handedness, 0.0);
    // Middle of each stripe's visible part: dark.
    for (const TruthLine& line : frame.truth) {
      const int u = static_cast<int>(std::lround(0.5 * (line.end_a.u + line.end_b.u)));
      const int v = static_cast<int>(std::lround(0.5 * (line.end_a.v + line.end_b.v)));
      EXPECT_LT(frame.image[v][u], 60) << "pose " << i << " line " << line.index;
    }
    // A board point inside the '#', away from every stripe: light.
    Point2d bare;
    ASSERT_TRUE(Project(cMo, options.camera, 0.01, -0.005, &bare));
    ASSERT_TRUE(bare.u >= 0 && bare.u < 640 && bare.v >= 0 && bare.v < 480);
    EXPECT_EQ(
        frame.image[static_cast<int>(std::lround(bare.v))][static_cast<int>(std::lround(bare.u))],
        target.board_grey);
  }
}

}  // namespace
}  // namespace oal
