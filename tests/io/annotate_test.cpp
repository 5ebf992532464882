#include "io/annotate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "detector/lens.h"
#include "scene/scene.h"

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
  Lens camera = Lens::WithKudKdu(150.0, 150.0, 79.5, 59.5, -0.2, 0.3);
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

// The goal lines are drawn dashed where the camera at the goal sees the target's centre lines,
// in lines 1-4's colours, and nowhere else.
TEST(DrawGoalLines, DashedAlongTheGoalsProjectionOfEachLine) {
  const LineTarget target = FourLineA3Target();
  const vpCameraParameters camera(600.0, 600.0, 319.5, 239.5);
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);  // fronto-parallel, 0.5 m
  cv::Mat image(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  DrawGoalLines(&image, target, cdMo, camera);
  int drawn_on_lines = 0, samples = 0;
  for (const TargetLine& line : target.lines) {
    for (int i = 1; i < 100; ++i) {
      const double t = i / 100.0;
      const double x = line.x1_m + t * (line.x2_m - line.x1_m);
      const double y = line.y1_m + t * (line.y2_m - line.y1_m);
      const int u = cvRound(319.5 + 600.0 * x / 0.5), v = cvRound(239.5 + 600.0 * y / 0.5);
      ++samples;
      drawn_on_lines += image.at<cv::Vec3b>(v, u) != cv::Vec3b(0, 0, 0);
    }
  }
  // Dashes: about half of the samples lie on a drawn piece, none on the other half's gaps.
  EXPECT_GT(drawn_on_lines, samples / 4);
  EXPECT_LT(drawn_on_lines, samples * 9 / 10);
  // Away from every line (the middle of the middle cell, and a corner) nothing is drawn.
  EXPECT_EQ(image.at<cv::Vec3b>(240, 320), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(image.at<cv::Vec3b>(5, 5), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace oal
