// The setup the evaluation commands read from a configuration and the files beside their
// inputs (app/evaluation_config.h), before the libraries in eval/ take it.
#include "app/evaluation_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "app/compare_command.h"
#include "app/config.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The setup `oalservo compare` and `evaluate` give the library: the configuration's target:
// section first, else the target.yaml beside the frames, else none; the detector is the
// configuration's either way.
TEST(CompareSetup, TheConfigsTargetComesFirstThenTheOneBesideTheFrames) {
  test::TestDir dir;
  const std::string frames = dir / "frames";
  fs::create_directories(frames);
  EXPECT_FALSE(TrackerSetupOf("", {frames}).target.has_value());
  EXPECT_EQ(TrackerSetupOf("", {frames}).target_origin, "");

  test::WriteText(fs::path(frames) / "target.yaml", TargetYaml(FourLineA4Target()));
  const TrackerSetup beside = TrackerSetupOf("", {frames});
  ASSERT_TRUE(beside.target.has_value());
  EXPECT_EQ(beside.target->name, "four-line-a4");
  EXPECT_EQ(beside.target_origin, (fs::path(frames) / "target.yaml").string());

  test::WriteText(dir / "detector.yaml", "detector:\n  step_px: 7\n");
  const TrackerSetup detector_only = TrackerSetupOf(dir / "detector.yaml", {frames});
  EXPECT_EQ(detector_only.detector.step_px, 7);
  ASSERT_TRUE(detector_only.target.has_value());
  EXPECT_EQ(detector_only.target->name, "four-line-a4");

  test::WriteText(dir / "a3.yaml", "target: {name: four-line-a3}\n");
  const TrackerSetup configured = TrackerSetupOf(dir / "a3.yaml", {frames});
  ASSERT_TRUE(configured.target.has_value());
  EXPECT_EQ(configured.target->name, "four-line-a3");
  EXPECT_EQ(configured.target_origin, dir / "a3.yaml");
}

// A malformed configuration, or a malformed target.yaml beside the frames, is an error that
// names the file and its line, and the comparison writes nothing.
TEST(CompareSetup, ABrokenConfigOrTargetFileBesideTheFramesNamesIt) {
  test::TestDir dir;
  const std::string frames = dir / "frames";
  fs::create_directories(frames);
  test::WriteText(dir / "bad.yaml", "detector:\n  no_such_key: 1\n");
  EXPECT_THAT(test::ErrorMessageOf([&] { TrackerSetupOf(dir / "bad.yaml", {frames}); }),
              AllOf(HasSubstr("bad.yaml:2"), HasSubstr("no_such_key")));

  test::WriteText(fs::path(frames) / "target.yaml", "target: {name: no-such-target}\n");
  EXPECT_THAT(test::ErrorMessageOf([&] { TrackerSetupOf("", {frames}); }),
              AllOf(HasSubstr("target.yaml:1"), HasSubstr("no-such-target")));

  const std::string out = dir / "out";
  EXPECT_THAT(test::ErrorMessageOf([&] {
                test::RunWithArgs(RunCompare,
                                  {"compare", frames, "--config", dir / "bad.yaml", "--out", out});
              }),
              HasSubstr("bad.yaml:2"));
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace oal
