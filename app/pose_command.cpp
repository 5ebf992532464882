#include "app/pose_command.h"

#include <visp3/core/vpMeterPixelConversion.h>

#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

#include "app/annotate.h"
#include "app/atomic_file.h"
#include "app/camera_file.h"
#include "app/command_line.h"
#include "app/config.h"
#include "app/image_source.h"
#include "app/json_io.h"
#include "detector/detector.h"
#include "scene/scene.h"
#include "servo/pose.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr double kAxisLengthM = 0.05;  // drawn target frame axes

std::string AnnotationName(int frame) {
  std::string number = std::to_string(frame);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return "pose_" + number + ".png";
}

// The camera file: --camera, or the camera.xml `oalservo render` writes next to its frames
// (in the first input if it is a directory, else in the first input's directory).
std::string FindCameraPath(const PoseCommandOptions& options, PoseSummary* summary) {
  if (!options.camera_path.empty()) return options.camera_path;
  const fs::path first = options.inputs.front();
  const fs::path dir = fs::is_directory(first) ? first : first.parent_path();
  const fs::path candidate = dir / "camera.xml";
  if (!fs::is_regular_file(candidate)) {
    throw std::runtime_error(
        "pose needs the camera intrinsics: give --camera FILE (no camera.xml in '" +
        (dir.empty() ? std::string(".") : dir.string()) + "')");
  }
  summary->warnings.push_back("no --camera: using the camera in '" + candidate.string() + "'");
  return candidate.string();
}

// Everything one run needs, opened before any output is started so that a bad input or
// configuration fails early.
struct PoseRun {
  AppConfig config;
  CameraFile camera;
  OalDetector detector;
  std::vector<std::unique_ptr<ImageSource>> sources;
  std::optional<vpCameraParameters> undistorted_by;  ///< set when lines are undistorted
};

AppConfig LoadPoseConfig(const PoseCommandOptions& options) {
  AppConfig config;
  if (!options.config_path.empty()) config = LoadConfig(options.config_path, config);
  config.detector.Check();
  return config;
}

Json Vector3(double x, double y, double z) {
  return Json::array({x, y, z});
}

Json FrameJson(int index, const Frame& frame, bool undistorted, const PoseResult& pose,
               double detect_us, double pose_us) {
  const bool ok = pose.status == PoseStatus::kOk;
  const bool identified = pose.line_index[0] >= 0 && pose.line_index[1] >= 0 &&
                          pose.line_index[2] >= 0 && pose.line_index[3] >= 0;
  Json cMo;  // null unless ok
  if (ok) {
    const vpTranslationVector t = pose.cMo.getTranslationVector();
    const vpThetaUVector tu = pose.cMo.getThetaUVector();
    cMo = Json{{"t_m", Vector3(t[0], t[1], t[2])}, {"thetau_rad", Vector3(tu[0], tu[1], tu[2])}};
  }
  auto if_ok = [ok](const Json& value) { return ok ? value : Json(); };
  // The pose covariance (vpPose, 6 x 6, translation then theta-u), row by row.
  Json covariance;
  if (ok && pose.covariance.getRows() == 6 && pose.covariance.getCols() == 6) {
    covariance = Json::array();
    for (unsigned int r = 0; r < 6; ++r) {
      Json row = Json::array();
      for (unsigned int c = 0; c < 6; ++c) row.push_back(pose.covariance[r][c]);
      covariance.push_back(std::move(row));
    }
  }
  Json corners;  // null until identified
  if (identified) {
    corners = Json::array();
    for (const Point2d& corner : pose.corners_px) corners.push_back(PointJson(corner));
  }
  return Json{
      {"frame", index},
      {"source", frame.source},
      {"width", frame.gray.cols},
      {"height", frame.gray.rows},
      {"status", ToString(pose.status)},
      {"message", pose.message},
      {"cMo", std::move(cMo)},
      {"roll_deg", if_ok(pose.roll_deg)},
      {"pitch_deg", if_ok(pose.pitch_deg)},
      {"yaw_deg", if_ok(pose.yaw_deg)},
      {"line1_roll_deg", if_ok(pose.line1_roll_deg)},
      {"plane_angles_deg", if_ok(Json::array({pose.plane_angle_deg[0], pose.plane_angle_deg[1]}))},
      {"residual_px", if_ok(pose.residual_px)},
      {"covariance", std::move(covariance)},
      {"method", if_ok(ToString(pose.method))},
      {"from_previous", if_ok(pose.from_previous)},
      {"lines", Json::array({pose.line_index[0], pose.line_index[1], pose.line_index[2],
                             pose.line_index[3]})},
      {"coordinates", undistorted ? "undistorted" : "image"},
      {"corners_px", std::move(corners)},
      {"time_us", Json{{"detect", detect_us}, {"pose", pose_us}}},
  };
}

// Pixel of the normalised point (x, y) in the frame: through the kdu model (the exact inverse
// of the detector's undistortion, as annotate.cpp draws lines) when the camera has
// distortion, else vpMeterPixelConversion.
cv::Point2d FramePixel(const vpCameraParameters& camera, double x, double y) {
  if (camera.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion &&
      camera.get_kdu() != 0.0) {
    const Point2d p = DistortedPixel(camera, x, y);
    return cv::Point2d(p.u, p.v);
  }
  double u = 0.0, v = 0.0;
  vpMeterPixelConversion::convertPoint(camera, x, y, u, v);
  return cv::Point2d(u, v);
}

void DrawText(cv::Mat& image, const std::string& text, const cv::Point& origin,
              const cv::Scalar& colour, double scale) {
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// The frame with the identified lines labelled 1-4, the corners, the target frame's axes
// (x red, y green, z blue, kAxisLengthM long) when the pose is ok, and the status.
cv::Mat AnnotatePose(const Frame& frame, const std::vector<DetectedLine>& lines,
                     const PoseResult& pose, const vpCameraParameters& camera,
                     const std::optional<vpCameraParameters>& undistorted_by) {
  static const cv::Scalar kLineColours[4] = {
      {0, 200, 255}, {255, 0, 200}, {255, 255, 0}, {0, 128, 255}};
  cv::Mat image;
  cv::cvtColor(frame.gray, image, cv::COLOR_GRAY2BGR);
  const int w = frame.gray.cols, h = frame.gray.rows;
  for (int k = 0; k < 4; ++k) {
    const int index = pose.line_index[k];
    if (index < 0 || index >= static_cast<int>(lines.size())) continue;
    const auto runs = LineInFrame(lines[index].line, w, h, undistorted_by);
    for (const auto& run : runs) {
      for (std::size_t i = 1; i < run.size(); ++i) {
        cv::line(image, run[i - 1], run[i], kLineColours[k], 2, cv::LINE_AA);
      }
    }
    if (runs.empty() || runs.front().empty()) continue;
    const auto& run = runs.front();
    const cv::Point2d at = run[run.size() / 3];
    DrawText(image, std::to_string(k + 1), cv::Point(cvRound(at.x) + 4, cvRound(at.y) - 4),
             kLineColours[k], 0.5);
  }
  const bool ok = pose.status == PoseStatus::kOk;
  if (ok) {
    for (const vpColVector& corner : pose.corners_m) {
      cv::circle(image, FramePixel(camera, corner[0], corner[1]), 3, cv::Scalar(255, 255, 255), 1,
                 cv::LINE_AA);
    }
    // Object origin and axis ends in the camera frame, projected.
    auto project = [&](double x, double y, double z) {
      vpColVector o(4);
      o[0] = x, o[1] = y, o[2] = z, o[3] = 1.0;
      const vpColVector c = pose.cMo * o;
      return FramePixel(camera, c[0] / c[2], c[1] / c[2]);
    };
    const cv::Point2d origin = project(0.0, 0.0, 0.0);
    const std::array<cv::Point2d, 3> ends = {project(kAxisLengthM, 0.0, 0.0),
                                             project(0.0, kAxisLengthM, 0.0),
                                             project(0.0, 0.0, kAxisLengthM)};
    const cv::Scalar kAxisColours[3] = {{0, 0, 255}, {0, 200, 0}, {255, 80, 0}};
    for (int a = 0; a < 3; ++a) {
      if (std::isfinite(ends[a].x) && std::isfinite(ends[a].y) && std::isfinite(origin.x) &&
          std::isfinite(origin.y)) {
        cv::arrowedLine(image, origin, ends[a], kAxisColours[a], 2, cv::LINE_AA, 0, 0.15);
      }
    }
  }
  DrawText(image, ToString(pose.status), cv::Point(4, 16),
           ok ? cv::Scalar(0, 220, 0) : cv::Scalar(0, 0, 255), 0.45);
  return image;
}

// Runs the detector and the pose over every frame, writing to `sink`; returns when the
// sources end or max_frames is reached.
void ProcessFrames(const PoseCommandOptions& options, PoseRun* run, std::ostream& sink,
                   bool flush_each, PoseSummary* summary) {
  const bool undistorted = run->detector.Undistorts();
  PoseOptions pose_options = run->config.pose;
  pose_options.camera = run->camera.camera;
  pose_options.lines_undistorted = undistorted;
  Frame frame;
  for (auto& source : run->sources) {
    std::optional<vpHomogeneousMatrix> previous_cMo;  // a sequence is one source
    while (options.max_frames == 0 || summary->frames < options.max_frames) {
      if (!source->Next(&frame)) break;
      if (summary->frames == 0) {
        if (auto warning =
                CameraSizeMismatch(run->camera, frame.gray.cols, frame.gray.rows, frame.source)) {
          summary->warnings.push_back(*warning + ": the poses will be wrong");
        }
      }
      pose_options.image_width = frame.gray.cols;
      pose_options.image_height = frame.gray.rows;
      const auto start = std::chrono::steady_clock::now();
      const std::vector<DetectedLine>& lines = run->detector.Detect(frame.view());
      const auto detected = std::chrono::steady_clock::now();
      const PoseResult pose = EstimatePose(lines, run->config.target, pose_options, previous_cMo);
      const auto stop = std::chrono::steady_clock::now();
      const double detect_us = std::chrono::duration<double, std::micro>(detected - start).count();
      const double pose_us = std::chrono::duration<double, std::micro>(stop - detected).count();
      WriteJsonLine(sink, FrameJson(summary->frames, frame, undistorted, pose, detect_us, pose_us),
                    flush_each);
      if (!options.annotate_dir.empty()) {
        WritePng(fs::path(options.annotate_dir) / AnnotationName(summary->frames),
                 AnnotatePose(frame, lines, pose, run->camera.camera, run->undistorted_by));
      }
      if (pose.status == PoseStatus::kOk) {
        previous_cMo = pose.cMo;
        ++summary->ok;
      } else {
        previous_cMo.reset();
      }
      ++summary->frames;
    }
  }
}

}  // namespace

void PoseCommandOptions::Check() const {
  CheckFrameCommand("PoseCommandOptions", inputs, max_frames, out_path);
}

PoseSummary EstimatePoses(const PoseCommandOptions& options, std::ostream& out) {
  options.Check();
  PoseSummary summary;
  AppConfig config = LoadPoseConfig(options);
  summary.camera_path = FindCameraPath(options, &summary);
  CameraFile camera = LoadCameraFile(summary.camera_path, options.camera_name);
  {
    // The target and the options with the camera, before any frame: a bad one fails here.
    PoseOptions check = config.pose;
    check.camera = camera.camera;
    check.Check();
    IdentifyTargetLines({}, config.target, check);  // throws if the target is not a '#'
  }
  OalDetector detector(config.detector, camera.camera);
  PoseRun run{std::move(config), std::move(camera), std::move(detector), {}, {}};
  if (run.detector.Undistorts()) run.undistorted_by = run.camera.camera;
  for (const std::string& input : options.inputs) {
    run.sources.push_back(OpenImageSource(input, &summary.warnings));
  }
  if (!options.annotate_dir.empty()) fs::create_directories(options.annotate_dir);
  WriteToFileOrConsole(options.out_path, out, [&](std::ostream& sink, bool flush_each) {
    ProcessFrames(options, &run, sink, flush_each, &summary);
  });
  return summary;
}

int RunPose(int argc, char** argv) {
  PoseCommandOptions options;
  CLI::App cli(
      "Camera pose from the four-line target (or the config's target) in every frame. Prints "
      "one JSON object per frame (JSON Lines) to stdout, or writes them to --out.",
      "oalservo pose");
  cli.add_option("INPUT", options.inputs,
                 "image, directory of images, printf pattern (frames/img%04d.png), video file, "
                 "or V4L2 device /dev/videoN")
      ->required();
  cli.add_option("--config", options.config_path,
                 "YAML configuration: detector, target and pose sections (see config/pose.yaml)");
  cli.add_option("--camera", options.camera_path,
                 "ViSP camera XML (required unless the first input's directory has a "
                 "camera.xml, as `oalservo render` writes)");
  cli.add_option("--camera-name", options.camera_name,
                 "camera to read from the camera file (default: the first in the file)");
  cli.add_option("--out", options.out_path, "JSON Lines output file (written atomically)");
  cli.add_option("--annotate", options.annotate_dir,
                 "directory for one PNG per frame with lines 1-4 and the target's axes drawn "
                 "(created if missing)");
  cli.add_option("--max-frames", options.max_frames, "stop after N frames (0: all)");
  cli.footer(
      "Examples:\n"
      "  oalservo render --count 20 --out data/ && oalservo pose data/ --out poses.jsonl\n"
      "  oalservo pose frames/ --camera camera.xml --config config/pose.yaml --annotate ann/\n"
      "  oalservo pose /dev/video0 --camera camera.xml --max-frames 100");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const PoseSummary summary = EstimatePoses(options, std::cout);
  for (const std::string& warning : summary.warnings) Warn("pose", warning);
  if (!options.out_path.empty()) {
    std::cerr << "oalservo pose: " << summary.frames << " frames, " << summary.ok
              << " with a pose, written to " << options.out_path << '\n';
  }
  return kExitOk;
}

}  // namespace oal
