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

#include "tests/eval/lines/synthetic_edge.h"
#include "tests/test_util.h"

namespace oal {
namespace {

constexpr double kMaxOffsetPx = 0.05;
constexpr double kMaxAngleDeg = 0.05;

double AngleErrorDeg(const LineParams& a, const LineParams& b) {
  return AngleBetween(a, b) * 180.0 / kPi;
}

// The fitted line's distance from the true one over the image (the larger of the two ends
// of the true line's visible part).
double OffsetErrorPx(const LineParams& truth, const LineParams& fit, int width, int height) {
  Point2d a, b;
  if (!ClipToRect(truth, 0.0, 0.0, width - 1.0, height - 1.0, &a, &b)) return 1e9;
  return std::max(std::fabs(fit.SignedDistance(a.u, a.v)), std::fabs(fit.SignedDistance(b.u, b.v)));
}

TEST(EdgeReference, RecoversSyntheticEdgesAtManyAngles) {
  constexpr int kWidth = 240, kHeight = 180;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(-20.0, 20.0);
  for (double theta_deg :
       {0.0, 0.3, 10.0, 17.0, 44.0, 45.0, 46.0, 60.0, 89.7, 90.0, 123.0, 135.0, 170.0, 179.5}) {
    const double theta = theta_deg * kPi / 180.0;
    // Through the image centre, shifted by a random sub-pixel offset along the normal.
    const double rho =
        (kWidth - 1) / 2.0 * std::cos(theta) + (kHeight - 1) / 2.0 * std::sin(theta) + offset(rng);
    const LineParams truth = Normalized(rho, theta);
    for (bool dark_positive : {false, true}) {
      const vpImage<unsigned char> image =
          dark_positive ? test::SyntheticEdge(kWidth, kHeight, truth, 210.0, 30.0, 0.0, 1)
                        : test::SyntheticEdge(kWidth, kHeight, truth, 30.0, 210.0, 0.0, 1);
      const EdgeReference ref = FitEdgeReference(image, EdgeReferenceOptions());
      ASSERT_EQ(ref.status, EdgeReferenceStatus::kFound) << theta_deg << ": " << ref.message;
      EXPECT_LT(AngleErrorDeg(truth, ref.line), kMaxAngleDeg) << theta_deg;
      EXPECT_LT(OffsetErrorPx(truth, ref.line, kWidth, kHeight), kMaxOffsetPx) << theta_deg;
      // The bright side, stated relative to the returned line's normal.
      const double aligned = std::cos(ref.line.theta_rad - truth.theta_rad) > 0.0 ? 1.0 : -1.0;
      const bool bright_positive_truth = !dark_positive;
      const bool bright_positive_ref = ref.polarity == EdgePolarity::kBrighterPositive;
      EXPECT_EQ(bright_positive_ref, aligned > 0.0 ? bright_positive_truth : !bright_positive_truth)
          << theta_deg;
      EXPECT_LT(ref.rms_residual_px, 0.05) << theta_deg;
    }
  }
}

TEST(EdgeReference, RecoversANoisyEdge) {
  constexpr int kWidth = 320, kHeight = 240;
  const LineParams truth = Normalized(150.3, 0.7);
  const vpImage<unsigned char> image =
      test::SyntheticEdge(kWidth, kHeight, truth, 40.0, 190.0, 3.0, 9);
  const EdgeReference ref = FitEdgeReference(image, EdgeReferenceOptions());
  ASSERT_EQ(ref.status, EdgeReferenceStatus::kFound) << ref.message;
  EXPECT_LT(AngleErrorDeg(truth, ref.line), kMaxAngleDeg);
  EXPECT_LT(OffsetErrorPx(truth, ref.line, kWidth, kHeight), kMaxOffsetPx);
  EXPECT_GT(ref.points, 200);
}

TEST(EdgeReference, PolarityAndPriorSelectTheEdge) {
  // A bright stripe: two parallel edges of opposite polarity 40 px apart.
  constexpr int kWidth = 240, kHeight = 180;
  const LineParams left{100.0, 0.1}, right{140.0, 0.1};
  vpImage<unsigned char> image = test::SyntheticEdge(kWidth, kHeight, left, 30.0, 200.0, 0.0, 1);
  const vpImage<unsigned char> second =
      test::SyntheticEdge(kWidth, kHeight, right, 200.0, 30.0, 0.0, 1);
  for (unsigned v = 0; v < image.getHeight(); ++v) {
    for (unsigned u = 0; u < image.getWidth(); ++u) {
      image[v][u] = std::min(image[v][u], second[v][u]);
    }
  }
  EdgeReferenceOptions options;
  options.polarity = EdgePolarity::kBrighterPositive;
  const EdgeReference rising = FitEdgeReference(image, options);
  ASSERT_EQ(rising.status, EdgeReferenceStatus::kFound);
  EXPECT_NEAR(rising.line.rho_px, left.rho_px, 0.1);
  options.polarity = EdgePolarity::kBrighterNegative;
  const EdgeReference falling = FitEdgeReference(image, options);
  ASSERT_EQ(falling.status, EdgeReferenceStatus::kFound);
  EXPECT_NEAR(falling.line.rho_px, right.rho_px, 0.1);
  // A prior near the right edge finds it whatever the polarity option.
  const EdgeReference near_prior =
      FitEdgeReference(image, EdgeReferenceOptions(), LineParams{137.0, 0.12});
  ASSERT_EQ(near_prior.status, EdgeReferenceStatus::kFound);
  EXPECT_NEAR(near_prior.line.rho_px, right.rho_px, 0.1);
  // A uniform image has no edge.
  const vpImage<unsigned char> flat(kHeight, kWidth, 128);
  const EdgeReference none = FitEdgeReference(flat, EdgeReferenceOptions());
  EXPECT_EQ(none.status, EdgeReferenceStatus::kTooFewPoints);
  EXPECT_FALSE(none.message.empty());
}

TEST(EdgeReference, OptionsCheckNamesTheField) {
  EdgeReferenceOptions options;
  options.inlier_px = -1.0;
  try {
    options.Check();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("inlier_px = -1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ToString(EdgePolarity::kBrighterNegative), "brighter-negative");
}

// Direction (angle) of the normal pointing to the bright side.
double BrightDirection(const EdgeReference& ref) {
  return ref.line.theta_rad + (ref.polarity == EdgePolarity::kBrighterPositive ? 0.0 : kPi);
}

const std::string kLineDir = std::string(OAL_VISP_IMAGES_DIR) + "/line";

TEST(EdgeReference, RealLineSequenceFitsEveryFrame) {
  if (!std::filesystem::exists(kLineDir + "/image.0001.pgm")) {
    GTEST_SKIP() << "ViSP's line/ sequence not found under " << kLineDir
                 << " (Debian package visp-images-data)";
  }
  constexpr double kMaxRmsPx = 0.5;
  constexpr double kMaxFrameToFrameDeg = 5.0;
  const std::vector<FrameReference> refs =
      FitEdgeSequence(kLineDir + "/image.%04d.pgm", 1, 33, EdgeReferenceOptions());
  ASSERT_EQ(refs.size(), 33u);
  // Frame 1: the edge that ViSP's trackMeLine example initialises on, near (row 96, col 191).
  ASSERT_EQ(refs[0].reference.status, EdgeReferenceStatus::kFound);
  EXPECT_LT(std::fabs(refs[0].reference.line.SignedDistance(191.0, 96.0)), 5.0);
  std::ostringstream table;
  for (std::size_t k = 0; k < refs.size(); ++k) {
    const EdgeReference& ref = refs[k].reference;
    ASSERT_EQ(ref.status, EdgeReferenceStatus::kFound)
        << "frame " << refs[k].frame << ": " << ref.message;
    EXPECT_LT(ref.rms_residual_px, kMaxRmsPx) << "frame " << refs[k].frame;
    EXPECT_GE(ref.points, 30) << "frame " << refs[k].frame;
    // The same physical polarity as frame 1: bright sides point the same way.
    EXPECT_GT(std::cos(BrightDirection(ref) - BrightDirection(refs[0].reference)), 0.0)
        << "frame " << refs[k].frame;
    if (k > 0) {
      EXPECT_LT(AngleErrorDeg(refs[k - 1].reference.line, ref.line), kMaxFrameToFrameDeg)
          << "frame " << refs[k].frame;
    }
    table << refs[k].frame << " rho " << ref.line.rho_px << " theta_deg "
          << ref.line.theta_rad * 180.0 / kPi << " points " << ref.points << " rms "
          << ref.rms_residual_px << " max " << ref.max_residual_px << "\n";
  }
  std::cout << table.str();

  // The residual is not an artefact of the support window: doubling inlier_px adds almost no
  // point to any frame.
  EdgeReferenceOptions wide;
  wide.inlier_px = 2.0 * EdgeReferenceOptions().inlier_px;
  const std::vector<FrameReference> wide_refs =
      FitEdgeSequence(kLineDir + "/image.%04d.pgm", 1, 33, wide);
  ASSERT_EQ(wide_refs.size(), refs.size());
  for (std::size_t k = 0; k < refs.size(); ++k) {
    ASSERT_EQ(wide_refs[k].reference.status, EdgeReferenceStatus::kFound);
    EXPECT_LE(wide_refs[k].reference.points, refs[k].reference.points * 102 / 100 + 1)
        << "frame " << refs[k].frame;
    EXPECT_LT(wide_refs[k].reference.rms_residual_px, kMaxRmsPx) << "frame " << refs[k].frame;
  }
}

TEST(EdgeReference, TruthCsvHasOneRowPerFoundFrame) {
  test::TestDir dir;
  std::vector<FrameReference> refs(3);
  refs[0].frame = 1;
  refs[0].reference.status = EdgeReferenceStatus::kFound;
  refs[0].reference.line = LineParams{12.5, 0.25};
  refs[1].frame = 2;  // not found: no row
  refs[2].frame = 3;
  refs[2].reference.status = EdgeReferenceStatus::kFound;
  refs[2].reference.line = LineParams{-3.0, 3.0};
  WriteTruthCsv(refs, std::filesystem::path(dir / "truth.csv"));
  std::ifstream in(dir / "truth.csv");
  std::stringstream content;
  content << in.rdbuf();
  EXPECT_EQ(content.str(), "frame,line,rho,theta\n1,0,12.5,0.25\n3,0,-3,3\n");
}

}  // namespace
}  // namespace oal
