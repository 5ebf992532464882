#include "app/calibrate_accuracy_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/command_line.h"
#include "app/evaluation_config.h"
#include "base/format.h"
#include "detector/lens.h"
#include "eval/rendered/calibrate_accuracy.h"
#include "io/camera_file.h"
#include "io/json_io.h"

namespace oal {
namespace {

// "kdu 0.2100" or "k1 -0.2664" (ViSP's or OpenCV's leading term).
std::string LensText(const Lens& camera) {
  if (camera.model() == Lens::Model::kOpenCV) return "k1 " + Fixed(camera.distortion().k1, 4);
  return "kdu " + Fixed(camera.kdu(), 4);
}

struct Worst {
  double px_pct = 0.0, py_pct = 0.0, u0_px = 0.0, v0_px = 0.0, lens_px = 0.0, rms_px = 0.0;
  int failed = 0;
};

Worst WorstOf(const std::vector<CameraCalibrationTrial>& trials) {
  Worst worst;
  for (const CameraCalibrationTrial& t : trials) {
    if (!t.failed.empty()) {
      ++worst.failed;
      continue;
    }
    worst.px_pct = std::max(worst.px_pct, t.px_error_pct());
    worst.py_pct = std::max(worst.py_pct, t.py_error_pct());
    worst.u0_px = std::max(worst.u0_px, t.u0_error_px());
    worst.v0_px = std::max(worst.v0_px, t.v0_error_px());
    worst.lens_px = std::max(worst.lens_px, t.lens_error_px);
    worst.rms_px = std::max(worst.rms_px, t.rms_px);
  }
  return worst;
}

std::string Table(const CalibrateAccuracyOptions& o,
                  const std::vector<CameraCalibrationTrial>& trials) {
  std::ostringstream out;
  out << "| camera | px true / found | py true / found | u0 true / found | v0 true / found | lens "
         "true / found | lens miss (px) | views used | RMS (px) |\n"
         "|---|---|---|---|---|---|---:|---:|---:|\n";
  for (std::size_t c = 0; c < trials.size(); ++c) {
    const CameraCalibrationTrial& t = trials[c];
    out << "| " << c << " | ";
    if (!t.failed.empty()) {
      out << Fixed(t.truth.px(), 1) << " / — | — | — | — | " << LensText(t.truth)
          << " / — | — | — | " << t.failed << " |\n";
      continue;
    }
    out << Fixed(t.truth.px(), 1) << " / " << Fixed(t.found.px(), 1) << " ("
        << Fixed(t.px_error_pct(), 3) << " %) | " << Fixed(t.truth.py(), 1) << " / "
        << Fixed(t.found.py(), 1) << " (" << Fixed(t.py_error_pct(), 3) << " %) | "
        << Fixed(t.truth.u0(), 1) << " / " << Fixed(t.found.u0(), 1) << " | "
        << Fixed(t.truth.v0(), 1) << " / " << Fixed(t.found.v0(), 1) << " | " << LensText(t.truth)
        << " / " << LensText(t.found) << " | " << Fixed(t.lens_error_px, 2) << " | " << t.used
        << " / " << t.views << " | " << Fixed(t.rms_px, 3) << " |\n";
  }
  const Worst w = WorstOf(trials);
  out << "\n"
      << o.target.name << ", " << trials.size() << " cameras of " << o.frames
      << " views: " << w.failed << " not calibrated; worst px " << Fixed(w.px_pct, 3) << " %, py "
      << Fixed(w.py_pct, 3) << " %, u0 " << Fixed(w.u0_px, 2) << " px, v0 " << Fixed(w.v0_px, 2)
      << " px, lens " << Fixed(w.lens_px, 2) << " px (within "
      << Fixed(100.0 * kLensJudgedFraction, 0) << " % of the way to the corners), RMS "
      << Fixed(w.rms_px, 3) << " px\n";
  return out.str();
}

nlohmann::json ToJson(const CalibrateAccuracyOptions& o,
                      const std::vector<CameraCalibrationTrial>& trials) {
  nlohmann::json options = RenderedFrameJson(o);
  options["target"] = o.target.name;
  options["cameras"] = o.cameras;
  options["views"] = o.frames;
  options["focal_px"] = {o.min_focal_px, o.max_focal_px};
  options["max_centre_offset_px"] = o.max_centre_offset_px;
  options["kdu"] = {o.min_kdu, o.max_kdu};
  options["tilt_deg"] = {o.min_tilt_deg, o.sampling.max_tilt_deg};
  options["distance_m"] = {o.sampling.min_distance_m, o.sampling.max_distance_m};
  nlohmann::json cameras = nlohmann::json::array();
  for (const CameraCalibrationTrial& t : trials) {
    nlohmann::json camera = {{"truth", CameraJson(t.truth, o.width, o.height)}, {"views", t.views}};
    if (t.failed.empty()) {
      camera["found"] = CameraJson(t.found, o.width, o.height);
      camera["used"] = t.used;
      camera["rms_px"] = t.rms_px;
      camera["px_error_pct"] = t.px_error_pct();
      camera["py_error_pct"] = t.py_error_pct();
      camera["u0_error_px"] = t.u0_error_px();
      camera["v0_error_px"] = t.v0_error_px();
      camera["lens_error_px"] = t.lens_error_px;
    } else {
      camera["failed"] = t.failed;
    }
    cameras.push_back(std::move(camera));
  }
  const Worst w = WorstOf(trials);
  return {{"options", std::move(options)},
          {"cameras", std::move(cameras)},
          {"not_calibrated", w.failed},
          {"worst",
           {{"px_error_pct", w.px_pct},
            {"py_error_pct", w.py_pct},
            {"u0_error_px", w.u0_px},
            {"v0_error_px", w.v0_px},
            {"lens_error_px", w.lens_px},
            {"rms_px", w.rms_px}}}};
}

}  // namespace

int RunCalibrateAccuracy(int argc, char** argv) {
  CLI::App cli{
      "Accuracy of `oalservo calibrate --target` on rendered views (fixed seeds): for each of "
      "--cameras cameras a focal length, a principal point off the centre and a lens are drawn, "
      "--views views of the printed sheet are rendered on the evaluation bench (photographs of "
      "Debian's visp-images-data, printed sheets and tools around it, noise and blur), tilted "
      "15-45 deg in any direction, found as `calibrate` finds them, and calibrated; the table "
      "gives each camera's truth and what came back.",
      "oalservo calibrate-accuracy"};
  CalibrateAccuracyOptions options;
  options.frames = 20;
  options.noise_sigma = 4.0;
  options.blur_sigma_px = 1.0;
  std::string target_name = options.target.name, out_path;
  cli.add_option("--cameras", options.cameras, "cameras drawn, [1, 1000]")->capture_default_str();
  cli.add_option("--views", options.frames, "views of each camera, >= 3")->capture_default_str();
  AddSeedOption(cli, &options.seed, "seed of the cameras, poses and noise, >= 0");
  cli.add_option("--target", target_name, "the printed target: " + TargetNameList())
      ->capture_default_str();
  cli.add_option("--noise", options.noise_sigma, "noise sigma, grey levels, [0, 100]")
      ->capture_default_str();
  cli.add_option("--blur", options.blur_sigma_px, "blur sigma, pixels, [0, 20]")
      ->capture_default_str();
  CLI::Option* max_kdu =
      cli.add_option("--max-kdu", options.max_kdu, "the lens drawn: ViSP's kdu in [0, this]")
          ->capture_default_str();
  std::string camera_path;
  cli.add_option("--camera", camera_path,
                 "every camera this file's (ViSP's .xml, OpenCV's or ROS's .yaml, at its image "
                 "size) instead of drawn ones")
      ->check(CLI::ExistingFile)
      ->excludes(max_kdu);
  cli.add_option("--background", options.backgrounds,
                 "image of the surface the target lies on, several in turn (default: "
                 "photographs of Debian's visp-images-data)");
  cli.add_option("--out", out_path, "write the report as JSON to this file");
  cli.footer(
      "Example:\n"
      "  oalservo calibrate-accuracy --cameras 5 --views 20 --seed 1 --out out/calibrate-a3.json");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;

  try {
    options.target = TargetByName(target_name);
  } catch (const std::invalid_argument& error) {
    throw UsageError(std::string("--target: ") + error.what());
  }
  if (!camera_path.empty()) {
    const CameraFile file = LoadCameraFile(camera_path);
    options.lens = file.camera;
    if (file.width > 0) {
      options.width = static_cast<int>(file.width);
      options.height = static_cast<int>(file.height);
    }
  }
  options.sampling = SheetSampling(options.target);
  options.sampling.max_tilt_deg = 45.0;
  options.scene = BenchScene();
  if (options.backgrounds.empty()) options.backgrounds = DefaultBenchPhotos();
  CheckInOptionWords([&] { options.Check(); },
                     {{"CalibrateAccuracyOptions::cameras", "--cameras"},
                      {"CalibrateAccuracyOptions::frames", "--views"},
                      {"RenderedFrameOptions::frames", "--views"},
                      {"RenderedFrameOptions::noise_sigma", "--noise"},
                      {"RenderedFrameOptions::blur_sigma_px", "--blur"},
                      {"CalibrateAccuracyOptions::lens", "--camera"},
                      {"CalibrateAccuracyOptions::max_kdu", "--max-kdu"}});
  CheckReportFile(out_path);
  const std::vector<CameraCalibrationTrial> trials =
      EvaluateCalibration(options, FrameProgress("view", 10.0, "views"));
  PrintAccuracyReport(Table(options, trials), ToJson(options, trials), out_path);
  return kExitOk;
}

}  // namespace oal
