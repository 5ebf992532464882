#include "app/demo_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// The demo's plumbing; the detector's accuracy is tested in tests/detector.
TEST(Demo, WritesThePicturesTheJsonAndATable) {
  test::TestDir dir;
  DemoCommandOptions options;
  options.out_dir = dir / "demo";
  std::ostringstream out;
  const DemoReport report = RunDemoScene(options, out);
  EXPECT_EQ(report.matches.size(), 4u);  // every line of the four-line target is visible
  for (const char* name : {"demo.png", "frame.png", "lines.json"}) {
    EXPECT_TRUE(fs::is_regular_file(fs::path(options.out_dir) / name)) << name;
  }
  const auto lines = nlohmann::json::parse(test::ReadText(dir / "demo/lines.json"));
  EXPECT_EQ(lines.at("truth").size(), 4u);
  EXPECT_EQ(lines.at("detected").size(), static_cast<std::size_t>(report.detected));
  EXPECT_EQ(lines.at("camera").at("kdu"), 0.15);
  EXPECT_EQ(lines.at("target"), "four-line-a3");
  EXPECT_THAT(out.str(), HasSubstr("angle err(deg)"));
  EXPECT_THAT(out.str(), HasSubstr("target lines found"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// The default scene is the A3 sheet on a bench, found without a prior and posed; the JSON says
// which region was scanned.
TEST(Demo, FindsTheSheetAndItsPose) {
  test::TestDir dir;
  DemoCommandOptions options;
  options.out_dir = dir / "demo";
  std::ostringstream out;
  const DemoReport report = RunDemoScene(options, out);
  EXPECT_EQ(report.pose_status, "ok") << out.str();
  for (const DemoMatch& match : report.matches) EXPECT_GE(match.detected_index, 0);
  const auto lines = nlohmann::json::parse(test::ReadText(dir / "demo/lines.json"));
  EXPECT_EQ(lines.at("scan").at("mode"), "target");
  EXPECT_EQ(lines.at("scan").at("region").size() >= 4, true);
  EXPECT_THAT(out.str(), HasSubstr("from the truth"));
}

// The paper's condition stays available: the 2 m board through a cheap wide lens.
TEST(Demo, TheBoardThroughACheapLens) {
  test::TestDir dir;
  DemoCommandOptions options;
  options.out_dir = dir / "demo";
  options.target = "four-line-board";
  std::ostringstream out;
  const DemoReport report = RunDemoScene(options, out);
  EXPECT_EQ(report.matches.size(), 4u);
  const auto lines = nlohmann::json::parse(test::ReadText(dir / "demo/lines.json"));
  EXPECT_EQ(lines.at("camera").at("kdu"), 0.33);
  EXPECT_EQ(lines.at("target"), "four-line-board");
}

TEST(Demo, AnUnknownTargetIsAnErrorNamingTheOption) {
  test::TestDir dir;
  DemoCommandOptions options;
  options.out_dir = dir / "demo";
  options.target = "four-line-a5";
  std::ostringstream out;
  EXPECT_THAT(test::ErrorMessageOf<std::invalid_argument>([&] { RunDemoScene(options, out); }),
              HasSubstr("--target"));
  EXPECT_FALSE(fs::exists(dir / "demo"));
}

// The table numbers the target's lines 1-4, as the docs and `oalservo target` do.
TEST(Demo, NumbersTheTargetLinesOneToFour) {
  test::TestDir dir;
  DemoCommandOptions options;
  options.out_dir = dir / "demo";
  std::ostringstream out;
  RunDemoScene(options, out);
  std::istringstream table(out.str());
  std::vector<int> numbers;
  for (std::string line; std::getline(table, line);) {
    std::istringstream words(line);
    int number = 0;
    if (line.rfind("     ", 0) == 0 && words >> number) numbers.push_back(number);
  }
  EXPECT_EQ(numbers, (std::vector<int>{1, 2, 3, 4})) << out.str();
  const auto lines = nlohmann::json::parse(test::ReadText(dir / "demo/lines.json"));
  EXPECT_EQ(lines.at("matches")[0].at("target_line"), 1);
  EXPECT_EQ(lines.at("matches")[0].at("truth_index"), 0);
}

// A failed output stream (stdout on a full disk) is an error, not a silent success.
TEST(Demo, AFailedOutputIsAnError) {
  test::TestDir dir;
  DemoCommandOptions options;
  options.out_dir = dir / "demo";
  std::ostringstream out;
  out.setstate(std::ios::badbit);
  EXPECT_THAT(test::ErrorMessageOf<std::runtime_error>([&] { RunDemoScene(options, out); }),
              HasSubstr("cannot write the output"));
}

TEST(Demo, NegativeSeedIsAUsageError) {
  test::TestDir dir;
  EXPECT_THROW(test::RunWithArgs(RunDemo, {"demo", "--seed", "-1", "--out", dir / "demo"}),
               UsageError);
  EXPECT_FALSE(fs::exists(dir / "demo"));
}

}  // namespace
}  // namespace oal
