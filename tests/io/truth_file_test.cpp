#include "io/truth_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <visp3/core/vpThetaUVector.h>

#include <stdexcept>

#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

TEST(TruthFile, ReadsLineAndPoseRowsAndRejectsBadOnes) {
  test::TestDir dir;
  test::WriteText(dir / "t.csv",
                  "frame,line,rho,theta\n# comment\n\n3,0,10.5,0.25\n3,1,-4,3.5\n"
                  "3,pose,0.1,0.2,0.5,0,0,0.3\n");
  const TruthCsv truth = LoadTruthCsvWithPoses(dir / "t.csv");
  ASSERT_EQ(truth.lines.at(3).size(), 2u);
  EXPECT_DOUBLE_EQ(truth.lines.at(3)[0].image_line.rho_px, 10.5);
  EXPECT_NEAR(truth.lines.at(3)[1].image_line.theta_rad, 3.5 - kPi, 1e-12);
  const vpHomogeneousMatrix& cMo = truth.poses.at(3);
  EXPECT_DOUBLE_EQ(cMo[2][3], 0.5);
  EXPECT_NEAR(vpThetaUVector(cMo.getRotationMatrix())[2], 0.3, 1e-12);

  test::WriteText(dir / "bad.csv", "1,0,2\n");
  EXPECT_THAT([&] { LoadTruthCsvWithPoses(dir / "bad.csv"); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("bad.csv:1: expected")));
  test::WriteText(dir / "twice.csv", "1,pose,0,0,1,0,0,0\n1,pose,0,0,1,0,0,0\n");
  EXPECT_THAT([&] { LoadTruthCsvWithPoses(dir / "twice.csv"); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("twice.csv:2: the pose")));
}

// The frame a CSV row names: the last run of digits of the file name, else the position.
TEST(TruthFile, FrameNumbersComeFromTheFileNameElseThePosition) {
  EXPECT_EQ(FrameNumber("dir/image.0001.pgm", 7), 1);
  EXPECT_EQ(FrameNumber("frame_0042.png", 0), 42);
  EXPECT_EQ(FrameNumber("clip.avi#12", 3), 12);
  EXPECT_EQ(FrameNumber("still.png", 5), 5);
  EXPECT_EQ(FrameNumber("shot_1234567890.png", 4), 4);  // too long to be a frame number
}

}  // namespace
}  // namespace oal
