#include "app/pose_command.h"

#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "app/command_line.h"
#include "app/config.h"
#include "app/frame_command.h"
#include "app/live_window.h"
#include "base/format.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "io/annotate.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"
#include "io/json_io.h"
#include "io/rendered_dataset.h"
#include "loop/lens_estimate.h"
#include "scene/scene.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

// The camera file: --camera, or the camera.xml or camera.yaml `oalservo render` writes next
// to its frames (in the first input if it is a directory, else in the first input's directory).
std::string FindCameraPath(const PoseCommandOptions& options, PoseSummary* summary) {
  if (!options.camera_path.empty()) return options.camera_path;
  const std::optional<std::filesystem::path> found =
      options.inputs.empty() ? std::nullopt : FindDatasetCamera(CompanionDirectory(options.inputs));
  if (!found) {
    throw std::runtime_error(
        "pose needs the camera intrinsics: give --camera FILE (no camera.xml or camera.yaml in '" +
        CompanionDirectory(options.inputs) + "')");
  }
  summary->warnings.push_back("no --camera: using the camera in '" + found->string() + "'");
  return found->string();
}

// Everything one run needs, opened before any output is started so that a bad input or
// configuration fails early.
struct PoseRun {
  AppConfig config;
  CameraFile camera;
  TargetPoseTracker tracker;
  std::vector<std::unique_ptr<ImageSource>> sources;
  std::optional<Lens> undistorted_by;  ///< set when lines are undistorted
  std::unique_ptr<LiveView> view;      ///< --display
};

// The configuration: --config, else the target.yaml `oalservo render` writes next to its
// frames (its target), else the defaults (the A3 sheet).
AppConfig LoadPoseConfig(const PoseCommandOptions& options, PoseSummary* summary) {
  AppConfig config;
  if (!options.config_path.empty()) {
    config = LoadConfig(options.config_path, config);
  } else if (const std::optional<std::string> target =
                 CompanionFile(options.inputs, "target.yaml")) {
    config = LoadConfig(*target, config);
    summary->warnings.push_back("no --config: using the target in '" + *target + "' ('" +
                                config.target.name + "')");
  }
  config.detector.Check();
  return config;
}

// What lines 1-4 tell of the camera file's kdu: null without a pose (kept, or refused by the
// model check) or when they cannot tell (all near the principal point, too few points).
Json LensJson(const TargetFrame& result) {
  if (!MeasuresLens(result) || !std::isfinite(result.lens.kdu_error_sd)) return Json();
  return Json{{"kdu_error", result.lens.kdu_error},
              {"kdu_error_sd", result.lens.kdu_error_sd},
              {"lines", result.lens.lines},
              {"contradicts_camera", ContradictsLens(result.lens)}};
}

Json FrameJson(int index, const Frame& frame, bool undistorted, const TargetFrame& result,
               ScanMode mode) {
  const PoseResult& pose = result.pose;
  const bool ok = result.status == TargetStatus::kOk;
  const bool identified = pose.line_index[0] >= 0 && pose.line_index[1] >= 0 &&
                          pose.line_index[2] >= 0 && pose.line_index[3] >= 0;
  const Json cMo = ok ? PoseJson(pose.cMo) : Json();  // null unless ok
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
      {"status", ToString(result.status)},
      {"message", result.message},
      {"pose_status", ToString(pose.status)},
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
      {"scan", ScanJson(result, mode)},
      {"stripe_agreement",
       result.pose.status == PoseStatus::kOk ? Json(result.agreement.Worst()) : Json()},
      {"straightness_px", if_ok(result.lens.bend_px)},
      {"lens", LensJson(result)},
      {"time_us",
       Json{{"find", result.find_us}, {"detect", result.detect_us}, {"pose", result.pose_us}}},
  };
}

// The frames of the inputs in order, each saying whether it begins a new input; frames held
// back (read ahead to tell the lens) come first.
class FrameFeed {
 public:
  explicit FrameFeed(std::vector<std::unique_ptr<ImageSource>>* sources) : sources_(*sources) {}

  bool Next(Frame* frame, bool* new_input) {
    if (!held_.empty()) {
      *frame = std::move(held_.front().frame);
      *new_input = held_.front().input != replayed_input_;
      replayed_input_ = held_.front().input;
      held_.pop_front();
      return true;
    }
    while (input_ < sources_.size()) {
      if (sources_[input_]->Next(frame)) {
        *new_input = input_ != replayed_input_;
        replayed_input_ = input_;
        return true;
      }
      ++input_;
    }
    return false;
  }
  /// Reads a frame ahead and holds a copy of it for Next(); false at the end.
  bool ReadAhead(Frame* frame) {
    while (input_ < sources_.size()) {
      if (sources_[input_]->Next(frame)) {
        held_.push_back({Frame{frame->gray.clone(), frame->source, frame->taken_s}, input_});
        return true;
      }
      ++input_;
    }
    return false;
  }

 private:
  struct Held {
    Frame frame;
    std::size_t input;
  };
  std::vector<std::unique_ptr<ImageSource>>& sources_;
  std::deque<Held> held_;
  std::size_t input_ = 0;
  std::size_t replayed_input_ = static_cast<std::size_t>(-1);
};

// Reads frames ahead until `frames` of them show the target, estimates kdu from their stripes
// and, when it succeeds, gives the tracker the camera with it. Says what it did in `summary`.
void EstimateLens(const PoseCommandOptions& options, FrameFeed* feed, PoseRun* run,
                  PoseSummary* summary) {
  const Lens pinhole = run->camera.camera;
  Frame frame;
  int read = 0;
  const ToldLens told = TellLensFromStripes(
      run->tracker, pinhole,
      [&](GrayImageView* view) {
        if ((options.max_frames != 0 && read >= options.max_frames) || !feed->ReadAhead(&frame)) {
          return false;
        }
        ++read;
        *view = frame.view();
        return true;
      },
      options.estimate_frames);
  if (!told.lens) {
    summary->warnings.push_back("--estimate-distortion: cannot tell the lens: " + told.why +
                                "; the poses are without distortion");
    return;
  }
  const PlumbLineResult& lens = *told.lens;
  std::ostringstream said;
  said.precision(4);
  said << std::fixed;
  summary->estimated_kdu = lens.kdu;
  run->camera.camera = WithLens(pinhole, lens);
  run->tracker = TargetPoseTracker(run->config.target, run->camera.camera, run->config.detector,
                                   run->config.pose, run->config.tracking);
  run->tracker.set_measure_lens(true);
  run->undistorted_by = run->camera.camera;
  said << "kdu " << lens.kdu << " +- " << lens.kdu_sd << " (kud " << lens.kud << ")"
       << " from the stripes of " << told.frames << " frames (they bend " << std::setprecision(2)
       << lens.rms_before_px << " px RMS from straight, " << lens.rms_after_px
       << " px corrected); every pose uses it";
  summary->notes.push_back(said.str());
}

// The frame in the live window: lines 1-4, the corners and the axes (a refused pose drawn as
// none), the region scanned, and a caption with the status, the time and the lens check.
// False once the user asked to stop.
bool ShowPose(const Frame& frame, const TargetFrame& result, const PoseRun& run, int index) {
  PoseResult drawn = result.pose;
  if (result.status != TargetStatus::kOk) drawn.status = PoseStatus::kDegenerate;
  std::string caption = "frame " + std::to_string(index) + ": " + ToString(result.status);
  if (!result.message.empty()) caption += " (" + result.message + ")";
  caption += ", " + Fixed(1e-3 * (result.find_us + result.detect_us + result.pose_us), 1) + " ms";
  if (MeasuresLens(result) && std::isfinite(result.lens.kdu_error_sd)) {
    caption += ContradictsLens(result.lens) ? ", lens check: the stripes bend (kdu off by " +
                                                  Fixed(result.lens.kdu_error, 3) + ")"
                                            : ", lens check: ok";
  }
  return run.view->Show(AnnotatePose(frame.gray, run.tracker.lines(), drawn, run.camera.camera,
                                     run.undistorted_by, result.region),
                        caption, frame.taken_s.has_value());
}

// Runs the detector and the pose over every frame, writing to `sink`; returns when the
// sources end, max_frames is reached or the user stops it from the live window.
void ProcessFrames(const PoseCommandOptions& options, PoseRun* run, std::ostream& sink,
                   bool flush_each, PoseSummary* summary) {
  FrameFeed feed(&run->sources);
  if (options.estimate_distortion) EstimateLens(options, &feed, run, summary);
  const bool undistorted = run->tracker.detector().Undistorts();
  Frame frame;
  bool new_input = false;
  while ((options.max_frames == 0 || summary->frames < options.max_frames) &&
         feed.Next(&frame, &new_input)) {
    if (new_input) run->tracker.Reset();  // a sequence is one input
    if (summary->frames == 0) {
      if (auto warning =
              CameraSizeMismatch(run->camera, frame.gray.cols, frame.gray.rows, frame.source)) {
        summary->warnings.push_back(*warning + ": the poses will be wrong");
      }
    }
    if (options.independent) run->tracker.Reset();
    const TargetFrame& result = run->tracker.Track(frame.view());
    WriteJsonLine(
        sink, FrameJson(summary->frames, frame, undistorted, result, run->tracker.options().scan),
        flush_each);
    if (!options.annotate_dir.empty()) {
      // A refused pose is not drawn as one: the lines and the region alone.
      PoseResult drawn = result.pose;
      if (result.status != TargetStatus::kOk) drawn.status = PoseStatus::kDegenerate;
      WritePng(AnnotationPath(options, "pose", summary->frames),
               AnnotatePose(frame.gray, run->tracker.lines(), drawn, run->camera.camera,
                            run->undistorted_by, result.region));
    }
    if (result.status == TargetStatus::kOk) ++summary->ok;
    if (MeasuresLens(result)) summary->lens.push_back(result.lens);
    ++summary->frames;
    if (run->view && !ShowPose(frame, result, *run, summary->frames - 1)) {
      summary->stopped_by_user = true;
      break;
    }
  }
}

}  // namespace

void PoseCommandOptions::Check() const {
  CheckFrameCommand(inputs, max_frames, out_path);
  CheckDisplayOptions(*this);
  CameraModeRequest(*this);  // a bad --camera-mode fails before any input is opened
  if (estimate_frames < 1 || estimate_frames > 100) {
    throw std::invalid_argument("--estimate-frames = " + std::to_string(estimate_frames) +
                                ": give 1 to 100 frames");
  }
}

PoseSummary EstimatePoses(const PoseCommandOptions& options, std::ostream& out) {
  options.Check();
  PoseSummary summary;
  AppConfig config = LoadPoseConfig(options, &summary);
  summary.camera_path = FindCameraPath(options, &summary);
  CameraFile camera = LoadCameraFile(summary.camera_path, options.camera_name);
  if (options.estimate_distortion && camera.camera.distorted()) {
    throw std::invalid_argument("--estimate-distortion is for a camera file without distortion; '" +
                                summary.camera_path + "' has a " + LensModelName(camera.camera) +
                                " lens: remove the flag, or give the camera without it");
  }
  // The target and the options with the camera, before any frame: a bad one fails here.
  TargetPoseTracker tracker(config.target, camera.camera, config.detector, config.pose,
                            config.tracking);
  tracker.set_measure_lens(true);  // every pose's lines feed the lens check
  PoseRun run{std::move(config), std::move(camera), std::move(tracker), {}, {}, {}};
  if (run.tracker.detector().Undistorts()) run.undistorted_by = run.camera.camera;
  run.sources = OpenInputs(options, &summary.warnings);
  if (options.display) run.view = OpenLiveView("oalservo pose", options.display_fps);
  WriteFrameRecords(options, out, [&](std::ostream& sink, bool flush_each) {
    ProcessFrames(options, &run, sink, flush_each, &summary);
  });
  if (summary.stopped_by_user) {
    summary.notes.push_back("stopped from the window after " + std::to_string(summary.frames) +
                            " frames");
  }
  const LensCheck lens = CheckLens(summary.lens);
  if (lens.mismatch) {
    // What to do, never what this run already did.
    summary.warnings.push_back(LensMismatchWarning(
        lens,
        options.estimate_distortion ? "the lens told from the stripes"
                                    : "'" + summary.camera_path + "'",
        options.estimate_distortion
            ? "Calibrate the camera (oalservo calibrate): one radial term told from four "
              "stripes does not hold this lens"
            : "Calibrate the camera (oalservo calibrate), or give one without distortion and "
              "--estimate-distortion"));
  }
  return summary;
}

int RunPose(int argc, char** argv) {
  PoseCommandOptions options;
  CLI::App cli(
      "Camera pose from the four-line target (the A3 sheet, or the config's target, or the "
      "target.yaml next to rendered frames) in every frame: the target is looked for in each "
      "frame (its middle cell, then the borders around it on its own plane), followed from "
      "frame to frame, and a pose the image does not show is refused. Prints one JSON object "
      "per frame (JSON Lines) to stdout, or writes them to --out.",
      "oalservo pose");
  AddInputsArgument(cli, &options);
  cli.add_option("--config", options.config_path,
                 "YAML configuration: detector, target, pose and tracking sections (see "
                 "config/pose.yaml); default: the target.yaml next to rendered frames, else the "
                 "A3 sheet")
      ->check(CLI::ExistingFile);
  cli.add_option("--camera", options.camera_path,
                 "camera file: ViSP's .xml, OpenCV's calibration .yaml or ROS's camera_info .yaml "
                 "(required unless the first input's directory has the camera.xml or camera.yaml "
                 "`oalservo render` writes)");
  cli.add_option("--camera-name", options.camera_name,
                 "camera to read from the camera file (default: the first in the file)");
  cli.add_flag("--independent", options.independent,
               "estimate each frame on its own (a rendered data set of random poses); by default "
               "the frames of one input are a sequence, the target followed from one to the next "
               "and a pose that jumps away from the last one held until the next frame agrees");
  cli.add_flag("--estimate-distortion", options.estimate_distortion,
               "the camera file has no distortion: tell the lens from the target's stripes, "
               "which must be straight, in the first frames that show it, then use it for every "
               "frame. Four stripes tell one radial term (ViSP's kdu), not OpenCV's k2, k3 or "
               "tangential terms: for those, calibrate (oalservo calibrate)");
  cli.add_option("--estimate-frames", options.estimate_frames,
                 "frames with the target that --estimate-distortion reads ahead")
      ->capture_default_str();
  AddOutputOptions(cli, &options,
                   "directory for one PNG per frame with lines 1-4 and the target's axes drawn "
                   "(created if missing)");
  AddDisplayOptions(cli, &options);
  cli.footer(
      "Examples:\n"
      "  oalservo render --count 20 --out data/ && oalservo pose data/ --independent --out "
      "poses.jsonl\n"
      "  oalservo pose frames/ --camera camera.xml --config config/pose.yaml --annotate ann/\n"
      "  oalservo pose /dev/video0 --camera camera.xml --max-frames 100\n"
      "  oalservo pose /dev/video0 --camera camera.yaml --display   # what the tracker sees, live");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const PoseSummary summary = EstimatePoses(options, std::cout);
  for (const std::string& note : summary.notes) std::cerr << "oalservo pose: " << note << '\n';
  for (const std::string& warning : summary.warnings) Warn("pose", warning);
  if (!options.out_path.empty()) {
    std::cerr << "oalservo pose: " << summary.frames << " frames, " << summary.ok
              << " with a pose, written to " << options.out_path << '\n';
  }
  return kExitOk;
}

}  // namespace oal
