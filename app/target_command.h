// `oalservo target`: a printable, true-scale page of a planar line target, written as PDF or
// SVG by the output's extension (print/ lays it out and writes it).
#pragma once

#include <string>

#include "print/target_page.h"
#include "target/line_target.h"

namespace oal {

struct TargetCommandOptions {
  /// A built-in target (TargetNames(), or "four-line"); empty: the config's, or the page's.
  std::string target;
  /// YAML file whose `target:` section gives the target; not with `target`.
  std::string config;
  std::string page = "a3";  ///< a4, a3, letter or full
  bool landscape = false;   ///< the sheet's long side across the page; not with full
  std::string out;          ///< the file to write: .pdf or .svg; required

  /// Throws std::invalid_argument naming the command-line option that is wrong.
  void Check() const;
};

/// The target the options name: `target`, else the config's, else the sheet target made for
/// `page` (four-line-a3 for full).
LineTarget TargetToPrint(const TargetCommandOptions& options);

/// Checks the options, draws the target and writes options.out atomically, as PDF or SVG by
/// its extension. Throws on bad options (another extension among them), a target the page
/// does not hold (TargetDoesNotFit) or an I/O error, and then writes nothing (a file already
/// at options.out is left as it was).
TargetPage WriteTargetPage(const TargetCommandOptions& options);

/// `oalservo target ...`; argv[0] is "target".
int RunTarget(int argc, char** argv);

}  // namespace oal
