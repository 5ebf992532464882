#include "app/target_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/atomic_file.h"
#include "app/command_line.h"
#include "app/config.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr double kMarginMm = 10.0;        // blank border of the page, each side
constexpr double kFooterGapMm = 6.0;      // board edge to the first footer line
constexpr double kFooterHeightMm = 30.0;  // title, note, scale bar and its label
constexpr double kFooterWidthMm = 120.0;  // the footer block, centred under the board
constexpr double kScaleBarMm = 100.0;
constexpr double kTextMm = 4.0;          // footer font size
constexpr double kNumberMm = 3.5;        // line-number font size
constexpr double kNumberInsetMm = 12.0;  // line number, from the line's end along the line
constexpr double kNumberGapMm = 3.0;     // line number, from the stripe's side

struct Sheet {
  const char* name;  // as on the command line
  const char* label;
  double width_mm, height_mm;  // portrait
};

constexpr Sheet kSheets[] = {
    {"a4", "A4", 210.0, 297.0}, {"a3", "A3", 297.0, 420.0}, {"letter", "US letter", 215.9, 279.4}};

const Sheet& SheetByName(const std::string& name) {
  for (const Sheet& sheet : kSheets) {
    if (name == sheet.name) return sheet;
  }
  throw std::invalid_argument("page '" + name + "' is not one of: a4, a3, letter, auto");
}

// Millimetres with at most 4 decimals, trailing zeros dropped ("12.5", "-80", "0.0125").
std::string Mm(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.4f", value);
  std::string out = text;
  while (out.back() == '0') out.pop_back();
  if (out.back() == '.') out.pop_back();
  if (out == "-0") out = "0";
  return out;
}

// The page for a drawing of need_w x need_h mm (margins included), or nothing if none fits.
bool FitOnSheet(const Sheet& sheet, double need_w, double need_h, TargetDrawing* drawing) {
  if (need_w <= sheet.width_mm && need_h <= sheet.height_mm) {
    drawing->page_width_mm = sheet.width_mm;
    drawing->page_height_mm = sheet.height_mm;
    drawing->page = std::string(sheet.label) + " portrait";
    return true;
  }
  if (need_w <= sheet.height_mm && need_h <= sheet.width_mm) {
    drawing->page_width_mm = sheet.height_mm;
    drawing->page_height_mm = sheet.width_mm;
    drawing->page = std::string(sheet.label) + " landscape";
    return true;
  }
  return false;
}

// The largest board that fits on `sheet` in portrait, with the margins and the footer.
std::pair<double, double> LargestBoardMm(const Sheet& sheet) {
  return {sheet.width_mm - 2.0 * kMarginMm,
          sheet.height_mm - 2.0 * kMarginMm - kFooterGapMm - kFooterHeightMm};
}

std::string TooLargeWarning(const LineTarget& target, const Sheet& sheet, double need_w,
                            double need_h) {
  const double usable_w = sheet.width_mm - 2.0 * kMarginMm;
  const double usable_h = sheet.height_mm - 2.0 * kMarginMm;
  const int across = static_cast<int>(std::ceil(need_w / usable_w));
  const int down = static_cast<int>(std::ceil(need_h / usable_h));
  const auto [largest_w, largest_h] = LargestBoardMm(sheet);
  std::ostringstream message;
  message << "target '" << target.name << "' (board " << Mm(1000.0 * target.board_width_m) << " x "
          << Mm(1000.0 * target.board_height_m) << " mm) does not fit on " << sheet.label << " ("
          << Mm(sheet.width_mm) << " x " << Mm(sheet.height_mm) << " mm, " << Mm(kMarginMm)
          << " mm margins) at true scale, so the SVG is written at full size, " << Mm(need_w)
          << " x " << Mm(need_h) << " mm. To print it: at 100 % on a plotter or at a print shop, "
          << "or tiled with a poster tool onto about " << across * down << " " << sheet.label
          << " sheets (" << across << " x " << down << ") joined edge to edge. Do not shrink it "
          << "to one page: the pose takes the target's lengths as printed (a scaled print needs "
          << "a target config scaled by the same factor). For one " << sheet.label
          << " sheet, draw a board of at most " << Mm(largest_w) << " x " << Mm(largest_h)
          << " mm: a config whose target: section has that board_width_m and board_height_m "
          << "(the stripes are clipped to the board; keep every line and crossing on it)";
  return message.str();
}

// The stripe of `line` as a polygon, millimetres in the drawing (board centre at cx, cy).
std::string StripePoints(const TargetLine& line, double cx, double cy) {
  const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
  const double length = std::hypot(dx, dy);
  const double nx = -dy / length * 0.5 * line.width_m, ny = dx / length * 0.5 * line.width_m;
  const double corners[4][2] = {{line.x1_m + nx, line.y1_m + ny},
                                {line.x2_m + nx, line.y2_m + ny},
                                {line.x2_m - nx, line.y2_m - ny},
                                {line.x1_m - nx, line.y1_m - ny}};
  std::string points;
  for (const auto& corner : corners) {
    points += (points.empty() ? "" : " ") + Mm(cx + 1000.0 * corner[0]) + "," +
              Mm(cy + 1000.0 * corner[1]);
  }
  return points;
}

// The number of line `index` beside both of its ends, inside the board.
std::string LineNumbers(const TargetLine& line, int index, double cx, double cy) {
  const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
  const double length_mm = 1000.0 * std::hypot(dx, dy);
  const double ex = 1000.0 * dx / length_mm, ey = 1000.0 * dy / length_mm;  // unit, along
  const double nx = -ey, ny = ex;                                           // unit, across
  const double inset = std::min(kNumberInsetMm, 0.25 * length_mm);
  const double side = 500.0 * line.width_m + kNumberGapMm + 0.5 * kNumberMm;
  std::string text;
  for (const double sign : {1.0, -1.0}) {
    // From the `from` end inward (sign +1), from the `to` end inward (sign -1).
    const double ax = cx + 1000.0 * (sign > 0 ? line.x1_m : line.x2_m);
    const double ay = cy + 1000.0 * (sign > 0 ? line.y1_m : line.y2_m);
    const double x = ax + sign * inset * ex + side * nx;
    const double y = ay + sign * inset * ey + side * ny;
    text += "    <text class=\"line-number\" x=\"" + Mm(x) + "\" y=\"" + Mm(y) + "\">" +
            std::to_string(index + 1) + "</text>\n";
  }
  return text;
}

}  // namespace

TargetDrawing DrawTargetSvg(const LineTarget& target, const std::string& page) {
  target.Check();
  if (page != "auto") SheetByName(page);  // rejects an unknown name
  const double board_w = 1000.0 * target.board_width_m;
  const double board_h = 1000.0 * target.board_height_m;
  const double content_w = std::max(board_w, kFooterWidthMm);
  const double content_h = board_h + kFooterGapMm + kFooterHeightMm;
  const double need_w = content_w + 2.0 * kMarginMm, need_h = content_h + 2.0 * kMarginMm;

  TargetDrawing drawing;
  bool placed = false;
  if (page == "auto") {
    placed = FitOnSheet(SheetByName("a4"), need_w, need_h, &drawing) ||
             FitOnSheet(SheetByName("a3"), need_w, need_h, &drawing);
  } else {
    placed = FitOnSheet(SheetByName(page), need_w, need_h, &drawing);
  }
  if (!placed) {
    drawing.fits = false;
    drawing.page = "full size";
    drawing.page_width_mm = need_w;
    drawing.page_height_mm = need_h;
    drawing.warning =
        TooLargeWarning(target, SheetByName(page == "auto" ? "a3" : page), need_w, need_h);
  }

  // The content block centred on the page; the board at its top, centred across.
  const double left = 0.5 * (drawing.page_width_mm - content_w);
  const double top = 0.5 * (drawing.page_height_mm - content_h);
  const double cx = left + 0.5 * content_w;  // board centre = object origin
  const double cy = top + 0.5 * board_h;
  const double board_x = cx - 0.5 * board_w, board_y = top;
  const double footer_x = cx - 0.5 * kFooterWidthMm;
  const double footer_y = top + board_h + kFooterGapMm;
  const std::string name = MarkupEscaped(target.name.empty() ? "unnamed" : target.name);

  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\""
      << Mm(drawing.page_width_mm) << "mm\" height=\"" << Mm(drawing.page_height_mm)
      << "mm\" viewBox=\"0 0 " << Mm(drawing.page_width_mm) << " " << Mm(drawing.page_height_mm)
      << "\">\n"
      << "  <title>oalservo target " << name << "</title>\n"
      << "  <desc>True scale: 1 unit = 1 mm. Object frame: x right, y down, origin at the board "
         "centre ("
      << Mm(cx) << ", " << Mm(cy) << "). Print at 100 %, do not scale.</desc>\n"
      << "  <defs>\n"
      << "    <clipPath id=\"board-clip\"><rect x=\"" << Mm(board_x) << "\" y=\"" << Mm(board_y)
      << "\" width=\"" << Mm(board_w) << "\" height=\"" << Mm(board_h) << "\"/></clipPath>\n"
      << "  </defs>\n"
      << "  <rect id=\"board\" x=\"" << Mm(board_x) << "\" y=\"" << Mm(board_y) << "\" width=\""
      << Mm(board_w) << "\" height=\"" << Mm(board_h)
      << "\" fill=\"none\" stroke=\"#b0b0b0\" stroke-width=\"0.25\"/>\n"
      << "  <g id=\"stripes\" clip-path=\"url(#board-clip)\" fill=\"#000000\" stroke=\"none\">\n";
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    svg << "    <polygon class=\"stripe\" id=\"line-" << i + 1 << "\" points=\""
        << StripePoints(target.lines[i], cx, cy) << "\"/>\n";
  }
  svg << "  </g>\n"
      << "  <g id=\"line-numbers\" fill=\"#808080\" font-family=\"sans-serif\" font-size=\""
      << Mm(kNumberMm) << "\" text-anchor=\"middle\" dominant-baseline=\"central\">\n";
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    svg << LineNumbers(target.lines[i], static_cast<int>(i), cx, cy);
  }
  const double bar_y = footer_y + 2.0 * kTextMm + 10.0;
  svg << "  </g>\n"
      << "  <g id=\"footer\" fill=\"#000000\" font-family=\"sans-serif\" font-size=\""
      << Mm(kTextMm) << "\">\n"
      << "    <text id=\"name\" x=\"" << Mm(footer_x) << "\" y=\"" << Mm(footer_y + kTextMm)
      << "\">target " << name << ": board " << Mm(board_w) << " x " << Mm(board_h) << " mm, "
      << target.lines.size() << " lines</text>\n"
      << "    <text id=\"note\" x=\"" << Mm(footer_x) << "\" y=\""
      << Mm(footer_y + 2.0 * kTextMm + 2.0) << "\">print at 100 %, do not scale</text>\n"
      << "    <line id=\"scale-bar\" x1=\"" << Mm(footer_x) << "\" y1=\"" << Mm(bar_y) << "\" x2=\""
      << Mm(footer_x + kScaleBarMm) << "\" y2=\"" << Mm(bar_y)
      << "\" stroke=\"#000000\" stroke-width=\"0.5\"/>\n";
  for (int mm = 0; mm <= static_cast<int>(kScaleBarMm); mm += 10) {
    const double tick = mm % 50 == 0 ? 3.0 : 1.5;
    svg << "    <line class=\"scale-tick\" x1=\"" << Mm(footer_x + mm) << "\" y1=\""
        << Mm(bar_y - tick) << "\" x2=\"" << Mm(footer_x + mm) << "\" y2=\"" << Mm(bar_y)
        << "\" stroke=\"#000000\" stroke-width=\"0.3\"/>\n";
  }
  svg << "    <text id=\"scale-label\" x=\"" << Mm(footer_x + kScaleBarMm + 3.0) << "\" y=\""
      << Mm(bar_y + 0.5 * kTextMm - 0.5) << "\">100 mm</text>\n"
      << "  </g>\n"
      << "</svg>\n";
  drawing.svg = svg.str();
  return drawing;
}

TargetDrawing WriteTargetSvg(const TargetCommandOptions& options) {
  if (options.out.empty()) throw std::invalid_argument("no output file given (--out FILE.svg)");
  const LineTarget target =
      options.config.empty() ? FourLineTarget() : LoadConfig(options.config).target;
  TargetDrawing drawing = DrawTargetSvg(target, options.page);
  const fs::path out(options.out);
  const fs::path dir = out.parent_path();
  if (!dir.empty() && !fs::is_directory(dir)) {
    throw std::runtime_error("cannot write '" + options.out + "': directory '" + dir.string() +
                             "' does not exist");
  }
  if (fs::is_directory(out)) {
    throw std::runtime_error("cannot write '" + options.out + "': it is a directory");
  }
  WriteFileAtomically(out, drawing.svg);
  return drawing;
}

int RunTarget(int argc, char** argv) {
  TargetCommandOptions options;
  CLI::App cli(
      "Write a printable, true-scale SVG drawing of the line target (1 unit = 1 mm; stripes "
      "black, line numbers, a 100 mm scale bar). A board larger than the page is written at "
      "full size with a warning saying how to print it; the built-in two-line and four-line "
      "targets are 2 m x 2 m boards, so they always are.",
      "oalservo target");
  cli.add_option("--config", options.config,
                 "YAML file whose 'target:' section gives the target (default: the built-in "
                 "four-line target, config/four-line-board.yaml)");
  cli.add_option("--out", options.out, "the SVG file to write")->required();
  cli.add_option("--page", options.page, "sheet: a4, a3, letter, or auto (A4, else A3)")
      ->check(CLI::IsMember({"a4", "a3", "letter", "auto"}))
      ->capture_default_str();
  const auto [a3_w, a3_h] = LargestBoardMm(SheetByName("a3"));
  cli.footer(
      "Examples:\n"
      "  oalservo target --out four-line.svg\n"
      "      the built-in 2 m x 2 m board at full size, for a plotter or a print shop (or tiles)\n"
      "  oalservo target --config my-board.yaml --page a3 --out board.svg\n"
      "      a board of your own (its target: section) up to " +
      Mm(a3_w) + " x " + Mm(a3_h) + " mm, on one A3 sheet");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const TargetDrawing drawing = WriteTargetSvg(options);
  if (!drawing.fits) Warn("target", drawing.warning);
  std::cerr << "oalservo target: " << options.out << " written (" << drawing.page << ", "
            << Mm(drawing.page_width_mm) << " x " << Mm(drawing.page_height_mm) << " mm)\n";
  return kExitOk;
}

}  // namespace oal
