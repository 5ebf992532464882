#include "eval/recordings/input_truth.h"

#include <cmath>

#include "base/angles.h"
#include "base/pose_distance.h"

namespace oal {

std::vector<LineError> MatchTruth(const std::vector<TargetLineTruth>& truth,
                                  const std::vector<DetectedLine>& held,
                                  const std::vector<int>& ids,
                                  const std::optional<PointUndistorter>& undistorter, bool json) {
  std::vector<ReferenceLine> references;
  for (const TargetLineTruth& target : truth) {
    ReferenceLine reference{target.image_line, target.end_a, target.end_b};
    if (undistorter) {
      reference.end_a = undistorter->Undistort(target.end_a);
      reference.end_b = undistorter->Undistort(target.end_b);
      reference.line = json ? target.ideal_line : LineThrough(reference.end_a, reference.end_b);
    }
    references.push_back(reference);
  }
  std::vector<LineParams> lines;
  for (const DetectedLine& line : held) lines.push_back(line.line);
  std::vector<LineError> errors(truth.size());
  for (std::size_t t = 0; t < truth.size(); ++t) errors[t].line = truth[t].id;
  for (const LineMatch& match :
       MatchLines(references, lines, kTruthMatchAngleDeg, kTruthMatchOffsetPx)) {
    LineError& error = errors[match.reference];
    error.track = ids[match.line];
    error.angle_deg = match.angle_deg;
    error.offset_px = match.offset_px;
  }
  return errors;
}

std::pair<double, double> PoseError(const vpHomogeneousMatrix& cMo,
                                    const vpHomogeneousMatrix& truth) {
  const PoseDistance d = Distance(truth, cMo);
  return {1000.0 * d.translation_m, kDegPerRad * d.rotation_rad};
}

}  // namespace oal
