// `oalservo target`: a printable, true-scale SVG of a planar line target on one page
// (target/target_svg.h lays it out and draws it).
#pragma once

#include <string>

#include "target/line_target.h"
#include "target/target_svg.h"

namespace oal {

struct TargetCommandOptions {
  /// A built-in target (TargetNames(), or "four-line"); empty: the config's, or the page's.
  std::string target;
  /// YAML file whose `target:` section gives the target; not with `target`.
  std::string config;
  std::string page = "a3";  ///< a4, a3, letter or full
  bool landscape = false;   ///< the sheet's long side across the page; not with full
  std::string out;          ///< the SVG file to write; required

  /// Throws std::invalid_argument naming the command-line option that is wrong.
  void Check() const;
};

/// The target the options name: `target`, else the config's, else the sheet target made for
/// `page` (four-line-a3 for full).
LineTarget TargetToPrint(const TargetCommandOptions& options);

/// Checks the options, draws the target and writes options.out atomically. Throws on bad
/// options, a target the page does not hold (TargetDoesNotFit) or an I/O error, and then
/// writes nothing (a file already at options.out is left as it was).
TargetDrawing WriteTargetSvg(const TargetCommandOptions& options);

/// `oalservo target ...`; argv[0] is "target".
int RunTarget(int argc, char** argv);

}  // namespace oal
