// Reading the SVG a target's page is drawn as (target/target_svg.h), for its tests and the
// target command's: simple searches on its text, which is written one element a line, and the
// plane geometry the checks need.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "base/angles.h"
#include "print/target_page.h"
#include "target/line_target.h"

namespace oal::test {

inline constexpr double kToleranceMm = 0.01;  // drawing coordinates against the target geometry

struct Point {
  double x = 0.0, y = 0.0;
};
using Polygon = std::vector<Point>;  // convex, corners in order

// ------------------------------------------------------------------------------------------
// Reading the SVG: simple searches on its text, which the command writes one element a line.

inline bool IsSpace(char c) {
  return c == ' ' || c == '\n' || c == '\t' || c == '\r';
}

// The value of attribute `name` in an element's opening tag, or throws. (String searches, not
// <regex>: std::regex over a whole drawing takes seconds in a sanitizer build.)
inline std::string AttributeIn(const std::string& tag, const std::string& name) {
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
inline std::vector<std::string> Tags(const std::string& svg, const std::string& element) {
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
inline std::string Attribute(const std::string& svg, const std::string& element,
                             const std::string& name) {
  const std::size_t begin = svg.find(element);
  if (begin == std::string::npos) throw std::runtime_error("no element " + element);
  const std::size_t end = svg.find('>', begin);
  return AttributeIn(svg.substr(begin, end - begin), name);
}

inline double Number(const std::string& svg, const std::string& element, const std::string& name) {
  return std::stod(Attribute(svg, element, name));
}

inline bool IsLineId(const std::string& id) {
  return id.size() > 5 && id.compare(0, 5, "line-") == 0 &&
         std::all_of(id.begin() + 5, id.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The `points` of every stripe polygon, in document order.
inline std::vector<Polygon> StripePolygons(const std::string& svg) {
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

inline double AttributeOf(const std::string& tag, const std::string& name) {
  return std::stod(AttributeIn(tag, name));
}

struct Text {
  std::string tag;      // the opening tag, for messages
  std::string content;  // as written (no entities in the tests' names)
  Point at;             // x, y: the middle of the baseline
  double size_mm = 0.0;
  double angle_deg = 0.0;  // rotate(angle x y); 0 without a transform
};

inline std::vector<Text> Texts(const std::string& svg) {
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

inline std::vector<Line> Lines(const std::string& svg) {
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

inline int Count(const std::string& text, const std::string& what) {
  int count = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

// ------------------------------------------------------------------------------------------
// Plane geometry on the page, millimetres.

inline Point Minus(Point a, Point b) {
  return {a.x - b.x, a.y - b.y};
}
inline double Cross(Point a, Point b) {
  return a.x * b.y - a.y * b.x;
}

inline double PointSegmentDistance(Point p, Point a, Point b) {
  const Point ab = Minus(b, a), ap = Minus(p, a);
  const double length2 = ab.x * ab.x + ab.y * ab.y;
  const double t = std::clamp((ap.x * ab.x + ap.y * ab.y) / length2, 0.0, 1.0);
  return std::hypot(ap.x - t * ab.x, ap.y - t * ab.y);
}

inline bool Inside(Point p, const Polygon& polygon) {
  bool positive = false, negative = false;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const double side =
        Cross(Minus(polygon[(i + 1) % polygon.size()], polygon[i]), Minus(p, polygon[i]));
    positive = positive || side > 0.0;
    negative = negative || side < 0.0;
  }
  return !(positive && negative);
}

inline bool Cross(Point a, Point b, Point c, Point d) {
  const double d1 = Cross(Minus(b, a), Minus(c, a)), d2 = Cross(Minus(b, a), Minus(d, a));
  const double d3 = Cross(Minus(d, c), Minus(a, c)), d4 = Cross(Minus(d, c), Minus(b, c));
  return ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0));
}

// 0 when the convex polygons overlap, else the distance between their outlines.
inline double Distance(const Polygon& a, const Polygon& b) {
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
inline Polygon Widened(Point a, Point b, double half_width) {
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
inline Polygon Extent(const Text& text) {
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
inline void ExpectPage(const std::string& svg, double width_mm, double height_mm) {
  ASSERT_EQ(svg.rfind("<svg", 0), 0u) << svg.substr(0, 80);
  EXPECT_THAT(svg, ::testing::HasSubstr("</svg>"));
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

// Every stripe polygon is the target line's rectangle (centre line widened by width / 2, flat
// ends) cut to the board, with the board centred on the page, upright (x right, y down) or
// turned by 90 degrees clockwise (object x down the page, object y to the left): each of the
// rectangle's corners on the board is a corner of the polygon, and each of the polygon's
// corners lies on the rectangle and on the board (no clipping is left to the renderer).
inline void ExpectStripesMatch(const std::string& svg, const LineTarget& target, double page_w,
                               double page_h, bool turned) {
  const double cx = 0.5 * page_w, cy = 0.5 * page_h;
  const auto on_page = [&](double x_m, double y_m) {
    return turned ? Point{cx - 1000.0 * y_m, cy + 1000.0 * x_m}
                  : Point{cx + 1000.0 * x_m, cy + 1000.0 * y_m};
  };
  const double board_half_x = 500.0 * (turned ? target.board_height_m : target.board_width_m);
  const double board_half_y = 500.0 * (turned ? target.board_width_m : target.board_height_m);
  const auto outside_board = [&](const Point& p) {
    return std::max(std::fabs(p.x - cx) - board_half_x, std::fabs(p.y - cy) - board_half_y);
  };
  const std::vector<Polygon> polygons = StripePolygons(svg);
  ASSERT_EQ(polygons.size(), target.lines.size());
  EXPECT_EQ(svg.find("clip"), std::string::npos);
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    SCOPED_TRACE(target.name + " line " + std::to_string(i + 1) + (turned ? " turned" : ""));
    const TargetLine& line = target.lines[i];
    const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
    const double length = std::hypot(dx, dy);
    const double nx = -dy / length * 0.5 * line.width_m, ny = dx / length * 0.5 * line.width_m;
    const Point expected[4] = {
        on_page(line.x1_m + nx, line.y1_m + ny), on_page(line.x2_m + nx, line.y2_m + ny),
        on_page(line.x2_m - nx, line.y2_m - ny), on_page(line.x1_m - nx, line.y1_m - ny)};
    for (const Point& corner : expected) {
      if (outside_board(corner) > kToleranceMm) continue;
      double nearest = HUGE_VAL;
      for (const Point& p : polygons[i])
        nearest = std::min(nearest, std::hypot(p.x - corner.x, p.y - corner.y));
      EXPECT_LT(nearest, kToleranceMm) << "corner (" << corner.x << ", " << corner.y << ")";
    }
    // On the rectangle: within half the width of the centre line, between its ends.
    const Point a = on_page(line.x1_m, line.y1_m), b = on_page(line.x2_m, line.y2_m);
    const double ux = (b.x - a.x) / (1000.0 * length), uy = (b.y - a.y) / (1000.0 * length);
    for (const Point& p : polygons[i]) {
      const double along = (p.x - a.x) * ux + (p.y - a.y) * uy;
      const double across = std::fabs((p.x - a.x) * uy - (p.y - a.y) * ux);
      EXPECT_LT(outside_board(p), kToleranceMm) << "(" << p.x << ", " << p.y << ")";
      EXPECT_LT(across, 500.0 * line.width_m + kToleranceMm) << "(" << p.x << ", " << p.y << ")";
      EXPECT_GT(along, -kToleranceMm);
      EXPECT_LT(along, 1000.0 * length + kToleranceMm);
    }
  }
}

// Everything but the stripes: thin and small, at least kClearanceMm from every stripe and
// from the page's edge, and (with `middle`, the page rectangle between the crossings) not
// in the middle cell. Returns how many texts and lines were checked.
inline int ExpectClearOfStripesAndEdge(const std::string& svg, double page_w, double page_h,
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
inline Polygon MiddleCell(const LineTarget& target, double page_w, double page_h, bool turned) {
  const double x0 = 1000.0 * target.lines[0].x1_m, x1 = 1000.0 * target.lines[2].x1_m;
  const double y0 = 1000.0 * target.lines[1].y1_m, y1 = 1000.0 * target.lines[3].y1_m;
  const auto on_page = [&](double x, double y) {
    return turned ? Point{0.5 * page_w - y, 0.5 * page_h + x}
                  : Point{0.5 * page_w + x, 0.5 * page_h + y};
  };
  return {on_page(x0, y0), on_page(x1, y0), on_page(x1, y1), on_page(x0, y1)};
}

// The scale bar is 100 mm long, ticks every 10 mm from its start to its end, at right angles.
inline void ExpectScaleBar(const std::string& svg) {
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
  EXPECT_THAT(svg, ::testing::HasSubstr(">100 mm</text>"));
  EXPECT_THAT(svg, ::testing::HasSubstr(">print at 100 %, do not scale</text>"));
}

struct SheetCase {
  const char* page;
  LineTarget (*target)();
  double short_mm, long_mm;  // the sheet
  const char* label;
};

inline const SheetCase kSheetCases[] = {
    {"a3", &FourLineA3Target, 297.0, 420.0, "A3"},
    {"a4", &FourLineA4Target, 210.0, 297.0, "A4"},
    {"letter", &FourLineLetterTarget, 215.9, 279.4, "US letter"}};

// A board that fits on A4 with a diagonal line and odd numbers.
inline LineTarget SmallTarget() {
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

}  // namespace oal::test
