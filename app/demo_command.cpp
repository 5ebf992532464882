#include "app/demo_command.h"

#include <visp3/core/vpThetaUVector.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "app/command_line.h"
#include "app/evaluation_config.h"
#include "app/render_command.h"
#include "base/angles.h"
#include "base/pose_distance.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "eval/lines/line_scoring.h"
#include "io/annotate.h"
#include "io/atomic_file.h"
#include "io/image_source.h"
#include "io/json_io.h"
#include "scene/scene.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

// A detected line further than this from a true line (in angle) is not its match.
constexpr double kMaxMatchAngleDeg = 10.0;

// The cheap-camera preset: a wide lens (kdu 0.33 at 640x480, px 600), sensor noise, a soft
// focus and light falling off by 30 % across the image.
RenderOptions CheapCamera() {
  RenderOptions options;
  options.width = 640;
  options.height = 480;
  options.camera = RenderCamera(options.width, options.height, 600.0, 0.33);
  options.noise_sigma = 8.0;
  options.blur_sigma_px = 1.0;
  options.illumination_gradient = 0.3;
  options.gradient_angle_rad = 0.5;
  return options;
}

// The visible true lines matched one to one with the detected ones (eval/lines/line_scoring.h's
// MatchLines), in undistorted pixels: a detected line more than kMaxMatchAngleDeg from a true
// one is not its match; the offset is bounded only by the image. Missed lines get a row too.
std::vector<DemoMatch> MatchTruth(const std::vector<TruthLine>& truth,
                                  const std::vector<DetectedLine>& detected, const Lens& camera) {
  const PointUndistorter undistorter(camera);
  std::vector<ReferenceLine> references;
  std::vector<int> reference_truth;  // the truth index of each reference
  for (const TruthLine& line : truth) {
    if (!line.visible) continue;
    references.push_back(
        {line.ideal, undistorter.Undistort(line.end_a), undistorter.Undistort(line.end_b)});
    reference_truth.push_back(line.index);
  }
  std::vector<LineParams> lines;
  for (const DetectedLine& line : detected) lines.push_back(line.line);
  constexpr double kAnyOffsetPx = 1e9;
  std::vector<DemoMatch> matches;
  std::vector<bool> found(references.size(), false);
  for (const LineMatch& pair : MatchLines(references, lines, kMaxMatchAngleDeg, kAnyOffsetPx)) {
    DemoMatch match;
    match.truth_index = reference_truth[pair.reference];
    match.detected_index = static_cast<int>(pair.line);
    match.angle_error_deg = pair.angle_deg;
    match.max_offset_px = pair.offset_px;
    matches.push_back(match);
    found[pair.reference] = true;
  }
  for (std::size_t r = 0; r < references.size(); ++r) {
    if (found[r]) continue;
    DemoMatch missed;
    missed.truth_index = reference_truth[r];
    matches.push_back(missed);
  }
  std::sort(matches.begin(), matches.end(),
            [](const DemoMatch& x, const DemoMatch& y) { return x.truth_index < y.truth_index; });
  return matches;
}

Json MatchJson(const DemoMatch& match) {
  Json json{{"target_line", match.truth_index + 1},
            {"truth_index", match.truth_index},
            {"detected_index", match.detected_index}};
  if (match.detected_index >= 0) {
    json["angle_error_deg"] = match.angle_error_deg;
    json["max_offset_px"] = match.max_offset_px;
  }
  return json;
}

Json DemoJson(const RenderOptions& render, const RenderedFrame& frame,
              const std::vector<DetectedLine>& lines, const DemoReport& report) {
  Json truth = Json::array(), detected = Json::array(), matches = Json::array();
  for (const TruthLine& line : frame.truth) truth.push_back(TruthLineJson(line));
  for (const DetectedLine& line : lines) detected.push_back(DetectedLineJson(line));
  for (const DemoMatch& match : report.matches) matches.push_back(MatchJson(match));
  return Json{{"camera", CameraJson(render.camera, render.width, render.height)},
              {"noise_sigma", render.noise_sigma},
              {"blur_sigma_px", render.blur_sigma_px},
              {"illumination_gradient", render.illumination_gradient},
              {"cMo", PoseJson(frame.cMo)},
              {"coordinates", "undistorted"},
              {"time_us", report.time_us},
              {"truth", std::move(truth)},
              {"detected", std::move(detected)},
              {"matches", std::move(matches)}};
}

void PrintTable(const DemoReport& report, const std::vector<TruthLine>& truth,
                const std::vector<DetectedLine>& lines, std::ostream& out) {
  char row[160];
  out << "  line  true rho(px) theta(deg)  found  rho(px) theta(deg)  angle err(deg)  max "
         "offset(px)\n";
  int found = 0;
  for (const DemoMatch& match : report.matches) {
    const LineParams& ideal = truth[static_cast<std::size_t>(match.truth_index)].ideal;
    if (match.detected_index < 0) {
      std::snprintf(row, sizeof(row), "%6d  %12.1f %10.2f  %5s\n", match.truth_index + 1,
                    ideal.rho_px, ideal.theta_rad * kDegPerRad, "-");
    } else {
      ++found;
      const LineParams& line = lines[static_cast<std::size_t>(match.detected_index)].line;
      std::snprintf(row, sizeof(row), "%6d  %12.1f %10.2f  %5d  %7.1f %10.2f  %14.3f  %15.2f\n",
                    match.truth_index + 1, ideal.rho_px, ideal.theta_rad * kDegPerRad,
                    match.detected_index, line.rho_px, line.theta_rad * kDegPerRad,
                    match.angle_error_deg, match.max_offset_px);
    }
    out << row;
  }
  out << found << " of " << report.matches.size() << " target lines found; the detector returned "
      << report.detected << " lines in " << std::lround(report.time_us) << " us\n";
}

}  // namespace

void DemoCommandOptions::Check() const {
  if (out_dir.empty()) throw std::invalid_argument("--out is empty");
  try {
    TargetByName(target);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string("--target: ") + error.what());
  }
}

namespace {

// The sheet's scene: an A3 (or A4, letter) sheet lying on a photograph of a bench among other
// sheets and tools, a calibrated lens (kdu 0.15), noise, a soft focus, light falling off.
struct SheetScene {
  RenderOptions render;
  PoseSampling sampling;
  std::string surface = "uniform grey";
};

SheetScene MakeSheetScene(const LineTarget& target) {
  SheetScene scene;
  scene.render.camera = RenderCamera(640, 480, 600.0, 0.15);
  scene.render.noise_sigma = 4.0;
  scene.render.blur_sigma_px = 1.0;
  const SceneOptions bench = BenchScene();
  bench.ApplyTo(&scene.render);
  std::vector<std::string> photos;
  try {
    photos = DefaultBenchPhotos();
  } catch (const std::runtime_error&) {
    // Without visp-images-data the sheet lies on a uniform grey surface.
  }
  if (!photos.empty()) {
    scene.render.background = ReadGrayImage(photos.front());
    scene.surface = fs::path(photos.front()).filename().string();
  }
  scene.sampling = SheetSampling(target);
  return scene;
}

struct Detection {
  std::vector<DetectedLine> lines;
  double time_us = 0.0;
  std::optional<TargetFrame> target;  ///< the tracker's frame, for a '#' target
};

Detection DetectTarget(const LineTarget& target, const RenderOptions& render,
                       const RenderedFrame& frame) {
  Detection detection;
  // The tracker sets the pose's camera and the frame's size itself.
  TargetPoseTracker tracker(target, render.camera, DetectorOptions(), PoseOptions());
  const auto start = std::chrono::steady_clock::now();
  const TargetFrame& result = tracker.Track(ViewOf(frame.image));
  detection.time_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  detection.lines = tracker.lines();
  detection.target = result;
  return detection;
}

Detection DetectImage(const RenderOptions& render, const RenderedFrame& frame) {
  Detection detection;
  OalDetector detector(DetectorOptions(), render.camera);
  const auto start = std::chrono::steady_clock::now();
  detection.lines = detector.Detect(frame.image);
  detection.time_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  return detection;
}

void PrintPose(const TargetFrame& result, const vpHomogeneousMatrix& cMo_true, std::ostream& out) {
  if (result.status != TargetStatus::kOk) {
    out << "No pose: " << ToString(result.status) << " (" << result.message << ")\n";
    return;
  }
  const vpHomogeneousMatrix& cMo = result.pose.cMo;
  const PoseDistance error = Distance(cMo_true, cMo);
  const double error_m = error.translation_m;
  const double distance_m = cMo_true.getTranslationVector().frobeniusNorm();
  const double error_deg = vpMath::deg(error.rotation_rad);
  char row[200];
  std::snprintf(row, sizeof(row),
                "Pose (borders from the %s, %d borders): %.2f mm (%.3f %% of the distance) and "
                "%.3f deg from the truth\n",
                ToString(result.source).c_str(), result.borders, error_m * 1000.0,
                100.0 * error_m / distance_m, error_deg);
  out << row;
}

}  // namespace

DemoReport RunDemoScene(const DemoCommandOptions& options, std::ostream& out) {
  options.Check();
  const LineTarget target = TargetByName(options.target);
  const bool sheet = IsSheet(target);
  const SheetScene sheet_scene = sheet ? MakeSheetScene(target) : SheetScene{};
  const RenderOptions render = sheet ? sheet_scene.render : CheapCamera();
  PoseSampling sampling = sheet_scene.sampling;
  if (!sheet) sampling.min_visible_length_px = 150.0;  // every line well inside the picture
  const SceneRenderer renderer(target, render);
  std::uint64_t state = options.seed;
  const RenderedFrame frame = renderer.Render(SamplePose(renderer, sampling, &state), options.seed);
  const bool grid = target.lines.size() == 4;
  const Detection detection =
      grid ? DetectTarget(target, render, frame) : DetectImage(render, frame);
  const std::vector<DetectedLine>& lines = detection.lines;

  DemoReport report;
  report.detected = static_cast<int>(lines.size());
  report.time_us = detection.time_us;
  report.matches = MatchTruth(frame.truth, lines, render.camera);
  if (detection.target) report.pose_status = ToString(detection.target->status);

  const fs::path dir(options.out_dir);
  fs::create_directories(dir);
  const cv::Mat image(static_cast<int>(frame.image.getHeight()),
                      static_cast<int>(frame.image.getWidth()), CV_8UC1, frame.image.bitmap);
  WritePng(dir / "frame.png", image);
  WritePng(dir / "demo.png", AnnotateLines(image, lines, render.camera));
  Json json = DemoJson(render, frame, lines, report);
  json["target"] = target.name;
  if (detection.target) {
    const TargetFrame& result = *detection.target;
    json["scan"] = ScanJson(result, ScanMode::kTarget);
    json["pose_status"] = ToString(result.status);
    if (result.status == TargetStatus::kOk) json["pose"] = PoseJson(result.pose.cMo);
  }
  WriteFileAtomically(dir / "lines.json", json.dump(2) + "\n");

  std::ostringstream text;
  if (sheet) {
    text << target.name << " lying on " << sheet_scene.surface
         << " among other sheets and tools: 640x480, px = py = 600, kdu = 0.15 (corrected), "
            "noise 4, blur 1 px, seed "
         << options.seed << '\n';
  } else {
    text << target.name
         << ", cheap camera: 640x480, px = py = 600, kdu = 0.33, noise 8, blur 1 px, light "
            "-30 %, seed "
         << options.seed << '\n';
  }
  text << "Lines in undistorted pixels (rho from the top-left pixel); line: the target's line "
          "1-4, found: the detected line's label in demo.png:\n";
  PrintTable(report, frame.truth, lines, text);
  if (detection.target) PrintPose(*detection.target, frame.cMo, text);
  text << "Wrote " << (dir / "frame.png").string() << ", " << (dir / "demo.png").string() << ", "
       << (dir / "lines.json").string() << '\n';
  WriteText(out, text.str());
  return report;
}

int RunDemo(int argc, char** argv) {
  DemoCommandOptions options;
  CLI::App cli(
      "Render one frame of a cheap camera (wide lens, noise, blur, uneven light), detect "
      "its lines with point undistortion and compare them with the truth.",
      "oalservo demo");
  cli.add_option("--out", options.out_dir, "output directory (created if missing)")
      ->capture_default_str();
  cli.add_option("--target", options.target,
                 "built-in target: " + TargetNameList() +
                     " (a sheet lies on a photograph of a bench; the board fills the view)")
      ->capture_default_str();
  AddSeedOption(cli, &options.seed, "seed of the pose and the noise, >= 0");
  cli.footer(
      "Examples:\n"
      "  oalservo demo --out out/demo\n"
      "      an A3 sheet on a bench: the lines, the pose and its error against the truth\n"
      "  oalservo demo --target four-line-board --seed 3 --out out/demo-board\n"
      "      the paper's 2 m board through a cheap wide lens");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  RunDemoScene(options, std::cout);
  return kExitOk;
}

}  // namespace oal
