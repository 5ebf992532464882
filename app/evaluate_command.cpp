#include "app/evaluate_command.h"

#include <CLI/CLI.hpp>
#include <iostream>

#include "app/command_line.h"
#include "app/evaluation_config.h"
#include "app/frame_command.h"
#include "app/live_window.h"
#include "eval/recordings/evaluate.h"

namespace oal {

int RunEvaluate(int argc, char** argv) {
  EvaluateOptions options;
  std::string shard;
  bool no_video = false;
  std::string config_path;
  CLI::App cli(
      "Evaluate the line tracker and the pose on recorded videos or image sequences: per-frame "
      "JSON Lines, a summary (detection rate, lost-track episodes, pose availability, errors "
      "against the truth), an annotated video and a self-contained HTML report per input, and "
      "an index (docs/EVALUATE.md).",
      "oalservo evaluate");
  cli.add_option("INPUT", options.inputs,
                 "video, directory of images, printf pattern (frames/img%04d.png: up to the "
                 "first missing file, with a warning if files follow the gap), or a directory "
                 "of videos and image directories")
      ->required();
  cli.add_option("--out", options.out_dir, "output directory (created if missing)")->required();
  cli.add_option("--config", config_path,
                 "YAML configuration: detector, target and pose sections (default: the "
                 "target.yaml `oalservo render` writes next to its frames, else the A3 sheet)")
      ->check(CLI::ExistingFile);
  cli.add_option(
      "--camera", options.camera_path,
      "camera file for every input: ViSP's .xml, OpenCV's or ROS's .yaml (default: "
      "camera.xml or camera.yaml next to each input; without a camera there is no pose)");
  cli.add_option("--truth", options.truth_path,
                 "truth of the single input: a CSV of lines and poses, or a directory of the "
                 "renderer's frame JSON (default: JSON next to the images, <video>.truth.csv)");
  cli.add_flag("--compare", options.compare,
               "also run oalservo compare's methods (vpMeLine, OpenCV) on each input");
  cli.add_option("--jobs", options.jobs, "inputs evaluated in parallel")->capture_default_str();
  cli.add_option("--shard", shard,
                 "I/N: only the inputs whose number is I modulo N (I from 0), for batch "
                 "schedulers; gather with a final run with --resume");
  cli.add_flag("--resume", options.resume,
               "skip the inputs a previous run completed (their summary.json exists)");
  cli.add_flag("--no-video", no_video, "do not write the annotated videos");
  cli.add_option("--video-scale", options.video_scale,
                 "size of the annotated videos relative to the frames (1: full size, four to five "
                 "times the encoding time of the default)")
      ->capture_default_str();
  cli.add_option("--video-codec", options.video_codec,
                 "codec of the annotated videos: xvid (MPEG-4 part 2, fastest) or mjpg "
                 "(every frame a key frame)")
      ->check(CLI::IsMember({"xvid", "mjpg"}))
      ->capture_default_str();
  cli.add_option("--lines", options.target_lines,
                 "lines held for the target to count as detected (0: the target's lines)")
      ->capture_default_str();
  cli.add_option("--max-frames", options.max_frames, "frames per input at most (0: all)");
  bool display = false;
  double display_fps = 30.0;
  cli.add_flag("--display", display,
               "show each frame annotated in a window as it is evaluated (one input; X11: "
               "$DISPLAY); a click or a key ends the input there, its frames so far evaluated");
  cli.add_option("--display-fps", display_fps, "with --display, frames shown a second at most")
      ->check(CLI::Range(0.1, 1000.0))
      ->capture_default_str();
  cli.add_option("--thumbnails", options.thumbnails, "worst frames shown per report")
      ->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo evaluate clip.mp4 --camera camera.xml --out out/eval\n"
      "  oalservo evaluate recordings/ --camera camera.xml --jobs 2 --out out/eval\n"
      "  oalservo evaluate recordings/ --shard $SLURM_ARRAY_TASK_ID/8 --out out/eval\n"
      "  oalservo evaluate '/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm' "
      "--config config/visp_line_edges.yaml --lines 1 --out out/eval-line");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  if (!shard.empty()) {
    try {
      std::tie(options.shard_index, options.shard_count) = ParseShard(shard);
    } catch (const std::invalid_argument& error) {
      throw UsageError(std::string("--shard ") + error.what());
    }
  }
  options.names = {{"target_lines", "--lines"},
                   {"video_codec", "--video-codec"},
                   {"camera_path", "--camera"},
                   {"truth_path", "--truth"},
                   {"calibrate", "oalservo calibrate"}};
  // Before the evaluation, whose own messages name options through options.names: translating
  // every message it throws would also turn plain words ("2 inputs", "jobs") into flags.
  CheckInOptionWords([&] { options.Check(); }, {{"EvaluateOptions::inputs", "INPUT"},
                                                {"EvaluateOptions::out_dir", "--out"},
                                                {"EvaluateOptions::jobs", "--jobs"},
                                                {"EvaluateOptions::shard", "--shard"},
                                                {"EvaluateOptions::max_frames", "--max-frames"},
                                                {"EvaluateOptions::video_scale", "--video-scale"},
                                                {"EvaluateOptions::video_codec", "--video-codec"},
                                                {"EvaluateOptions::thumbnails", "--thumbnails"},
                                                {"EvaluateOptions::target_lines", "--lines"}});
  options.write_video = !no_video;
  options.setup = TrackerSetupOf(config_path, options.inputs);
  std::unique_ptr<LiveView> view;
  if (display) {
    if (options.inputs.size() != 1 || options.jobs != 1) {
      throw UsageError("--display shows one input evaluated alone (got " +
                       std::to_string(options.inputs.size()) + " inputs, --jobs " +
                       std::to_string(options.jobs) + ")");
    }
    view = OpenLiveView("oalservo evaluate", display_fps);
  }
  const FrameViewer viewer = [&view](const cv::Mat& annotated, const std::string& caption) {
    return view->Show(annotated, caption, false);
  };
  const EvaluateResult result =
      Evaluate(options, FrameProgress("evaluate: frame"), view ? viewer : FrameViewer());
  int failed = 0, resumed = 0;
  for (const InputOutcome& input : result.inputs) {
    if (input.status == "failed") {
      ++failed;
      Warn("evaluate", "input '" + input.input + "' failed: " + input.error);
    }
    resumed += input.status == "resumed";
    // What summary.json warns about (a video cut short, nearly nothing detected) is said here
    // too: a user reads the console first.
    if (input.status == "complete" && input.summary.is_object() &&
        input.summary.contains("warnings")) {
      for (const Json& warning : input.summary.at("warnings")) {
        Warn("evaluate", input.name + ": " + warning.get<std::string>());
      }
    }
  }
  for (const std::string& skipped : result.skipped) Warn("evaluate", "skipped " + skipped);
  std::cerr << "oalservo evaluate: " << result.inputs.size() << " input(s), " << result.frames
            << " frames evaluated"
            << (resumed > 0 ? ", " + std::to_string(resumed) + " resumed" : "")
            << (failed > 0 ? ", " + std::to_string(failed) + " failed" : "") << "; report "
            << result.index_path << '\n';
  return failed > 0 ? kExitError : kExitOk;
}

}  // namespace oal
