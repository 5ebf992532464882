#include "app/edge_reference.h"

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
#include "tests/test_util.h"

namespace oal {
namespace {

constexpr double kMaxOffsetPx = 0.05;
constexpr double kMaxAngleDeg = 0.05;

// A straight edge, exact box-filtered coverage (64 x 64 samples in the pixels it crosses):
// grey `dark` where u·cosθ + v·sinθ < ρ, `bright` beyond, rounded to 8 bits, plus optional
// Gaussian noise.
vpImage<unsigned char> SyntheticEdge(int width, int height, const LineParams& edge, double dark,
                                     double bright, double noise_sigma, unsigned seed) {
  constexpr int kSub = 64;
  const double c = std::cos(edge.theta_rad), s = std::sin(edge.theta_rad);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma > 0.0 ? noise_sigma : 1.0);
  vpImage<unsigned char> image(static_cast<unsigned>(height), static_cast<unsigned>(width));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double d = edge.SignedDistance(u, v);
      double coverage = d > 0.0 ? 1.0 : 0.0;
      if (std::fabs(d) < 0.75) {  // the pixel square may straddle the edge
        int inside = 0;
        for (int i = 0; i < kSub; ++i) {
          for (int j = 0; j < kSub; ++j) {
            const double uu = u - 0.5 + (i + 0.5) / kSub, vv = v - 0.5 + (j + 0.5) / kSub;
            inside += uu * c + vv * s > edge.rho_px ? 1 : 0;
          }
        }
        coverage = static_cast<double>(inside) / (kSub * kSub);
      }
      double grey = dark + (bright - dark) * coverage;
      if (noise_sigma > 0.0) grey += noise(rng);
      image[v][u] = static_cast<unsigned char>(std::lround(std::clamp(grey, 0.0, 255.0)));
    }
  }
  return image;
}

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
          dark_positive ? SyntheticEdge(kWidth, kHeight, truth, 210.0, 30.0, 0.0, 1)
                        : SyntheticEdge(kWidth, kHeight, truth, 30.0, 210.0, 0.0, 1);
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
  const vpImage<unsigned char> image = SyntheticEdge(kWidth, kHeight, truth, 40.0, 190.0, 3.0, 9);
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
  vpImage<unsigned char> image = SyntheticEdge(kWidth, kHeight, left, 30.0, 200.0, 0.0, 1);
  const vpImage<unsigned char> second = SyntheticEdge(kWidth, kHeight, right, 200.0, 30.0, 0.0, 1);
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
             : SyntheticEdge(size, size, LineParams{size / 2.0 - 5.5 + frame, 0.0}, 40.0, 200.0,
                             0.0, 1);
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
