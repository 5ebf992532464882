#include "app/annotate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "detector/lens.h"

namespace oal {
namespace {

constexpr double kOnLineTolerancePx = 1e-6;

TEST(LineInFrame, StraightWithoutCameraFromBorderToBorder) {
  const LineParams line = LineThrough(Point2d{0.0, 10.0}, Point2d{100.0, 60.0});
  const auto runs = LineInFrame(line, 160, 120, std::nullopt);
  ASSERT_EQ(runs.size(), 1u);
  ASSERT_EQ(runs[0].size(), 2u);
  EXPECT_NEAR(std::min(runs[0][0].x, runs[0][1].x), 0.0, 1e-9);
  EXPECT_NEAR(std::max(runs[0][0].x, runs[0][1].x), 159.0, 1e-9);
  EXPECT_TRUE(LineInFrame(LineParams{500.0, 0.0}, 160, 120, std::nullopt).empty());
}

// Curved runs, once undistorted, lie on the undistorted line, and span the frame.
TEST(LineInFrame, CurvedWithDistortionAndOnTheLineOnceUndistorted) {
  vpCameraParameters camera;
  camera.initPersProjWithDistortion(150.0, 150.0, 79.5, 59.5, -0.2, 0.3);
  const PointUndistorter undistorter(camera);
  // The undistorted image of a line through two distorted pixels near the top edge.
  const Point2d a = undistorter.Undistort({5.0, 10.0}), b = undistorter.Undistort({155.0, 15.0});
  const LineParams line = LineThrough(a, b);
  const auto runs = LineInFrame(line, 160, 120, camera);
  ASSERT_EQ(runs.size(), 1u);
  ASSERT_GT(runs[0].size(), 20u);
  double max_bend = 0.0;
  const LineParams chord = LineThrough(Point2d{runs[0].front().x, runs[0].front().y},
                                       Point2d{runs[0].back().x, runs[0].back().y});
  for (const cv::Point2d& p : runs[0]) {
    EXPECT_GE(p.x, -0.5);
    EXPECT_LE(p.x, 159.5);
    const Point2d u = undistorter.Undistort(Point2d{p.x, p.y});
    EXPECT_NEAR(line.SignedDistance(u.u, u.v), 0.0, kOnLineTolerancePx);
    max_bend = std::max(max_bend, std::abs(chord.SignedDistance(p.x, p.y)));
  }
  EXPECT_GT(max_bend, 1.0) << "a line off-centre should bend visibly with kdu = 0.3";
}

TEST(AnnotateLines, DrawsInColourOnACopy) {
  const cv::Mat gray(120, 160, CV_8UC1, cv::Scalar(128));
  DetectedLine line;
  line.line = LineParams{80.0, 0.0};  // the vertical u = 80
  const cv::Mat image = AnnotateLines(gray, {line}, std::nullopt);
  ASSERT_EQ(image.type(), CV_8UC3);
  const cv::Vec3b on = image.at<cv::Vec3b>(60, 80), off = image.at<cv::Vec3b>(60, 20);
  EXPECT_NE(on, cv::Vec3b(128, 128, 128));
  EXPECT_EQ(off, cv::Vec3b(128, 128, 128));
  EXPECT_EQ(gray.at<unsigned char>(60, 80), 128);
}

}  // namespace
}  // namespace oal
