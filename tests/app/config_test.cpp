#include "app/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "io/camera_file.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// The message of the std::runtime_error `yaml` raises, or "" if it loads.
std::string ErrorOf(const std::string& yaml) {
  return test::ConfigErrorOf(yaml, "cfg.yaml");
}

void ExpectSameOptions(const DetectorOptions& a, const DetectorOptions& b) {
  EXPECT_EQ(a.start_px, b.start_px);
  EXPECT_EQ(a.step_px, b.step_px);
  EXPECT_EQ(a.polarity, b.polarity);
  EXPECT_EQ(a.threshold_mode, b.threshold_mode);
  EXPECT_EQ(a.fixed_threshold, b.fixed_threshold);
  EXPECT_EQ(a.min_contrast, b.min_contrast);
  EXPECT_EQ(a.min_relative_contrast, b.min_relative_contrast);
  EXPECT_EQ(a.min_width_px, b.min_width_px);
  EXPECT_EQ(a.max_width_px, b.max_width_px);
  EXPECT_EQ(a.min_crossing_angle_deg, b.min_crossing_angle_deg);
  EXPECT_EQ(a.max_points_per_border, b.max_points_per_border);
  EXPECT_EQ(a.skip_same_side_pairs, b.skip_same_side_pairs);
  EXPECT_EQ(a.max_pair_width_ratio, b.max_pair_width_ratio);
  EXPECT_EQ(a.angle_change_deg, b.angle_change_deg);
  EXPECT_EQ(a.r_change_px, b.r_change_px);
  EXPECT_EQ(a.max_lines, b.max_lines);
  EXPECT_EQ(a.count_visible_borders_only, b.count_visible_borders_only);
  EXPECT_EQ(a.refit_lines, b.refit_lines);
  EXPECT_EQ(a.rank_by_support, b.rank_by_support);
  EXPECT_EQ(a.support_tolerance_px, b.support_tolerance_px);
  EXPECT_EQ(a.max_output_lines, b.max_output_lines);
  EXPECT_EQ(a.min_votes, b.min_votes);
  EXPECT_EQ(a.min_support, b.min_support);
  EXPECT_EQ(a.duplicate_angle_deg, b.duplicate_angle_deg);
  EXPECT_EQ(a.duplicate_r_px, b.duplicate_r_px);
}

TEST(Config, EmptyFileKeepsTheBase) {
  ExpectSameOptions(ParseConfig("", "cfg.yaml").detector, DetectorOptions());
  ExpectSameOptions(ParseConfig("detector:\n", "cfg.yaml").detector, DetectorOptions());
  AppConfig paper;
  paper.detector = DetectorOptions::Paper();
  ExpectSameOptions(ParseConfig("# nothing\n", "cfg.yaml", paper).detector, paper.detector);
}

TEST(Config, ReadsEveryKey) {
  const AppConfig config = ParseConfig(
      "detector:\n"
      "  start_px: 4\n  step_px: 3\n  polarity: edges\n  threshold_mode: fixed\n"
      "  fixed_threshold: 100\n  min_contrast: 20\n  min_relative_contrast: 0.25\n"
      "  min_width_px: 1.5\n  max_width_px: 30\n"
      "  min_crossing_angle_deg: 20\n  max_points_per_border: 16\n"
      "  skip_same_side_pairs: false\n  max_pair_width_ratio: 2.5\n  angle_change_deg: 1.5\n  "
      "r_change_px: 3.5\n"
      "  max_lines: 30\n  count_visible_borders_only: false\n  refit_lines: false\n"
      "  rank_by_support: false\n  support_tolerance_px: 2.5\n  max_output_lines: 5\n"
      "  min_votes: 4\n  min_support: 8\n  duplicate_angle_deg: 4\n  duplicate_r_px: 9\n",
      "cfg.yaml");
  const DetectorOptions& o = config.detector;
  EXPECT_EQ(o.start_px, 4);
  EXPECT_EQ(o.step_px, 3);
  EXPECT_EQ(o.polarity, Polarity::kEdges);
  EXPECT_EQ(o.threshold_mode, ThresholdMode::kFixed);
  EXPECT_EQ(o.fixed_threshold, 100);
  EXPECT_EQ(o.min_contrast, 20);
  EXPECT_EQ(o.min_relative_contrast, 0.25);
  EXPECT_EQ(o.min_width_px, 1.5);
  EXPECT_EQ(o.max_width_px, 30.0);
  EXPECT_EQ(o.min_crossing_angle_deg, 20.0);
  EXPECT_EQ(o.max_points_per_border, 16);
  EXPECT_FALSE(o.skip_same_side_pairs);
  EXPECT_EQ(o.max_pair_width_ratio, 2.5);
  EXPECT_EQ(o.angle_change_deg, 1.5);
  EXPECT_EQ(o.r_change_px, 3.5);
  EXPECT_EQ(o.max_lines, 30);
  EXPECT_FALSE(o.count_visible_borders_only);
  EXPECT_FALSE(o.refit_lines);
  EXPECT_FALSE(o.rank_by_support);
  EXPECT_EQ(o.support_tolerance_px, 2.5);
  EXPECT_EQ(o.max_output_lines, 5);
  EXPECT_EQ(o.min_votes, 4);
  EXPECT_EQ(o.min_support, 8);
  EXPECT_EQ(o.duplicate_angle_deg, 4.0);
  EXPECT_EQ(o.duplicate_r_px, 9.0);
}

TEST(Config, PaperIsTheBaseWhereverItIsWritten) {
  const DetectorOptions o =
      ParseConfig("detector:\n  step_px: 7\n  paper: true\n", "cfg.yaml").detector;
  DetectorOptions expected = DetectorOptions::Paper();
  expected.step_px = 7;
  ExpectSameOptions(o, expected);

  AppConfig paper;
  paper.detector = DetectorOptions::Paper();
  ExpectSameOptions(ParseConfig("detector: {paper: false}\n", "cfg.yaml", paper).detector,
                    DetectorOptions());
}

TEST(Config, ShippedFilesAreTheDefaultsAndThePaper) {
  const std::string dir = std::string(OAL_SOURCE_DIR) + "/config/";
  ExpectSameOptions(LoadConfig(dir + "detector.yaml").detector, DetectorOptions());
  ExpectSameOptions(LoadConfig(dir + "paper.yaml").detector, DetectorOptions::Paper());
  EXPECT_EQ(LoadConfig(dir + "visp_line_edges.yaml").detector.polarity, Polarity::kEdges);
}

TEST(Config, UnknownKeyNamesFileLineKeyAndTheKnownKeys) {
  const std::string error = ErrorOf("detector:\n  step_px: 5\n  stepp_px: 3\n");
  EXPECT_THAT(error, HasSubstr("cfg.yaml:3: key 'detector.stepp_px' is unknown (known: "));
  EXPECT_THAT(error, HasSubstr("step_px"));
  EXPECT_THAT(error, HasSubstr("duplicate_r_px"));
}

TEST(Config, WrongTypeNamesFileLineAndField) {
  EXPECT_EQ(ErrorOf("detector:\n  step_px: abc\n"),
            "cfg.yaml:2: 'detector.step_px' must be an integer, got 'abc'");
  EXPECT_EQ(ErrorOf("detector:\n\n  step_px: 2.5\n"),
            "cfg.yaml:3: 'detector.step_px' must be an integer, got '2.5'");
  EXPECT_EQ(ErrorOf("detector:\n  r_change_px: far\n"),
            "cfg.yaml:2: 'detector.r_change_px' must be a number, got 'far'");
  EXPECT_EQ(ErrorOf("detector:\n  refit_lines: 2\n"),
            "cfg.yaml:2: 'detector.refit_lines' must be true or false, got '2'");
  EXPECT_EQ(ErrorOf("detector:\n  polarity: grey\n"),
            "cfg.yaml:2: 'detector.polarity' must be one of dark, light, edges, got 'grey'");
  EXPECT_EQ(ErrorOf("detector:\n  threshold_mode: [otsu]\n"),
            "cfg.yaml:2: 'detector.threshold_mode' must be one of fixed, otsu, got 'a sequence'");
  EXPECT_EQ(ErrorOf("detector:\n  paper: maybe\n"),
            "cfg.yaml:2: 'detector.paper' must be true or false, got 'maybe'");
}

TEST(Config, OutOfRangeValueNamesFileLineAndField) {
  const std::string error = ErrorOf("detector:\n  start_px: 5\n  step_px: 0\n");
  EXPECT_THAT(error, HasSubstr("cfg.yaml:3: 'detector.step_px' is invalid: "));
  EXPECT_THAT(error, HasSubstr("1 <= step_px <= 1000"));
  EXPECT_THAT(ErrorOf("detector:\n  min_relative_contrast: 1.5\n"),
              HasSubstr("cfg.yaml:2: 'detector.min_relative_contrast' is invalid"));
  // A constraint between two fields: the line of the field Check() names, if the file set it.
  EXPECT_THAT(ErrorOf("detector:\n  min_width_px: 10\n  max_width_px: 5\n"),
              HasSubstr("cfg.yaml:3: 'detector.max_width_px' is invalid"));
  EXPECT_THAT(ErrorOf("tracking:\n  tracked_borders: 8\n  quick_max_identification_cost: -1\n"),
              HasSubstr("cfg.yaml:3: 'tracking.quick_max_identification_cost' is invalid"));
  EXPECT_THAT(ErrorOf("tracking:\n  quick_max_identification_cost: cheap\n"),
              HasSubstr("cfg.yaml:2: 'tracking.quick_max_identification_cost' must be a number"));
  EXPECT_THAT(ErrorOf("pose:\n  previous_accept_px: 0.5\n  homography_accept_px: -0.5\n"),
              HasSubstr("cfg.yaml:3: 'pose.homography_accept_px' is invalid"));
  EXPECT_THAT(ErrorOf("pose:\n  homography_accept_px: [0.5]\n"),
              HasSubstr("cfg.yaml:2: 'pose.homography_accept_px' must be a number"));
  const std::string above_default_max = std::to_string(DetectorOptions().max_width_px + 1.0);
  EXPECT_THAT(ErrorOf("detector:\n  min_width_px: " + above_default_max + "\n"),
              HasSubstr("cfg.yaml: section 'detector' is invalid: detector.max_width_px = "));
}

TEST(Config, SectionsOtherThanTheKnownOnesAreRejected) {
  EXPECT_EQ(ErrorOf("detector: {}\ndetectr:\n  step_px: 5\n"),
            "cfg.yaml:2: section 'detectr' is unknown (known: detector, target, pose, camera, "
            "robot, servo, goal, target_pose, source, output, tracking, scene)");
  EXPECT_EQ(ErrorOf("render:\n  gain: 0.5\n"),
            "cfg.yaml:1: section 'render' is not supported by this version of oalservo "
            "(supported: detector, target, pose, camera, robot, servo, goal, target_pose, source, "
            "output, tracking, scene)");
  EXPECT_THAT(ErrorOf("- detector\n"), HasSubstr("cfg.yaml:1: the top level must be a map"));
  EXPECT_THAT(ErrorOf("detector: 5\n"), HasSubstr("cfg.yaml:1: section 'detector' must be a map"));
}

TEST(Config, RepeatedKeysAreRejected) {
  EXPECT_EQ(ErrorOf("detector:\n  step_px: 5\n  start_px: 1\n  step_px: 6\n"),
            "cfg.yaml:4: key 'detector.step_px' is repeated (first at line 2)");
}

TEST(Config, SyntaxErrorNamesFileAndLine) {
  // An unclosed bracket on the last line: that line, not the one past the end of the file.
  EXPECT_THAT(ErrorOf("detector:\n  step_px: 5\n  polarity: [dark\n"),
              HasSubstr("cfg.yaml:3: YAML syntax error"));
  EXPECT_THAT(ErrorOf("detector:\n  step_px: 5\n  polarity: [dark\n"),
              HasSubstr("(at the end of the file)"));
  // A bad indentation inside the file: its own line.
  EXPECT_THAT(ErrorOf("detector:\n  step_px: 5\n polarity: dark\n"),
              HasSubstr("cfg.yaml:3: YAML syntax error"));
}

TEST(Config, LoadConfigNamesTheFile) {
  test::TestDir dir;
  EXPECT_THROW(
      {
        try {
          LoadConfig(dir / "missing.yaml");
        } catch (const std::runtime_error& error) {
          EXPECT_THAT(error.what(), HasSubstr("missing.yaml"));
          throw;
        }
      },
      std::runtime_error);
  test::WriteText(dir / "bad.yaml", "detector:\n  bogus: 1\n");
  try {
    LoadConfig(dir / "bad.yaml");
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr(dir / "bad.yaml:2: key 'detector.bogus' is unknown"));
  }
}

// ------------------------------------------------------------------------------------------
// scene: a lived-in scene's conditions

TEST(ConfigTracking, TheStripeFitAndTheModelCheckKeys) {
  const AppConfig config = ParseConfig(
      "tracking:\n  fit_stripes: false\n  min_stripe_seen: 0.5\n  stripe_tolerance_px: 2\n"
      "  stripe_tolerance_fraction: 0.2\n  stripe_width_tolerance: 0.4\n",
      "cfg.yaml");
  EXPECT_FALSE(config.tracking.fit_stripes);
  EXPECT_EQ(config.tracking.min_stripe_seen, 0.5);
  EXPECT_EQ(config.tracking.StripeCheck().centre_tolerance_px, 2.0);
  EXPECT_EQ(config.tracking.StripeCheck().centre_tolerance_fraction, 0.2);
  EXPECT_EQ(config.tracking.StripeCheck().width_tolerance, 0.4);
  EXPECT_THAT(ErrorOf("tracking:\n  stripe_tolerance_fraction: 2\n"),
              HasSubstr("cfg.yaml:2: 'tracking.stripe_tolerance_fraction' is invalid: 2"));
  EXPECT_THAT(ErrorOf("tracking:\n  min_stripe_seen: -0.1\n"),
              HasSubstr("cfg.yaml:2: 'tracking.min_stripe_seen' is invalid"));
  EXPECT_THAT(ErrorOf("tracking:\n  fit_stripes: maybe\n"),
              HasSubstr("cfg.yaml:2: 'tracking.fit_stripes' must be true or false"));
}

// The sheet finder's contrast, in grey levels and in proportion to a dim frame's paper.
TEST(ConfigTracking, TheSheetFindersContrastKeys) {
  const AppConfig config = ParseConfig(
      "tracking:\n  finder:\n    min_contrast: 25\n    min_relative_contrast: 0.1\n", "cfg.yaml");
  EXPECT_EQ(config.tracking.finder.min_contrast, 25);
  EXPECT_EQ(config.tracking.finder.min_relative_contrast, 0.1);
  EXPECT_THAT(ErrorOf("tracking:\n  finder:\n    min_relative_contrast: 1.5\n"),
              HasSubstr("cfg.yaml:3: 'tracking.finder.min_relative_contrast' is invalid: 1.5"));
}

// Where the tracker looks when no middle or edge cell gives a pose.
TEST(ConfigTracking, TheCornerCellsAndTheImageFallbackKeys) {
  EXPECT_TRUE(ParseConfig("tracking:\n  max_candidates: 3\n", "cfg.yaml").tracking.corner_cells);
  const AppConfig config =
      ParseConfig("tracking:\n  corner_cells: false\n  image_fallback: false\n", "cfg.yaml");
  EXPECT_FALSE(config.tracking.corner_cells);
  EXPECT_FALSE(config.tracking.image_fallback);
  EXPECT_THAT(ErrorOf("tracking:\n  corner_cells: 2\n"),
              HasSubstr("cfg.yaml:2: 'tracking.corner_cells' must be true or false"));
}

// The settings in pixels and the focal length they are given for; a region's sample step.
TEST(ConfigTracking, TheReferenceFocalLengthAndTheRegionSampleStep) {
  const AppConfig config = ParseConfig(
      "tracking:\n  reference_focal_px: 914\ndetector:\n  region_sample_step: 3\n", "cfg.yaml");
  EXPECT_EQ(config.tracking.reference_focal_px, 914.0);
  EXPECT_EQ(config.detector.region_sample_step, 3);
  EXPECT_THAT(ErrorOf("tracking:\n  reference_focal_px: 0.5\n"),
              HasSubstr("cfg.yaml:2: 'tracking.reference_focal_px' is invalid: 0.5"));
  EXPECT_THAT(ErrorOf("tracking:\n  reference_focal_px: wide\n"),
              HasSubstr("cfg.yaml:2: 'tracking.reference_focal_px'"));
  EXPECT_THAT(ErrorOf("detector:\n  region_sample_step: 0\n"),
              HasSubstr("cfg.yaml:2: 'detector.region_sample_step' is invalid: 0"));
}

TEST(ConfigScene, ReadsTheLivedInConditions) {
  const AppConfig config = ParseConfig(
      "scene:\n"
      "  occluders: {fraction: 0.6, kinds: [hand, pen], grey: [40, 200], texture_grey: 8,\n"
      "              shadow_darkness: 0.2}\n"
      "  glare: {fraction: 0.4, sigma_m: [0.01, 0.02], peak_grey: [300, 400]}\n"
      "  exposure: {fraction: 0.3, gain: [0.4, 1.6]}\n"
      "  motion_blur: {fraction: 0.5, length_px: [2, 10]}\n"
      "  jpeg: {fraction: 0.25, quality: [50, 80]}\n",
      "cfg.yaml");
  const LivedInOptions& lived_in = config.scene.lived_in;
  EXPECT_EQ(lived_in.occluders.fraction, 0.6);
  ASSERT_EQ(lived_in.occluders.kinds.size(), 2u);
  EXPECT_EQ(lived_in.occluders.kinds[1], OccluderKind::kPen);
  EXPECT_EQ(lived_in.occluders.grey.hi, 200.0);
  EXPECT_EQ(lived_in.occluders.texture_grey, 8.0);
  EXPECT_EQ(lived_in.occluders.shadow_darkness, 0.2);
  EXPECT_EQ(lived_in.glare.sigma_m.lo, 0.01);
  EXPECT_EQ(lived_in.glare.peak_grey.hi, 400.0);
  EXPECT_EQ(lived_in.exposure.gain.lo, 0.4);
  EXPECT_EQ(lived_in.motion_blur.length_px.hi, 10.0);
  EXPECT_EQ(lived_in.jpeg.fraction, 0.25);
  EXPECT_EQ(lived_in.jpeg.quality.lo, 50.0);
  EXPECT_FALSE(AppConfig().scene.lived_in.Any());
}

TEST(ConfigScene, TheShippedLivedInSceneLoads) {
  const AppConfig config = LoadConfig(std::string(OAL_SOURCE_DIR) + "/config/scene-lived-in.yaml");
  EXPECT_EQ(config.scene.lived_in.occluders.fraction, 0.6);
  EXPECT_EQ(config.scene.lived_in.glare.fraction, 0.4);
  EXPECT_EQ(config.scene.lived_in.exposure.fraction, 0.3);
  EXPECT_EQ(config.scene.lived_in.motion_blur.fraction, 0.5);
  EXPECT_EQ(config.scene.lived_in.jpeg.fraction, 0.5);
}

TEST(ConfigScene, TheShippedOccludedSceneHasAnOccluderInEveryFrameAndNothingElse) {
  const AppConfig config = LoadConfig(std::string(OAL_SOURCE_DIR) + "/config/scene-occluded.yaml");
  const LivedInOptions& lived_in = config.scene.lived_in;
  EXPECT_EQ(lived_in.occluders.fraction, 1.0);
  EXPECT_EQ(lived_in.occluders.kinds.size(), 4u);
  EXPECT_EQ(lived_in.glare.fraction, 0.0);
  EXPECT_EQ(lived_in.exposure.fraction, 0.0);
  EXPECT_EQ(lived_in.motion_blur.fraction, 0.0);
  EXPECT_EQ(lived_in.jpeg.fraction, 0.0);
  EXPECT_TRUE(config.scene.annotations);
}

TEST(ConfigScene, BadLivedInValuesNameFileLineAndKey) {
  EXPECT_THAT(ErrorOf("scene:\n  glare:\n    sigma_m: [0.01, 0.02]\n    fraction: 1.5\n"),
              HasSubstr("cfg.yaml:4: 'scene.glare.fraction' is invalid: 1.5"));
  EXPECT_THAT(ErrorOf("scene:\n  jpeg:\n    quality: [40]\n"),
              HasSubstr("cfg.yaml:3: 'scene.jpeg.quality' must be a range [lo, hi] of two "
                        "numbers, got 'a sequence of 1'"));
  EXPECT_THAT(ErrorOf("scene:\n  jpeg:\n    quality: [90, 40]\n"),
              HasSubstr("cfg.yaml:3: 'scene.jpeg.quality' is invalid"));
  EXPECT_THAT(ErrorOf("scene:\n  occluders:\n    kinds: [hand, foot]\n"),
              HasSubstr("cfg.yaml:3: 'scene.occluders.kinds[1]' must be one of hand, pen, cable, "
                        "tool, got 'foot'"));
  EXPECT_THAT(ErrorOf("scene:\n  occluders:\n    kinds: []\n"),
              HasSubstr("cfg.yaml:3: 'scene.occluders.kinds' must be a sequence of kinds"));
  EXPECT_THAT(ErrorOf("scene:\n  motion_blur:\n    length_px: [3, fast]\n"),
              HasSubstr("cfg.yaml:3: 'scene.motion_blur.length_px[1]' must be a number"));
  EXPECT_THAT(ErrorOf("scene:\n  exposure: 0.3\n"),
              HasSubstr("cfg.yaml:2: 'scene.exposure' must be a map of keys"));
  EXPECT_THAT(ErrorOf("scene:\n  glare:\n    strength: 3\n"),
              HasSubstr("cfg.yaml:3: key 'scene.glare.strength' is unknown (known: fraction, "
                        "sigma_m, peak_grey)"));
}

// ------------------------------------------------------------------------------------------
// target:

void ExpectSameTarget(const LineTarget& a, const LineTarget& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.board_width_m, b.board_width_m);
  EXPECT_EQ(a.board_height_m, b.board_height_m);
  EXPECT_EQ(a.board_grey, b.board_grey);
  EXPECT_EQ(a.line_grey, b.line_grey);
  ASSERT_EQ(a.lines.size(), b.lines.size());
  for (std::size_t i = 0; i < a.lines.size(); ++i) {
    SCOPED_TRACE("line " + std::to_string(i + 1));
    EXPECT_EQ(a.lines[i].x1_m, b.lines[i].x1_m);
    EXPECT_EQ(a.lines[i].y1_m, b.lines[i].y1_m);
    EXPECT_EQ(a.lines[i].x2_m, b.lines[i].x2_m);
    EXPECT_EQ(a.lines[i].y2_m, b.lines[i].y2_m);
    EXPECT_EQ(a.lines[i].width_m, b.lines[i].width_m);
  }
}

TEST(ConfigTarget, DefaultIsTheA3SheetAndSectionsReplaceIt) {
  ExpectSameTarget(ParseConfig("", "cfg.yaml").target, FourLineA3Target());
  ExpectSameTarget(ParseConfig("target:\n", "cfg.yaml").target, FourLineA3Target());
  ExpectSameTarget(ParseConfig("target: {name: two-line}\n", "cfg.yaml").target, TwoLineTarget());
  ExpectSameTarget(ParseConfig("target:\n  name: four-line\n", "cfg.yaml").target,
                   FourLineTarget());
}

TEST(ConfigTarget, ShippedFilesAreExactlyTheBuiltInTargets) {
  const std::string dir = std::string(OAL_SOURCE_DIR) + "/config/";
  ExpectSameTarget(LoadConfig(dir + "four-line-board.yaml").target, FourLineTarget());
  ExpectSameTarget(LoadConfig(dir + "two-line-target.yaml").target, TwoLineTarget());
  // The sheet targets: the built-in computes each stripe's end as half the sheet less the
  // 10 mm margin in binary floating point (0.5 * 0.420 - 0.010 = 0.19999999999999998), the
  // file writes the decimal (0.200); the two differ in the last bit only, so the ends are
  // compared to 1e-12 m (a picometre) and everything else exactly.
  const auto expect_same_sheet = [](const LineTarget& file, const LineTarget& built_in) {
    constexpr double kLastBitM = 1e-12;
    EXPECT_EQ(file.name, built_in.name);
    EXPECT_EQ(file.board_width_m, built_in.board_width_m);
    EXPECT_EQ(file.board_height_m, built_in.board_height_m);
    EXPECT_EQ(file.board_grey, built_in.board_grey);
    EXPECT_EQ(file.line_grey, built_in.line_grey);
    ASSERT_EQ(file.lines.size(), built_in.lines.size());
    for (std::size_t i = 0; i < file.lines.size(); ++i) {
      SCOPED_TRACE(built_in.name + " line " + std::to_string(i + 1));
      EXPECT_NEAR(file.lines[i].x1_m, built_in.lines[i].x1_m, kLastBitM);
      EXPECT_NEAR(file.lines[i].y1_m, built_in.lines[i].y1_m, kLastBitM);
      EXPECT_NEAR(file.lines[i].x2_m, built_in.lines[i].x2_m, kLastBitM);
      EXPECT_NEAR(file.lines[i].y2_m, built_in.lines[i].y2_m, kLastBitM);
      EXPECT_EQ(file.lines[i].width_m, built_in.lines[i].width_m);
    }
  };
  expect_same_sheet(LoadConfig(dir + "four-line-a3.yaml").target, FourLineA3Target());
  expect_same_sheet(LoadConfig(dir + "four-line-a4.yaml").target, FourLineA4Target());
  expect_same_sheet(LoadConfig(dir + "four-line-letter.yaml").target, FourLineLetterTarget());
  // They leave the detector alone.
  ExpectSameOptions(LoadConfig(dir + "four-line-board.yaml").detector, DetectorOptions());
}

TEST(ConfigTarget, ReadsAFullDescription) {
  const LineTarget target = ParseConfig(
                                "detector: {step_px: 4}\n"
                                "target:\n"
                                "  name: desk\n"
                                "  board_width_m: 0.4\n"
                                "  board_height_m: 0.3\n"
                                "  line_grey: 0\n"
                                "  lines:\n"
                                "    - {from: [-0.1, -0.15], to: [-0.1, 0.15], width: 0.02}\n"
                                "    - from: [-0.2, 0.05]\n"
                                "      to: [0.2, 0]\n"
                                "      width: 1e-2\n",
                                "cfg.yaml")
                                .target;
  EXPECT_EQ(target.name, "desk");
  EXPECT_EQ(target.board_width_m, 0.4);
  EXPECT_EQ(target.board_height_m, 0.3);
  EXPECT_EQ(target.board_grey, LineTarget().board_grey);  // optional
  EXPECT_EQ(target.line_grey, 0);
  ASSERT_EQ(target.lines.size(), 2u);
  EXPECT_EQ(target.lines[1].x1_m, -0.2);
  EXPECT_EQ(target.lines[1].y1_m, 0.05);
  EXPECT_EQ(target.lines[1].x2_m, 0.2);
  EXPECT_EQ(target.lines[1].y2_m, 0.0);
  EXPECT_EQ(target.lines[1].width_m, 0.01);
  // A blank board.
  EXPECT_TRUE(
      ParseConfig("target: {name: b, board_width_m: 1, board_height_m: 1, lines: []}\n", "cfg.yaml")
          .target.lines.empty());
}

// A full description with `line` as the only entry of `lines:` (at file line 6).
std::string TargetWithLine(const std::string& line) {
  return "target:\n  name: t\n  board_width_m: 0.4\n  board_height_m: 0.3\n  lines:\n    - " +
         line + "\n";
}

TEST(ConfigTarget, MalformedLinesNameFileLineAndKey) {
  // The only entry of `lines:` and the message it raises.
  const struct {
    const char* line;
    const char* message;
  } kCases[] = {
      {"{from: [0, 0], to: [0, 0], width: 0.01}",
       "cfg.yaml:6: 'target.lines[0]' has from == to = [0, 0]: a line needs two different ends"},
      {"{from: [0, 0], to: [0.1, 0], width: 0}",
       "cfg.yaml:6: 'target.lines[0].width' must be > 0 (metres), got '0'"},
      {"{from: [0, 0], to: [0.1, 0], width: -0.01}",
       "cfg.yaml:6: 'target.lines[0].width' must be > 0 (metres), got '-0.01'"},
      {"{from: [0, 0], to: [0.25, 0], width: 0.01}",
       "cfg.yaml:6: 'target.lines[0].to' = [0.25, 0] lies outside the board (|x| <= 0.2, "
       "|y| <= 0.15 m: the board is centred on the origin)"},
      {"{from: [0, 0], to: [0.1], width: 0.01}",
       "cfg.yaml:6: 'target.lines[0].to' must be a point [x, y] in metres, got 'a sequence of 1'"},
      {"{from: [0, a], to: [0.1, 0], width: 0.01}",
       "cfg.yaml:6: 'target.lines[0].from[1]' must be a number, got 'a'"},
      {"{from: [0, .inf], to: [0.1, 0], width: 0.01}",
       "cfg.yaml:6: 'target.lines[0].from[1]' must be a finite number, got '.inf'"},
      {"{from: [0, 0], to: [0.1, 0]}",
       "cfg.yaml:6: 'target.lines[0]' has no 'width' (a line needs from, to, width)"},
      {"{from: [0, 0], to: [0.1, 0], width: 0.01, colour: 3}",
       "cfg.yaml:6: key 'target.lines[0].colour' is unknown (known: from, to, width)"},
      {"{from: [0, 0], to: [0.1, 0], from: [0, 0.1], width: 1}",
       "cfg.yaml:6: key 'target.lines[0].from' is repeated (first at line 6)"},
      {"[0, 0, 0.1, 0]",
       "cfg.yaml:6: 'target.lines[0]' must be a map {from: [x, y], to: [x, y], width: w}, got "
       "'a sequence'"},
  };
  for (const auto& c : kCases) EXPECT_EQ(ErrorOf(TargetWithLine(c.line)), c.message) << c.line;
  // The second entry, on its own line.
  EXPECT_EQ(ErrorOf(TargetWithLine("{from: [0, 0], to: [0.1, 0], width: 0.01}\n"
                                   "    - {from: [0, 0], to: [0.1, -0.2], width: 0.01}")),
            "cfg.yaml:7: 'target.lines[1].to' = [0.1, -0.2] lies outside the board (|x| <= 0.2, "
            "|y| <= 0.15 m: the board is centred on the origin)");
}

TEST(ConfigTarget, MalformedBoardNamesFileLineAndKey) {
  EXPECT_EQ(ErrorOf("target: {name: five-line}\n"),
            "cfg.yaml:1: 'target.name' = 'five-line' is not a shipped target (four-line-a3, "
            "four-line-a4, four-line-letter, four-line-board, two-line); describe it in full "
            "with board_width_m, board_height_m and lines");
  EXPECT_THAT(ErrorOf("target:\n  name: four-line\n  board_grey: 200\n"),
              HasSubstr("cfg.yaml:3: key 'target.board_grey' needs a full target description"));
  EXPECT_THAT(ErrorOf("target:\n  board_width_m: 1\n"),
              HasSubstr("cfg.yaml:2: key 'target.board_width_m' needs a full target description"));
  EXPECT_THAT(ErrorOf("target:\n  name: x\n  board_height_m: 1\n  lines: []\n"),
              HasSubstr("cfg.yaml:2: 'target.board_width_m' is missing"));
  EXPECT_THAT(ErrorOf("target:\n  board_width_m: 1\n  board_height_m: 1\n  lines: []\n"),
              HasSubstr("'target.name' is missing"));
  EXPECT_THAT(ErrorOf("target:\n  name: x\n  board_with_m: 1\n"),
              HasSubstr("cfg.yaml:3: key 'target.board_with_m' is unknown (known: name, "
                        "board_width_m, board_height_m, board_grey, line_grey, lines)"));
  EXPECT_EQ(ErrorOf("target:\n  name: x\n  board_width_m: wide\n"),
            "cfg.yaml:3: 'target.board_width_m' must be a number, got 'wide'");
  EXPECT_EQ(ErrorOf("target:\n  name: x\n  lines: 4\n"),
            "cfg.yaml:3: 'target.lines' must be a sequence of {from: [x, y], to: [x, y], width: "
            "w} ([] for none), got '4'");
  EXPECT_EQ(ErrorOf("target:\n  name: ''\n"), "cfg.yaml:2: 'target.name' must not be empty");
  EXPECT_EQ(ErrorOf("target: [four-line]\n"), "cfg.yaml:1: section 'target' must be a map of keys");
  // Out of range: LineTarget::Check(), at the line that set the field.
  const std::string board =
      ErrorOf("target:\n  name: x\n  board_width_m: -1\n  board_height_m: 1\n  lines: []\n");
  EXPECT_THAT(board, HasSubstr("cfg.yaml:3: 'target.board_width_m' is invalid: -1 (needs"));
  EXPECT_THAT(board, HasSubstr("board_width_m > 0"));
  EXPECT_THAT(ErrorOf("target:\n  name: x\n  board_width_m: 1\n  board_height_m: 1\n"
                      "  lines: []\n  line_grey: 300\n"),
              HasSubstr("cfg.yaml:6: 'target.line_grey' is invalid: 300 (needs 0 <= line_grey <= "
                        "255)"));
  // The board is checked before the lines against it.
  EXPECT_THAT(
      ErrorOf(TargetWithLine("{from: [0, 0], to: [0.1, 0], width: 0.01}") + "  board_grey: -5\n"),
      HasSubstr("'target.board_grey' is invalid"));
  EXPECT_EQ(ErrorOf("target:\n  name: x\n  name: y\n"),
            "cfg.yaml:3: key 'target.name' is repeated (first at line 2)");
}

}  // namespace
}  // namespace oal

namespace oal {
namespace {

using ::testing::HasSubstr;

// camera.file: the ViSP camera XML is the canonical form of the lens; a config names it
// (relative to the config's folder) instead of the inline keys.
TEST(ConfigCameraFile, TheFileGivesTheIntrinsicsAndTheImageSize) {
  const test::TestDir dir;
  Lens lens = Lens::WithKudKdu(812.5, 810.25, 331.0, 244.5, -0.12, 0.13);
  SaveCameraFile(dir / "lens.xml", lens, "Wide", 800, 600);
  const AppConfig config =
      ParseConfig("camera:\n  file: lens.xml\n  name: Wide\n  noise: 1.5\n", dir / "servo.yaml");
  EXPECT_DOUBLE_EQ(config.camera.px, 812.5);
  EXPECT_DOUBLE_EQ(config.camera.py, 810.25);
  EXPECT_DOUBLE_EQ(config.camera.u0, 331.0);
  EXPECT_DOUBLE_EQ(config.camera.v0, 244.5);
  EXPECT_DOUBLE_EQ(config.camera.kdu, 0.13);
  EXPECT_EQ(config.camera.width, 800);
  EXPECT_EQ(config.camera.height, 600);
  EXPECT_DOUBLE_EQ(config.camera.noise, 1.5);  // the other keys stay inline
  EXPECT_EQ(config.camera.file, dir / "lens.xml");
}

TEST(ConfigCameraFile, ConflictsAndMissingFilesNameTheLine) {
  const test::TestDir dir;
  Lens lens = Lens::Pinhole(600, 600, 159.5, 119.5);
  SaveCameraFile(dir / "lens.xml", lens, "Camera", 320, 240);
  const std::string yaml = dir / "servo.yaml";
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  file: lens.xml\n  px: 700\n", yaml),
              HasSubstr("servo.yaml:3: 'camera.px' and 'camera.file' (line 2) are both given"));
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  width: 640\n  file: lens.xml\n", yaml),
              HasSubstr("servo.yaml:2: camera.width x camera.height is 640x480 but camera.file '" +
                        dir / "lens.xml" + "' (line 3) was calibrated for 320x240 images"));
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  file: missing.xml\n", yaml),
              HasSubstr("servo.yaml:2: camera.file: "));
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  file: lens.xml\n  name: Other\n", yaml),
              HasSubstr("servo.yaml:2: camera.file: "));
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  name: Camera\n", yaml),
              HasSubstr("servo.yaml:2: 'camera.name' picks a camera of camera.file, which is not "
                        "given"));
  // The size the file gives agrees with the inline one: fine.
  EXPECT_EQ(
      ParseConfig("camera:\n  file: lens.xml\n  width: 320\n  height: 240\n", yaml).camera.width,
      320);
}

// OpenCV's model, inline or from OpenCV's calibration YAML.
TEST(ConfigCameraFile, OpenCvsModelInlineOrFromItsFile) {
  const test::TestDir dir;
  const std::string yaml = dir / "servo.yaml";
  const AppConfig inline_lens =
      ParseConfig("camera:\n  distortion: [-0.27, -0.04, 0.0018, -0.0003, 0.24]\n", yaml);
  const Lens lens = inline_lens.camera.Camera();
  EXPECT_EQ(lens.model(), Lens::Model::kOpenCV);
  EXPECT_DOUBLE_EQ(lens.distortion().k3, 0.24);
  SaveCameraFile(dir / "lens.yaml", lens, "", 640, 480);
  EXPECT_EQ(ParseConfig("camera:\n  file: lens.yaml\n", yaml).camera.Camera(), lens);
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  distortion: [0.1, 0.2, 0.3]\n", yaml),
              HasSubstr("servo.yaml:2: 'camera.distortion' must be OpenCV's distortion "
                        "coefficients [k1, k2, p1, p2, k3] (4, 5 or 8 numbers), got 'a sequence "
                        "of 3'"));
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  distortion: [0.1, x, 0, 0, 0]\n", yaml),
              HasSubstr("servo.yaml:2: 'camera.distortion[1]' must be a number"));
  EXPECT_THAT(test::ConfigErrorOf("camera:\n  kdu: 0.1\n  distortion: [0.1, 0, 0, 0, 0]\n", yaml),
              HasSubstr("kdu = 0 when distortion (OpenCV's coefficients) is given"));
  EXPECT_THAT(
      test::ConfigErrorOf("camera:\n  file: lens.yaml\n  distortion: [0.1, 0, 0, 0, 0]\n", yaml),
      HasSubstr("'camera.distortion' and 'camera.file' (line 2) are both given"));
}

}  // namespace
}  // namespace oal
