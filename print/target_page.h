// A printable, true-scale page of a planar line target (`oalservo target`): laid out here,
// written as SVG (print/target_svg.h) or PDF (print/target_pdf.h) from the same geometry.
//
// The target: any LineTarget; `oalservo target` takes a built-in by name, a config's
// `target:`, or the sheet target made for the page (SheetTargetName: four-line-a4 for a4,
// four-line-a3 for a3, four-line-letter for letter; config/four-line-*.yaml).
//
// The page: exactly the sheet (A4, A3, US letter), portrait unless `landscape`, 1 SVG unit =
// 1 mm (width/height in mm, viewBox in mm); or `full`, the board at its full size with 10 mm
// around it (the 2 m board, for a plotter or a print shop). The board is centred on the page,
// upright (object x to the right, y down, as the camera sees it) when it fits so, else turned
// by 90 degrees clockwise (object x down the page, y to the left), which the SVG's <desc> and
// the drawing's note say. A board that fits the page in neither orientation is refused
// (TargetDoesNotFit, saying what to print instead); nothing is tiled or scaled.
//
// What is printed: the stripes, black filled polygons exactly as the target has them (the
// centre line widened by width / 2 on both sides, flat ends), cut to the board here (no
// renderer's clipping is needed, so every renderer draws them alike); the board's
// outline is not printed (the sheet is the board, and an outline would be one more line for
// the camera). Everything else is small and thin (text 3 mm, strokes at most 0.3 mm, grey),
// because a camera looks at the sheet and a thick mark would be a line: the line numbers
// 1..N beside both ends of each stripe, the target's name and size with "print at 100 %, do
// not scale", and a 100 mm scale bar with a tick every 10 mm. Each of those is at least
// kClearanceMm from every stripe and from the page's edge (a printer's margin is 3-6 mm),
// never between the stripes' crossings (the middle cell of the '#', from which the tracker
// finds the target), and laid out in the paper between the stripes by a search: a corner
// cell of the '#' first, else the cell with the most room, upright first, then turned by 90
// degrees, then (the scale bar on a small sheet) at a slant. A text's extent is estimated as
// kTextWidthEm per character by kTextHeightEm, around a centre kTextBaselineEm above its
// baseline (see the constants); its `x`, `y` are the middle of its baseline (text-anchor
// middle).
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "target/line_target.h"

namespace oal {

/// Distance kept from every stripe and from the page's edge by everything but the stripes, mm.
inline constexpr double kClearanceMm = 5.0;
/// The estimated extent of a text of N characters at font size S (sans-serif): N *
/// kTextWidthEm * S wide, kTextHeightEm * S tall, centred kTextBaselineEm * S above the
/// baseline. Generous for DejaVu Sans and Helvetica (capitals, digits, '%', descenders).
inline constexpr double kTextWidthEm = 0.7;
inline constexpr double kTextHeightEm = 1.05;
inline constexpr double kTextBaselineEm = 0.275;

/// A board that fits the page in neither orientation; the message says what does not fit and
/// what to do instead.
class TargetDoesNotFit : public std::runtime_error {
 public:
  /// What a caller needs to say what to print instead, in its own words.
  struct Alternatives {
    std::string page;                 ///< the page asked ("a3")
    std::string page_target;          ///< the target made for that page ("four-line-a3")
    std::vector<std::string> larger;  ///< sheets that hold this board ("a3", ...)
    double full_width_mm = 0.0, full_height_mm = 0.0;  ///< the page "full" would be
  };
  TargetDoesNotFit(const std::string& message, Alternatives alternatives)
      : std::runtime_error(message), alternatives_(std::move(alternatives)) {}
  const Alternatives& alternatives() const { return alternatives_; }

 private:
  Alternatives alternatives_;
};

/// A point on the page, millimetres from its top left corner, y down.
struct PagePoint {
  double x_mm = 0.0, y_mm = 0.0;
};

/// A stripe as printed: a filled black polygon, its corners in order.
struct PageStripe {
  int line = 0;  ///< 1-based, as the target numbers its lines
  std::vector<PagePoint> corners;
};

/// Which printed group a mark belongs to (the SVG's groups, the PDF's drawing order).
enum class PageGroup { kLineNumbers, kLegend, kScale };

/// A thin grey line (the scale bar and its ticks), flat ends.
struct PageLine {
  PagePoint a, b;
  double stroke_mm = 0.0;
  PageGroup group = PageGroup::kScale;
  std::string id;     ///< the SVG's id (one mark), or empty
  std::string klass;  ///< the SVG's class (a kind of mark), or empty
};

/// A grey sans-serif text of kPageTextMm, `at` the middle of its baseline, turned by
/// angle_deg (clockwise on the page) about it.
struct PageText {
  PagePoint at;
  double angle_deg = 0.0;
  std::string text;
  PageGroup group = PageGroup::kLegend;
  std::string id, klass;
};

/// Font size of every text, mm, and the grey of everything but the stripes (0 black, 1 white).
inline constexpr double kPageTextMm = 3.0;
inline constexpr double kPageGrey = 0.5;

/// A target laid out on a page.
struct TargetPage {
  double page_width_mm = 0.0;
  double page_height_mm = 0.0;
  std::string page;         ///< "A4 portrait", "A3 landscape", ..., or "full size"
  bool turned = false;      ///< drawn turned by 90 degrees (clockwise) to fit the page
  std::string note;         ///< when turned: what that means for printing; else empty
  std::string warning;      ///< a stripe within kClearanceMm of the page's edge; else empty
  std::string target_name;  ///< "unnamed" for a target without a name
  std::string description;  ///< what the page is and how to print it (SVG <desc>, PDF subject)
  std::vector<PageStripe> stripes;
  std::vector<PageLine> lines;
  std::vector<PageText> texts;
};

/// Lays `target` out on `page` ("a4", "a3", "letter" or "full"), portrait unless
/// `landscape` (not with "full"). Throws std::invalid_argument for another page name, for
/// landscape with "full" or for a target that fails Check(), TargetDoesNotFit for a board the
/// page does not hold, std::runtime_error when the legend finds no room.
TargetPage DrawTargetPage(const LineTarget& target, const std::string& page,
                          bool landscape = false);

/// Millimetres as the page's files write them: at most 4 decimals, trailing zeros dropped
/// ("12.5", "-80", "0.0125").
std::string FormatMm(double value);

/// Throws std::invalid_argument unless `page` is a4, a3, letter or full.
void CheckPageName(const std::string& page);

/// The sheet target made for `page`: four-line-a4 for a4, four-line-a3 for a3,
/// four-line-letter for letter; for full, the first built-in (four-line-a3).
std::string SheetTargetName(const std::string& page);

}  // namespace oal
