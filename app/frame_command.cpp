#include "app/frame_command.h"

#include <CLI/CLI.hpp>

#include "io/image_source.h"

namespace oal {

std::string CompanionDirectory(const std::vector<std::string>& inputs) {
  if (inputs.empty()) return ".";
  const std::filesystem::path first = inputs.front();
  const std::filesystem::path dir =
      std::filesystem::is_directory(first) ? first : first.parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

std::optional<std::string> CompanionFile(const std::vector<std::string>& inputs,
                                         const std::string& name) {
  if (inputs.empty()) return std::nullopt;
  const std::filesystem::path candidate = std::filesystem::path(CompanionDirectory(inputs)) / name;
  if (!std::filesystem::is_regular_file(candidate)) return std::nullopt;
  return candidate.string();
}

std::vector<std::unique_ptr<ImageSource>> OpenInputs(const FrameCommandOptions& options,
                                                     std::vector<std::string>* warnings) {
  std::vector<std::unique_ptr<ImageSource>> sources;
  for (const std::string& input : options.inputs) {
    sources.push_back(OpenImageSource(input, warnings));
  }
  return sources;
}

std::filesystem::path AnnotationPath(const FrameCommandOptions& options, const std::string& prefix,
                                     int frame) {
  std::string number = std::to_string(frame);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return std::filesystem::path(options.annotate_dir) / (prefix + "_" + number + ".png");
}

void AddInputsArgument(CLI::App& cli, FrameCommandOptions* options) {
  cli.add_option("INPUT", options->inputs,
                 "image, directory of images, printf pattern (frames/img%04d.png: from index "
                 "0 or 1 up to the first missing file, with a warning if files follow the gap), "
                 "video file, or V4L2 device /dev/videoN")
      ->required();
}

void AddOutputOptions(CLI::App& cli, FrameCommandOptions* options,
                      const std::string& annotate_help) {
  cli.add_option("--out", options->out_path, "JSON Lines output file (written atomically)");
  cli.add_option("--annotate", options->annotate_dir, annotate_help);
  cli.add_option("--max-frames", options->max_frames, "stop after N frames (0: all)");
}

}  // namespace oal
