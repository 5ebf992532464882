// `oalservo compare INPUT [--truth FILE|DIR] [--config FILE] [--camera FILE] [--out DIR]
// [--lines N]`: line detectors and trackers head to head (eval/lines/compare.h has the methods, the
// truth formats and the metric definitions).
#pragma once

namespace oal {

/// `oalservo compare ...`; argv[0] is "compare". Prints the markdown table to stdout.
int RunCompare(int argc, char** argv);

}  // namespace oal
