#include "app/calibrate_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/command_line.h"
#include "app/evaluation_config.h"
#include "base/format.h"
#include "calibration/calibrate.h"
#include "calibration/chessboard.h"
#include "calibration/sheet_view_finder.h"
#include "calibration/view_selector.h"
#include "detector/lens.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"

namespace oal {
namespace {

// "9x6": inner corners along a row and along a column.
void ParseChessboard(const std::string& text, ChessboardOptions* options) {
  int columns = 0, rows = 0;
  char x = 0, rest = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &columns, &x, &rows, &rest) != 3 ||
      (x != 'x' && x != 'X') || columns < 2 || rows < 2 || columns > 100 || rows > 100) {
    throw UsageError("--chessboard " + text +
                     ": expected the inner corners as COLUMNSxROWS, e.g. 9x6 (2 to 100 each)");
  }
  options->columns = columns;
  options->rows = rows;
}

// "k1 <text>, k2 <text>, ..." over the distortion terms fitted (those fixed at zero left
// out), `text` of each term's value and standard deviation.
std::string FittedTerms(const CalibrationResult& result,
                        const std::function<std::string(double, double)>& text) {
  const auto values = result.camera.distortion().ToArray();
  const auto sds = result.distortion_sd.ToArray();
  std::string line;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (values[i] == 0.0 && sds[i] == 0.0) continue;
    line += (line.empty() ? "" : ", ") + std::string(Distortion::kNames[i]) + " " +
            text(values[i], sds[i]);
  }
  return line;
}

// `points`: what a view's points are ("corners", "stripe points").
void PrintReport(const CalibrationResult& result, const std::string& points) {
  for (const CalibrationViewReport& view : result.views) {
    if (view.used) {
      std::cout << view.name << ": " << view.points << " " << points << ", RMS "
                << Fixed(view.rms_px, 3) << " px, tilt " << Fixed(view.tilt_deg, 1) << " deg\n";
    } else {
      std::cout << view.name << ": not used: " << view.rejected << '\n';
    }
  }
  const Lens& camera = result.camera;
  std::cout << "px " << Fixed(camera.px(), 2) << " +- " << Fixed(result.px_sd, 2) << ", py "
            << Fixed(camera.py(), 2) << " +- " << Fixed(result.py_sd, 2) << ", u0 "
            << Fixed(camera.u0(), 2) << " +- " << Fixed(result.u0_sd, 2) << ", v0 "
            << Fixed(camera.v0(), 2) << " +- " << Fixed(result.v0_sd, 2) << " px\n";
  if (camera.distorted()) {
    std::cout << LensModelName(camera) << ": " << FittedTerms(result, [](double value, double sd) {
      return Fixed(value, 5) + " +- " + Fixed(sd, 5);
    }) << '\n';
    for (const std::string& fixed : result.fixed_terms) std::cout << fixed << '\n';
  }
  std::cout << "reprojection RMS " << Fixed(result.rms_px, 3) << " px";
  if (camera.distorted()) {
    std::cout << " (ViSP's one-term approximation, kud/kdu: " << Fixed(result.visp_rms_px, 3)
              << " px)";
  }
  std::cout << '\n';
  for (const std::string& advice : result.advice) Warn("calibrate", advice);
}

// What the camera file says of the calibration: each parameter's standard deviation, the
// terms fixed at zero, the RMS of the model the file holds.
std::vector<std::string> FileComments(const CalibrationResult& result, CameraFileFormat format) {
  const Lens& camera = result.camera;
  std::vector<std::string> comments = {
      "oalservo calibrate: " + LensModelName(camera) + " lens",
      "standard deviations: px " + Fixed(result.px_sd, 3) + ", py " + Fixed(result.py_sd, 3) +
          ", u0 " + Fixed(result.u0_sd, 3) + ", v0 " + Fixed(result.v0_sd, 3) + " px"};
  if (camera.distorted()) {
    comments.back() += "; " + FittedTerms(result, [](double, double sd) { return Fixed(sd, 6); });
    for (const std::string& fixed : result.fixed_terms) comments.push_back(fixed);
  }
  comments.push_back(format == CameraFileFormat::kViSPXml && camera.distorted()
                         ? "reprojection RMS of this file's one-term model " +
                               Fixed(result.visp_rms_px, 3) + " px (the full model's " +
                               Fixed(result.rms_px, 3) + " px)"
                         : "reprojection RMS " + Fixed(result.rms_px, 3) + " px");
  return comments;
}

// Finds the calibration target in a frame: the chessboard or the line target.
class ViewFinder {
 public:
  ViewFinder(std::optional<ChessboardOptions> chessboard, LineTarget target, AppConfig config)
      : chessboard_(std::move(chessboard)),
        target_(std::move(target)),
        config_(std::move(config)) {}

  CalibrationView Find(const Frame& frame) {
    if (chessboard_) {
      std::optional<CalibrationView> view =
          FindChessboard(frame.view(), *chessboard_, frame.source);
      return view ? std::move(*view) : CalibrationView{frame.source, {}, {}};
    }
    if (!sheet_) {
      sheet_.emplace(target_, frame.gray.cols, frame.gray.rows, config_.detector, config_.pose,
                     config_.tracking);
    }
    return sheet_->Find(frame.view(), frame.source);
  }

  /// Whether LookThrough can help: the line target, once a frame has been seen.
  bool CanLookThrough() const { return !chessboard_ && sheet_.has_value(); }
  /// Looks through `camera` first from now on (SheetViewFinder::LookThrough).
  void LookThrough(const Lens& camera) { sheet_->LookThrough(camera); }

 private:
  std::optional<ChessboardOptions> chessboard_;
  LineTarget target_;
  AppConfig config_;
  std::optional<SheetViewFinder> sheet_;
};

// Whether the finder found the target in the view.
bool ShowsTarget(const CalibrationView& view) {
  return !view.points.empty() || !view.lines.empty();
}

// The frames of `inputs` again, in the same order: each view of `views` (one per frame) that
// has no target is looked for again by `finder`. Returns how many were found.
int FindAgain(const std::vector<std::string>& inputs, ViewFinder* finder,
              std::vector<CalibrationView>* views) {
  int found = 0;
  std::size_t index = 0;
  for (const std::string& input : inputs) {
    std::vector<std::string> warnings;  // said on the first reading
    const std::unique_ptr<ImageSource> source = OpenImageSource(input, &warnings);
    Frame frame;
    while (index < views->size() && source->Next(&frame)) {
      CalibrationView& view = (*views)[index++];
      if (ShowsTarget(view)) continue;
      view = finder->Find(frame);
      found += ShowsTarget(view);
    }
  }
  return found;
}

// What the user is told when the live selection's verdict changes.
std::string LiveStatus(ViewSelector::Verdict verdict, const ViewSelector& selector) {
  switch (verdict) {
    case ViewSelector::Verdict::kNoTarget:
      return "looking for the target";
    case ViewSelector::Verdict::kMoving:
      return "hold the target still";
    case ViewSelector::Verdict::kTooLike:
      return "like view " + std::to_string(selector.similar_to() + 1) +
             ": move to a new pose (tilt the other way, towards another corner, nearer or "
             "farther)";
    case ViewSelector::Verdict::kTaken:
      break;
  }
  return "";
}

// The frames of `inputs`, all the same size (*width x *height from the first), each with the
// target found or not. With `live`, only those the selection takes, up to `wanted`, stopping
// early at a stop signal.
std::vector<CalibrationView> CollectViews(const std::vector<std::string>& inputs,
                                          ViewFinder* finder, bool live, int wanted, int* width,
                                          int* height) {
  std::vector<CalibrationView> views;
  std::optional<ViewSelector> selector;
  std::optional<StopSignalScope> stop;
  if (live) stop.emplace();
  std::string status;
  for (const std::string& input : inputs) {
    std::vector<std::string> warnings;
    const std::unique_ptr<ImageSource> source = OpenImageSource(input, &warnings);
    for (const std::string& warning : warnings) Warn("calibrate", warning);
    Frame frame;
    while (!(stop && stop->interrupted()->load()) && source->Next(&frame)) {
      if (*width == 0) *width = frame.gray.cols, *height = frame.gray.rows;
      if (frame.gray.cols != *width || frame.gray.rows != *height) {
        throw std::runtime_error(frame.source + ": " + std::to_string(frame.gray.cols) + "x" +
                                 std::to_string(frame.gray.rows) + " pixels, the first view " +
                                 std::to_string(*width) + "x" + std::to_string(*height) +
                                 ": one calibration is for one image size");
      }
      CalibrationView view = finder->Find(frame);
      if (!live) {
        views.push_back(std::move(view));
        continue;
      }
      if (!selector) selector.emplace(*width, *height);
      const ViewSelector::Verdict verdict = selector->Offer(view);
      if (verdict == ViewSelector::Verdict::kTaken) {
        views.push_back(std::move(view));
        std::cout << "view " << views.size() << " of " << wanted << " taken: " << frame.source
                  << std::endl;
        status.clear();
        if (static_cast<int>(views.size()) == wanted) return views;
      } else if (const std::string now = LiveStatus(verdict, *selector); now != status) {
        status = now;
        std::cout << "  " << status << std::endl;
      }
    }
  }
  if (stop && stop->signal_number() != 0) {
    std::cout << StopSignalName(stop->signal_number()) << ": " << views.size()
              << " views taken, calibrating with them\n";
  }
  return views;
}

}  // namespace

int RunCalibrate(int argc, char** argv) {
  CLI::App cli{
      "Calibrates the camera from views of the printed line target (default: four-line-a3, as "
      "`oalservo target` writes it) or of a printed chessboard: px, py, u0, v0 and the lens in "
      "OpenCV's model (k1, k2, p1, p2, k3; a term the views cannot tell from zero is fixed at "
      "zero, and said), with each view's reprojection RMS and each parameter's standard "
      "deviation, written as OpenCV's calibration YAML (--out camera.yaml), ROS's camera_info "
      "(--ros) or ViSP's camera XML (--out camera.xml: one radial term, the best approximation, "
      "and how far it misses); detect, pose, evaluate and servo read all three.",
      "oalservo calibrate"};
  std::vector<std::string> inputs;
  std::string chessboard_text, out_path, name = "Camera", config_path;
  std::string target_name = FourLineA3Target().name;
  ChessboardOptions chessboard;
  bool no_distortion = false, live = false, rational = false, ros = false;
  int wanted_views = 20;
  cli.add_option("INPUT", inputs,
                 "images, directories of images, printf patterns, videos or a camera "
                 "(/dev/video0, with --live) showing the target "
                 "(10-30 views, tilted 20-45 deg in different directions, some near the "
                 "image's corners)")
      ->required();
  CLI::Option* target_option =
      cli.add_option("--target", target_name, "the printed line target: " + TargetNameList())
          ->capture_default_str();
  CLI::Option* config_option =
      cli.add_option("--config", config_path,
                     "YAML config whose 'target:' is the printed target (its 'detector:', "
                     "'pose:' and 'tracking:' find it)")
          ->check(CLI::ExistingFile);
  CLI::Option* chessboard_option =
      cli.add_option("--chessboard", chessboard_text,
                     "a chessboard instead: its inner corners, COLUMNSxROWS (e.g. 9x6 for a "
                     "board of 10 x 7 squares)");
  CLI::Option* square_option =
      cli.add_option("--square", chessboard.square_m, "side of a square as printed, metres");
  cli.add_option("--out", out_path,
                 "the camera file to write: .yaml or .yml (OpenCV's calibration YAML, the full "
                 "model), .xml (ViSP's camera XML: one radial term)")
      ->required();
  cli.add_flag("--ros", ros, "write ROS's camera_info YAML instead of OpenCV's (--out a .yaml)");
  cli.add_flag("--rational", rational,
               "fit OpenCV's rational model too (k4, k5, k6), for lenses wider than ~100 deg");
  cli.add_option("--name", name, "the camera's name in the file")->capture_default_str();
  CLI::Option* no_distortion_option =
      cli.add_flag("--no-distortion", no_distortion,
                   "a distortion-free model (perspectiveProjWithoutDistortion)");
  CLI::Option* live_option = cli.add_flag(
      "--live", live,
      "take a view only when the target has held still for a few frames and stands apart "
      "from the views taken, up to --views, saying each time what to do (a camera: "
      "/dev/video0; a video works too); Ctrl-C calibrates with the views taken");
  cli.add_option("--views", wanted_views, "with --live: the views to take")
      ->check(CLI::Range(3, 1000))
      ->capture_default_str()
      ->needs(live_option);
  no_distortion_option->excludes("--rational");
  chessboard_option->excludes(target_option)->excludes(config_option)->needs(square_option);
  square_option->needs(chessboard_option);
  cli.footer(
      "Examples:\n"
      "  oalservo calibrate shots/ --out camera.yaml                   # the A3 sheet\n"
      "  oalservo calibrate shots/ --target four-line-a4 --out camera.yaml\n"
      "  oalservo calibrate shots/ --chessboard 9x6 --square 0.025 --out camera.yaml\n"
      "  oalservo calibrate shots/ --out head_camera.yaml --ros      # ROS's camera_info\n"
      "  oalservo calibrate shots/ --out camera.xml   # ViSP's XML, for ViSP's own tools\n"
      "  oalservo calibrate /dev/video0 --live --out camera.yaml     # move, hold, move...\n"
      "Print at 100 % and check the scale bar (or measure a square); lay the sheet flat. The "
      "line target needs its four crossings in view; the stripes' points, which must lie on "
      "straight lines, tell the lens. Views in which the target is not found are listed and "
      "left out.");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const bool use_chessboard = chessboard_option->count() > 0;
  AppConfig config;
  LineTarget target;
  if (use_chessboard) {
    ParseChessboard(chessboard_text, &chessboard);
    CheckInOptionWords([&] { chessboard.Check(); }, {{"ChessboardOptions::square_m", "--square"}});
  } else {
    if (!config_path.empty()) {
      config =
          LoadAccuracyConfig(config_path, "calibrate", {"target", "detector", "pose", "tracking"},
                             "a calibration needs only the printed target");
    }
    target = AccuracyTarget(target_name, target_option->count() > 0, config_path, config);
  }
  const std::string what = use_chessboard
                               ? "the whole chessboard (" + chessboard_text + " inner corners)"
                               : "the target " + target.name;

  // The output before the work: a bad --out fails now, and the file appears only whole.
  const std::filesystem::path out(out_path);
  CameraFileFormat format = CameraFileFormat::kOpenCvYaml;
  try {
    format = CameraFileFormatFor(out_path, ros);
  } catch (const std::invalid_argument& error) {
    throw UsageError(std::string("--out ") + (ros ? "with --ros: " : "") + error.what());
  }
  PrepareOutputFile(out, "--out");

  ViewFinder finder(use_chessboard ? std::optional<ChessboardOptions>(chessboard) : std::nullopt,
                    target, config);
  int width = 0, height = 0;
  std::vector<CalibrationView> views =
      CollectViews(inputs, &finder, live, wanted_views, &width, &height);
  if (live && static_cast<int>(views.size()) < CalibrationOptions().min_views) {
    throw std::runtime_error(std::to_string(views.size()) + " views taken from " + inputs.front() +
                             ", at least " + std::to_string(CalibrationOptions().min_views) +
                             " needed: nothing written to " + out_path);
  }
  if (views.empty()) throw std::runtime_error("no image in " + inputs.front());

  CalibrationOptions options;
  options.width = width;
  options.height = height;
  options.estimate_distortion = !no_distortion;
  options.rational = rational;
  if (use_chessboard) options.min_points_per_view = chessboard.columns * chessboard.rows;
  const auto say_not_found = [&]() {
    for (const CalibrationView& view : views) {
      if (!ShowsTarget(view))
        std::cout << view.name << ": not used: " << what << " was not found\n";
    }
  };
  const auto calibrate = [&]() {
    std::vector<CalibrationView> found;
    std::copy_if(views.begin(), views.end(), std::back_inserter(found), ShowsTarget);
    if (static_cast<int>(found.size()) < options.min_views) {
      say_not_found();
      throw std::runtime_error(std::to_string(found.size()) + " of " +
                               std::to_string(views.size()) + " images show " + what +
                               ", at least " + std::to_string(options.min_views) +
                               " needed: nothing written to " + out_path);
    }
    try {
      return Calibrate(found, options);
    } catch (const std::runtime_error& error) {
      say_not_found();
      throw std::runtime_error(std::string(error.what()) + "\nnothing written to " + out_path);
    }
  };
  CalibrationResult result = calibrate();
  // Near the image's corners a wide lens bends the stripes past what the finder's pinhole
  // guesses identify: the frames where it found no target are looked at again through the
  // lens the others gave. (Live views are taken only where the target was found.)
  if (!live && finder.CanLookThrough() && !std::all_of(views.begin(), views.end(), ShowsTarget)) {
    finder.LookThrough(result.camera);
    if (const int again = FindAgain(inputs, &finder, &views); again > 0) {
      std::cout << "found the target in " << again << " more view" << (again == 1 ? "" : "s")
                << " through the lens the others gave; calibrating again\n";
      result = calibrate();
    }
  }
  say_not_found();
  const auto found =
      static_cast<std::size_t>(std::count_if(views.begin(), views.end(), ShowsTarget));
  PrintReport(result, use_chessboard ? "corners" : "stripe points");
  const std::optional<std::string> note =
      SaveCameraFile(out_path, result.camera, name, static_cast<unsigned>(width),
                     static_cast<unsigned>(height), format, FileComments(result, format));
  std::cout << "wrote " << out_path << " (" << CameraFileFormatName(format) << ", camera '" << name
            << "', " << width << "x" << height << ", " << found << " of " << views.size()
            << " views)\n";
  if (note) {
    Warn("calibrate", *note + "; reprojection RMS " + Fixed(result.visp_rms_px, 3) +
                          " px against the full model's " + Fixed(result.rms_px, 3) +
                          " px. For the full model write --out camera.yaml");
  }
  return kExitOk;
}

}  // namespace oal
