#include "app/camera_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>

#include "app/command_line.h"
#include "base/format.h"
#include "detector/lens.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"

namespace oal {
namespace {

void PrintCamera(const CameraFile& file, const std::string& path) {
  const Lens& lens = file.camera;
  std::cout << path << ": " << CameraFileFormatName(file.format);
  if (!file.name.empty()) std::cout << ", camera '" << file.name << "'";
  if (file.width > 0) std::cout << ", " << file.width << "x" << file.height;
  std::cout << "\n"
            << LensModelName(lens) << ": px " << Fixed(lens.px(), 3) << ", py "
            << Fixed(lens.py(), 3) << ", u0 " << Fixed(lens.u0(), 3) << ", v0 "
            << Fixed(lens.v0(), 3);
  if (lens.model() == Lens::Model::kViSP) {
    std::cout << ", kud " << Fixed(lens.kud(), 6) << ", kdu " << Fixed(lens.kdu(), 6);
  } else if (lens.model() == Lens::Model::kOpenCV) {
    const auto values = lens.distortion().ToArray();
    const std::size_t count = lens.distortion().IsRational() ? 8 : 5;
    for (std::size_t i = 0; i < count; ++i)
      std::cout << ", " << Distortion::kNames[i] << " " << values[i];
  }
  std::cout << '\n';
}

}  // namespace

int RunCamera(int argc, char** argv) {
  CLI::App cli{
      "Reads a camera file (ViSP's .xml, OpenCV's calibration .yaml or ROS's camera_info "
      ".yaml), shows its lens and, with --out, writes it in the format --out's extension names: "
      "a lens the new format cannot hold exactly (OpenCV's model in ViSP's XML, which has one "
      "radial term) is written as its best approximation over the image, and the command says "
      "how far it misses.",
      "oalservo camera"};
  std::string in_path, name, out_path, out_name;
  bool ros = false;
  cli.add_option("FILE", in_path, "the camera file to read")->required()->check(CLI::ExistingFile);
  cli.add_option("--name", name, "the camera to read from a ViSP XML (default: its first)");
  cli.add_option("--out", out_path,
                 "write the camera to this file: .xml (ViSP's XML), .yaml or .yml (OpenCV's "
                 "calibration YAML, or ROS's camera_info with --ros)");
  cli.add_flag("--ros", ros, "with --out: ROS's camera_info YAML")->needs("--out");
  cli.add_option("--out-name", out_name,
                 "the camera's name in the file written (default: the one read, else Camera)")
      ->needs("--out");
  cli.footer(
      "Examples:\n"
      "  oalservo camera camera.yaml                        # what the file holds\n"
      "  oalservo camera camera.yaml --out camera.xml       # for ViSP's own tools\n"
      "  oalservo camera camera.yaml --out head.yaml --ros  # for ROS");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  CameraFileFormat format = CameraFileFormat::kOpenCvYaml;
  if (!out_path.empty()) {
    try {
      format = CameraFileFormatFor(out_path, ros);
    } catch (const std::invalid_argument& error) {
      throw UsageError(std::string("--out: ") + error.what());
    }
  }
  const CameraFile file = LoadCameraFile(in_path, name);
  PrintCamera(file, in_path);
  if (out_path.empty()) return kExitOk;
  PrepareOutputFile(std::filesystem::path(out_path), "--out");
  const std::string written_name =
      !out_name.empty() ? out_name : (file.name.empty() ? std::string("Camera") : file.name);
  const std::optional<std::string> note = SaveCameraFile(
      out_path, file.camera, written_name, file.width, file.height, format,
      {"written by oalservo camera from " + std::filesystem::path(in_path).filename().string()});
  std::cout << "wrote " << out_path << " (" << CameraFileFormatName(format) << ")\n";
  if (note) Warn("camera", *note);
  return kExitOk;
}

}  // namespace oal
