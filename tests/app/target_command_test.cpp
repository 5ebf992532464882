#include "app/target_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/config.h"
#include "app/render_command.h"
#include "scene/scene.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kToleranceMm = 0.01;  // drawing coordinates against the target geometry
constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

struct Point {
  double x = 0.0, y = 0.0;
};
using Polygon = std::vector<Point>;  // convex, corners in order

// ------------------------------------------------------------------------------------------
// Reading the SVG: simple searches on its text, which the command writes one element a line.

bool IsSpace(char c) {
  return c == ' ' || c == '\n' || c == '\t' || c == '\r';
}

// The value of attribute `name` in an element's opening tag, or throws. (String searches, not
// <regex>: std::regex over a whole drawing takes seconds in a sanitizer build.)
std::string AttributeIn(const std::string& tag, const std::string& name) {
  const std::string key = name + "=\"";
  for (std::size_t at = tag.find(key); at != std::string::npos; at = tag.find(key, at + 1)) {
    if (at == 0 || !IsSpace(tag[at - 1])) continue;
    const std::size_t first = at + key.size();
    const std::size_t last = tag.find('"', first);
    if (last == std::string::npos) break;
    return tag.substr(first, last - first);
  }
  throw std::runtime_error("no " + name + " in " + tag);
}

// Every opening tag of `element` (such as "line", not "linearGradient"), in document order.
std::vector<std::string> Tags(const std::string& svg, const std::string& element) {
  std::vector<std::string> tags;
  const std::string open = "<" + element;
  for (std::size_t at = svg.find(open); at != std::string::npos; at = svg.find(open, at + 1)) {
    const std::size_t after = at + open.size();
    if (after >= svg.size() || !(IsSpace(svg[after]) || svg[after] == '>')) continue;
    const std::size_t end = svg.find('>', after);
    if (end == std::string::npos) break;
    tags.push_back(svg.substr(at, end + 1 - at));
  }
  return tags;
}

// The value of attribute `name` of the first element starting with `element` (such as
// `<line id="scale-bar"`), or throws.
std::string Attribute(const std::string& svg, const std::string& element, const std::string& name) {
  const std::size_t begin = svg.find(element);
  if (begin == std::string::npos) throw std::runtime_error("no element " + element);
  const std::size_t end = svg.find('>', begin);
  return AttributeIn(svg.substr(begin, end - begin), name);
}

double Number(const std::string& svg, const std::string& element, const std::string& name) {
  return std::stod(Attribute(svg, element, name));
}

bool IsLineId(const std::string& id) {
  return id.size() > 5 && id.compare(0, 5, "line-") == 0 &&
         std::all_of(id.begin() + 5, id.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The `points` of every stripe polygon, in document order.
std::vector<Polygon> StripePolygons(const std::string& svg) {
  std::vector<Polygon> polygons;
  for (const std::string& tag : Tags(svg, "polygon")) {
    if (AttributeIn(tag, "class") != "stripe" || !IsLineId(AttributeIn(tag, "id"))) continue;
    Polygon polygon;
    std::istringstream in(AttributeIn(tag, "points"));
    std::string pair;
    while (in >> pair) {
      const std::size_t comma = pair.find(',');
      polygon.push_back(Point{std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1))});
    }
    polygons.push_back(polygon);
  }
  return polygons;
}

double AttributeOf(const std::string& tag, const std::string& name) {
  return std::stod(AttributeIn(tag, name));
}

struct Text {
  std::string tag;      // the opening tag, for messages
  std::string content;  // as written (no entities in the tests' names)
  Point at;             // x, y: the middle of the baseline
  double size_mm = 0.0;
  double angle_deg = 0.0;  // rotate(angle x y); 0 without a transform
};

std::vector<Text> Texts(const std::string& svg) {
  std::vector<Text> texts;
  std::size_t from = 0;
  for (const std::string& tag : Tags(svg, "text")) {
    Text text;
    text.tag = tag;
    const std::size_t begin = svg.find(tag, from) + tag.size();
    const std::size_t end = svg.find("</text>", begin);
    if (end == std::string::npos) throw std::runtime_error("unclosed " + tag);
    from = end;
    text.content = svg.substr(begin, end - begin);
    text.at = {AttributeOf(text.tag, "x"), AttributeOf(text.tag, "y")};
    text.size_mm = AttributeOf(text.tag, "font-size");
    if (text.tag.find(" transform=\"") != std::string::npos) {
      const std::string transform = AttributeIn(text.tag, "transform");
      const std::size_t open = transform.find("rotate("), close = transform.find(')');
      if (open == std::string::npos || close == std::string::npos) {
        throw std::runtime_error("not a rotation: " + text.tag);
      }
      std::istringstream in(transform.substr(open + 7, close - open - 7));
      double x = 0.0, y = 0.0;
      if (!(in >> text.angle_deg >> x >> y)) throw std::runtime_error("bad rotate in " + text.tag);
      EXPECT_NEAR(x, text.at.x, 1e-9) << text.tag;  // about its own anchor
      EXPECT_NEAR(y, text.at.y, 1e-9) << text.tag;
    }
    texts.push_back(text);
  }
  return texts;
}

struct Line {
  std::string tag;
  Point a, b;
  double stroke_mm = 0.0;
};

std::vector<Line> Lines(const std::string& svg) {
  std::vector<Line> lines;
  for (const std::string& tag : Tags(svg, "line")) {
    Line line;
    line.tag = tag;
    line.a = {AttributeOf(line.tag, "x1"), AttributeOf(line.tag, "y1")};
    line.b = {AttributeOf(line.tag, "x2"), AttributeOf(line.tag, "y2")};
    line.stroke_mm = AttributeOf(line.tag, "stroke-width");
    lines.push_back(line);
  }
  return lines;
}

int Count(const std::string& text, const std::string& what) {
  int count = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

// ------------------------------------------------------------------------------------------
// Plane geometry on the page, millimetres.

Point Minus(Point a, Point b) {
  return {a.x - b.x, a.y - b.y};
}
double Cross(Point a, Point b) {
  return a.x * b.y - a.y * b.x;
}

double PointSegmentDistance(Point p, Point a, Point b) {
  const Point ab = Minus(b, a), ap = Minus(p, a);
  const double length2 = ab.x * ab.x + ab.y * ab.y;
  const double t = std::clamp((ap.x * ab.x + ap.y * ab.y) / length2, 0.0, 1.0);
  return std::hypot(ap.x - t * ab.x, ap.y - t * ab.y);
}

bool Inside(Point p, const Polygon& polygon) {
  bool positive = false, negative = false;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const double side =
        Cross(Minus(polygon[(i + 1) % polygon.size()], polygon[i]), Minus(p, polygon[i]));
    positive = positive || side > 0.0;
    negative = negative || side < 0.0;
  }
  return !(positive && negative);
}

bool Cross(Point a, Point b, Point c, Point d) {
  const double d1 = Cross(Minus(b, a), Minus(c, a)), d2 = Cross(Minus(b, a), Minus(d, a));
  const double d3 = Cross(Minus(d, c), Minus(a, c)), d4 = Cross(Minus(d, c), Minus(b, c));
  return ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0));
}

// 0 when the convex polygons overlap, else the distance between their outlines.
double Distance(const Polygon& a, const Polygon& b) {
  if (Inside(a[0], b) || Inside(b[0], a)) return 0.0;
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      const Point a0 = a[i], a1 = a[(i + 1) % a.size()], b0 = b[j], b1 = b[(j + 1) % b.size()];
      if (Cross(a0, a1, b0, b1)) return 0.0;
      distance =
          std::min({distance, PointSegmentDistance(a0, b0, b1), PointSegmentDistance(b0, a0, a1)});
    }
  }
  return distance;
}

// The rectangle of segment a-b widened by half_width (flat ends: the SVG's butt caps).
Polygon Widened(Point a, Point b, double half_width) {
  const Point d = Minus(b, a);
  const double length = std::hypot(d.x, d.y);
  const Point n{-d.y / length * half_width, d.x / length * half_width};
  return {{a.x + n.x, a.y + n.y},
          {b.x + n.x, b.y + n.y},
          {b.x - n.x, b.y - n.y},
          {a.x - n.x, a.y - n.y}};
}

// A text's estimated extent (app/target_command.h): kTextWidthEm per character by
// kTextHeightEm, centred kTextBaselineEm above the middle of its baseline, turned with it.
Polygon Extent(const Text& text) {
  const double s = text.size_mm;
  const double half_w = 0.5 * kTextWidthEm * s * static_cast<double>(text.content.size());
  const double half_h = 0.5 * kTextHeightEm * s;
  const double c = std::cos(text.angle_deg * kRadPerDeg),
               sn = std::sin(text.angle_deg * kRadPerDeg);
  Polygon box;
  for (const auto& [x, y] : {std::pair{-half_w, -half_h}, std::pair{half_w, -half_h},
                             std::pair{half_w, half_h}, std::pair{-half_w, half_h}}) {
    const double ly = y - kTextBaselineEm * s;  // the box centre is above the baseline
    box.push_back({text.at.x + c * x - sn * ly, text.at.y + sn * x + c * ly});
  }
  return box;
}

// ------------------------------------------------------------------------------------------
// What a drawing must be.

// The page is `width_mm` x `height_mm` in millimetres and its viewBox the same numbers.
void ExpectPage(const std::string& svg, double width_mm, double height_mm) {
  ASSERT_EQ(svg.rfind("<svg", 0), 0u) << svg.substr(0, 80);
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  const std::string width = Attribute(svg, "<svg", "width");
  const std::string height = Attribute(svg, "<svg", "height");
  ASSERT_GE(width.size(), 2u);
  ASSERT_GE(height.size(), 2u);
  EXPECT_EQ(width.substr(width.size() - 2), "mm");
  EXPECT_EQ(height.substr(height.size() - 2), "mm");
  EXPECT_NEAR(std::stod(width), width_mm, 1e-9);
  EXPECT_NEAR(std::stod(height), height_mm, 1e-9);
  std::istringstream view_box(Attribute(svg, "<svg", "viewBox"));
  double x0 = -1.0, y0 = -1.0, w = 0.0, h = 0.0;
  view_box >> x0 >> y0 >> w >> h;
  EXPECT_EQ(x0, 0.0);
  EXPECT_EQ(y0, 0.0);
  EXPECT_NEAR(w, width_mm, 1e-9);
  EXPECT_NEAR(h, height_mm, 1e-9);
}

// Every stripe polygon's corners are the target line's rectangle (centre line widened by
// width / 2, flat ends) with the board centred on the page, upright (x right, y down) or
// turned by 90 degrees clockwise (object x down the page, object y to the left).
void ExpectStripesMatch(const std::string& svg, const LineTarget& target, double page_w,
                        double page_h, bool turned) {
  const double cx = 0.5 * page_w, cy = 0.5 * page_h;
  const auto on_page = [&](double x_m, double y_m) {
    return turned ? Point{cx - 1000.0 * y_m, cy + 1000.0 * x_m}
                  : Point{cx + 1000.0 * x_m, cy + 1000.0 * y_m};
  };
  const std::vector<Polygon> polygons = StripePolygons(svg);
  ASSERT_EQ(polygons.size(), target.lines.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    SCOPED_TRACE(target.name + " line " + std::to_string(i + 1) + (turned ? " turned" : ""));
    const TargetLine& line = target.lines[i];
    ASSERT_EQ(polygons[i].size(), 4u);
    const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
    const double length = std::hypot(dx, dy);
    const double nx = -dy / length * 0.5 * line.width_m, ny = dx / length * 0.5 * line.width_m;
    const Point expected[4] = {
        on_page(line.x1_m + nx, line.y1_m + ny), on_page(line.x2_m + nx, line.y2_m + ny),
        on_page(line.x2_m - nx, line.y2_m - ny), on_page(line.x1_m - nx, line.y1_m - ny)};
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(polygons[i][k].x, expected[k].x, kToleranceMm) << "corner " << k;
      EXPECT_NEAR(polygons[i][k].y, expected[k].y, kToleranceMm) << "corner " << k;
    }
    EXPECT_NEAR(
        std::hypot(polygons[i][0].x - polygons[i][3].x, polygons[i][0].y - polygons[i][3].y),
        1000.0 * line.width_m, kToleranceMm);
  }
}

// Everything but the stripes: thin and small, at least kClearanceMm from every stripe and
// from the page's edge, and (with `middle`, the page rectangle between the crossings) not
// in the middle cell. Returns how many texts and lines were checked.
int ExpectClearOfStripesAndEdge(const std::string& svg, double page_w, double page_h,
                                const Polygon* middle = nullptr) {
  constexpr double kRoundingMm = 1e-3;  // coordinates are written to 0.1 um
  const std::vector<Polygon> stripes = StripePolygons(svg);
  std::vector<std::pair<std::string, Polygon>> marks;
  for (const Text& text : Texts(svg)) {
    EXPECT_LE(text.size_mm, 4.0) << text.tag;
    marks.emplace_back(text.tag + text.content, Extent(text));
  }
  for (const Line& line : Lines(svg)) {
    EXPECT_LE(line.stroke_mm, 0.5) << line.tag;
    marks.emplace_back(line.tag, Widened(line.a, line.b, 0.5 * line.stroke_mm));
  }
  for (const auto& [what, polygon] : marks) {
    SCOPED_TRACE(what);
    for (const Point& p : polygon) {
      EXPECT_GE(p.x, kClearanceMm - kRoundingMm);
      EXPECT_GE(p.y, kClearanceMm - kRoundingMm);
      EXPECT_LE(p.x, page_w - kClearanceMm + kRoundingMm);
      EXPECT_LE(p.y, page_h - kClearanceMm + kRoundingMm);
    }
    for (std::size_t i = 0; i < stripes.size(); ++i) {
      EXPECT_GE(Distance(polygon, stripes[i]), kClearanceMm - kRoundingMm) << "stripe " << i + 1;
    }
    if (middle != nullptr) {
      EXPECT_GT(Distance(polygon, *middle), 0.0) << "in the middle cell";
    }
  }
  return static_cast<int>(marks.size());
}

// The middle cell's rectangle on the page: between the crossings of lines 1/3 with 2/4.
Polygon MiddleCell(const LineTarget& target, double page_w, double page_h, bool turned) {
  const double x0 = 1000.0 * target.lines[0].x1_m, x1 = 1000.0 * target.lines[2].x1_m;
  const double y0 = 1000.0 * target.lines[1].y1_m, y1 = 1000.0 * target.lines[3].y1_m;
  const auto on_page = [&](double x, double y) {
    return turned ? Point{0.5 * page_w - y, 0.5 * page_h + x}
                  : Point{0.5 * page_w + x, 0.5 * page_h + y};
  };
  return {on_page(x0, y0), on_page(x1, y0), on_page(x1, y1), on_page(x0, y1)};
}

// The scale bar is 100 mm long, ticks every 10 mm from its start to its end, at right angles.
void ExpectScaleBar(const std::string& svg) {
  const Point a{Number(svg, "<line id=\"scale-bar\"", "x1"),
                Number(svg, "<line id=\"scale-bar\"", "y1")};
  const Point b{Number(svg, "<line id=\"scale-bar\"", "x2"),
                Number(svg, "<line id=\"scale-bar\"", "y2")};
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  EXPECT_NEAR(length, 100.0, 1e-3);
  const Point along{(b.x - a.x) / length, (b.y - a.y) / length};
  std::vector<Line> ticks;
  for (const Line& line : Lines(svg)) {
    if (line.tag.find("class=\"scale-tick\"") != std::string::npos) ticks.push_back(line);
  }
  ASSERT_EQ(ticks.size(), 11u);
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    SCOPED_TRACE("tick " + std::to_string(k));
    EXPECT_NEAR(ticks[k].a.x, a.x + 10.0 * k * along.x, 1e-3);  // on the bar
    EXPECT_NEAR(ticks[k].a.y, a.y + 10.0 * k * along.y, 1e-3);
    const Point tick = Minus(ticks[k].b, ticks[k].a);
    EXPECT_NEAR(tick.x * along.x + tick.y * along.y, 0.0, 1e-3);  // across it
    EXPECT_GT(std::hypot(tick.x, tick.y), 1.0);
  }
  EXPECT_THAT(svg, HasSubstr(">100 mm</text>"));
  EXPECT_THAT(svg, HasSubstr(">print at 100 %, do not scale</text>"));
}

struct SheetCase {
  const char* page;
  LineTarget (*target)();
  double short_mm, long_mm;  // the sheet
  const char* label;
};

const SheetCase kSheetCases[] = {{"a3", &FourLineA3Target, 297.0, 420.0, "A3"},
                                 {"a4", &FourLineA4Target, 210.0, 297.0, "A4"},
                                 {"letter", &FourLineLetterTarget, 215.9, 279.4, "US letter"}};

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

// ------------------------------------------------------------------------------------------

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

TEST(TargetCommand, WithoutATargetThePagesSheetTarget) {
  TargetCommandOptions options;
  EXPECT_EQ(options.page, "a3");
  EXPECT_FALSE(options.landscape);
  EXPECT_EQ(TargetToPrint(options).name, "four-line-a3");
  options.page = "a4";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-a4");
  options.page = "letter";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-letter");
  options.page = "full";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-a3");
  options.target = "four-line-board";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-board");
  options.target = "four-line";  // the older name
  EXPECT_EQ(TargetToPrint(options).name, "four-line-board");
}

TEST(TargetCommand, OptionErrorsNameTheOption) {
  const auto error = [](auto change) {
    TargetCommandOptions options;
    options.out = "t.svg";
    change(&options);
    try {
      options.Check();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error([](TargetCommandOptions*) {}), "no error");
  const std::string bad_target = error([](TargetCommandOptions* o) { o->target = "six-line"; });
  EXPECT_THAT(bad_target, HasSubstr("--target = six-line: it is one of four-line-a3"));
  EXPECT_THAT(bad_target, HasSubstr("four-line-board"));
  EXPECT_THAT(error([](TargetCommandOptions* o) {
                o->target = "four-line-a4";
                o->config = "x.yaml";
              }),
              HasSubstr("--target four-line-a4 and --config x.yaml both name a target"));
  EXPECT_THAT(error([](TargetCommandOptions* o) { o->page = "a5"; }), HasSubstr("--page = a5"));
  EXPECT_THAT(error([](TargetCommandOptions* o) {
                o->page = "full";
                o->landscape = true;
              }),
              HasSubstr("--landscape is for a sheet"));
  EXPECT_THAT(error([](TargetCommandOptions* o) { o->out.clear(); }), HasSubstr("--out"));
}

TEST(TargetCommand, WritesTheConfigsTargetAtomically) {
  test::TestDir dir;
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
  EXPECT_FALSE(drawing.turned);
  const std::string svg = test::ReadText(options.out);
  EXPECT_EQ(svg, drawing.svg);
  ExpectStripesMatch(svg, SmallTarget(), 210.0, 297.0, false);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// config/four-line-*.yaml draw exactly the built-ins; the 2 m boards' files need --page full.
TEST(TargetCommand, ShippedConfigsDrawTheBuiltInTargets) {
  test::TestDir dir;
  const std::string config_dir = std::string(OAL_SOURCE_DIR) + "/config/";
  for (const SheetCase& sheet : kSheetCases) {
    SCOPED_TRACE(sheet.page);
    TargetCommandOptions options;
    options.config = config_dir + "four-line-" + sheet.page + ".yaml";
    options.page = sheet.page;
    options.landscape = true;
    options.out = dir / (std::string(sheet.page) + ".svg");
    WriteTargetSvg(options);
    ExpectStripesMatch(test::ReadText(options.out), sheet.target(), sheet.long_mm, sheet.short_mm,
                       false);
  }
  TargetCommandOptions options;
  options.config = config_dir + "four-line-board.yaml";
  options.out = dir / "board.svg";
  EXPECT_THROW(WriteTargetSvg(options), TargetDoesNotFit);
  options.page = "full";
  WriteTargetSvg(options);
  ExpectStripesMatch(test::ReadText(options.out), FourLineTarget(), 2020.0, 2020.0, false);
  options.config = config_dir + "two-line-target.yaml";
  options.out = dir / "two.svg";
  WriteTargetSvg(options);
  ExpectStripesMatch(test::ReadText(options.out), TwoLineTarget(), 2020.0, 2020.0, false);
}

// Refused: nothing is written, and a file already there is left as it was.
TEST(TargetCommand, RefusalWritesNothingAndLeavesAFileAlone) {
  test::TestDir dir;
  TargetCommandOptions options;
  options.target = "four-line-board";
  options.page = "a4";
  options.out = dir / "board.svg";
  EXPECT_THROW(WriteTargetSvg(options), TargetDoesNotFit);
  EXPECT_TRUE(fs::is_empty(dir.path()));
  test::WriteText(options.out, "the previous file\n");
  EXPECT_THROW(WriteTargetSvg(options), TargetDoesNotFit);
  EXPECT_EQ(test::ReadText(options.out), "the previous file\n");
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(TargetCommand, BadOutputDirectoryIsAClearErrorAndLeavesNothing) {
  test::TestDir dir;
  TargetCommandOptions options;
  options.out = dir / "missing/target.svg";
  try {
    WriteTargetSvg(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("--out"));
    EXPECT_THAT(error.what(), HasSubstr("missing"));
    EXPECT_THAT(error.what(), HasSubstr("does not exist"));
  }
  options.out = dir.path().string();  // a directory
  EXPECT_THROW(WriteTargetSvg(options), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir.path()));
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
  EXPECT_FALSE(fs::exists(dir / "t.svg"));
}

// The binary, as a user runs it.
int RunTargetBinary(const std::string& arguments, const std::string& err_file) {
  const std::string command =
      std::string("'") + OAL_OALSERVO_PATH + "' target " + arguments + " 2>'" + err_file + "'";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status)) << command;
  return WEXITSTATUS(status);
}

TEST(TargetCommand, BinaryWritesTheA3SheetByDefault) {
  test::TestDir dir;
  ASSERT_EQ(RunTargetBinary("--out '" + (dir / "t.svg") + "'", dir / "err.txt"), 0);
  const std::string err = test::ReadText(dir / "err.txt");
  EXPECT_THAT(err, HasSubstr("oalservo target: " + (dir / "t.svg") +
                             " written (A3 portrait, 297 x 420 mm)"));
  EXPECT_THAT(err, HasSubstr("'four-line-a3' (board 420 x 297 mm) is drawn turned by 90 degrees"));
  const std::string svg = test::ReadText(dir / "t.svg");
  ExpectPage(svg, 297.0, 420.0);
  ExpectStripesMatch(svg, FourLineA3Target(), 297.0, 420.0, true);

  ASSERT_EQ(
      RunTargetBinary("--page a4 --landscape --out '" + (dir / "a4.svg") + "'", dir / "err.txt"),
      0);
  EXPECT_THAT(test::ReadText(dir / "err.txt"), Not(HasSubstr("turned")));
  ExpectStripesMatch(test::ReadText(dir / "a4.svg"), FourLineA4Target(), 297.0, 210.0, false);

  ASSERT_EQ(
      RunTargetBinary("--target four-line-board --page full --out '" + (dir / "board.svg") + "'",
                      dir / "err.txt"),
      0);
  ExpectPage(test::ReadText(dir / "board.svg"), 2020.0, 2020.0);
}

TEST(TargetCommand, BinaryRefusesABoardLargerThanThePage) {
  test::TestDir dir;
  test::WriteText(dir / "board.svg", "the previous file\n");
  EXPECT_EQ(
      RunTargetBinary("--target four-line-board --page a3 --out '" + (dir / "board.svg") + "'",
                      dir / "err.txt"),
      1);
  const std::string err = test::ReadText(dir / "err.txt");
  EXPECT_THAT(err, HasSubstr("oalservo target: error: target 'four-line-board' (board 2000 x "
                             "2000 mm) does not fit on the A3 page"));
  EXPECT_THAT(err, HasSubstr("--page a3 without --target or --config prints four-line-a3"));
  EXPECT_THAT(err, HasSubstr("--page full"));
  EXPECT_EQ(test::ReadText(dir / "board.svg"), "the previous file\n");
  EXPECT_EQ(RunTargetBinary("--target four-line-board --out '" + (dir / "new.svg") + "'",
                            dir / "err.txt"),
            1);
  EXPECT_FALSE(fs::exists(dir / "new.svg"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
  // A bad --target is an error naming it (1); a page that is not a choice, a usage error (2).
  EXPECT_EQ(RunTargetBinary("--target six-line --out '" + (dir / "x.svg") + "'", dir / "err.txt"),
            1);
  EXPECT_THAT(test::ReadText(dir / "err.txt"), HasSubstr("--target = six-line"));
  EXPECT_EQ(RunTargetBinary("--page a5 --out '" + (dir / "x.svg") + "'", dir / "err.txt"), 2);
  EXPECT_EQ(RunTargetBinary("--target two-line --config x.yaml --out '" + (dir / "x.svg") + "'",
                            dir / "err.txt"),
            2);
  EXPECT_FALSE(fs::exists(dir / "x.svg"));
}

TEST(TargetCommand, BinaryHelpHasAnExampleForEachCase) {
  test::TestDir dir;
  const std::string help =
      std::string("'") + OAL_OALSERVO_PATH + "' target --help >'" + (dir / "help.txt") + "'";
  ASSERT_EQ(std::system(help.c_str()), 0);
  const std::string text = test::ReadText(dir / "help.txt");
  EXPECT_THAT(text, HasSubstr("oalservo target --out four-line-a3.svg\n"));
  EXPECT_THAT(text, HasSubstr("oalservo target --page a3 --landscape --out four-line-a3.svg\n"));
  EXPECT_THAT(text, HasSubstr("oalservo target --page a4 --landscape --out four-line-a4.svg\n"));
  EXPECT_THAT(text, HasSubstr("--target four-line-board --page full --out"));
  EXPECT_THAT(text, HasSubstr("--config my-target.yaml --page a4"));
  for (const std::string& name : TargetNames()) EXPECT_THAT(text, HasSubstr(name));
  EXPECT_THAT(text, HasSubstr("--landscape"));
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
