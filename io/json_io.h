// JSON forms of the detector's and the renderer's results, shared by the commands so that a
// line, a pose or a camera reads the same in every file oalservo writes.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "detector/detector.h"
#include "detector/lens.h"
#include "scene/scene.h"
#include "servo/target_tracker.h"

namespace oal {

/// Keys keep the order they are written in, so files read naturally.
using Json = nlohmann::ordered_json;

/// [u, v]
Json PointJson(const Point2d& point);
/// {rho, theta}: pixels, radians (detector/line.h convention).
Json LineJson(const LineParams& line);
/// {rho, theta, votes, count, borders, support, width, end_a, end_b}
Json DetectedLineJson(const DetectedLine& line);
/// {index, visible, ideal, distorted_fit, end_a, end_b, visible_length_px, width_px}
Json TruthLineJson(const TruthLine& line);
/// The one form of a pose in every JSON the product writes (render's truth, pose, demo):
/// {matrix: 4x4 rows, t_m: [x,y,z] metres, thetau_rad: [tux,tuy,tuz] (theta-u, radians)}
Json PoseJson(const vpHomogeneousMatrix& cMo);
/// {model, px, py, u0, v0, kud, kdu, width, height}
Json CameraJson(const Lens& camera, int width, int height);
/// Where the target tracker looked for the frame's target: {mode, source, borders,
/// candidates, region (the outermost border scanned, image pixels; empty: the whole image)}.
Json ScanJson(const TargetFrame& result, ScanMode mode);

/// Writes `record` as one line of JSON Lines; flushes when asked; throws
/// std::runtime_error if the stream failed (disk full, closed pipe).
void WriteJsonLine(std::ostream& sink, const Json& record, bool flush);

/// Writes `text` and flushes; throws std::runtime_error if the stream failed, as
/// WriteJsonLine does. For tables and reports printed on stdout.
void WriteText(std::ostream& sink, const std::string& text);

}  // namespace oal
