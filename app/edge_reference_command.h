#pragma once

namespace oal {

/// `oalservo edge-reference PATTERN --out FILE.csv`: the independent sub-pixel edge fit of
/// eval/lines/edge_reference.h over an image sequence, written as compare's truth CSV.
int RunEdgeReference(int argc, char** argv);

}  // namespace oal
