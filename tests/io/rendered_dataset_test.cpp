#include "io/rendered_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const StagedDataset::Names kNames{"the folder", "permission"};

TEST(RenderedDataset, KnowsItsOwnFilesByName) {
  EXPECT_EQ(DatasetFrameName(7, ".png"), "frame_0007.png");
  EXPECT_EQ(DatasetFrameName(12345, ".json"), "frame_12345.json");
  for (const char* name :
       {"frame_0001.png", "frame_12.json", "camera.xml", "target.yaml", "sequence.json"}) {
    EXPECT_TRUE(IsDatasetFile(name)) << name;
  }
  for (const char* name : {"notes.txt", "frame_.png", "frame_01a.png", "frame_0001.jpg",
                           "lines.jsonl", "my_camera.xml"}) {
    EXPECT_FALSE(IsDatasetFile(name)) << name;
  }
}

// Without Commit() nothing is left: neither the temporary folder nor the parents made for it.
TEST(RenderedDataset, AnUncommittedDatasetLeavesNothingBehind) {
  test::TestDir dir;
  const fs::path out = dir.path() / "new" / "deeper" / "set";
  {
    StagedDataset staged(out.string(), false, kNames);
    test::WriteText(staged.dir() / "frame_0000.json", "{}");
    EXPECT_TRUE(fs::exists(staged.dir() / "frame_0000.json"));
  }
  EXPECT_FALSE(fs::exists(dir.path() / "new"));
}

// Replacing a data set removes its files and keeps the user's own.
TEST(RenderedDataset, ReplacingADatasetKeepsOtherFiles) {
  test::TestDir dir;
  const fs::path out = dir.path() / "set";
  fs::create_directories(out);
  test::WriteText(out / "frame_0000.png", "old");
  test::WriteText(out / "frame_0001.png", "old");
  test::WriteText(out / "notes.txt", "mine");
  EXPECT_THAT([&] { StagedDataset(out.string(), false, kNames); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  HasSubstr("the folder '" + out.string() +
                            "' already holds a rendered data set (2 frames); pass permission")));
  StagedDataset staged(out.string(), true, kNames);
  test::WriteText(staged.dir() / "frame_0000.png", "new");
  staged.Commit();
  EXPECT_EQ(test::ReadText(out / "frame_0000.png"), "new");
  EXPECT_FALSE(fs::exists(out / "frame_0001.png"));
  EXPECT_EQ(test::ReadText(out / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(staged.dir()));
}

TEST(RenderedDataset, AFileWhereTheFolderShouldBeIsRefused) {
  test::TestDir dir;
  test::WriteText(dir / "taken", "x");
  EXPECT_THAT(
      [&] { StagedDataset(dir / "taken", true, kNames); },
      ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("exists and is not a folder")));
}

}  // namespace
}  // namespace oal
