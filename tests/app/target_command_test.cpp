#include "app/target_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/config.h"
#include "app/render_command.h"
#include "scene/scene.h"
#include "tests/app/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

constexpr double kToleranceMm = 0.01;  // drawing coordinates against the target geometry

struct Point {
  double x = 0.0, y = 0.0;
};

// The value of attribute `name` of the first element matching `element` (a regex prefix such
// as `<rect id="board"`), or throws.
std::string Attribute(const std::string& svg, const std::string& element, const std::string& name) {
  const std::size_t begin = svg.find(element);
  if (begin == std::string::npos) throw std::runtime_error("no element " + element);
  const std::size_t end = svg.find('>', begin);
  const std::string tag = svg.substr(begin, end - begin);
  const std::regex pattern("\\s" + name + "=\"([^\"]*)\"");
  std::smatch match;
  if (!std::regex_search(tag, match, pattern))
    throw std::runtime_error("no " + name + " in " + tag);
  return match[1];
}

double Number(const std::string& svg, const std::string& element, const std::string& name) {
  return std::stod(Attribute(svg, element, name));
}

// The `points` of every stripe polygon, in document order.
std::vector<std::vector<Point>> StripePolygons(const std::string& svg) {
  std::vector<std::vector<Point>> polygons;
  const std::regex pattern("<polygon class=\"stripe\" id=\"line-\\d+\" points=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), pattern);
       it != std::sregex_iterator(); ++it) {
    std::vector<Point> polygon;
    std::istringstream in((*it)[1].str());
    std::string pair;
    while (in >> pair) {
      const std::size_t comma = pair.find(',');
      polygon.push_back(Point{std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1))});
    }
    polygons.push_back(polygon);
  }
  return polygons;
}

int Count(const std::string& text, const std::string& what) {
  int count = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

// The SVG's page is in millimetres and its viewBox in the same numbers: 1 unit = 1 mm.
void ExpectTrueScale(const std::string& svg, double width_mm, double height_mm) {
  ASSERT_EQ(svg.rfind("<svg", 0), 0u) << svg.substr(0, 80);
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  const std::string width = Attribute(svg, "<svg", "width");
  const std::string height = Attribute(svg, "<svg", "height");
  ASSERT_EQ(width.substr(width.size() - 2), "mm");
  ASSERT_EQ(height.substr(height.size() - 2), "mm");
  EXPECT_NEAR(std::stod(width), width_mm, 1e-9);
  EXPECT_NEAR(std::stod(height), height_mm, 1e-9);
  std::istringstream view_box(Attribute(svg, "<svg", "viewBox"));
  double x0 = -1.0, y0 = -1.0, w = 0.0, h = 0.0;
  view_box >> x0 >> y0 >> w >> h;
  EXPECT_EQ(x0, 0.0);
  EXPECT_EQ(y0, 0.0);
  EXPECT_NEAR(w, width_mm, 1e-9);
  EXPECT_NEAR(h, height_mm, 1e-9);
  // The scale bar spans 100 viewBox units, i.e. 100 mm on paper.
  EXPECT_NEAR(
      Number(svg, "<line id=\"scale-bar\"", "x2") - Number(svg, "<line id=\"scale-bar\"", "x1"),
      100.0, 1e-9);
  EXPECT_EQ(Number(svg, "<line id=\"scale-bar\"", "y1"),
            Number(svg, "<line id=\"scale-bar\"", "y2"));
  EXPECT_THAT(svg, HasSubstr(">100 mm</text>"));
  EXPECT_THAT(svg, HasSubstr("print at 100 %, do not scale"));
}

// Every stripe polygon, converted back to metres on the board (origin at the centre of the
// board rectangle), is the rectangle of its target line.
void ExpectStripesMatch(const std::string& svg, const LineTarget& target) {
  const double board_x = Number(svg, "<rect id=\"board\"", "x");
  const double board_y = Number(svg, "<rect id=\"board\"", "y");
  const double board_w = Number(svg, "<rect id=\"board\"", "width");
  const double board_h = Number(svg, "<rect id=\"board\"", "height");
  EXPECT_NEAR(board_w, 1000.0 * target.board_width_m, kToleranceMm);
  EXPECT_NEAR(board_h, 1000.0 * target.board_height_m, kToleranceMm);
  const double cx = board_x + 0.5 * board_w, cy = board_y + 0.5 * board_h;

  const std::vector<std::vector<Point>> polygons = StripePolygons(svg);
  ASSERT_EQ(polygons.size(), target.lines.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    SCOPED_TRACE("line " + std::to_string(i + 1));
    const TargetLine& line = target.lines[i];
    ASSERT_EQ(polygons[i].size(), 4u);
    const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
    const double length = std::hypot(dx, dy);
    const double nx = -dy / length * 0.5 * line.width_m, ny = dx / length * 0.5 * line.width_m;
    const Point expected[4] = {{line.x1_m + nx, line.y1_m + ny},
                               {line.x2_m + nx, line.y2_m + ny},
                               {line.x2_m - nx, line.y2_m - ny},
                               {line.x1_m - nx, line.y1_m - ny}};
    for (int k = 0; k < 4; ++k) {
      // Back to millimetres on the board.
      const double x_mm = polygons[i][k].x - cx, y_mm = polygons[i][k].y - cy;
      EXPECT_NEAR(x_mm, 1000.0 * expected[k].x, kToleranceMm) << "corner " << k;
      EXPECT_NEAR(y_mm, 1000.0 * expected[k].y, kToleranceMm) << "corner " << k;
    }
    // Its width across, from the drawing alone.
    EXPECT_NEAR(
        std::hypot(polygons[i][0].x - polygons[i][3].x, polygons[i][0].y - polygons[i][3].y),
        1000.0 * line.width_m, kToleranceMm);
  }
}

// A board that fits on A4 with a diagonal line and odd numbers.
LineTarget SmallTarget() {
  LineTarget target;
  target.name = "small";
  target.board_width_m = 0.15;
  target.board_height_m = 0.2;
  target.lines = {TargetLine{-0.05, -0.1, -0.05, 0.1, 0.012},
                  TargetLine{-0.075, 0.031, 0.075, -0.0423, 0.00733},
                  TargetLine{0.0, -0.1, 0.07, 0.1, 0.005}};
  return target;
}

TEST(TargetSvg, SmallBoardOnA4AtTrueScale) {
  const LineTarget target = SmallTarget();
  const TargetDrawing drawing = DrawTargetSvg(target, "a4");
  EXPECT_TRUE(drawing.fits);
  EXPECT_TRUE(drawing.warning.empty());
  EXPECT_EQ(drawing.page, "A4 portrait");
  ExpectTrueScale(drawing.svg, 210.0, 297.0);
  ExpectStripesMatch(drawing.svg, target);
  // Numbers 1..3 beside both ends of each line.
  EXPECT_EQ(Count(drawing.svg, "<text class=\"line-number\""), 6);
  for (const char* number : {">1</text>", ">2</text>", ">3</text>"}) {
    EXPECT_EQ(Count(drawing.svg, number), 2) << number;
  }
  EXPECT_THAT(drawing.svg, HasSubstr("target small: board 150 x 200 mm, 3 lines"));
}

TEST(TargetSvg, PagesAndOrientation) {
  LineTarget wide = SmallTarget();
  wide.board_width_m = 0.25;  // A4 only in landscape
  wide.board_height_m = 0.12;
  const TargetDrawing a4 = DrawTargetSvg(wide, "a4");
  EXPECT_EQ(a4.page, "A4 landscape");
  ExpectTrueScale(a4.svg, 297.0, 210.0);
  const TargetDrawing letter = DrawTargetSvg(SmallTarget(), "letter");
  EXPECT_EQ(letter.page, "US letter portrait");
  ExpectTrueScale(letter.svg, 215.9, 279.4);
  LineTarget large = SmallTarget();
  large.board_width_m = 0.25;  // A3 portrait, not A4
  large.board_height_m = 0.3;
  const TargetDrawing automatic = DrawTargetSvg(large, "auto");
  EXPECT_TRUE(automatic.fits);
  EXPECT_EQ(automatic.page, "A3 portrait");
  ExpectStripesMatch(automatic.svg, large);
  EXPECT_FALSE(DrawTargetSvg(large, "a4").fits);
  EXPECT_THROW(DrawTargetSvg(SmallTarget(), "a5"), std::invalid_argument);
}

TEST(TargetSvg, FourLineBoardTooLargeIsFullSizeWithAWarning) {
  const LineTarget target = FourLineTarget();
  const TargetDrawing drawing = DrawTargetSvg(target, "a4");
  EXPECT_FALSE(drawing.fits);
  EXPECT_EQ(drawing.page, "full size");
  EXPECT_THAT(drawing.warning, HasSubstr("does not fit on A4"));
  EXPECT_THAT(drawing.warning, HasSubstr("board 2000 x 2000 mm"));
  EXPECT_THAT(drawing.warning, HasSubstr("full size"));
  EXPECT_GT(drawing.page_width_mm, 2000.0);
  ExpectTrueScale(drawing.svg, drawing.page_width_mm, drawing.page_height_mm);
  ExpectStripesMatch(drawing.svg, target);
  EXPECT_EQ(Count(drawing.svg, "<polygon class=\"stripe\""), 4);
  EXPECT_THAT(DrawTargetSvg(target, "auto").warning, HasSubstr("does not fit on A3"));
}

// The built-in boards are 2 m x 2 m (scene/scene.cpp, config/*-target.yaml), so every page
// warns; the warning says how to print it, and the largest board it names for one sheet fits.
TEST(TargetSvg, TooLargeWarningSaysHowToPrintAndWhichBoardFits) {
  for (const LineTarget& target : {FourLineTarget(), TwoLineTarget()}) {
    EXPECT_EQ(target.board_width_m, 2.0) << target.name;
    EXPECT_EQ(target.board_height_m, 2.0) << target.name;
  }
  const std::string warning = DrawTargetSvg(FourLineTarget(), "a4").warning;
  EXPECT_THAT(warning, HasSubstr("plotter"));
  EXPECT_THAT(warning, HasSubstr("tiled with a poster tool onto about"));
  EXPECT_THAT(warning, HasSubstr("scaled by the same factor"));
  EXPECT_THAT(warning, HasSubstr("For one A4 sheet, draw a board of at most 190 x 241 mm"));
  EXPECT_THAT(DrawTargetSvg(FourLineTarget(), "a3").warning,
              HasSubstr("For one A3 sheet, draw a board of at most 277 x 364 mm"));
  // Just under those sizes a board fits; just over (in height) it does not.
  LineTarget board = SmallTarget();
  board.board_width_m = 0.1899;
  board.board_height_m = 0.2409;
  EXPECT_EQ(DrawTargetSvg(board, "a4").page, "A4 portrait");
  board.board_height_m = 0.2411;
  EXPECT_FALSE(DrawTargetSvg(board, "a4").fits);
  board.board_width_m = 0.2769;
  board.board_height_m = 0.3639;
  EXPECT_EQ(DrawTargetSvg(board, "a3").page, "A3 portrait");
  board.board_height_m = 0.3641;
  EXPECT_FALSE(DrawTargetSvg(board, "a3").fits);
}

TEST(TargetSvg, NameIsEscapedAndBadTargetsAreRejected) {
  LineTarget target = SmallTarget();
  target.name = "a<b&\"c\"";
  const std::string svg = DrawTargetSvg(target, "a4").svg;
  EXPECT_THAT(svg, HasSubstr("a&lt;b&amp;&quot;c&quot;"));
  EXPECT_THAT(svg, ::testing::Not(HasSubstr("a<b")));
  target.lines[0].width_m = 0.0;
  EXPECT_THROW(DrawTargetSvg(target, "a4"), std::invalid_argument);
}

TEST(TargetCommand, WritesTheConfigsTargetAtomically) {
  test::TestDir dir;
  const LineTarget expected = SmallTarget();
  test::WriteText(dir / "small.yaml",
                  "target:\n  name: small\n  board_width_m: 0.15\n  board_height_m: 0.2\n"
                  "  lines:\n"
                  "    - {from: [-0.05, -0.1], to: [-0.05, 0.1], width: 0.012}\n"
                  "    - {from: [-0.075, 0.031], to: [0.075, -0.0423], width: 0.00733}\n"
                  "    - {from: [0, -0.1], to: [0.07, 0.1], width: 0.005}\n");
  TargetCommandOptions options;
  options.config = dir / "small.yaml";
  options.out = dir / "small.svg";
  options.page = "a4";
  const TargetDrawing drawing = WriteTargetSvg(options);
  EXPECT_TRUE(drawing.fits);
  const std::string svg = test::ReadText(options.out);
  EXPECT_EQ(svg, drawing.svg);
  ExpectStripesMatch(svg, expected);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(TargetCommand, ShippedConfigsDrawTheBuiltInTargets) {
  test::TestDir dir;
  const std::string config_dir = std::string(OAL_SOURCE_DIR) + "/config/";
  TargetCommandOptions options;
  options.config = config_dir + "two-line-target.yaml";
  options.out = dir / "two.svg";
  WriteTargetSvg(options);
  ExpectStripesMatch(test::ReadText(options.out), TwoLineTarget());
  options.config.clear();  // no config: the built-in four-line target
  options.out = dir / "four.svg";
  EXPECT_FALSE(WriteTargetSvg(options).fits);
  ExpectStripesMatch(test::ReadText(options.out), FourLineTarget());
}

TEST(TargetCommand, BadOutputDirectoryIsAClearErrorAndLeavesNothing) {
  test::TestDir dir;
  TargetCommandOptions options;
  options.out = dir / "missing/target.svg";
  try {
    WriteTargetSvg(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("missing"));
    EXPECT_THAT(error.what(), HasSubstr("does not exist"));
  }
  options.out = dir.path().string();  // a directory
  EXPECT_THROW(WriteTargetSvg(options), std::runtime_error);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(TargetCommand, BadConfigNamesTheFile) {
  test::TestDir dir;
  test::WriteText(dir / "bad.yaml", "target:\n  name: five-line\n");
  TargetCommandOptions options;
  options.config = dir / "bad.yaml";
  options.out = dir / "t.svg";
  try {
    WriteTargetSvg(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr(dir / "bad.yaml:2: 'target.name' = 'five-line'"));
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "t.svg"));
}

// The binary: the command is in the table, warns about a large board and exits 0.
TEST(TargetCommand, BinaryWarnsAboutALargeBoard) {
  test::TestDir dir;
  const std::string command = std::string("'") + OAL_OALSERVO_PATH + "' target --out '" +
                              (dir / "four.svg") + "' --page a4 2>'" + (dir / "err.txt") + "'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const std::string err = test::ReadText(dir / "err.txt");
  EXPECT_THAT(err, HasSubstr("oalservo target: warning: target 'four-line-board'"));
  EXPECT_THAT(err, HasSubstr("does not fit on A4"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "four.svg"));
  // The help's examples: the built-in board without a page it cannot fit, and a board of
  // one's own of a size that fits the page it names.
  const std::string help =
      std::string("'") + OAL_OALSERVO_PATH + "' target --help >'" + (dir / "help.txt") + "'";
  ASSERT_EQ(std::system(help.c_str()), 0);
  const std::string help_text = test::ReadText(dir / "help.txt");
  EXPECT_THAT(help_text, HasSubstr("oalservo target --out four-line.svg\n"));
  EXPECT_THAT(help_text, HasSubstr("--page a3 --out board.svg"));
  EXPECT_THAT(help_text, HasSubstr("up to 277 x 364 mm, on one A3 sheet"));
  EXPECT_THAT(help_text, ::testing::Not(HasSubstr("two-line-target.yaml")));
  const std::string bad = std::string("'") + OAL_OALSERVO_PATH + "' target --out '" +
                          (dir / "x.svg") + "' --page a5 2>/dev/null";
  const int bad_status = std::system(bad.c_str());
  ASSERT_TRUE(WIFEXITED(bad_status));
  EXPECT_EQ(WEXITSTATUS(bad_status), 2);
}

// `oalservo render --config FILE` renders the config's target and names it in the truth.
TEST(TargetCommand, RenderTakesTheTargetFromAConfig) {
  test::TestDir dir;
  test::WriteText(dir / "desk.yaml",
                  "target:\n  name: desk\n  board_width_m: 0.6\n  board_height_m: 0.6\n"
                  "  lines:\n"
                  "    - {from: [-0.05, -0.3], to: [-0.05, 0.3], width: 0.02}\n"
                  "    - {from: [-0.3, 0.02], to: [0.3, 0.02], width: 0.01}\n"
                  "    - {from: [-0.3, -0.3], to: [0.3, 0.3], width: 0.01}\n");
  RenderCommandOptions options;
  options.config = dir / "desk.yaml";
  options.target = "ignored-with-a-config";
  options.count = 1;
  options.width = 64;
  options.height = 48;
  options.fx_px = 60.0;
  options.out_dir = dir / "data";
  ASSERT_EQ(RenderDataset(options), 1);
  const auto truth = nlohmann::json::parse(test::ReadText(dir / "data/frame_0000.json"));
  EXPECT_EQ(truth["target"], "desk");
  EXPECT_EQ(truth["lines"].size(), 3u);
}

}  // namespace
}  // namespace oal
