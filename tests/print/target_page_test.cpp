#include "print/target_page.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "print/target_svg.h"
#include "tests/print/svg_reading.h"

namespace oal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using namespace test;  // the SVG reading helpers

// Each sheet target on its own page: the page is exactly the sheet, portrait with the target
// turned, or on a landscape page upright; its stripes are the target's to 0.01 mm.
TEST(TargetCommandSvg, SheetTargetsOnTheirOwnPage) {
  for (const SheetCase& sheet : kSheetCases) {
    SCOPED_TRACE(sheet.page);
    const LineTarget target = sheet.target();
    EXPECT_NEAR(target.board_width_m * 1000.0, sheet.long_mm, 1e-9);
    EXPECT_NEAR(target.board_height_m * 1000.0, sheet.short_mm, 1e-9);

    const TargetPage portrait = DrawTargetPage(target, sheet.page);
    EXPECT_EQ(portrait.page, std::string(sheet.label) + " portrait");
    EXPECT_TRUE(portrait.turned);
    EXPECT_THAT(portrait.note, HasSubstr("drawn turned by 90 degrees"));
    EXPECT_THAT(portrait.note, HasSubstr("or lay it out on a landscape page"));
    EXPECT_TRUE(portrait.warning.empty()) << portrait.warning;
    EXPECT_THAT(TargetSvg(portrait), HasSubstr("drawn turned by 90 degrees clockwise"));
    ExpectPage(TargetSvg(portrait), sheet.short_mm, sheet.long_mm);
    ExpectStripesMatch(TargetSvg(portrait), target, sheet.short_mm, sheet.long_mm, true);

    const TargetPage landscape = DrawTargetPage(target, sheet.page, true);
    EXPECT_EQ(landscape.page, std::string(sheet.label) + " landscape");
    EXPECT_FALSE(landscape.turned);
    EXPECT_TRUE(landscape.note.empty());
    EXPECT_THAT(TargetSvg(landscape), Not(HasSubstr("turned")));
    ExpectPage(TargetSvg(landscape), sheet.long_mm, sheet.short_mm);
    ExpectStripesMatch(TargetSvg(landscape), target, sheet.long_mm, sheet.short_mm, false);

    for (const TargetPage* drawing : {&portrait, &landscape}) {
      // Numbers 1-4 beside both ends of each stripe, the name, the note, the scale bar.
      EXPECT_EQ(Count(TargetSvg(*drawing), "<text class=\"line-number\""), 8);
      for (const char* number : {">1</text>", ">2</text>", ">3</text>", ">4</text>"}) {
        EXPECT_EQ(Count(TargetSvg(*drawing), number), 2) << number;
      }
      EXPECT_THAT(TargetSvg(*drawing), HasSubstr(">target " + target.name + "</text>"));
      EXPECT_THAT(TargetSvg(*drawing),
                  HasSubstr("<title>oalservo target " + target.name + "</title>"));
      ExpectScaleBar(TargetSvg(*drawing));
      // No board outline (the sheet is the board), and nothing for a renderer to clip.
      EXPECT_EQ(Count(TargetSvg(*drawing), "<rect"), 0);
      EXPECT_THAT(TargetSvg(*drawing), Not(HasSubstr("clip")));
    }
  }
}

// Each line number sits beside an end of its own stripe: nearer to that end than to any
// other stripe's end.
TEST(TargetCommandSvg, LineNumbersAreBesideTheirStripesEnds) {
  for (const SheetCase& sheet : kSheetCases) {
    const LineTarget target = sheet.target();
    const TargetPage drawing = DrawTargetPage(target, sheet.page, true);
    const double cx = 0.5 * drawing.page_width_mm, cy = 0.5 * drawing.page_height_mm;
    for (const Text& text : Texts(TargetSvg(drawing))) {
      if (text.tag.find("line-number") == std::string::npos) continue;
      SCOPED_TRACE(std::string(sheet.page) + " " + text.tag + text.content);
      double nearest = std::numeric_limits<double>::infinity();
      std::size_t nearest_line = 0;
      for (std::size_t i = 0; i < target.lines.size(); ++i) {
        const TargetLine& line = target.lines[i];
        for (const Point end : {Point{cx + 1000.0 * line.x1_m, cy + 1000.0 * line.y1_m},
                                Point{cx + 1000.0 * line.x2_m, cy + 1000.0 * line.y2_m}}) {
          const double d = std::hypot(text.at.x - end.x, text.at.y - end.y);
          if (d < nearest) {
            nearest = d;
            nearest_line = i;
          }
        }
      }
      EXPECT_EQ(text.content, std::to_string(nearest_line + 1));
      EXPECT_LT(nearest, 30.0);
    }
  }
}

// Nothing but the stripes comes within 5 mm of a stripe or of the page's edge, nothing is in
// the middle cell, texts are at most 4 mm and strokes at most 0.5 mm: on every built-in's page,
// both orientations, the board at full size and a board of one's own.
TEST(TargetCommandSvg, EverythingElseIsSmallThinAndClearOfTheStripesAndTheEdge) {
  for (const SheetCase& sheet : kSheetCases) {
    const LineTarget target = sheet.target();
    for (const bool landscape : {false, true}) {
      SCOPED_TRACE(std::string(sheet.page) + (landscape ? " landscape" : " portrait"));
      const TargetPage drawing = DrawTargetPage(target, sheet.page, landscape);
      const Polygon middle =
          MiddleCell(target, drawing.page_width_mm, drawing.page_height_mm, drawing.turned);
      // 8 numbers, 3 legend lines, the scale label; the bar and 11 ticks.
      EXPECT_EQ(ExpectClearOfStripesAndEdge(TargetSvg(drawing), drawing.page_width_mm,
                                            drawing.page_height_mm, &middle),
                8 + 3 + 1 + 1 + 11);
    }
  }
  const TargetPage board = DrawTargetPage(FourLineTarget(), "full");
  const Polygon middle =
      MiddleCell(FourLineTarget(), board.page_width_mm, board.page_height_mm, false);
  EXPECT_EQ(ExpectClearOfStripesAndEdge(TargetSvg(board), board.page_width_mm, board.page_height_mm,
                                        &middle),
            24);
  const TargetPage two = DrawTargetPage(TwoLineTarget(), "full");
  EXPECT_EQ(ExpectClearOfStripesAndEdge(TargetSvg(two), two.page_width_mm, two.page_height_mm), 20);
  const TargetPage small = DrawTargetPage(SmallTarget(), "a4");
  EXPECT_GE(ExpectClearOfStripesAndEdge(TargetSvg(small), 210.0, 297.0), 16);
}

TEST(TargetCommandSvg, LineNumbersStandApartFromTheScaleBarAndTheLegend) {
  // A number next to the scale bar's end reads as part of the bar: numbers keep 6 mm from
  // every other mark (their middles, farther still).
  const auto distance = [](const PagePoint& p, const PagePoint& a, const PagePoint& b) {
    const double dx = b.x_mm - a.x_mm, dy = b.y_mm - a.y_mm;
    const double t = std::clamp(
        ((p.x_mm - a.x_mm) * dx + (p.y_mm - a.y_mm) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    return std::hypot(p.x_mm - (a.x_mm + t * dx), p.y_mm - (a.y_mm + t * dy));
  };
  for (const char* page_name : {"a4", "a3", "letter"}) {
    for (const bool landscape : {false, true}) {
      const TargetPage page =
          DrawTargetPage(TargetByName(SheetTargetName(page_name)), page_name, landscape);
      SCOPED_TRACE(page.page);
      int numbers = 0;
      for (const PageText& number : page.texts) {
        if (number.klass != "line-number") continue;
        ++numbers;
        for (const PageLine& line : page.lines) {
          EXPECT_GT(distance(number.at, line.a, line.b), 6.0) << number.text;
        }
        for (const PageText& other : page.texts) {
          if (other.klass == "line-number") continue;
          EXPECT_GT(std::hypot(number.at.x_mm - other.at.x_mm, number.at.y_mm - other.at.y_mm), 6.0)
              << number.text << " and " << other.text;
        }
      }
      EXPECT_EQ(numbers, 8);
    }
  }
}

TEST(TargetCommandSvg, ScaleBarIsExactly100mm) {
  for (const SheetCase& sheet : kSheetCases) {
    for (const bool landscape : {false, true}) {
      SCOPED_TRACE(std::string(sheet.page) + (landscape ? " landscape" : " portrait"));
      ExpectScaleBar(TargetSvg(DrawTargetPage(sheet.target(), sheet.page, landscape)));
    }
  }
  ExpectScaleBar(TargetSvg(DrawTargetPage(FourLineTarget(), "full")));
  ExpectScaleBar(TargetSvg(DrawTargetPage(SmallTarget(), "a4")));
}

// A board of one's own: upright when it fits so, else turned; portrait unless landscape.
TEST(TargetCommandSvg, PagesAndOrientation) {
  const TargetPage small = DrawTargetPage(SmallTarget(), "a4");
  EXPECT_EQ(small.page, "A4 portrait");
  EXPECT_FALSE(small.turned);
  ExpectPage(TargetSvg(small), 210.0, 297.0);
  ExpectStripesMatch(TargetSvg(small), SmallTarget(), 210.0, 297.0, false);
  EXPECT_EQ(Count(TargetSvg(small), "<text class=\"line-number\""), 6);

  LineTarget wide = SmallTarget();
  wide.board_width_m = 0.25;  // A4 only turned, or on a landscape page
  wide.board_height_m = 0.12;
  wide.lines[2] = TargetLine{0.0, -0.06, 0.07, 0.06, 0.005};
  const TargetPage turned = DrawTargetPage(wide, "a4");
  EXPECT_EQ(turned.page, "A4 portrait");
  EXPECT_TRUE(turned.turned);
  ExpectPage(TargetSvg(turned), 210.0, 297.0);
  ExpectStripesMatch(TargetSvg(turned), wide, 210.0, 297.0, true);
  const TargetPage upright = DrawTargetPage(wide, "a4", true);
  EXPECT_EQ(upright.page, "A4 landscape");
  EXPECT_FALSE(upright.turned);
  ExpectPage(TargetSvg(upright), 297.0, 210.0);
  ExpectStripesMatch(TargetSvg(upright), wide, 297.0, 210.0, false);

  const TargetPage letter = DrawTargetPage(SmallTarget(), "letter", true);
  EXPECT_EQ(letter.page, "US letter landscape");
  ExpectPage(TargetSvg(letter), 279.4, 215.9);
  const TargetPage a3 = DrawTargetPage(SmallTarget(), "a3");
  ExpectPage(TargetSvg(a3), 297.0, 420.0);
  ExpectStripesMatch(TargetSvg(a3), SmallTarget(), 297.0, 420.0, false);

  EXPECT_THROW(DrawTargetPage(SmallTarget(), "a5"), std::invalid_argument);
  EXPECT_THROW(DrawTargetPage(SmallTarget(), "auto"), std::invalid_argument);
  EXPECT_THROW(DrawTargetPage(SmallTarget(), "full", true), std::invalid_argument);
}

// --page full: the board at its full size with 10 mm around it (the 2 m board's only page).
TEST(TargetCommandSvg, FullPageIsTheBoardWithMargins) {
  const TargetPage board = DrawTargetPage(FourLineTarget(), "full");
  EXPECT_EQ(board.page, "full size");
  EXPECT_FALSE(board.turned);
  ExpectPage(TargetSvg(board), 2020.0, 2020.0);
  ExpectStripesMatch(TargetSvg(board), FourLineTarget(), 2020.0, 2020.0, false);
  EXPECT_EQ(Count(TargetSvg(board), "<text class=\"line-number\""), 8);
  EXPECT_THAT(TargetSvg(board), HasSubstr(">target four-line-board</text>"));
  EXPECT_THAT(TargetSvg(board), HasSubstr(">board 2000 x 2000 mm</text>"));
  // The stripes run to the board's edges: each is cut there (ExpectStripesMatch), the board
  // 10 mm in from the page's edge.
  double left = HUGE_VAL, right = -HUGE_VAL;
  for (const PageStripe& stripe : board.stripes) {
    for (const PagePoint& p : stripe.corners) {
      left = std::min(left, p.x_mm);
      right = std::max(right, p.x_mm);
    }
  }
  EXPECT_NEAR(left, 10.0, 1e-9);
  EXPECT_NEAR(right, 2010.0, 1e-9);
  const TargetPage a3 = DrawTargetPage(FourLineA3Target(), "full");
  ExpectPage(TargetSvg(a3), 440.0, 317.0);
  ExpectStripesMatch(TargetSvg(a3), FourLineA3Target(), 440.0, 317.0, false);
}

// A board the page holds in neither orientation is refused, saying what to print instead.
TEST(TargetCommandSvg, BoardLargerThanThePageIsRefused) {
  try {
    DrawTargetPage(FourLineTarget(), "a3");
    FAIL() << "no error";
  } catch (const TargetDoesNotFit& error) {
    const std::string message = error.what();
    EXPECT_THAT(message, HasSubstr("target 'four-line-board' (board 2000 x 2000 mm) does not fit "
                                   "on the A3 page (297 x 420 mm), upright or turned"));
    EXPECT_THAT(message, HasSubstr("nothing was written"));
    // In the library's own words (the command line says which options): the alternatives.
    EXPECT_THAT(message, HasSubstr("print the target made for this sheet (four-line-a3)"));
    EXPECT_THAT(message, HasSubstr("at its full size (2020 x 2020 mm, for a plotter or a print"));
    EXPECT_THAT(message, Not(HasSubstr("--")));
    EXPECT_THAT(message, Not(HasSubstr("a page that holds")));  // no sheet does
    EXPECT_EQ(error.alternatives().page, "a3");
    EXPECT_EQ(error.alternatives().page_target, "four-line-a3");
    EXPECT_TRUE(error.alternatives().larger.empty());
    EXPECT_EQ(error.alternatives().full_width_mm, 2020.0);
  }
  // The A3 target on an A4 page: the A4 target, or the A3 page.
  try {
    DrawTargetPage(FourLineA3Target(), "a4", true);
    FAIL() << "no error";
  } catch (const TargetDoesNotFit& error) {
    EXPECT_THAT(error.what(), HasSubstr("does not fit on the A4 page (297 x 210 mm)"));
    EXPECT_THAT(error.what(), HasSubstr("the target made for this sheet (four-line-a4)"));
    EXPECT_THAT(error.what(), HasSubstr("a page that holds this one (A3)"));
    EXPECT_EQ(error.alternatives().larger, std::vector<std::string>{"a3"});
  }
  // The A4 sheet is longer than US letter.
  EXPECT_THROW(DrawTargetPage(FourLineA4Target(), "letter"), TargetDoesNotFit);
  EXPECT_THROW(DrawTargetPage(TwoLineTarget(), "a4"), TargetDoesNotFit);
  // Letter and A4 fit upright on a portrait A3 page (a page larger than the sheet).
  EXPECT_FALSE(DrawTargetPage(FourLineLetterTarget(), "a3").turned);
  EXPECT_FALSE(DrawTargetPage(FourLineA4Target(), "a3").turned);
}

// A stripe of one's own target nearer than 5 mm to the page's edge is printed with a warning.
TEST(TargetCommandSvg, StripeNearThePageEdgeWarns) {
  LineTarget target;
  target.name = "to-the-edge";
  target.board_width_m = 0.210;
  target.board_height_m = 0.297;
  target.lines = {TargetLine{-0.05, -0.1485, -0.05, 0.1485, 0.02},
                  TargetLine{-0.095, 0.0, 0.095, 0.0, 0.01}};
  const TargetPage drawing = DrawTargetPage(target, "a4");
  EXPECT_THAT(drawing.warning, HasSubstr("line 1's stripe comes within 0 mm of the page's edge"));
  EXPECT_THAT(drawing.warning, Not(HasSubstr("line 2")));
  ExpectStripesMatch(TargetSvg(drawing), target, 210.0, 297.0, false);
}

TEST(TargetCommandSvg, NameIsEscapedAndBadTargetsAreRejected) {
  LineTarget target = SmallTarget();
  target.name = "a<b&\"c\"";
  const std::string svg = TargetSvg(DrawTargetPage(target, "a4"));
  EXPECT_THAT(svg, HasSubstr("a&lt;b&amp;&quot;c&quot;"));
  EXPECT_THAT(svg, Not(HasSubstr("a<b")));
  target.lines[0].width_m = 0.0;
  EXPECT_THROW(DrawTargetPage(target, "a4"), std::invalid_argument);
}

// ------------------------------------------------------------------------------------------
// The command.

}  // namespace
}  // namespace oal
