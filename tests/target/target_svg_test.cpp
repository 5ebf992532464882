#include "target/target_svg.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "tests/target/svg_reading.h"

namespace oal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using namespace test;  // the SVG reading helpers

// Each sheet target on its own page: the page is exactly the sheet, portrait with the target
// turned, or --landscape with it upright; its stripes are the target's to 0.01 mm.
TEST(TargetCommandSvg, SheetTargetsOnTheirOwnPage) {
  for (const SheetCase& sheet : kSheetCases) {
    SCOPED_TRACE(sheet.page);
    const LineTarget target = sheet.target();
    EXPECT_NEAR(target.board_width_m * 1000.0, sheet.long_mm, 1e-9);
    EXPECT_NEAR(target.board_height_m * 1000.0, sheet.short_mm, 1e-9);

    const TargetDrawing portrait = DrawTargetSvg(target, sheet.page);
    EXPECT_EQ(portrait.page, std::string(sheet.label) + " portrait");
    EXPECT_TRUE(portrait.turned);
    EXPECT_THAT(portrait.note, HasSubstr("drawn turned by 90 degrees"));
    EXPECT_THAT(portrait.note, HasSubstr("--landscape"));
    EXPECT_TRUE(portrait.warning.empty()) << portrait.warning;
    EXPECT_THAT(portrait.svg, HasSubstr("drawn turned by 90 degrees clockwise"));
    ExpectPage(portrait.svg, sheet.short_mm, sheet.long_mm);
    ExpectStripesMatch(portrait.svg, target, sheet.short_mm, sheet.long_mm, true);

    const TargetDrawing landscape = DrawTargetSvg(target, sheet.page, true);
    EXPECT_EQ(landscape.page, std::string(sheet.label) + " landscape");
    EXPECT_FALSE(landscape.turned);
    EXPECT_TRUE(landscape.note.empty());
    EXPECT_THAT(landscape.svg, Not(HasSubstr("turned")));
    ExpectPage(landscape.svg, sheet.long_mm, sheet.short_mm);
    ExpectStripesMatch(landscape.svg, target, sheet.long_mm, sheet.short_mm, false);

    for (const TargetDrawing* drawing : {&portrait, &landscape}) {
      // Numbers 1-4 beside both ends of each stripe, the name, the note, the scale bar.
      EXPECT_EQ(Count(drawing->svg, "<text class=\"line-number\""), 8);
      for (const char* number : {">1</text>", ">2</text>", ">3</text>", ">4</text>"}) {
        EXPECT_EQ(Count(drawing->svg, number), 2) << number;
      }
      EXPECT_THAT(drawing->svg, HasSubstr(">target " + target.name + "</text>"));
      EXPECT_THAT(drawing->svg, HasSubstr("<title>oalservo target " + target.name + "</title>"));
      ExpectScaleBar(drawing->svg);
      // No board outline: the sheet is the board.
      EXPECT_EQ(Count(drawing->svg, "<rect"), 1);  // the stripes' clip path only
      EXPECT_THAT(drawing->svg, HasSubstr("<clipPath id=\"board-clip\"><rect"));
    }
  }
}

// Each line number sits beside an end of its own stripe: nearer to that end than to any
// other stripe's end.
TEST(TargetCommandSvg, LineNumbersAreBesideTheirStripesEnds) {
  for (const SheetCase& sheet : kSheetCases) {
    const LineTarget target = sheet.target();
    const TargetDrawing drawing = DrawTargetSvg(target, sheet.page, true);
    const double cx = 0.5 * drawing.page_width_mm, cy = 0.5 * drawing.page_height_mm;
    for (const Text& text : Texts(drawing.svg)) {
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
      const TargetDrawing drawing = DrawTargetSvg(target, sheet.page, landscape);
      const Polygon middle =
          MiddleCell(target, drawing.page_width_mm, drawing.page_height_mm, drawing.turned);
      // 8 numbers, 3 legend lines, the scale label; the bar and 11 ticks.
      EXPECT_EQ(ExpectClearOfStripesAndEdge(drawing.svg, drawing.page_width_mm,
                                            drawing.page_height_mm, &middle),
                8 + 3 + 1 + 1 + 11);
    }
  }
  const TargetDrawing board = DrawTargetSvg(FourLineTarget(), "full");
  const Polygon middle =
      MiddleCell(FourLineTarget(), board.page_width_mm, board.page_height_mm, false);
  EXPECT_EQ(
      ExpectClearOfStripesAndEdge(board.svg, board.page_width_mm, board.page_height_mm, &middle),
      24);
  const TargetDrawing two = DrawTargetSvg(TwoLineTarget(), "full");
  EXPECT_EQ(ExpectClearOfStripesAndEdge(two.svg, two.page_width_mm, two.page_height_mm), 20);
  const TargetDrawing small = DrawTargetSvg(SmallTarget(), "a4");
  EXPECT_GE(ExpectClearOfStripesAndEdge(small.svg, 210.0, 297.0), 16);
}

TEST(TargetCommandSvg, ScaleBarIsExactly100mm) {
  for (const SheetCase& sheet : kSheetCases) {
    for (const bool landscape : {false, true}) {
      SCOPED_TRACE(std::string(sheet.page) + (landscape ? " landscape" : " portrait"));
      ExpectScaleBar(DrawTargetSvg(sheet.target(), sheet.page, landscape).svg);
    }
  }
  ExpectScaleBar(DrawTargetSvg(FourLineTarget(), "full").svg);
  ExpectScaleBar(DrawTargetSvg(SmallTarget(), "a4").svg);
}

// A board of one's own: upright when it fits so, else turned; portrait unless landscape.
TEST(TargetCommandSvg, PagesAndOrientation) {
  const TargetDrawing small = DrawTargetSvg(SmallTarget(), "a4");
  EXPECT_EQ(small.page, "A4 portrait");
  EXPECT_FALSE(small.turned);
  ExpectPage(small.svg, 210.0, 297.0);
  ExpectStripesMatch(small.svg, SmallTarget(), 210.0, 297.0, false);
  EXPECT_EQ(Count(small.svg, "<text class=\"line-number\""), 6);

  LineTarget wide = SmallTarget();
  wide.board_width_m = 0.25;  // A4 only turned, or on a landscape page
  wide.board_height_m = 0.12;
  wide.lines[2] = TargetLine{0.0, -0.06, 0.07, 0.06, 0.005};
  const TargetDrawing turned = DrawTargetSvg(wide, "a4");
  EXPECT_EQ(turned.page, "A4 portrait");
  EXPECT_TRUE(turned.turned);
  ExpectPage(turned.svg, 210.0, 297.0);
  ExpectStripesMatch(turned.svg, wide, 210.0, 297.0, true);
  const TargetDrawing upright = DrawTargetSvg(wide, "a4", true);
  EXPECT_EQ(upright.page, "A4 landscape");
  EXPECT_FALSE(upright.turned);
  ExpectPage(upright.svg, 297.0, 210.0);
  ExpectStripesMatch(upright.svg, wide, 297.0, 210.0, false);

  const TargetDrawing letter = DrawTargetSvg(SmallTarget(), "letter", true);
  EXPECT_EQ(letter.page, "US letter landscape");
  ExpectPage(letter.svg, 279.4, 215.9);
  const TargetDrawing a3 = DrawTargetSvg(SmallTarget(), "a3");
  ExpectPage(a3.svg, 297.0, 420.0);
  ExpectStripesMatch(a3.svg, SmallTarget(), 297.0, 420.0, false);

  EXPECT_THROW(DrawTargetSvg(SmallTarget(), "a5"), std::invalid_argument);
  EXPECT_THROW(DrawTargetSvg(SmallTarget(), "auto"), std::invalid_argument);
  EXPECT_THROW(DrawTargetSvg(SmallTarget(), "full", true), std::invalid_argument);
}

// --page full: the board at its full size with 10 mm around it (the 2 m board's only page).
TEST(TargetCommandSvg, FullPageIsTheBoardWithMargins) {
  const TargetDrawing board = DrawTargetSvg(FourLineTarget(), "full");
  EXPECT_EQ(board.page, "full size");
  EXPECT_FALSE(board.turned);
  ExpectPage(board.svg, 2020.0, 2020.0);
  ExpectStripesMatch(board.svg, FourLineTarget(), 2020.0, 2020.0, false);
  EXPECT_EQ(Count(board.svg, "<text class=\"line-number\""), 8);
  EXPECT_THAT(board.svg, HasSubstr(">target four-line-board</text>"));
  EXPECT_THAT(board.svg, HasSubstr(">board 2000 x 2000 mm</text>"));
  // The stripes run to the board's edges, so they are clipped to the board.
  EXPECT_NEAR(Number(board.svg, "<rect", "x"), 10.0, 1e-9);
  EXPECT_NEAR(Number(board.svg, "<rect", "width"), 2000.0, 1e-9);
  const TargetDrawing a3 = DrawTargetSvg(FourLineA3Target(), "full");
  ExpectPage(a3.svg, 440.0, 317.0);
  ExpectStripesMatch(a3.svg, FourLineA3Target(), 440.0, 317.0, false);
}

// A board the page holds in neither orientation is refused, saying what to print instead.
TEST(TargetCommandSvg, BoardLargerThanThePageIsRefused) {
  try {
    DrawTargetSvg(FourLineTarget(), "a3");
    FAIL() << "no error";
  } catch (const TargetDoesNotFit& error) {
    const std::string message = error.what();
    EXPECT_THAT(message, HasSubstr("target 'four-line-board' (board 2000 x 2000 mm) does not fit "
                                   "on the A3 page (297 x 420 mm), upright or turned"));
    EXPECT_THAT(message, HasSubstr("nothing was written"));
    EXPECT_THAT(message, HasSubstr("--page a3 without --target or --config prints four-line-a3"));
    EXPECT_THAT(message, HasSubstr("--page full (2020 x 2020 mm, for a plotter or a print shop)"));
    EXPECT_THAT(message, Not(HasSubstr("a page that holds")));  // no sheet does
  }
  // The A3 target on an A4 page: the A4 target, or the A3 page.
  try {
    DrawTargetSvg(FourLineA3Target(), "a4", true);
    FAIL() << "no error";
  } catch (const TargetDoesNotFit& error) {
    EXPECT_THAT(error.what(), HasSubstr("does not fit on the A4 page (297 x 210 mm)"));
    EXPECT_THAT(error.what(), HasSubstr("--page a4 without --target or --config prints "
                                        "four-line-a4"));
    EXPECT_THAT(error.what(), HasSubstr("a page that holds this one (--page a3)"));
  }
  // The A4 sheet is longer than US letter.
  EXPECT_THROW(DrawTargetSvg(FourLineA4Target(), "letter"), TargetDoesNotFit);
  EXPECT_THROW(DrawTargetSvg(TwoLineTarget(), "a4"), TargetDoesNotFit);
  // Letter and A4 fit upright on a portrait A3 page (a page larger than the sheet).
  EXPECT_FALSE(DrawTargetSvg(FourLineLetterTarget(), "a3").turned);
  EXPECT_FALSE(DrawTargetSvg(FourLineA4Target(), "a3").turned);
}

// A stripe of one's own target nearer than 5 mm to the page's edge is printed with a warning.
TEST(TargetCommandSvg, StripeNearThePageEdgeWarns) {
  LineTarget target;
  target.name = "to-the-edge";
  target.board_width_m = 0.210;
  target.board_height_m = 0.297;
  target.lines = {TargetLine{-0.05, -0.1485, -0.05, 0.1485, 0.02},
                  TargetLine{-0.095, 0.0, 0.095, 0.0, 0.01}};
  const TargetDrawing drawing = DrawTargetSvg(target, "a4");
  EXPECT_THAT(drawing.warning, HasSubstr("line 1's stripe comes within 0 mm of the page's edge"));
  EXPECT_THAT(drawing.warning, Not(HasSubstr("line 2")));
  ExpectStripesMatch(drawing.svg, target, 210.0, 297.0, false);
}

TEST(TargetCommandSvg, NameIsEscapedAndBadTargetsAreRejected) {
  LineTarget target = SmallTarget();
  target.name = "a<b&\"c\"";
  const std::string svg = DrawTargetSvg(target, "a4").svg;
  EXPECT_THAT(svg, HasSubstr("a&lt;b&amp;&quot;c&quot;"));
  EXPECT_THAT(svg, Not(HasSubstr("a<b")));
  target.lines[0].width_m = 0.0;
  EXPECT_THROW(DrawTargetSvg(target, "a4"), std::invalid_argument);
}

// ------------------------------------------------------------------------------------------
// The command.

}  // namespace
}  // namespace oal
