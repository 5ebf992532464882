#include "target/line_target.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "base/check.h"

namespace oal {

void LineTarget::Check() const {
  RequireOption(board_width_m > 0.0, "LineTarget::board_width_m", board_width_m,
                "board_width_m > 0");
  RequireOption(board_height_m > 0.0, "LineTarget::board_height_m", board_height_m,
                "board_height_m > 0");
  RequireOption(board_grey >= 0 && board_grey <= 255, "LineTarget::board_grey", board_grey,
                "0 <= board_grey <= 255");
  RequireOption(line_grey >= 0 && line_grey <= 255, "LineTarget::line_grey", line_grey,
                "0 <= line_grey <= 255");
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const TargetLine& line = lines[i];
    const std::string prefix = "LineTarget::lines[" + std::to_string(i) + "].";
    for (const auto& [field, value] : {std::pair<const char*, double>{"x1_m", line.x1_m},
                                       {"y1_m", line.y1_m},
                                       {"x2_m", line.x2_m},
                                       {"y2_m", line.y2_m}}) {
      RequireOption(std::isfinite(value), prefix + field, value, std::string(field) + " is finite");
    }
    RequireOption(line.width_m > 0.0, prefix + "width_m", line.width_m, "width_m > 0");
    const double length = std::hypot(line.x2_m - line.x1_m, line.y2_m - line.y1_m);
    RequireOption(length > 0.0, prefix + "length", length, "the two ends differ");
  }
}

LineTarget TwoLineTarget() {
  LineTarget target;
  target.name = "two-line";
  target.lines = {TargetLine{-0.06, -1.0, -0.06, 1.0, 0.02},
                  TargetLine{0.06, -1.0, 0.06, 1.0, 0.02}};
  return target;
}

LineTarget FourLineTarget() {
  LineTarget target;
  target.name = "four-line-board";
  // Lines 1 and 3 vertical (0.18 m apart), lines 2 and 4 horizontal (0.13 m apart); the
  // widths 30, 15, 20 and 17.5 mm differ, line 1 is the widest.
  target.lines = {
      TargetLine{-0.08, -1.0, -0.08, 1.0, 0.03}, TargetLine{-1.0, -0.07, 1.0, -0.07, 0.015},
      TargetLine{0.10, -1.0, 0.10, 1.0, 0.02}, TargetLine{-1.0, 0.06, 1.0, 0.06, 0.0175}};
  return target;
}

namespace {

// A '#' on one landscape sheet (config/four-line-a3.yaml explains the choices): the stripes
// run from margin to margin, the four crossings form a half_x x half_y rectangle (times 2)
// centred on the sheet, lines 1 and 3 at x = -+half_x, lines 2 and 4 at y = -+half_y.
LineTarget SheetTarget(const std::string& name, double sheet_width_m, double sheet_height_m,
                       double margin_m, double half_x_m, double half_y_m,
                       const std::array<double, 4>& widths_m) {
  LineTarget target;
  target.name = name;
  target.board_width_m = sheet_width_m;
  target.board_height_m = sheet_height_m;
  const double x_end = 0.5 * sheet_width_m - margin_m, y_end = 0.5 * sheet_height_m - margin_m;
  target.lines = {TargetLine{-half_x_m, -y_end, -half_x_m, y_end, widths_m[0]},
                  TargetLine{-x_end, -half_y_m, x_end, -half_y_m, widths_m[1]},
                  TargetLine{half_x_m, -y_end, half_x_m, y_end, widths_m[2]},
                  TargetLine{-x_end, half_y_m, x_end, half_y_m, widths_m[3]}};
  return target;
}

}  // namespace

LineTarget FourLineA3Target() {
  return SheetTarget("four-line-a3", 0.420, 0.297, 0.010, 0.090, 0.062,
                     {0.024, 0.012, 0.016, 0.014});
}

LineTarget FourLineA4Target() {
  return SheetTarget("four-line-a4", 0.297, 0.210, 0.010, 0.063, 0.043,
                     {0.018, 0.009, 0.012, 0.0105});
}

LineTarget FourLineLetterTarget() {
  return SheetTarget("four-line-letter", 0.2794, 0.2159, 0.010, 0.0594, 0.0441,
                     {0.018, 0.009, 0.012, 0.0105});
}

const std::vector<std::string>& TargetNames() {
  static const std::vector<std::string> names = {"four-line-a3", "four-line-a4", "four-line-letter",
                                                 "four-line-board", "two-line"};
  return names;
}

std::string TargetNameList() {
  std::string list;
  for (const std::string& name : TargetNames()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

LineTarget TargetByName(const std::string& name) {
  if (name == "two-line") return TwoLineTarget();
  if (name == "four-line-board" || name == "four-line") return FourLineTarget();
  if (name == "four-line-a3") return FourLineA3Target();
  if (name == "four-line-a4") return FourLineA4Target();
  if (name == "four-line-letter") return FourLineLetterTarget();
  throw std::invalid_argument("target '" + name + "' is not one of: " + TargetNameList());
}

}  // namespace oal
