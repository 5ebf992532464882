// `oalservo target`: a printable, true-scale SVG drawing of the planar line target (the
// `target:` section of a config file, config/four-line-board.yaml by default the built-in
// four-line target).
//
// The drawing: 1 SVG unit = 1 mm (width/height in mm, viewBox in mm), the object frame's x
// to the right and y down with the board centre at the centre of the board rectangle, i.e. the
// board seen from the front, as the camera sees it (scene/scene.h). The board is the paper
// (outlined thinly, not filled: print on white), the stripes are black filled polygons, each
// the rectangle of its centre line widened by width_m / 2 on both sides (flat ends, as the
// renderer draws them), clipped to the board. Line numbers 1..N (line 1 = lines[0]) are
// printed small in grey beside both ends of each stripe, near the board edge; below the board
// sit the target name, the note "print at 100 %, do not scale" and a 100 mm scale bar.
//
// Pages: the drawing is centred on the chosen sheet (A4, A3 or US letter, portrait or
// landscape, whichever holds it; `auto`: A4, else A3). A board too large for the sheet is not
// tiled or shrunk: the SVG is written at full size (page = drawing plus margins) and a warning
// says so and how to print it: on a plotter, tiled by a poster tool onto N sheets, or as a
// smaller board of the largest size the sheet holds (given in the warning). The built-in four-line
// target's board is 2 m x 2 m, so it always takes this path; a print shop or plotter prints it
// at 100 %.
#pragma once

#include <string>

#include "scene/scene.h"

namespace oal {

/// A drawing of a target and the page it was laid out on.
struct TargetDrawing {
  std::string svg;              ///< the whole SVG document
  double page_width_mm = 0.0;   ///< the SVG's width
  double page_height_mm = 0.0;  ///< the SVG's height
  std::string page;             ///< "A4 portrait", ..., or "full size"
  bool fits = true;             ///< false: larger than the requested sheet, drawn at full size
  std::string warning;          ///< why it does not fit, with what to do; empty when it fits
};

/// Lays `target` out on `page` ("a4", "a3", "letter" or "auto"). Throws
/// std::invalid_argument for another page name or a target that fails Check().
TargetDrawing DrawTargetSvg(const LineTarget& target, const std::string& page);

struct TargetCommandOptions {
  std::string config;         ///< YAML file with a `target:` section; empty: FourLineTarget()
  std::string out;            ///< the SVG file to write; required
  std::string page = "auto";  ///< a4, a3, letter or auto
};

/// Reads the target, draws it and writes options.out atomically (nothing is left behind on
/// error). Returns the drawing (for its warning); throws on bad options or I/O errors.
TargetDrawing WriteTargetSvg(const TargetCommandOptions& options);

/// `oalservo target ...`; argv[0] is "target".
int RunTarget(int argc, char** argv);

}  // namespace oal
