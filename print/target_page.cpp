// The page is laid out by a search over the cells of the target for its legend and scale bar;
// what is printed is handed on as page geometry (the writers only draw it).
#include "print/target_page.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "base/angles.h"
#include "base/format.h"

namespace oal {
namespace {

constexpr double kFullMarginMm = 10.0;  // the full page: blank paper around the board
constexpr double kGapMm = 1.5;          // between two printed items other than stripes
// A line number keeps farther from the other marks, so that it is read as its stripe's and not
// as a part of the scale bar or the legend beside it.
constexpr double kNumberGapMm = 6.0;
constexpr double kSlackMm = 0.02;  // kept beyond every clearance (survives rounding)
constexpr double kTextMm = kPageTextMm;
constexpr double kLineSpacingMm = 4.5;  // the legend's lines, baseline to baseline
constexpr double kScaleBarMm = 100.0;
constexpr double kBarStrokeMm = 0.3;
constexpr double kTickStrokeMm = 0.25;
constexpr double kLongTickMm = 3.0;   // at 0, 50 and 100 mm
constexpr double kShortTickMm = 1.5;  // every other 10 mm

struct Sheet {
  const char* name;            // as on the command line
  const char* label;           // as in messages
  double width_mm, height_mm;  // portrait
  const char* target;          // the built-in made for it
};

constexpr Sheet kSheets[] = {{"a4", "A4", 210.0, 297.0, "four-line-a4"},
                             {"a3", "A3", 297.0, 420.0, "four-line-a3"},
                             {"letter", "US letter", 215.9, 279.4, "four-line-letter"}};

const Sheet* SheetByName(const std::string& name) {
  for (const Sheet& sheet : kSheets) {
    if (name == sheet.name) return &sheet;
  }
  return nullptr;  // "full"
}

}  // namespace

void CheckPageName(const std::string& page) {
  if (page != "full" && SheetByName(page) == nullptr) {
    throw std::invalid_argument("page '" + page + "': it is one of a4, a3, letter, full");
  }
}

std::string SheetTargetName(const std::string& page) {
  const Sheet* sheet = SheetByName(page);
  return sheet != nullptr ? sheet->target : TargetNames().front();
}

std::string FormatMm(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.4f", value);
  std::string out = text;
  while (out.back() == '0') out.pop_back();
  if (out.back() == '.') out.pop_back();
  if (out == "-0") out = "0";
  return out;
}

namespace {

// ------------------------------------------------------------------------------------------
// Plane geometry, millimetres, in the board's frame (origin at its centre, x right, y down).

struct P {
  double x = 0.0, y = 0.0;
};
P operator+(P a, P b) {
  return {a.x + b.x, a.y + b.y};
}
P operator-(P a, P b) {
  return {a.x - b.x, a.y - b.y};
}
P operator*(double s, P a) {
  return {s * a.x, s * a.y};
}
double Dot(P a, P b) {
  return a.x * b.x + a.y * b.y;
}
double Cross(P a, P b) {
  return a.x * b.y - a.y * b.x;
}
P Rotated(P a, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return {c * a.x - s * a.y, s * a.x + c * a.y};
}

using Polygon = std::vector<P>;  // convex, its corners in order

double PointSegmentDistance(P p, P a, P b) {
  const P ab = b - a;
  const double length2 = Dot(ab, ab);
  const double t = length2 > 0.0 ? std::clamp(Dot(p - a, ab) / length2, 0.0, 1.0) : 0.0;
  const P d = p - (a + t * ab);
  return std::sqrt(d.x * d.x + d.y * d.y);  // not hypot: millions of calls, millimetres
}

bool SegmentsCross(P a, P b, P c, P d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  return ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0));
}

bool InsideConvex(P p, const Polygon& polygon) {
  bool positive = false, negative = false;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const double side = Cross(polygon[(i + 1) % polygon.size()] - polygon[i], p - polygon[i]);
    positive = positive || side > 0.0;
    negative = negative || side < 0.0;
  }
  return !(positive && negative);
}

// 0 when they overlap, else the shortest distance between their outlines.
double PolygonDistance(const Polygon& a, const Polygon& b) {
  if (InsideConvex(a[0], b) || InsideConvex(b[0], a)) return 0.0;
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const P a0 = a[i], a1 = a[(i + 1) % a.size()];
    for (std::size_t j = 0; j < b.size(); ++j) {
      const P b0 = b[j], b1 = b[(j + 1) % b.size()];
      if (SegmentsCross(a0, a1, b0, b1)) return 0.0;
      distance =
          std::min({distance, PointSegmentDistance(a0, b0, b1), PointSegmentDistance(b0, a0, a1)});
    }
  }
  return distance;
}

struct Box {
  double x0, y0, x1, y1;
};

Box BoundsOf(const Polygon& polygon) {
  Box box{polygon[0].x, polygon[0].y, polygon[0].x, polygon[0].y};
  for (const P& p : polygon) {
    box = {std::min(box.x0, p.x), std::min(box.y0, p.y), std::max(box.x1, p.x),
           std::max(box.y1, p.y)};
  }
  return box;
}

// A lower bound of the distance between anything in `a` and anything in `b`.
double BoxDistance(const Box& a, const Box& b) {
  const double dx = std::max({0.0, a.x0 - b.x1, b.x0 - a.x1});
  const double dy = std::max({0.0, a.y0 - b.y1, b.y0 - a.y1});
  return std::sqrt(dx * dx + dy * dy);
}

Polygon Rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

// The rectangle of segment a-b widened by half_width on both sides (flat ends).
Polygon WidenedSegment(P a, P b, double half_width) {
  const P d = b - a;
  const double length = std::hypot(d.x, d.y);
  const P n{-d.y / length * half_width, d.x / length * half_width};
  return {a + n, b + n, b - n, a - n};
}

// The convex hull (Andrew's monotone chain), corners in order.
Polygon ConvexHull(std::vector<P> points) {
  std::sort(points.begin(), points.end(),
            [](P a, P b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  Polygon hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && Cross(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// The stripe of `line`: its centre line widened by width / 2, flat ends; millimetres.
Polygon StripeOf(const TargetLine& line) {
  return WidenedSegment({1000.0 * line.x1_m, 1000.0 * line.y1_m},
                        {1000.0 * line.x2_m, 1000.0 * line.y2_m}, 500.0 * line.width_m);
}

// `polygon` cut to the convex `window` (Sutherland-Hodgman): the part of a stripe on the board.
Polygon ClippedToConvex(const Polygon& polygon, const Polygon& window) {
  Polygon out = polygon;
  const double orientation = Cross(window[1] - window[0], window[2] - window[1]) > 0.0 ? 1.0 : -1.0;
  for (std::size_t e = 0; e < window.size() && !out.empty(); ++e) {
    const P a = window[e], b = window[(e + 1) % window.size()];
    const auto inside = [&](P p) { return orientation * Cross(b - a, p - a) >= 0.0; };
    const Polygon in = out;
    out.clear();
    for (std::size_t i = 0; i < in.size(); ++i) {
      const P p = in[i], q = in[(i + 1) % in.size()];
      if (inside(p)) out.push_back(p);
      if (inside(p) != inside(q)) {
        const double t = Cross(b - a, p - a) / Cross(b - a, p - q);
        out.push_back(p + t * (q - p));
      }
    }
  }
  return out;
}

// ------------------------------------------------------------------------------------------
// What is printed besides the stripes: items made of texts and thin lines, in their own
// frame; an item's pose puts its origin at `at` on the board, turned by angle_deg.

struct TextPart {
  P centre;  // of its estimated extent
  std::string text;
  std::string id, klass;  // the page's (one of them)
};

struct LinePart {
  P a, b;
  double stroke_mm;
  std::string id, klass;  // the page's (one of them)
};

struct Item {
  std::vector<TextPart> texts;
  std::vector<LinePart> lines;
};

struct Pose {
  P at;
  double angle_deg = 0.0;
};

// A text's estimated extent in its item's frame (upright: the item turns it).
Polygon TextExtent(const TextPart& text) {
  const double half_w = 0.5 * kTextWidthEm * kTextMm * static_cast<double>(text.text.size());
  const double half_h = 0.5 * kTextHeightEm * kTextMm;
  return Rectangle(text.centre.x - half_w, text.centre.y - half_h, text.centre.x + half_w,
                   text.centre.y + half_h);
}

// Everything an item inks, as convex polygons in its own frame.
std::vector<Polygon> PartsOf(const Item& item) {
  std::vector<Polygon> parts;
  for (const TextPart& text : item.texts) parts.push_back(TextExtent(text));
  for (const LinePart& line : item.lines) {
    parts.push_back(WidenedSegment(line.a, line.b, 0.5 * line.stroke_mm));
  }
  return parts;
}

// `parts` moved to `pose`, into *out (its memory reused: the layout search places an item
// some hundred thousand times).
void PlaceInto(const std::vector<Polygon>& parts, const Pose& pose, std::vector<Polygon>* out) {
  const double angle = pose.angle_deg * kRadPerDeg;
  const double c = std::cos(angle), s = std::sin(angle);
  out->resize(parts.size());
  for (std::size_t k = 0; k < parts.size(); ++k) {
    Polygon& placed = (*out)[k];
    placed.resize(parts[k].size());
    for (std::size_t i = 0; i < parts[k].size(); ++i) {
      const P& p = parts[k][i];
      placed[i] = pose.at + P{c * p.x - s * p.y, s * p.x + c * p.y};
    }
  }
}

std::vector<Polygon> Placed(const std::vector<Polygon>& parts, const Pose& pose) {
  std::vector<Polygon> out;
  PlaceInto(parts, pose, &out);
  return out;
}

// The stripes, the middle cell and the items placed so far; how much room a new item has.
class Layout {
 public:
  // half_w_mm, half_h_mm: the page's half extents along the board's x and y.
  Layout(const LineTarget& target, double half_w_mm, double half_h_mm)
      : half_w_(half_w_mm), half_h_(half_h_mm) {
    for (const TargetLine& line : target.lines) Add(&stripes_, StripeOf(line));
    // The crossings of the centre lines; their bounding rectangle holds the middle cell.
    std::vector<P> crossings;
    for (std::size_t i = 0; i < target.lines.size(); ++i) {
      for (std::size_t j = i + 1; j < target.lines.size(); ++j) {
        const TargetLine& a = target.lines[i];
        const TargetLine& b = target.lines[j];
        const P a0{1000.0 * a.x1_m, 1000.0 * a.y1_m}, a1{1000.0 * a.x2_m, 1000.0 * a.y2_m};
        const P b0{1000.0 * b.x1_m, 1000.0 * b.y1_m}, b1{1000.0 * b.x2_m, 1000.0 * b.y2_m};
        const double denominator = Cross(a1 - a0, b1 - b0);
        if (std::fabs(denominator) < 1e-12) continue;  // parallel
        const double s = Cross(b0 - a0, b1 - b0) / denominator;
        const double t = Cross(b0 - a0, a1 - a0) / denominator;
        if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) crossings.push_back(a0 + s * (a1 - a0));
      }
    }
    if (crossings.size() >= 2) {
      const Box box = BoundsOf(crossings);
      if (box.x1 - box.x0 > 1e-6 && box.y1 - box.y0 > 1e-6) {
        middle_ = box;
        Add(&obstacles_, Rectangle(box.x0, box.y0, box.x1, box.y1));
      }
    }
  }

  // The smallest of: room to the page's edge, to every stripe and to the middle cell, each
  // less kClearanceMm, and to every item placed, less item_gap. >= 0: the item may go there.
  // Stops early (returning a value below `bound`) once it is below `bound`.
  double Clearance(const std::vector<Polygon>& parts, double bound,
                   double item_gap = kGapMm) const {
    double room = std::numeric_limits<double>::infinity();
    for (const Polygon& part : parts) {
      for (const P& p : part) {
        room = std::min({room, half_w_ - std::fabs(p.x), half_h_ - std::fabs(p.y)});
      }
    }
    room -= kClearanceMm;
    if (room < bound) return room;
    for (const Polygon& part : parts) {
      const Box part_box = BoundsOf(part);
      for (const auto& [polygons, keep] :
           {std::pair<const Shapes*, double>{&stripes_, kClearanceMm},
            {&obstacles_, kClearanceMm},
            {&items_, item_gap}}) {
        for (const auto& [polygon, box] : *polygons) {
          if (BoxDistance(part_box, box) - keep >= room) continue;
          room = std::min(room, PolygonDistance(part, polygon) - keep);
          if (room < bound) return room;
        }
      }
    }
    return room;
  }

  // Whether every part lies in one corner cell: beyond the middle cell's rectangle both
  // across and along, all on the same side. Without a middle cell, anywhere is a corner.
  bool InCorner(const std::vector<Polygon>& parts) const {
    if (!middle_) return true;
    int side_x = 0, side_y = 0;
    for (const Polygon& part : parts) {
      for (const P& p : part) {
        const int sx = p.x < middle_->x0 ? -1 : (p.x > middle_->x1 ? 1 : 0);
        const int sy = p.y < middle_->y0 ? -1 : (p.y > middle_->y1 ? 1 : 0);
        if (sx == 0 || sy == 0) return false;
        if (side_x == 0) side_x = sx, side_y = sy;
        if (sx != side_x || sy != side_y) return false;
      }
    }
    return true;
  }

  void Place(const std::vector<Polygon>& parts) {
    for (const Polygon& part : parts) Add(&items_, part);
  }

  double half_w() const { return half_w_; }
  double half_h() const { return half_h_; }
  std::optional<P> centre() const {
    if (!middle_) return std::nullopt;
    return P{0.5 * (middle_->x0 + middle_->x1), 0.5 * (middle_->y0 + middle_->y1)};
  }

 private:
  using Shapes = std::vector<std::pair<Polygon, Box>>;
  static void Add(Shapes* shapes, Polygon polygon) {
    const Box box = BoundsOf(polygon);
    shapes->emplace_back(std::move(polygon), box);
  }

  double half_w_, half_h_;
  Shapes stripes_, obstacles_, items_;
  std::optional<Box> middle_;
};

// One way of placing an item: a set of angles tried over the whole page, optionally only in
// a corner cell; `angle_span_deg` > 0 lets the refinement turn it that much more.
struct SearchStep {
  bool corner_only;
  std::vector<double> angles_deg;
  double angle_span_deg = 0.0;
};

struct Found {
  Pose pose;
  double clearance = -std::numeric_limits<double>::infinity();
};

// The pose with the most room for `item` in the first step that has room at all: a grid over
// the page (the item's convex hull, which has less room than the item), then a pattern search
// from the best few (the item's own parts).
std::optional<Pose> PlaceItem(const Item& item, const std::vector<SearchStep>& steps,
                              const Layout& layout) {
  const std::vector<Polygon> parts = PartsOf(item);
  std::vector<P> corners;
  for (const Polygon& part : parts) corners.insert(corners.end(), part.begin(), part.end());
  const std::vector<Polygon> hull = {ConvexHull(corners)};
  // A grid of about 100 steps across the page finds the starts; the pattern search from the
  // best few places the item to 0.005 mm.
  const double grid_mm = std::max(2.0, 2.0 * std::max(layout.half_w(), layout.half_h()) / 100.0);
  constexpr std::size_t kStarts = 8;

  for (const SearchStep& step : steps) {
    std::vector<Polygon> placed;
    const auto room_at = [&](const std::vector<Polygon>& shape, const Pose& pose, double bound) {
      PlaceInto(shape, pose, &placed);
      if (step.corner_only && !layout.InCorner(placed)) return -kClearanceMm * 10.0;
      return layout.Clearance(placed, bound);
    };
    // The grid, bottom row first, keeping the best kStarts at least a grid step apart.
    std::vector<Found> starts;
    for (const double angle : step.angles_deg) {
      for (double y = layout.half_h(); y >= -layout.half_h(); y -= grid_mm) {
        for (double x = -layout.half_w(); x <= layout.half_w(); x += grid_mm) {
          const Pose pose{{x, y}, angle};
          const double worst = starts.size() < kStarts ? -kClearanceMm : starts.back().clearance;
          const double room = room_at(hull, pose, worst);
          if (room <= worst) continue;
          bool merged = false;
          for (Found& start : starts) {
            if (start.pose.angle_deg == angle && std::fabs(start.pose.at.x - x) < 1.5 * grid_mm &&
                std::fabs(start.pose.at.y - y) < 1.5 * grid_mm) {
              if (room > start.clearance) start = {pose, room};
              merged = true;
              break;
            }
          }
          if (!merged) starts.push_back({pose, room});
          std::stable_sort(starts.begin(), starts.end(), [](const Found& a, const Found& b) {
            return a.clearance > b.clearance;
          });
          if (starts.size() > kStarts) starts.pop_back();
        }
      }
    }
    // Pattern search from each, on the item's own parts.
    Found best;
    for (const Found& start : starts) {
      Found here{start.pose, room_at(parts, start.pose, -kClearanceMm * 10.0)};
      const double base_angle = start.pose.angle_deg;
      for (double h = 0.5 * grid_mm; h >= 0.005; h *= 0.5) {
        const double turn = step.angle_span_deg > 0.0 ? std::min(1.0, h) : 0.0;
        for (bool moved = true; moved;) {
          moved = false;
          const double moves[10][3] = {{h, 0, 0},    {-h, 0, 0},   {0, h, 0},  {0, -h, 0},
                                       {h, h, 0},    {h, -h, 0},   {-h, h, 0}, {-h, -h, 0},
                                       {0, 0, turn}, {0, 0, -turn}};
          for (const auto& move : moves) {
            const Pose pose{{here.pose.at.x + move[0], here.pose.at.y + move[1]},
                            here.pose.angle_deg + move[2]};
            if (move[2] != 0.0 &&
                std::fabs(pose.angle_deg - base_angle) > step.angle_span_deg + 1e-9) {
              continue;
            }
            if (move[0] == 0.0 && move[1] == 0.0 && move[2] == 0.0) continue;
            const double room = room_at(parts, pose, here.clearance);
            if (room > here.clearance + 1e-9) {
              here = {pose, room};
              moved = true;
            }
          }
        }
      }
      if (here.clearance > best.clearance + 1e-3) best = here;
    }
    if (best.clearance >= kSlackMm) return best.pose;
  }
  return std::nullopt;
}

// Where line `index`'s number goes beside its `from` end (at_from) or its `to` end: beside
// the stripe, as near the end as there is room, on the side away from the middle first.
std::optional<Pose> PlaceLineNumber(const Item& number, const TargetLine& line, bool at_from,
                                    const Layout& layout) {
  const P from{1000.0 * line.x1_m, 1000.0 * line.y1_m}, to{1000.0 * line.x2_m, 1000.0 * line.y2_m};
  const P end = at_from ? from : to;
  const P d = (at_from ? to : from) - end;
  const double length = std::hypot(d.x, d.y);
  const P along = (1.0 / length) * d;  // inward from the end
  const P across{-along.y, along.x};
  const P centre = layout.centre().value_or(P{0.0, 0.0});
  const double outward = Dot(end - centre, across) >= 0.0 ? 1.0 : -1.0;
  const std::vector<Polygon> parts = PartsOf(number);
  const Box extent = BoundsOf(parts[0]);
  const double support = 0.5 * ((extent.x1 - extent.x0) * std::fabs(across.x) +
                                (extent.y1 - extent.y0) * std::fabs(across.y));
  const double side = 500.0 * line.width_m + kClearanceMm + support + kSlackMm;
  std::vector<Polygon> placed;
  for (const double sign : {outward, -outward}) {
    for (double t = 0.0; t <= std::min(40.0, 0.5 * length); t += 1.0) {
      for (const double extra : {0.0, 0.5, 1.0, 2.0, 4.0, 8.0}) {
        const Pose pose{end + t * along + (sign * (side + extra)) * across, 0.0};
        PlaceInto(parts, pose, &placed);
        if (layout.Clearance(placed, kSlackMm, kNumberGapMm) >= kSlackMm) return pose;
      }
    }
  }
  return std::nullopt;
}

std::string SheetSize(const LineTarget& target) {
  return FormatMm(1000.0 * target.board_width_m) + " x " +
         FormatMm(1000.0 * target.board_height_m) + " mm";
}

Item ScaleBar() {
  Item bar;
  const double half = 0.5 * kScaleBarMm;
  bar.lines.push_back({{-half, 0.0}, {half, 0.0}, kBarStrokeMm, "scale-bar", ""});
  for (int mm = 0; mm <= static_cast<int>(kScaleBarMm); mm += 10) {
    const double tick = mm % 50 == 0 ? kLongTickMm : kShortTickMm;
    const double x = -half + mm;
    bar.lines.push_back({{x, 0.0}, {x, -tick}, kTickStrokeMm, "", "scale-tick"});
  }
  const double label_y = 0.5 * kBarStrokeMm + 0.8 + 0.5 * kTextHeightEm * kTextMm;
  bar.texts.push_back({{0.0, label_y}, "100 mm", "scale-label", ""});
  return bar;
}

Item Legend(const LineTarget& target) {
  const std::string name = target.name.empty() ? "unnamed" : target.name;
  Item legend;
  legend.texts.push_back({{0.0, -kLineSpacingMm}, "target " + name, "name", ""});
  legend.texts.push_back({{0.0, 0.0}, "board " + SheetSize(target), "size", ""});
  legend.texts.push_back({{0.0, kLineSpacingMm}, "print at 100 %, do not scale", "note", ""});
  return legend;
}

std::vector<double> SlantsDeg() {
  std::vector<double> slants;
  for (double a = 5.0; a < 90.0; a += 5.0) slants.insert(slants.end(), {-a, a});
  return slants;
}

// The page: its size and whether the board is drawn turned on it.
struct Page {
  double width_mm = 0.0, height_mm = 0.0;
  std::string label;
  bool turned = false;
};

TargetDoesNotFit DoesNotFit(const LineTarget& target, const Sheet& sheet, const Page& page) {
  const auto holds = [&](const Sheet& other) {
    const double w = 1000.0 * target.board_width_m, h = 1000.0 * target.board_height_m;
    const double eps = 1e-6;
    return (w <= other.width_mm + eps && h <= other.height_mm + eps) ||
           (h <= other.width_mm + eps && w <= other.height_mm + eps);
  };
  TargetDoesNotFit::Alternatives instead;
  instead.page = sheet.name;
  instead.page_target = sheet.target;
  std::string larger;
  for (const Sheet& other : kSheets) {
    if (!holds(other)) continue;
    instead.larger.push_back(other.name);
    larger += std::string(larger.empty() ? "" : " or ") + other.label;
  }
  instead.full_width_mm = 1000.0 * target.board_width_m + 2.0 * kFullMarginMm;
  instead.full_height_mm = 1000.0 * target.board_height_m + 2.0 * kFullMarginMm;
  std::ostringstream message;
  message << "target '" << target.name << "' (board " << SheetSize(target)
          << ") does not fit on the " << sheet.label << " page (" << FormatMm(page.width_mm)
          << " x " << FormatMm(page.height_mm)
          << " mm), upright or turned, and is not scaled to fit (the "
          << "pose takes the target's lengths as printed); nothing was written. Instead: "
          << "print the target made for this sheet (" << sheet.target << ")";
  if (!larger.empty()) message << ", or a page that holds this one (" << larger << ")";
  message << ", or this target at its full size (" << FormatMm(instead.full_width_mm) << " x "
          << FormatMm(instead.full_height_mm) << " mm, for a plotter or a print shop)";
  return TargetDoesNotFit(message.str(), std::move(instead));
}

Page LayOutPage(const LineTarget& target, const std::string& page_name, bool landscape) {
  CheckPageName(page_name);
  const double board_w = 1000.0 * target.board_width_m, board_h = 1000.0 * target.board_height_m;
  Page page;
  const Sheet* sheet = SheetByName(page_name);
  if (sheet == nullptr) {
    if (landscape) {
      throw std::invalid_argument(
          "a landscape page is for a sheet (a4, a3 or letter): the full page is the board's own "
          "size and orientation");
    }
    page.width_mm = board_w + 2.0 * kFullMarginMm;
    page.height_mm = board_h + 2.0 * kFullMarginMm;
    page.label = "full size";
    return page;
  }
  page.width_mm = landscape ? sheet->height_mm : sheet->width_mm;
  page.height_mm = landscape ? sheet->width_mm : sheet->height_mm;
  page.label = std::string(sheet->label) + (landscape ? " landscape" : " portrait");
  constexpr double kEps = 1e-6;  // mm: a board the size of the sheet fits it
  if (board_w <= page.width_mm + kEps && board_h <= page.height_mm + kEps) return page;
  if (board_h <= page.width_mm + kEps && board_w <= page.height_mm + kEps) {
    page.turned = true;
    return page;
  }
  throw DoesNotFit(target, *sheet, page);
}

}  // namespace

TargetPage DrawTargetPage(const LineTarget& target, const std::string& page_name, bool landscape) {
  target.Check();
  const Page page = LayOutPage(target, page_name, landscape);
  TargetPage drawing;
  drawing.page_width_mm = page.width_mm;
  drawing.page_height_mm = page.height_mm;
  drawing.page = page.label;
  drawing.turned = page.turned;
  const std::string name = target.name.empty() ? "unnamed" : target.name;
  if (page.turned) {
    drawing.note = "'" + name + "' (board " + SheetSize(target) +
                   ") is drawn turned by 90 degrees to fit the " + page.label +
                   " page: print it as it is, at 100 % (the print is the same target), and "
                   "hold the sheet turned a quarter turn counterclockwise to see it upright; "
                   "or lay it out on a landscape page to have it upright";
  }

  // Board frame -> page: the board centred on the page, turned by +90 degrees (clockwise on
  // the page, whose y points down) when page.turned.
  const double cx = 0.5 * page.width_mm, cy = 0.5 * page.height_mm;
  const auto to_page = [&](P p) {
    return page.turned ? P{cx - p.y, cy + p.x} : P{cx + p.x, cy + p.y};
  };
  const double extra_turn_deg = page.turned ? 90.0 : 0.0;
  Layout layout(target, 0.5 * (page.turned ? page.height_mm : page.width_mm),
                0.5 * (page.turned ? page.width_mm : page.height_mm));

  // A stripe within kClearanceMm of the page's edge (a target of one's own).
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    double room = std::numeric_limits<double>::infinity();
    for (const P& p : StripeOf(target.lines[i])) {
      const double x = std::clamp(p.x, -500.0 * target.board_width_m, 500.0 * target.board_width_m);
      const double y =
          std::clamp(p.y, -500.0 * target.board_height_m, 500.0 * target.board_height_m);
      room = std::min({room, layout.half_w() - std::fabs(x), layout.half_h() - std::fabs(y)});
    }
    if (room < kClearanceMm - 1e-9) {
      drawing.warning += std::string(drawing.warning.empty() ? "" : "; ") + "line " +
                         std::to_string(i + 1) + "'s stripe comes within " + FormatMm(room) +
                         " mm of the page's edge, where printers leave 3-6 mm blank: its ink "
                         "there will be missing (end the stripes at least 10 mm inside the board)";
    }
  }

  // The scale bar, the legend, then the line numbers (each avoids those before it).
  struct Drawn {
    Item item;
    Pose pose;
  };
  // Places `item` by `steps`, or says that the page has no room for `what` and what to do.
  const auto place = [&](const Item& item, const std::vector<SearchStep>& steps,
                         const std::string& what, const std::string& instead) {
    const std::optional<Pose> pose = PlaceItem(item, steps, layout);
    if (!pose) {
      throw std::runtime_error("target '" + name + "': no room on the " + page.label +
                               " page for " + what + " " + FormatMm(kClearanceMm) +
                               " mm clear of every stripe and of the page's edge; " + instead);
    }
    layout.Place(Placed(PartsOf(item), *pose));
    return *pose;
  };
  const Item bar = ScaleBar();
  const Pose bar_pose = place(
      bar,
      {{true, {0.0}}, {true, {-90.0}}, {false, {0.0}}, {false, {-90.0}}, {false, SlantsDeg(), 2.5}},
      "the 100 mm scale bar",
      "use a larger page (the full page prints the board at its full size)");
  const Item legend = Legend(target);
  const Pose legend_pose =
      place(legend, {{true, {0.0}}, {false, {0.0}}, {true, {-90.0}}, {false, {-90.0}}},
            "its name and \"print at 100 %\"", "use a larger page or a shorter name");
  std::vector<Drawn> numbers;
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    Item number;
    number.texts.push_back({{0.0, 0.0}, std::to_string(i + 1), "", "line-number"});
    for (const bool at_from : {true, false}) {
      if (const auto pose = PlaceLineNumber(number, target.lines[i], at_from, layout)) {
        layout.Place(Placed(PartsOf(number), *pose));
        numbers.push_back({number, *pose});
      }
    }
  }

  // What is printed, in page coordinates.
  const auto add_text = [&](const TextPart& text, const Pose& pose, PageGroup group) {
    const double angle = pose.angle_deg * kRadPerDeg;
    const P baseline = text.centre + P{0.0, kTextBaselineEm * kTextMm};
    const P at = to_page(pose.at + Rotated(baseline, angle));
    drawing.texts.push_back(
        {{at.x, at.y}, pose.angle_deg + extra_turn_deg, text.text, group, text.id, text.klass});
  };
  const auto add_line = [&](const LinePart& line, const Pose& pose) {
    const double angle = pose.angle_deg * kRadPerDeg;
    const P a = to_page(pose.at + Rotated(line.a, angle));
    const P b = to_page(pose.at + Rotated(line.b, angle));
    drawing.lines.push_back(
        {{a.x, a.y}, {b.x, b.y}, line.stroke_mm, PageGroup::kScale, line.id, line.klass});
  };
  const Polygon board = Rectangle(-500.0 * target.board_width_m, -500.0 * target.board_height_m,
                                  500.0 * target.board_width_m, 500.0 * target.board_height_m);
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    PageStripe stripe{static_cast<int>(i + 1), {}};
    for (const P& corner : ClippedToConvex(StripeOf(target.lines[i]), board)) {
      const P p = to_page(corner);
      stripe.corners.push_back({p.x, p.y});
    }
    if (stripe.corners.size() >= 3) drawing.stripes.push_back(std::move(stripe));
  }
  for (const Drawn& number : numbers) {
    add_text(number.item.texts[0], number.pose, PageGroup::kLineNumbers);
  }
  for (const TextPart& text : legend.texts) add_text(text, legend_pose, PageGroup::kLegend);
  for (const LinePart& line : bar.lines) add_line(line, bar_pose);
  for (const TextPart& text : bar.texts) add_text(text, bar_pose, PageGroup::kScale);

  drawing.target_name = name;
  std::ostringstream description;
  description << "Target " << name << " (board " << SheetSize(target) << "), page " << page.label
              << ", " << FormatMm(page.width_mm) << " x " << FormatMm(page.height_mm)
              << " mm. True scale: 1 unit = 1 mm; print at 100 %, do not scale, and check the "
                 "100 mm scale bar. ";
  if (page.turned) {
    description << "The target is drawn turned by 90 degrees clockwise to fit the page: its x "
                   "axis points down the page and its y axis to the left; print it as it is (the "
                   "print is the same target) and hold the sheet turned a quarter turn "
                   "counterclockwise to see it upright, or lay it out on a landscape page. ";
  } else {
    description << "Object frame: x to the right, y down. ";
  }
  description << "The board's centre, the object origin, is at (" << FormatMm(cx) << ", "
              << FormatMm(cy) << "); its outline is not printed.";
  drawing.description = description.str();
  return drawing;
}

}  // namespace oal
