// The truth of one input of `oalservo evaluate` (eval/recordings/evaluate.h), frame by frame: from
// --truth, the <video>.truth.csv beside a video, or the renderer's JSON beside each image; and
// the tracked lines and the pose scored against it.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "eval/lines/line_scoring.h"
#include "io/image_source.h"
#include "io/truth_file.h"

namespace oal {

/// A truth line is found when a tracked line is within both bounds of it.
inline constexpr double kTruthMatchAngleDeg = 5.0;
inline constexpr double kTruthMatchOffsetPx = 10.0;

/// A frame's truth: its visible lines and its pose, when known.
struct FrameTruth {
  bool known = false;
  std::vector<TargetLineTruth> lines;  ///< visible lines, image pixels
  std::optional<vpHomogeneousMatrix> cMo;
};

/// Where an input's truth comes from, and each frame's.
class TruthReader {
 public:
  /// `truth_path`: --truth ("" when not given); `input`: what OpenImageSource opens.
  TruthReader(const std::string& truth_path, const std::string& input) {
    if (!truth_path.empty()) {
      if (std::filesystem::path(truth_path).extension() == ".csv") {
        UseCsv(truth_path);
      } else if (std::filesystem::is_directory(truth_path)) {
        kind_ = "json";
        json_dir_ = truth_path;
      } else {
        throw std::runtime_error("truth '" + truth_path +
                                 "' is neither a .csv file nor a directory of frame JSON files");
      }
    } else if (HasVideoExtension(input)) {
      const std::filesystem::path csv =
          std::filesystem::path(input).replace_extension(".truth.csv");
      if (std::filesystem::is_regular_file(csv)) UseCsv(csv.string());
    } else {
      kind_ = "auto";  // JSON next to the images, decided at the first frame
    }
  }

  const std::string& kind() const { return kind_; }
  const std::string& path() const { return path_; }

  FrameTruth Get(const std::string& source, int index, int width, int height) {
    FrameTruth truth;
    if (kind_ == "auto") {
      kind_ = std::filesystem::is_regular_file(JsonPath(source)) ? "json" : "none";
      if (kind_ == "json") path_ = std::filesystem::path(JsonPath(source)).parent_path().string();
    }
    if (kind_ == "json") {
      const std::string path = JsonPath(source);
      if (!std::filesystem::is_regular_file(path)) return truth;  // this frame has none
      truth.known = true;
      truth.lines = LoadTruthJson(path);
      truth.cMo = LoadTruthPoseJson(path);
    } else if (kind_ == "csv") {
      truth.known = true;
      const int number = FrameNumber(source, index);
      const auto lines = csv_.lines.find(number);
      if (lines != csv_.lines.end()) {
        for (TargetLineTruth line : lines->second) {
          if (ClipToRect(line.image_line, 0.0, 0.0, width - 1.0, height - 1.0, &line.end_a,
                         &line.end_b)) {
            truth.lines.push_back(line);
          }
        }
      }
      const auto pose = csv_.poses.find(number);
      if (pose != csv_.poses.end()) truth.cMo = pose->second;
    }
    return truth;
  }

 private:
  void UseCsv(const std::string& path) {
    kind_ = "csv";
    path_ = path;
    csv_ = LoadTruthCsvWithPoses(path);
  }
  std::string JsonPath(const std::string& source) const {
    const std::filesystem::path image(source);
    return json_dir_.empty()
               ? std::filesystem::path(image).replace_extension(".json").string()
               : (std::filesystem::path(json_dir_) / (image.stem().string() + ".json")).string();
  }

  std::string kind_ = "none";  ///< none, json, csv (auto until the first frame)
  std::string path_;           ///< the CSV, or the JSON files' directory
  std::string json_dir_;
  TruthCsv csv_;
};

/// One truth line against the tracked lines: the matched track's errors.
struct LineError {
  int line = 0;
  int track = -1;  ///< -1: not found
  double angle_deg = 0.0, offset_px = 0.0;
};

/// Matches truth lines to tracked lines (`held`, their track `ids`) one to one, closest pairs
/// first (angle / kTruthMatchAngleDeg + offset / kTruthMatchOffsetPx, both within bounds). The
/// truth is compared in the tracker's coordinates: undistorted pixels when it undistorts
/// (`undistorter`; the JSON's `ideal` line when `json`, else a CSV line through its undistorted
/// chord ends), else image pixels.
std::vector<LineError> MatchTruth(const std::vector<TargetLineTruth>& truth,
                                  const std::vector<DetectedLine>& held,
                                  const std::vector<int>& ids,
                                  const std::optional<PointUndistorter>& undistorter, bool json);

/// Translation (mm) and rotation (degrees) between an estimated and a true cMo.
std::pair<double, double> PoseError(const vpHomogeneousMatrix& cMo,
                                    const vpHomogeneousMatrix& truth);

}  // namespace oal
