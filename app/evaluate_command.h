// `oalservo evaluate INPUT... --out DIR [--config FILE] [--camera FILE] [--truth FILE]
// [--compare] [--jobs N] [--shard I/N] [--resume]`: offline evaluation of the tracker and the
// pose on recorded videos, with an HTML report (eval/recordings/evaluate.h; docs/EVALUATE.md).
#pragma once

namespace oal {

/// `oalservo evaluate ...`; argv[0] is "evaluate". Exit code 0 when every input was
/// evaluated, 1 when some failed (the others are still evaluated and reported).
int RunEvaluate(int argc, char** argv);

}  // namespace oal
