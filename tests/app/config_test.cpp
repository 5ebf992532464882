#include "app/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "tests/app/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// The message of the std::runtime_error `yaml` raises, or "" if it loads.
std::string ErrorOf(const std::string& yaml) {
  try {
    ParseConfig(yaml, "cfg.yaml");
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

void ExpectSameOptions(const DetectorOptions& a, const DetectorOptions& b) {
  EXPECT_EQ(a.start_px, b.start_px);
  EXPECT_EQ(a.step_px, b.step_px);
  EXPECT_EQ(a.polarity, b.polarity);
  EXPECT_EQ(a.threshold_mode, b.threshold_mode);
  EXPECT_EQ(a.fixed_threshold, b.fixed_threshold);
  EXPECT_EQ(a.min_contrast, b.min_contrast);
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
      "  fixed_threshold: 100\n  min_contrast: 20\n  min_width_px: 1.5\n  max_width_px: 30\n"
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
  // A constraint between two fields: the line of the field Check() names, if the file set it.
  EXPECT_THAT(ErrorOf("detector:\n  min_width_px: 10\n  max_width_px: 5\n"),
              HasSubstr("cfg.yaml:3: 'detector.max_width_px' is invalid"));
  const std::string above_default_max = std::to_string(DetectorOptions().max_width_px + 1.0);
  EXPECT_THAT(ErrorOf("detector:\n  min_width_px: " + above_default_max + "\n"),
              HasSubstr("cfg.yaml: section 'detector' is invalid: DetectorOptions::max_width_px"));
}

TEST(Config, SectionsOtherThanTheKnownOnesAreRejected) {
  EXPECT_EQ(ErrorOf("detector: {}\ndetectr:\n  step_px: 5\n"),
            "cfg.yaml:2: section 'detectr' is unknown (known: detector)");
  EXPECT_EQ(ErrorOf("servo:\n  gain: 0.5\n"),
            "cfg.yaml:1: section 'servo' is not supported by this version of oalservo "
            "(supported: detector)");
  EXPECT_THAT(ErrorOf("- detector\n"), HasSubstr("cfg.yaml:1: the top level must be a map"));
  EXPECT_THAT(ErrorOf("detector: 5\n"), HasSubstr("cfg.yaml:1: section 'detector' must be a map"));
}

TEST(Config, RepeatedKeysAreRejected) {
  EXPECT_EQ(ErrorOf("detector:\n  step_px: 5\n  start_px: 1\n  step_px: 6\n"),
            "cfg.yaml:4: key 'detector.step_px' is repeated (first at line 2)");
}

TEST(Config, SyntaxErrorNamesFileAndLine) {
  EXPECT_THAT(ErrorOf("detector:\n  step_px: 5\n  polarity: [dark\n"), HasSubstr("cfg.yaml:"));
  EXPECT_THAT(ErrorOf("detector:\n  step_px: 5\n  polarity: [dark\n"),
              HasSubstr("YAML syntax error"));
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

}  // namespace
}  // namespace oal
