// Targets, option checks and construction errors.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "scene/scene.h"

namespace oal {
namespace {

// The message of the std::invalid_argument thrown by `f`, or "" if none.
template <typename F>
std::string InvalidArgumentMessage(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

bool IsVertical(const TargetLine& line) {
  return line.x1_m == line.x2_m;
}

TEST(Targets, TargetByNameReturnsTheShippedTargets) {
  EXPECT_EQ(TargetByName("two-line").name, "two-line");
  EXPECT_EQ(TargetByName("two-line").lines.size(), 2u);
  EXPECT_EQ(TargetByName("four-line").name, "four-line-board");  // the older name
  EXPECT_EQ(TargetByName("four-line-board").name, "four-line-board");
  for (const std::string& name : TargetNames()) EXPECT_EQ(TargetByName(name).name, name);
  EXPECT_EQ(TargetByName("four-line").lines.size(), 4u);
  const std::string message = InvalidArgumentMessage([] { TargetByName("nope"); });
  EXPECT_NE(message.find("'nope'"), std::string::npos) << message;
}

TEST(Targets, TwoLineTargetIsTwoParallelStripesAcrossTheBoard) {
  const LineTarget target = TwoLineTarget();
  EXPECT_NO_THROW(target.Check());
  ASSERT_EQ(target.lines.size(), 2u);
  for (const TargetLine& line : target.lines) {
    EXPECT_TRUE(IsVertical(line));
    EXPECT_DOUBLE_EQ(std::fabs(line.y2_m - line.y1_m), target.board_height_m);
    EXPECT_DOUBLE_EQ(line.width_m, 0.02);
  }
  EXPECT_DOUBLE_EQ(target.lines[1].x1_m - target.lines[0].x1_m, 0.12);
  EXPECT_LT(target.line_grey, target.board_grey);
}

TEST(Targets, FourLineTargetLinesAreDistinguishable) {
  const LineTarget target = FourLineTarget();
  EXPECT_NO_THROW(target.Check());
  ASSERT_EQ(target.lines.size(), 4u);
  // Line 1 (index 0) is the widest; all widths differ.
  for (std::size_t i = 1; i < 4; ++i) {
    EXPECT_GT(target.lines[0].width_m, target.lines[i].width_m + 0.005) << i;
    for (std::size_t j = i + 1; j < 4; ++j) {
      EXPECT_NE(target.lines[i].width_m, target.lines[j].width_m) << i << " " << j;
    }
  }
  // Two vertical (0, 2) and two horizontal (1, 3) stripes spanning the board, with
  // different spacings, crossing within 0.13 m of the centre.
  EXPECT_TRUE(IsVertical(target.lines[0]));
  EXPECT_TRUE(IsVertical(target.lines[2]));
  EXPECT_EQ(target.lines[1].y1_m, target.lines[1].y2_m);
  EXPECT_EQ(target.lines[3].y1_m, target.lines[3].y2_m);
  const double vertical_gap = std::fabs(target.lines[2].x1_m - target.lines[0].x1_m);
  const double horizontal_gap = std::fabs(target.lines[3].y1_m - target.lines[1].y1_m);
  EXPECT_GT(std::fabs(vertical_gap - horizontal_gap), 0.03);
  // Asymmetric about the centre, so the '#' has no symmetry that swaps lines.
  EXPECT_NE(target.lines[0].x1_m, -target.lines[2].x1_m);
  EXPECT_NE(target.lines[1].y1_m, -target.lines[3].y1_m);
  for (int v : {0, 2}) {
    EXPECT_DOUBLE_EQ(std::fabs(target.lines[v].y2_m - target.lines[v].y1_m), 2.0);
    for (int h : {1, 3}) {
      EXPECT_DOUBLE_EQ(std::fabs(target.lines[h].x2_m - target.lines[h].x1_m), 2.0);
      EXPECT_LT(std::hypot(target.lines[v].x1_m, target.lines[h].y1_m), 0.13);
    }
  }
}

TEST(LineTargetCheck, NamesTheFieldValueAndConstraint) {
  LineTarget target = FourLineTarget();
  target.lines[2].width_m = -1.0;
  EXPECT_EQ(InvalidArgumentMessage([&] { target.Check(); }),
            "LineTarget::lines[2].width_m = -1. Violated constraint: width_m > 0");
}

TEST(LineTargetCheck, RejectsEachBadField) {
  const auto message_for = [](auto mutate) {
    LineTarget target = TwoLineTarget();
    mutate(target);
    return InvalidArgumentMessage([&] { target.Check(); });
  };
  EXPECT_NE(message_for([](LineTarget& t) {
              t.board_width_m = 0.0;
            }).find("LineTarget::board_width_m = 0."),
            std::string::npos);
  EXPECT_NE(message_for([](LineTarget& t) {
              t.board_height_m = -2.0;
            }).find("LineTarget::board_height_m = -2."),
            std::string::npos);
  EXPECT_NE(message_for([](LineTarget& t) { t.line_grey = 300; }).find("LineTarget::line_grey"),
            std::string::npos);
  EXPECT_NE(message_for([](LineTarget& t) { t.board_grey = -1; }).find("LineTarget::board_grey"),
            std::string::npos);
  EXPECT_NE(message_for([](LineTarget& t) {
              t.lines[1].x2_m = t.lines[1].x1_m, t.lines[1].y2_m = t.lines[1].y1_m;
            }).find("LineTarget::lines[1].length"),
            std::string::npos);
  EXPECT_NE(message_for([](LineTarget& t) {
              t.lines[0].y1_m = std::nan("");
            }).find("LineTarget::lines[0].y1_m"),
            std::string::npos);
  EXPECT_EQ(message_for([](LineTarget& t) { t.lines.clear(); }), "");  // a blank board is fine
}

TEST(RenderOptionsCheck, RejectsEachBadField) {
  const auto message_for = [](auto mutate) {
    RenderOptions options;
    mutate(options);
    return InvalidArgumentMessage([&] { options.Check(); });
  };
  EXPECT_EQ(message_for([](RenderOptions&) {}), "");
  EXPECT_EQ(message_for([](RenderOptions& o) { o.width = 8; }),
            "RenderOptions::width = 8. Violated constraint: 16 <= width <= 8192");
  EXPECT_NE(message_for([](RenderOptions& o) { o.height = 9000; }).find("RenderOptions::height"),
            std::string::npos);
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.noise_sigma = -1.0;
            }).find("RenderOptions::noise_sigma = -1."),
            std::string::npos);
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.blur_sigma_px = 25.0;
            }).find("RenderOptions::blur_sigma_px"),
            std::string::npos);
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.illumination_gradient = 0.95;
            }).find("RenderOptions::illumination_gradient"),
            std::string::npos);
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.gradient_angle_rad = INFINITY;
            }).find("RenderOptions::gradient_angle_rad"),
            std::string::npos);
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.background_grey = 256;
            }).find("RenderOptions::background_grey"),
            std::string::npos);
  EXPECT_NE(
      message_for([](RenderOptions& o) { o.supersample = 0; }).find("RenderOptions::supersample"),
      std::string::npos);
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.camera = vpCameraParameters(-600, 600, 320, 240);
            }).find("RenderOptions::camera.px"),
            std::string::npos);
  // A kdu so negative that the pixel -> ray map folds over inside the image.
  EXPECT_NE(message_for([](RenderOptions& o) {
              o.camera = Lens::WithKudKdu(600, 600, 319.5, 239.5, 0.0, -1.0);
            }).find("RenderOptions::camera.kdu"),
            std::string::npos);
}

TEST(PoseSamplingCheck, RejectsEachBadField) {
  const auto message_for = [](auto mutate) {
    PoseSampling sampling;
    mutate(sampling);
    return InvalidArgumentMessage([&] { sampling.Check(); });
  };
  EXPECT_EQ(message_for([](PoseSampling&) {}), "");
  EXPECT_NE(message_for([](PoseSampling& s) {
              s.min_distance_m = 0.0;
            }).find("PoseSampling::min_distance_m"),
            std::string::npos);
  EXPECT_NE(message_for([](PoseSampling& s) {
              s.max_distance_m = 0.3;
            }).find("PoseSampling::max_distance_m"),
            std::string::npos);
  EXPECT_NE(message_for([](PoseSampling& s) {
              s.max_tilt_deg = 85.0;
            }).find("PoseSampling::max_tilt_deg"),
            std::string::npos);
  EXPECT_NE(message_for([](PoseSampling& s) {
              s.max_offset_m = -0.1;
            }).find("PoseSampling::max_offset_m"),
            std::string::npos);
  EXPECT_NE(message_for([](PoseSampling& s) {
              s.min_visible_length_px = -1.0;
            }).find("PoseSampling::min_visible_length_px"),
            std::string::npos);
}

TEST(SceneRenderer, ConstructorChecksTargetAndOptions) {
  LineTarget target = TwoLineTarget();
  target.lines[0].width_m = 0.0;
  EXPECT_THROW(SceneRenderer(target, RenderOptions()), std::invalid_argument);
  RenderOptions options;
  options.supersample = 9;
  EXPECT_THROW(SceneRenderer(TwoLineTarget(), options), std::invalid_argument);
}

}  // namespace
}  // namespace oal
