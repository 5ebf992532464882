// Rendered sequences: names, determinism, and that each scenario has the property it
// claims. Most checks use the ground truth only; frames are rendered where the image matters.
#include "scene/sequence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/statistics.h"
#include "scene/scene.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::SameImage;

constexpr std::uint64_t kSeed = 7;
constexpr int kFrames = 24;

std::vector<std::vector<TruthLine>> TruthOf(const Sequence& sequence) {
  const SceneRenderer renderer(sequence.target, sequence.options);
  std::vector<std::vector<TruthLine>> truth;
  for (const SequenceFrame& frame : sequence.frames) {
    truth.push_back(renderer.Truth(frame.cMo, frame.effects));
  }
  return truth;
}

// Median over lines and consecutive frame pairs of LineDisplacementPx (both frames visible).
double MedianDisplacementPx(const std::vector<std::vector<TruthLine>>& truth) {
  std::vector<double> d;
  for (std::size_t i = 1; i < truth.size(); ++i) {
    for (std::size_t l = 0; l < truth[i].size(); ++l) {
      const double value = LineDisplacementPx(truth[i - 1][l], truth[i][l]);
      if (std::isfinite(value)) d.push_back(value);
    }
  }
  if (d.empty()) return std::nan("");
  return MedianInPlace(&d);
}

double MeanGrey(const vpImage<unsigned char>& image) {
  return std::accumulate(image.bitmap, image.bitmap + image.getSize(), 0.0) /
         static_cast<double>(image.getSize());
}

bool SamePose(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  for (unsigned r = 0; r < 4; ++r) {
    for (unsigned c = 0; c < 4; ++c) {
      if (a[r][c] != b[r][c]) return false;
    }
  }
  return true;
}

TEST(SequenceKind, NamesRoundTrip) {
  const std::vector<SequenceKind> kinds = AllSequenceKinds();
  ASSERT_EQ(kinds.size(), 6u);
  for (const SequenceKind kind : kinds) {
    EXPECT_EQ(SequenceKindFromString(ToString(kind)), kind);
  }
  EXPECT_STREQ(ToString(SequenceKind::kLeaveReenter), "leave-reenter");
  EXPECT_EQ(SequenceKindNames(), "slow, fast, occlusion, illumination, leave-reenter, distortion");
  try {
    SequenceKindFromString("wobbly");
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'wobbly' is not one of: slow, fast"),
              std::string::npos)
        << error.what();
  }
}

TEST(Sequence, BadFrameCountIsRejected) {
  EXPECT_THROW(MakeSequence(SequenceKind::kSlow, 0, kSeed), std::invalid_argument);
  EXPECT_THROW(MakeSequence(SequenceKind::kSlow, 100001, kSeed), std::invalid_argument);
  EXPECT_EQ(MakeSequence(SequenceKind::kLeaveReenter, 1, kSeed).frames.size(), 1u);
}

TEST(Sequence, CommonSettings) {
  for (const SequenceKind kind : AllSequenceKinds()) {
    const Sequence s = MakeSequence(kind, kFrames, kSeed);
    SCOPED_TRACE(ToString(kind));
    EXPECT_EQ(s.kind, kind);
    EXPECT_EQ(s.seed, kSeed);
    EXPECT_EQ(s.target.name, "four-line-board");
    EXPECT_EQ(s.frames.size(), static_cast<std::size_t>(kFrames));
    EXPECT_EQ(s.options.width, 640);
    EXPECT_EQ(s.options.height, 480);
    EXPECT_EQ(s.options.camera.px(), 600.0);
    EXPECT_GE(s.options.noise_sigma, 4.0);
    EXPECT_LE(s.options.noise_sigma, 6.0);
    EXPECT_EQ(s.options.blur_sigma_px, 1.0);
    EXPECT_NE(s.description.find(ToString(kind)), std::string::npos);
    EXPECT_NO_THROW(s.options.Check());
    // Every line is in view at the start (leave-reenter and occlusion start plain too).
    const SceneRenderer renderer(s.target, s.options);
    for (const TruthLine& line : renderer.Truth(s.frames[0].cMo, s.frames[0].effects)) {
      EXPECT_TRUE(line.visible) << "line " << line.index;
    }
    // Distinct noise per frame.
    EXPECT_NE(s.frames[0].noise_seed, s.frames[1].noise_seed);
  }
}

TEST(Sequence, SameSeedSameSequenceOtherSeedOther) {
  for (const SequenceKind kind : AllSequenceKinds()) {
    SCOPED_TRACE(ToString(kind));
    const Sequence a = MakeSequence(kind, kFrames, kSeed);
    const Sequence b = MakeSequence(kind, kFrames, kSeed);
    const Sequence c = MakeSequence(kind, kFrames, kSeed + 1);
    EXPECT_EQ(a.description, b.description);
    for (int i = 0; i < kFrames; ++i) {
      EXPECT_TRUE(SamePose(a.frames[i].cMo, b.frames[i].cMo)) << "frame " << i;
      EXPECT_EQ(a.frames[i].noise_seed, b.frames[i].noise_seed);
      EXPECT_EQ(a.frames[i].effects.gain, b.frames[i].effects.gain);
      EXPECT_EQ(a.frames[i].effects.occluders.size(), b.frames[i].effects.occluders.size());
    }
    EXPECT_FALSE(SamePose(a.frames[1].cMo, c.frames[1].cMo));
  }
}

TEST(Sequence, SameSeedSameImages) {
  const Sequence a = MakeSequence(SequenceKind::kOcclusion, 10, kSeed);
  const Sequence b = MakeSequence(SequenceKind::kOcclusion, 10, kSeed);
  const SceneRenderer ra(a.target, a.options), rb(b.target, b.options);
  const int i = 5;  // the occluder is in the image
  ASSERT_FALSE(a.frames[i].effects.occluders.empty());
  const RenderedFrame fa = ra.Render(a.frames[i].cMo, a.frames[i].noise_seed, a.frames[i].effects);
  const RenderedFrame fb = rb.Render(b.frames[i].cMo, b.frames[i].noise_seed, b.frames[i].effects);
  EXPECT_TRUE(SameImage(fa.image, fb.image));
}

TEST(Sequence, SlowLinesMoveOneToTwoPixelsPerFrame) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    const double median =
        MedianDisplacementPx(TruthOf(MakeSequence(SequenceKind::kSlow, 30, seed)));
    EXPECT_LT(median, 3.0) << "seed " << seed;
    EXPECT_GT(median, 0.5) << "seed " << seed;
  }
}

TEST(Sequence, FastLinesMoveTensOfPixelsPerFrame) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    const auto truth = TruthOf(MakeSequence(SequenceKind::kFast, 30, seed));
    const double median = MedianDisplacementPx(truth);
    EXPECT_GT(median, 15.0) << "seed " << seed;
    EXPECT_LT(median, 50.0) << "seed " << seed;
    // Fast, but the lines stay in view.
    int visible = 0, total = 0;
    for (const auto& frame : truth) {
      for (const TruthLine& line : frame) {
        visible += line.visible ? 1 : 0;
        ++total;
      }
    }
    EXPECT_GE(visible, 0.95 * total) << "seed " << seed;
  }
}

TEST(Sequence, DistortionIsHeavyAndMotionModerate) {
  const Sequence s = MakeSequence(SequenceKind::kDistortion, 30, kSeed);
  ASSERT_EQ(s.options.camera.model(), Lens::Model::kViSP);
  EXPECT_GE(s.options.camera.kdu(), 0.45);
  EXPECT_LE(s.options.camera.kdu(), 0.5);
  EXPECT_NEAR(s.options.camera.kud(), FitKud(s.options.camera, 640, 480), 1e-12);
  const double median = MedianDisplacementPx(TruthOf(s));
  EXPECT_GT(median, 2.0);
  EXPECT_LT(median, 10.0);
  for (const SequenceKind kind : AllSequenceKinds()) {
    if (kind == SequenceKind::kDistortion) continue;
    EXPECT_EQ(MakeSequence(kind, 2, kSeed).options.camera.kdu(), 0.0) << ToString(kind);
  }
}

TEST(Sequence, LeaveReenterLinesLeaveAndComeBack) {
  for (const std::uint64_t seed : {1, 2, 3, 4, 5, 6}) {
    const auto truth = TruthOf(MakeSequence(SequenceKind::kLeaveReenter, 20, seed));
    bool some_left_and_returned = false;
    int lines_in_view_throughout = 0;
    for (std::size_t l = 0; l < truth[0].size(); ++l) {
      std::vector<bool> visible;
      for (const auto& frame : truth) visible.push_back(frame[l].visible);
      const auto gone = std::find(visible.begin(), visible.end(), false);
      if (gone == visible.end()) {
        ++lines_in_view_throughout;
        continue;
      }
      const auto back = std::find(gone, visible.end(), true);
      const long frames_out = std::distance(gone, back);
      if (visible.front() && back != visible.end() && frames_out >= 3) {
        some_left_and_returned = true;
      }
    }
    EXPECT_TRUE(some_left_and_returned) << "seed " << seed;
    EXPECT_GE(lines_in_view_throughout, 2) << "seed " << seed;
    for (const TruthLine& line : truth.back()) EXPECT_TRUE(line.visible) << "seed " << seed;
  }
}

TEST(Sequence, OcclusionHidesPartOfALineForAStretch) {
  for (const std::uint64_t seed : {1, 2, 3, 4}) {
    const Sequence s = MakeSequence(SequenceKind::kOcclusion, 20, seed);
    const auto truth = TruthOf(s);
    int frames_partly_hidden = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const bool has_occluder = !s.frames[i].effects.occluders.empty();
      bool partly = false;
      for (const TruthLine& line : truth[i]) {
        EXPECT_TRUE(line.visible) << "seed " << seed << " frame " << i;  // occlusion keeps it
        EXPECT_GE(line.occluded_fraction, 0.0);
        EXPECT_LT(line.occluded_fraction, 0.7) << "seed " << seed << " frame " << i;
        if (!has_occluder) {
          EXPECT_EQ(line.occluded_fraction, 0.0);
        }
        partly = partly || line.occluded_fraction > 0.05;
      }
      frames_partly_hidden += partly ? 1 : 0;
    }
    EXPECT_GE(frames_partly_hidden, 2) << "seed " << seed;
    EXPECT_TRUE(s.frames.front().effects.occluders.empty());
    EXPECT_TRUE(s.frames.back().effects.occluders.empty());
  }
}

TEST(Sequence, OccluderIsRenderedWhereItIs) {
  const Sequence s = MakeSequence(SequenceKind::kOcclusion, 20, kSeed);
  const SceneRenderer renderer(s.target, s.options);
  int checked = 0;
  for (const SequenceFrame& frame : s.frames) {
    if (frame.effects.occluders.empty()) continue;
    const Occluder& o = frame.effects.occluders[0];
    const int u = static_cast<int>(std::lround(o.centre_u_px));
    const int v = static_cast<int>(std::lround(o.centre_v_px));
    if (u < 2 || v < 2 || u > 637 || v > 477) continue;
    const RenderedFrame image = renderer.Render(frame.cMo, frame.noise_seed, frame.effects);
    double sum = 0.0;  // 5x5 mean: noise sigma 5 -> about 1 grey level
    for (int dv = -2; dv <= 2; ++dv) {
      for (int du = -2; du <= 2; ++du) sum += image.image[v + dv][u + du];
    }
    EXPECT_NEAR(sum / 25.0, o.grey, 4.0);
    if (++checked == 2) break;
  }
  EXPECT_GT(checked, 0);
}

TEST(Sequence, IlluminationDropsAtTheChangeFrame) {
  const int count = 12;
  const Sequence s = MakeSequence(SequenceKind::kIllumination, count, kSeed);
  EXPECT_GT(s.options.illumination_gradient, 0.0);
  const int change = count / 2;
  for (int i = 0; i < count; ++i) {
    EXPECT_EQ(s.frames[i].effects.gain == 1.0, i < change) << "frame " << i;
  }
  const SceneRenderer renderer(s.target, s.options);
  const auto render = [&](int i) {
    return renderer.Render(s.frames[i].cMo, s.frames[i].noise_seed, s.frames[i].effects);
  };
  const double before = MeanGrey(render(change - 1).image);
  const double after = MeanGrey(render(change).image);
  EXPECT_LT(after, 0.7 * before) << before << " -> " << after;
  // The frames before the change differ only by the slow motion.
  EXPECT_NEAR(MeanGrey(render(change - 2).image), before, 0.05 * before);
}

TEST(LineDisplacement, PerpendicularDistanceOnly) {
  TruthLine a;
  a.visible = true;
  a.end_a = {100.0, 0.0};
  a.end_b = {100.0, 479.0};
  TruthLine b = a;
  b.distorted_fit = LineParams{103.0, 0.0};  // u = 103
  EXPECT_NEAR(LineDisplacementPx(a, b), 3.0, 1e-12);
  b.distorted_fit = LineParams{100.0, 0.0};
  EXPECT_NEAR(LineDisplacementPx(a, b), 0.0, 1e-12);
  b.visible = false;
  EXPECT_TRUE(std::isnan(LineDisplacementPx(a, b)));
}

}  // namespace
}  // namespace oal
