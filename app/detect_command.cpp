#include "app/detect_command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>

#include "app/command_line.h"
#include "app/config.h"
#include "app/frame_command.h"
#include "app/live_window.h"
#include "base/format.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "detector/line_fit.h"
#include "io/annotate.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"
#include "io/json_io.h"

namespace oal {
namespace {

DetectorOptions LoadDetectorOptions(const DetectCommandOptions& options) {
  AppConfig config;
  if (options.paper) config.detector = DetectorOptions::Paper();
  if (!options.config_path.empty()) config = LoadConfig(options.config_path, config);
  config.detector.Check();
  return config.detector;
}

// Everything one run needs, opened before any output is started so that a bad input or
// configuration fails early.
struct DetectRun {
  OalDetector detector;
  std::optional<CameraFile> camera;
  std::vector<std::unique_ptr<ImageSource>> sources;
  std::optional<Lens> undistorted_by;  ///< set when lines are undistorted
  std::unique_ptr<LiveView> view;      ///< --display
};

OalDetector MakeDetector(const DetectorOptions& options, const std::optional<CameraFile>& camera) {
  return camera ? OalDetector(options, camera->camera) : OalDetector(options);
}

std::optional<CameraFile> LoadCamera(const DetectCommandOptions& options) {
  if (options.camera_path.empty()) return std::nullopt;
  return LoadCameraFile(options.camera_path, options.camera_name);
}

// How much the four strongest lines bend after the camera's correction, as `pose` measures
// lines 1-4 (RadialBend::bend_px); empty with fewer than four lines. Without a camera file the
// principal point is taken at the image's centre and the focal length as its width (the bend
// does not depend on the focal length). Not a lens check by itself: detect knows no target,
// and among the strongest lines of a cluttered scene some are not straight edges (a line of
// text, points of two objects); pose, evaluate and servo check the lens on the target's lines.
std::optional<double> Straightness(const std::vector<DetectedLine>& lines, const DetectRun& run,
                                   const Frame& frame) {
  if (lines.size() < 4) return std::nullopt;
  Point2d principal_point{0.5 * (frame.gray.cols - 1), 0.5 * (frame.gray.rows - 1)};
  double focal_px = frame.gray.cols;
  if (run.camera) {
    const Lens& camera = run.camera->camera;
    principal_point = Point2d{camera.u0(), camera.v0()};
    focal_px = std::sqrt(camera.px() * camera.py());
  }
  return RadialBendOfFour({lines[0].line, lines[1].line, lines[2].line, lines[3].line},
                          run.detector.feature_points(),
                          2.0 * run.detector.options().support_tolerance_px, {}, principal_point,
                          focal_px)
      .bend_px;
}

Json FrameJson(int index, const Frame& frame, double time_us, bool undistorted,
               const std::vector<DetectedLine>& lines, std::optional<double> straightness_px) {
  Json json_lines = Json::array();
  for (const DetectedLine& line : lines) json_lines.push_back(DetectedLineJson(line));
  return Json{{"frame", index},
              {"source", frame.source},
              {"width", frame.gray.cols},
              {"height", frame.gray.rows},
              {"time_us", time_us},
              {"coordinates", undistorted ? "undistorted" : "image"},
              // detect scans the paper's concentric borders of the whole image (as `pose`
              // writes it: an empty region is the whole image); `pose` scans the target's.
              {"scan", Json{{"mode", "image"}, {"region", Json::array()}}},
              {"straightness_px", straightness_px ? Json(*straightness_px) : Json()},
              {"lines", std::move(json_lines)}};
}

// Runs the detector over every frame, writing to `sink`; returns when the sources end or
// max_frames is reached.
void ProcessFrames(const DetectCommandOptions& options, DetectRun* run, std::ostream& sink,
                   bool flush_each, DetectSummary* summary) {
  const bool undistorted = run->detector.Undistorts();
  Frame frame;
  for (auto& source : run->sources) {
    while (options.max_frames == 0 || summary->frames < options.max_frames) {
      if (!source->Next(&frame)) break;
      if (summary->frames == 0 && run->camera) {
        if (auto warning =
                CameraSizeMismatch(*run->camera, frame.gray.cols, frame.gray.rows, frame.source)) {
          summary->warnings.push_back(*warning);
        }
      }
      const auto start = std::chrono::steady_clock::now();
      const std::vector<DetectedLine>& lines = run->detector.Detect(frame.view());
      const auto stop = std::chrono::steady_clock::now();
      const double time_us = std::chrono::duration<double, std::micro>(stop - start).count();
      const std::optional<double> straightness = Straightness(lines, *run, frame);
      if (straightness) summary->straightness_px.push_back(*straightness);
      WriteJsonLine(sink,
                    FrameJson(summary->frames, frame, time_us, undistorted, lines, straightness),
                    flush_each);
      if (!options.annotate_dir.empty()) {
        WritePng(AnnotationPath(options, "lines", summary->frames),
                 AnnotateLines(frame.gray, lines, run->undistorted_by));
      }
      summary->lines += static_cast<int>(lines.size());
      ++summary->frames;
      if (run->view && !run->view->Show(AnnotateLines(frame.gray, lines, run->undistorted_by),
                                        "frame " + std::to_string(summary->frames - 1) + ": " +
                                            std::to_string(lines.size()) + " lines, " +
                                            Fixed(1e-3 * time_us, 2) + " ms",
                                        frame.taken_s.has_value())) {
        summary->stopped_by_user = true;
        return;
      }
    }
  }
}

}  // namespace

void DetectCommandOptions::Check() const {
  CheckFrameCommand(inputs, max_frames, out_path);
  CheckDisplayOptions(*this);
  CameraModeRequest(*this);  // a bad --camera-mode fails before any input is opened
  if (!camera_name.empty() && camera_path.empty()) {
    throw std::invalid_argument("DetectCommandOptions::camera_name '" + camera_name +
                                "' needs camera_path (the camera file to read it from)");
  }
}

DetectSummary DetectImages(const DetectCommandOptions& options, std::ostream& out) {
  options.Check();
  DetectSummary summary;
  std::optional<CameraFile> camera = LoadCamera(options);
  DetectRun run{MakeDetector(LoadDetectorOptions(options), camera), std::move(camera), {}, {}, {}};
  if (run.detector.Undistorts()) run.undistorted_by = run.camera->camera;
  run.sources = OpenInputs(options, &summary.warnings);
  if (options.display) run.view = OpenLiveView("oalservo detect", options.display_fps);
  WriteFrameRecords(options, out, [&](std::ostream& sink, bool flush_each) {
    ProcessFrames(options, &run, sink, flush_each, &summary);
  });
  return summary;
}

int RunDetect(int argc, char** argv) {
  DetectCommandOptions options;
  CLI::App cli(
      "Detect lines with the OAL detector. Prints one JSON object per frame (JSON "
      "Lines) to stdout, or writes them to --out. Each object's \"frame\" is the frame's "
      "position in this run, from 0 over all inputs; \"source\" is its file (or "
      "video#index). `compare` and `edge-reference` number frames by the number in the file "
      "name instead (image.0001.pgm is frame 1); match them by \"source\".",
      "oalservo detect");
  AddInputsArgument(cli, &options);
  cli.add_option("--config", options.config_path, "YAML configuration (see config/detector.yaml)")
      ->check(CLI::ExistingFile);
  cli.add_flag("--paper", options.paper,
               "start from the paper's algorithm (every remedy off); --config still overrides");
  CLI::Option* camera = cli.add_option(
      "--camera", options.camera_path,
      "camera file (ViSP's .xml, OpenCV's or ROS's .yaml); with distortion, lines are "
      "in undistorted pixels");
  cli.add_option("--camera-name", options.camera_name,
                 "camera to read from --camera (default: the first in the file)")
      ->needs(camera);
  AddOutputOptions(cli, &options,
                   "directory for one PNG per frame with the lines drawn (created if missing)");
  AddDisplayOptions(cli, &options);
  cli.footer(
      "Examples:\n"
      "  oalservo detect frames/ --out lines.jsonl --annotate annotated/\n"
      "  oalservo detect data/ --camera data/camera.xml\n"
      "  oalservo detect '/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm' "
      "--config config/visp_line_edges.yaml\n"
      "  oalservo detect /dev/video0 --max-frames 100\n"
      "  oalservo detect /dev/video0 --display   # the lines found, live");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const DetectSummary summary = DetectImages(options, std::cout);
  for (const std::string& warning : summary.warnings) Warn("detect", warning);
  if (summary.stopped_by_user) {
    std::cerr << "oalservo detect: stopped from the window after " << summary.frames << " frames\n";
  }
  if (!options.out_path.empty()) {
    std::cerr << "oalservo detect: " << summary.frames << " frames, " << summary.lines
              << " lines written to " << options.out_path << '\n';
  }
  return kExitOk;
}

}  // namespace oal
