#include "eval/lines/edge_reference.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <visp3/io/vpImageIo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "app/edge_reference_command.h"
#include "tests/app/command_test_util.h"
#include "tests/eval/lines/synthetic_edge.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Writes frames first..last of `pattern_dir`/e%d.pgm (a vertical edge moving 1 px a frame,
// or a flat grey image when `flat`), of `size` x `size` px; returns the pattern.
std::string WriteEdgeFrames(const fs::path& pattern_dir, int first, int last, bool flat,
                            int size = 64) {
  fs::create_directories(pattern_dir);
  for (int frame = first; frame <= last; ++frame) {
    vpImage<unsigned char> image =
        flat ? vpImage<unsigned char>(static_cast<unsigned>(size), static_cast<unsigned>(size), 128)
             : test::SyntheticEdge(size, size, LineParams{size / 2.0 - 5.5 + frame, 0.0}, 40.0,
                                   200.0, 0.0, 1);
    vpImageIo::write(image, (pattern_dir / ("e" + std::to_string(frame) + ".pgm")).string());
  }
  return (pattern_dir / "e%d.pgm").string();
}

// What `oalservo edge-reference ARGS...` throws, or "" when it returns rc 0 (checked).
std::string EdgeReferenceError(const std::vector<std::string>& args) {
  std::vector<std::string> argv{"edge-reference"};
  argv.insert(argv.end(), args.begin(), args.end());
  return test::ErrorMessageOf([&] { EXPECT_EQ(test::RunWithArgs(RunEdgeReference, argv), 0); });
}

TEST(EdgeReferenceCommand, WritesTheTruthCsvAndCreatesItsDirectory) {
  test::TestDir dir;
  const std::string pattern = WriteEdgeFrames(dir.path() / "seq", 1, 3, false);
  const std::string out = dir / "new/deeper/truth.csv";
  testing::internal::CaptureStdout();
  const std::string error = EdgeReferenceError({pattern, "--out", out});
  const std::string printed = testing::internal::GetCapturedStdout();
  ASSERT_EQ(error, "");
  EXPECT_THAT(printed, HasSubstr("3 of 3 frames have a reference; wrote " + out));
  const std::vector<std::string> rows = test::ReadLines(out);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], "frame,line,rho,theta");
  EXPECT_EQ(rows[1].substr(0, 4), "1,0,");
  EXPECT_EQ(rows[3].substr(0, 4), "3,0,");
}

// These ran forever (the search for the last frame never ended when the name did not
// change with the frame number): now they fail at once.
TEST(EdgeReferenceCommand, ASingleImageOrADirectoryIsNotASequence) {
  test::TestDir dir;
  WriteEdgeFrames(dir.path() / "seq", 1, 1, false);
  const std::string image = dir / "seq/e1.pgm";
  fs::create_directories(dir / "empty");
  for (const std::string& input : {image, dir / "empty", dir / "seq"}) {
    const std::string error = EdgeReferenceError({input, "--out", dir / "x.csv"});
    EXPECT_THAT(error, HasSubstr("pattern '" + input + "' has no %d conversion")) << input;
    EXPECT_THAT(error, HasSubstr("not a sequence")) << input;
    EXPECT_THROW(LastSequenceFrame(input, 1), std::invalid_argument) << input;
  }
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
  // A pattern whose first frame does not exist names that file.
  EXPECT_THAT(EdgeReferenceError({dir / "seq/e%d.pgm", "--first", "4", "--out", dir / "x.csv"}),
              HasSubstr("frame 4 (" + dir / "seq/e4.pgm" + ") does not exist"));
  EXPECT_EQ(LastSequenceFrame(dir / "seq/e%d.pgm", 1), 1);
}

// Frames are read as every command reads images: a file cut short is an error naming it,
// not a frame decoded from half its data.
TEST(EdgeReferenceCommand, AFrameCutShortIsAnError) {
  test::TestDir dir;
  const std::string pattern = WriteEdgeFrames(dir.path() / "seq", 1, 3, false);
  const fs::path cut = dir.path() / "seq/e2.pgm";
  fs::resize_file(cut, fs::file_size(cut) / 2);
  const std::string error = EdgeReferenceError({pattern, "--out", dir / "x.csv"});
  EXPECT_THAT(error, HasSubstr(cut.string()));
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
}

TEST(EdgeReferenceCommand, FirstAfterLastIsRejected) {
  test::TestDir dir;
  const std::string pattern = WriteEdgeFrames(dir.path() / "seq", 1, 5, false);
  EXPECT_THAT(EdgeReferenceError({pattern, "--first", "5", "--last", "3", "--out", dir / "x.csv"}),
              HasSubstr("--first 5 is after --last 3"));
  EXPECT_THAT(EdgeReferenceError({pattern, "--first", "-1", "--out", dir / "x.csv"}),
              HasSubstr("--first -1"));
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
  EXPECT_THROW(FitEdgeSequence(pattern, 5, 3, EdgeReferenceOptions()), std::invalid_argument);
  EXPECT_EQ(LastSequenceFrame(pattern, 2), 5);
}

TEST(EdgeReferenceCommand, FramesWithoutReferenceWriteNothing) {
  test::TestDir dir;
  // Frames 1-2 have an edge, frame 3 is flat.
  const std::string pattern = WriteEdgeFrames(dir.path() / "seq", 1, 2, false);
  WriteEdgeFrames(dir.path() / "seq", 3, 3, true);
  testing::internal::CaptureStdout();
  const std::string error = EdgeReferenceError({pattern, "--out", dir / "x.csv"});
  const std::string printed = testing::internal::GetCapturedStdout();
  EXPECT_THAT(error, HasSubstr("1 of 3 frames have no reference (frames 3)"));
  EXPECT_THAT(error, HasSubstr("nothing written to " + dir / "x.csv"));
  EXPECT_THAT(printed, ::testing::Not(HasSubstr("wrote")));
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());

  // Frames too small for the fit: the error names the file.
  const std::string tiny = WriteEdgeFrames(dir.path() / "tiny", 1, 1, true, 5);
  EXPECT_THAT(EdgeReferenceError({tiny, "--out", dir / "x.csv"}),
              HasSubstr(dir / "tiny/e1.pgm" + ": FitEdgeReference: image of 5 x 5 px"));
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
}

TEST(EdgeReferenceCommand, AnUnwritableOutFailsBeforeTheWork) {
  test::TestDir dir;
  const std::string pattern = WriteEdgeFrames(dir.path() / "seq", 1, 2, false);
  test::WriteText(dir / "file", "not a directory\n");
  EXPECT_THAT(EdgeReferenceError({pattern, "--out", dir / "file/x.csv"}),
              HasSubstr("--out " + dir / "file/x.csv" + ": cannot create directory"));
  // Checked before the frames are read: frames the fit rejects are not reached.
  const std::string tiny = WriteEdgeFrames(dir.path() / "tiny", 1, 1, true, 5);
  EXPECT_THAT(EdgeReferenceError({tiny, "--out", dir / "file/x.csv"}),
              HasSubstr("cannot create directory"));
  fs::create_directories(dir / "taken.csv");
  EXPECT_THAT(EdgeReferenceError({pattern, "--out", dir / "taken.csv"}),
              HasSubstr("is a directory"));
}

}  // namespace
}  // namespace oal
