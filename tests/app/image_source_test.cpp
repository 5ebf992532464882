#include "app/image_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <string>

#include "tests/app/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A 160x120 grey picture whose grey level encodes `tag`, to tell frames apart.
cv::Mat Picture(int tag) {
  cv::Mat image(120, 160, CV_8UC1, cv::Scalar(200));
  cv::line(image, {10, 10}, {150, 110}, cv::Scalar(tag), 5);
  return image;
}

void WriteImage(const std::string& path, int tag) {
  ASSERT_TRUE(cv::imwrite(path, Picture(tag)));
}

// The message of the std::runtime_error opening `spec` raises, or "" if it opens.
std::string OpenError(const std::string& spec) {
  try {
    OpenImageSource(spec);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

std::vector<Frame> ReadAll(ImageSource& source) {
  std::vector<Frame> frames;
  Frame frame;
  while (source.Next(&frame)) {
    frame.gray = frame.gray.clone();
    frames.push_back(frame);
  }
  return frames;
}

TEST(ExpandPattern, FormatsOneIntegerConversion) {
  EXPECT_EQ(ExpandPattern("img%04d.png", 7), "img0007.png");
  EXPECT_EQ(ExpandPattern("img%d.png", 12), "img12.png");
  EXPECT_EQ(ExpandPattern("a%%b%3d.pgm", 5), "a%b  5.pgm");
  EXPECT_EQ(ExpandPattern("x%02d", 123), "x123");
  EXPECT_THROW(ExpandPattern("img%s.png", 1), std::runtime_error);
  EXPECT_THROW(ExpandPattern("img%d_%d.png", 1), std::runtime_error);
  EXPECT_THROW(ExpandPattern("img%%.png", 1), std::runtime_error);
}

TEST(ImageSource, ReadsOneImageAsGrey) {
  test::TestDir dir;
  const cv::Mat colour(120, 160, CV_8UC3, cv::Scalar(10, 20, 30));
  ASSERT_TRUE(cv::imwrite(dir / "c.png", colour));
  auto source = OpenImageSource(dir / "c.png");
  const std::vector<Frame> frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].gray.type(), CV_8UC1);
  EXPECT_EQ(frames[0].gray.cols, 160);
  EXPECT_EQ(frames[0].source, dir / "c.png");
  const GrayImageView view = frames[0].view();
  EXPECT_EQ(view.width, 160);
  EXPECT_EQ(view.height, 120);
  EXPECT_EQ(view.data, frames[0].gray.data);  // a view, not a copy
}

TEST(ImageSource, DirectoryIsSortedByNameAndSkipsOtherFiles) {
  test::TestDir dir;
  WriteImage(dir / "b.png", 2);
  WriteImage(dir / "a.pgm", 1);
  WriteImage(dir / "c.jpg", 3);
  test::WriteText(dir / "notes.txt", "not an image");
  fs::create_directory(dir.path() / "sub");
  std::vector<std::string> warnings;
  auto source = OpenImageSource(dir.path().string(), &warnings);
  const std::vector<Frame> frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(fs::path(frames[0].source).filename(), "a.pgm");
  EXPECT_EQ(fs::path(frames[1].source).filename(), "b.png");
  EXPECT_EQ(fs::path(frames[2].source).filename(), "c.jpg");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("skipped 2 non-image entries"));
  EXPECT_THAT(warnings[0], HasSubstr("notes.txt"));
}

TEST(ImageSource, PatternStartsAtZeroOrOneAndStopsAtTheFirstGap) {
  test::TestDir dir;
  for (int i = 1; i <= 3; ++i) WriteImage(dir / ("f" + std::to_string(i) + ".png"), i);
  WriteImage(dir / "f5.png", 5);  // after the gap: not read
  auto source = OpenImageSource(dir / "f%d.png");
  const std::vector<Frame> frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].source, dir / "f3.png");
  WriteImage(dir / "f0.png", 0);
  EXPECT_EQ(ReadAll(*OpenImageSource(dir / "f%d.png")).size(), 4u);
  EXPECT_THAT(OpenError(dir / "g%03d.png"), HasSubstr("no file matches the pattern"));
  EXPECT_THAT(OpenError(dir / "g%03d.png"), HasSubstr("g001.png"));
}

TEST(ImageSource, VideoFramesComeOutGrey) {
  test::TestDir dir;
  const std::string path = dir / "clip.avi";
  {
    cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, {160, 120});
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG AVI files here";
    cv::Mat colour;
    for (int i = 0; i < 4; ++i) {
      cv::cvtColor(Picture(40 * i), colour, cv::COLOR_GRAY2BGR);
      writer.write(colour);
    }
  }
  auto source = OpenImageSource(path);
  const std::vector<Frame> frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].gray.type(), CV_8UC1);
  EXPECT_EQ(frames[3].source, path + "#3");
}

TEST(ImageSource, BadInputsFailWithTheReason) {
  test::TestDir dir;
  EXPECT_EQ(OpenError(dir / "missing.png"),
            "no such file or directory '" + dir / "missing.png" + "'");

  test::WriteText(dir / "text.png", "this is not a PNG\n");
  EXPECT_THAT(OpenError(dir / "text.png"), HasSubstr("cannot decode image '" + dir / "text.png'"));

  WriteImage(dir / "whole.png", 50);
  const std::string png = test::ReadText(dir / "whole.png");
  test::WriteText(dir / "truncated.png", png.substr(0, png.size() / 2));
  EXPECT_THAT(OpenError(dir / "truncated.png"), HasSubstr("cannot decode image"));

  test::WriteText(dir / "garbage.avi", std::string(4096, '\x5a'));
  EXPECT_THAT(OpenError(dir / "garbage.avi"), HasSubstr("video '" + dir / "garbage.avi'"));
  test::WriteText(dir / "empty.avi", "");
  EXPECT_THAT(OpenError(dir / "empty.avi"), HasSubstr("video '" + dir / "empty.avi'"));

  EXPECT_EQ(OpenError("/dev/video99"), "no V4L2 device at /dev/video99");

  test::WriteText(dir / "notes.txt", "hello");
  EXPECT_THAT(OpenError(dir / "notes.txt"), HasSubstr("unsupported input"));

  fs::create_directory(dir.path() / "empty");
  EXPECT_THAT(OpenError(dir / "empty"), HasSubstr("has no images"));
}

TEST(ImageSource, EmptyVideoHasNoFrames) {
  test::TestDir dir;
  const std::string path = dir / "empty_clip.avi";
  {
    cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, {160, 120});
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG AVI files here";
  }
  const std::string error = OpenError(path);
  EXPECT_THAT(error, HasSubstr("video '" + path + "'"));
}

TEST(ImageSource, BadImageInADirectoryFailsWhenReached) {
  test::TestDir dir;
  WriteImage(dir / "a.png", 1);
  test::WriteText(dir / "b.png", "garbage");
  auto source = OpenImageSource(dir.path().string());
  Frame frame;
  EXPECT_TRUE(source->Next(&frame));
  try {
    source->Next(&frame);
    FAIL() << "no error for b.png";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("cannot decode image '" + dir / "b.png'"));
  }
}

}  // namespace
}  // namespace oal
