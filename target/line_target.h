// The planar line targets: stripes printed on a light board, and the built-in ones (the
// paper's 2 m boards, the '#' on a printable sheet). What the pose, the tracker and the
// renderer share about a target; nothing of images or cameras.
#pragma once

#include <string>
#include <vector>

namespace oal {

/// A straight stripe on the target plane, metres in the object frame.
struct TargetLine {
  double x1_m = 0.0, y1_m = 0.0;  ///< one end of the centre line
  double x2_m = 0.0, y2_m = 0.0;  ///< the other end
  double width_m = 0.01;          ///< printed width, > 0
};

/// A light board with dark stripes, centred on the object origin.
struct LineTarget {
  std::string name;
  double board_width_m = 2.0;     ///< along x, > 0
  double board_height_m = 2.0;    ///< along y, > 0
  int board_grey = 215;           ///< [0, 255]
  int line_grey = 35;             ///< [0, 255]
  std::vector<TargetLine> lines;  ///< may be empty (a blank board)

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// Two parallel stripes on a 2 m board (the paper's line-detection target).
LineTarget TwoLineTarget();
/// Four stripes in a '#' on a 2 m x 2 m board, whose asymmetric spacing and widths make
/// lines 1-4 identifiable (the paper's pose target, Figure 2, in the paper's condition: the
/// lines traverse the image). Line 1 is the widest. Named "four-line-board".
LineTarget FourLineTarget();
/// The '#' printed on one landscape sheet: the sheet is the board, the stripes end 10 mm
/// inside its edges, the four crossings are centred on it (config/four-line-a3.yaml gives
/// the geometry and why). A3 (420 x 297 mm), A4 (297 x 210 mm), US letter (279.4 x 215.9).
LineTarget FourLineA3Target();
LineTarget FourLineA4Target();
LineTarget FourLineLetterTarget();
/// The built-in targets' names, the default first: "four-line-a3", "four-line-a4",
/// "four-line-letter", "four-line-board", "two-line".
const std::vector<std::string>& TargetNames();
/// TargetNames() joined for messages and help: "four-line-a3, four-line-a4, ...".
std::string TargetNameList();
/// One of TargetNames() ("four-line" is kept as a name of "four-line-board"); throws
/// std::invalid_argument listing them otherwise.
LineTarget TargetByName(const std::string& name);

}  // namespace oal
