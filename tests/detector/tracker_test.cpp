#include "detector/tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "base/angles.h"
#include "scene/scene.h"
#include "test_images.h"

namespace oal {
namespace {

// A small two- or four-line scene whose camera slides sideways by `shift_m` per frame.
class TrackerScene {
 public:
  explicit TrackerScene(const char* target) : renderer_(TargetByName(target), Options()) {}

  static RenderOptions Options() {
    RenderOptions options;
    options.width = 320;
    options.height = 240;
    options.camera = vpCameraParameters(300.0, 300.0, 159.5, 119.5);
    options.noise_sigma = 3.0;
    options.blur_sigma_px = 0.8;
    return options;
  }

  // Camera 0.6 m in front of the board, rolled by `roll_deg`, moved by x_m along its x axis.
  RenderedFrame Frame(double x_m, std::uint64_t seed, double roll_deg = 20.0) const {
    const vpHomogeneousMatrix cMo(x_m, 0.01, 0.6, 0.0, 0.0, roll_deg * kRadPerDeg);
    return renderer_.Render(cMo, seed);
  }

 private:
  SceneRenderer renderer_;
};

// The track whose line is closest to `truth`, or nullptr.
const TrackedLine* Near(const OalLineTracker& tracker, const LineParams& truth) {
  const TrackedLine* best = nullptr;
  double best_distance = 1e9;
  for (const TrackedLine& track : tracker.getLines()) {
    if (track.status == TrackStatus::kLost) continue;
    const double distance = AngleBetween(track.line.line, truth) / kRadPerDeg +
                            std::fabs(RhoAlignedTo(truth, track.line.line) - truth.rho_px);
    if (distance < best_distance) {
      best_distance = distance;
      best = &track;
    }
  }
  return best_distance < 3.0 ? best : nullptr;
}

TEST(OalLineTracker, InitTrackingDetectsWithoutClicks) {
  const TrackerScene scene("four-line");
  OalLineTracker tracker;
  tracker.initTracking(scene.Frame(0.0, 1).image);
  EXPECT_EQ(tracker.count(TrackStatus::kNew), 4);
  EXPECT_EQ(tracker.getLines().size(), 4u);
  for (const TrackedLine& track : tracker.getLines()) EXPECT_EQ(track.frames_seen, 1);
}

// Sideways motion x(frame): every target line keeps one id over the whole sequence.
template <typename Motion>
void ExpectStableIdentities(Motion x_of_frame) {
  const TrackerScene scene("four-line");
  OalLineTracker tracker;
  std::map<int, int> id_of_truth;  // truth line index -> track id
  for (int frame = 0; frame < 12; ++frame) {
    const RenderedFrame rendered = scene.Frame(x_of_frame(frame), 100 + frame);
    if (frame == 0) {
      tracker.initTracking(rendered.image);
    } else {
      tracker.track(rendered.image);
    }
    for (const TruthLine& truth : rendered.truth) {
      const TrackedLine* track = Near(tracker, truth.ideal);
      ASSERT_NE(track, nullptr) << "frame " << frame << " line " << truth.index;
      const auto [it, inserted] = id_of_truth.emplace(truth.index, track->id);
      EXPECT_EQ(track->id, it->second) << "frame " << frame << " line " << truth.index;
      if (frame > 0) {
        EXPECT_EQ(track->status, TrackStatus::kTracked);
      }
    }
  }
  EXPECT_EQ(id_of_truth.size(), 4u);
}

TEST(OalLineTracker, KeepsIdentitiesUnderSlowMotion) {
  ExpectStableIdentities([](int frame) { return -0.03 + 0.001 * frame; });  // 0.5 px/frame
}

TEST(OalLineTracker, KeepsIdentitiesUnderFastMotion) {
  // Back and forth, up to ~25 px per frame at this scale (px = 300, 0.6 m).
  ExpectStableIdentities([](int frame) { return 0.06 * std::sin(0.9 * frame); });
}

TEST(OalLineTracker, LinesLostOnABlankFrameComeBackWithTheirIds) {
  const TrackerScene scene("two-line");
  OalLineTracker tracker;
  const RenderedFrame first = scene.Frame(0.0, 1);
  tracker.initTracking(first.image);
  ASSERT_EQ(tracker.getLines().size(), 2u);
  const int id0 = Near(tracker, first.truth[0].ideal)->id;
  const int id1 = Near(tracker, first.truth[1].ideal)->id;

  testing::TestImage blank(320, 240, 200);
  vpImage<unsigned char> blank_image(240, 320);
  std::copy(blank.pixels.begin(), blank.pixels.end(), blank_image.bitmap);
  tracker.track(blank_image);
  EXPECT_EQ(tracker.count(TrackStatus::kLost), 2);
  tracker.track(blank_image);
  EXPECT_EQ(tracker.getLines()[0].frames_lost, 2);

  const RenderedFrame again = scene.Frame(0.002, 2);
  tracker.track(again.image);
  EXPECT_EQ(tracker.count(TrackStatus::kTracked), 2);
  EXPECT_EQ(Near(tracker, again.truth[0].ideal)->id, id0);
  EXPECT_EQ(Near(tracker, again.truth[1].ideal)->id, id1);
}

TEST(OalLineTracker, LostTracksAreDroppedAfterMaxLostFrames) {
  const TrackerScene scene("two-line");
  TrackerOptions options;
  options.max_lost_frames = 2;
  OalLineTracker tracker(options);
  tracker.initTracking(scene.Frame(0.0, 1).image);
  vpImage<unsigned char> blank(240, 320, 200);
  for (int i = 0; i < 3; ++i) tracker.track(blank);
  EXPECT_TRUE(tracker.getLines().empty());
  tracker.track(scene.Frame(0.0, 3).image);  // re-detects by itself, with new ids
  ASSERT_EQ(tracker.getLines().size(), 2u);
  for (const TrackedLine& track : tracker.getLines()) {
    EXPECT_EQ(track.status, TrackStatus::kNew);
    EXPECT_GE(track.id, 2);
  }
}

TEST(TrackedLine, VispMeLineConvention) {
  TrackedLine track;
  track.line.line = Normalized(120.0, 0.3);  // u cos + v sin = rho
  const double rho = track.getRho(), theta = track.getTheta();
  double a = 0.0, b = 0.0, c = 0.0;
  track.getEquationParam(a, b, c);
  for (double t : {-50.0, 0.0, 80.0}) {
    const double u = 120.0 * std::cos(0.3) - t * std::sin(0.3);
    const double v = 120.0 * std::sin(0.3) + t * std::cos(0.3);
    const double i = v, j = u;  // vpMeLine: i = row, j = column
    EXPECT_NEAR(i * std::cos(theta) + j * std::sin(theta) - rho, 0.0, 1e-9);
    EXPECT_NEAR(a * i + b * j + c, 0.0, 1e-9);
  }
}

TEST(OalLineTracker, IntersectionOfTwoTrackedLines) {
  TrackedLine vertical, horizontal;
  vertical.line.line = LineParams{40.0, 0.0};
  horizontal.line.line = LineParams{25.0, kPi / 2.0};
  vpImagePoint ip;
  ASSERT_TRUE(OalLineTracker::intersection(vertical, horizontal, ip));
  EXPECT_NEAR(ip.get_u(), 40.0, 1e-9);
  EXPECT_NEAR(ip.get_v(), 25.0, 1e-9);
  EXPECT_FALSE(OalLineTracker::intersection(vertical, vertical, ip));
}

TEST(TrackerOptions, CheckNamesTheField) {
  TrackerOptions options;
  options.gate_offset_px = -1.0;
  EXPECT_THROW(OalLineTracker tracker(options), std::invalid_argument);
  try {
    options.Check();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("gate_offset_px = -1"), std::string::npos);
  }
}

}  // namespace
}  // namespace oal

namespace oal {
namespace {

// Step 1 of the tracker's identity: a seed collects the votes of a line that barely moved.
TEST(OalDetector, SeededEntryCarriesItsIdToTheLineThatGrewFromIt) {
  testing::TestImage image(320, 240, 210);
  const LineParams truth{140.0, 0.4};
  testing::PaintStripe(&image, truth, 6.0, 30);
  OalDetector detector;
  const std::vector<LineSeed> seeds = {{7, LineParams{141.5, 0.41}},  // the line, moved a bit
                                       {9, LineParams{10.0, 2.0}}};   // a line that is gone
  const auto& lines = detector.Detect(image.View(), seeds);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].seed_id, 7);
  EXPECT_NEAR(lines[0].line.rho_px, truth.rho_px, 0.3);  // the refit forgets the seed's offset
  EXPECT_EQ(detector.Detect(image.View()).front().seed_id, -1);
}

TEST(OalLineTracker, SeededLinesKeepTheirIdsWithoutTheGate) {
  const TrackerScene scene("two-line");
  TrackerOptions options;
  options.gate_offset_px = 0.5;  // association by gate alone would lose them
  options.gate_angle_deg = 0.05;
  OalLineTracker tracker(options);
  tracker.initTracking(scene.Frame(0.0, 1).image);
  ASSERT_EQ(tracker.getLines().size(), 2u);
  for (int frame = 1; frame < 6; ++frame) {
    tracker.track(scene.Frame(0.002 * frame, frame).image);  // 1 px per frame
    EXPECT_EQ(tracker.count(TrackStatus::kTracked), 2) << "frame " << frame;
    EXPECT_EQ(tracker.count(TrackStatus::kNew), 0) << "frame " << frame;
  }
}

}  // namespace
}  // namespace oal

namespace oal {
namespace {

TEST(OalLineTracker, NewLinesReplaceTheLongestLostTracksWhenFull) {
  const TrackerScene scene("two-line");
  TrackerOptions options;
  options.max_tracks = 2;
  OalLineTracker tracker(options);
  tracker.initTracking(scene.Frame(0.0, 1).image);
  ASSERT_EQ(tracker.getLines().size(), 2u);
  // The board rolled by 90 deg: two lines far outside every gate.
  tracker.track(scene.Frame(0.0, 2, 110.0).image);
  ASSERT_EQ(tracker.getLines().size(), 2u);
  EXPECT_EQ(tracker.count(TrackStatus::kNew), 2);
  for (const TrackedLine& track : tracker.getLines()) EXPECT_GE(track.id, 2);
}

}  // namespace
}  // namespace oal
