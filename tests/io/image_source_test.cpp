#include "io/image_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <string>

#include "tests/test_util.h"

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

TEST(ImageSource, CompanionFilesOfTheRendererAreSkippedWithoutAWarning) {
  test::TestDir dir;
  WriteImage(dir / "frame_0000.png", 1);
  test::WriteText(dir / "frame_0000.json", "{}");
  test::WriteText(dir / "sequence.json", "{}");
  test::WriteText(dir / "camera.xml", "<root/>");
  test::WriteText(dir / "clip.truth.csv", "frame,line,rho,theta\n");
  std::vector<std::string> warnings;
  EXPECT_EQ(ReadAll(*OpenImageSource(dir.path().string(), &warnings)).size(), 1u);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  test::WriteText(dir / "notes.txt", "not an image");  // still unexpected
  test::WriteText(dir / "other.xml", "<root/>");
  OpenImageSource(dir.path().string(), &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("skipped 2 non-image entries"));
  EXPECT_THAT(warnings[0], HasSubstr("notes.txt, other.xml"));
  EXPECT_TRUE(IsCompanionFile("a/b/camera.xml"));
  EXPECT_TRUE(IsCompanionFile("frame_0007.JSON"));
  EXPECT_FALSE(IsCompanionFile("camera.xml.bak"));
  EXPECT_FALSE(IsCompanionFile("truth.csv"));
}

TEST(ImageSource, PatternStartsAtZeroOrOneAndStopsAtTheFirstGap) {
  test::TestDir dir;
  for (int i = 1; i <= 3; ++i) WriteImage(dir / ("f" + std::to_string(i) + ".png"), i);
  std::vector<std::string> warnings;
  EXPECT_EQ(ReadAll(*OpenImageSource(dir / "f%d.png", &warnings)).size(), 3u);
  EXPECT_TRUE(warnings.empty());  // nothing after the end
  WriteImage(dir / "f5.png", 5);  // after the gap: not read, but warned about
  WriteImage(dir / "f7.png", 7);
  auto source = OpenImageSource(dir / "f%d.png", &warnings);
  const std::vector<Frame> frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].source, dir / "f3.png");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "pattern '" + dir / "f%d.png" +
                             "': the sequence ends at the missing file '" + dir / "f4.png" +
                             "'; 2 files after the gap ('" + dir / "f5.png" + "' ... '" +
                             dir / "f7.png" + "') are not read");
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
  EXPECT_EQ(OpenError(dir / "truncated.png"),
            "cannot decode image '" + dir / "truncated.png" +
                "': truncated PNG (the file ends before its IEND chunk)");
  test::WriteText(dir / "no_iend.png", png.substr(0, png.size() - 12));
  EXPECT_THAT(OpenError(dir / "no_iend.png"), HasSubstr("truncated PNG"));

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

// libjpeg decodes a JPEG cut short with a warning only ("Premature end of JPEG file"),
// filling the missing rows with grey: such a file must fail like a truncated PNG.
TEST(ImageSource, TruncatedJpegIsRejectedNamingTheFile) {
  test::TestDir dir;
  WriteImage(dir / "whole.jpg", 50);
  const std::string jpeg = test::ReadText(dir / "whole.jpg");
  ASSERT_GT(jpeg.size(), 1000u);
  const std::string expected = "cannot decode image '" + dir / "half.jpg" +
                               "': truncated JPEG (no end-of-image marker after the image data)";
  test::WriteText(dir / "half.jpg", jpeg.substr(0, jpeg.size() / 2));
  EXPECT_EQ(OpenError(dir / "half.jpg"), expected);
  test::WriteText(dir / "head.jpg", jpeg.substr(0, 500));  // `head -c 500`
  EXPECT_THAT(OpenError(dir / "head.jpg"), HasSubstr("'" + dir / "head.jpg" + "': truncated JPEG"));
  test::WriteText(dir / "header.jpg", jpeg.substr(0, 40));  // inside the header segments
  EXPECT_THAT(OpenError(dir / "header.jpg"), HasSubstr("truncated JPEG (the file ends inside"));
  test::WriteText(dir / "no_eoi.jpg", jpeg.substr(0, jpeg.size() - 2));
  EXPECT_THAT(OpenError(dir / "no_eoi.jpg"), HasSubstr("truncated JPEG"));

  // Whole files with something after the end-of-image marker still decode.
  test::WriteText(dir / "padded.jpg", jpeg + std::string(64, '\0'));
  test::WriteText(dir / "trailer.jpg", jpeg + "camera maker trailer");
  for (const char* name : {"whole.jpg", "padded.jpg", "trailer.jpg"}) {
    EXPECT_EQ(OpenError(dir / name), "") << name;
    Frame frame;
    ASSERT_TRUE(OpenImageSource(dir / name)->Next(&frame));
    EXPECT_EQ(frame.gray.cols, 160) << name;
  }

  // In a directory, the truncated frame fails when reached, naming its file.
  fs::create_directory(dir.path() / "seq");
  fs::copy_file(dir / "whole.jpg", dir / "seq/a.jpg");
  fs::copy_file(dir / "half.jpg", dir / "seq/b.jpg");
  fs::copy_file(dir / "whole.jpg", dir / "seq/c.jpg");
  auto source = OpenImageSource(dir / "seq");
  Frame frame;
  ASSERT_TRUE(source->Next(&frame));
  try {
    source->Next(&frame);
    FAIL() << "no error for b.jpg";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("'" + dir / "seq/b.jpg" + "': truncated JPEG"));
  }
  EXPECT_EQ(frame.source, dir / "seq/b.jpg");  // the failing file, for the caller's record
  ASSERT_TRUE(source->Next(&frame));
  EXPECT_EQ(frame.source, dir / "seq/c.jpg");
}

}  // namespace
}  // namespace oal
