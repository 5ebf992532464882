#include "app/demo_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/app/test_util.h"

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
  const auto json = nlohmann::json::parse(test::ReadText(dir / "demo/lines.json"));
  EXPECT_EQ(json.at("truth").size(), 4u);
  EXPECT_EQ(json.at("detected").size(), static_cast<std::size_t>(report.detected));
  EXPECT_EQ(json.at("camera").at("kdu"), 0.33);
  EXPECT_THAT(out.str(), HasSubstr("angle err(deg)"));
  EXPECT_THAT(out.str(), HasSubstr("target lines found"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

}  // namespace
}  // namespace oal
