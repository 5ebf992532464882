#include "app/edge_reference_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>

#include "app/command_line.h"
#include "eval/lines/edge_reference.h"
#include "io/atomic_file.h"

namespace oal {

int RunEdgeReference(int argc, char** argv) {
  CLI::App cli{
      "Reference lines for an image sequence showing one straight light/dark edge (e.g. "
      "ViSP's line/ sequence): a sub-pixel gradient-maximum edge fit that shares no code "
      "with the OAL detector, followed from frame to frame. Writes the truth CSV that "
      "`oalservo compare --truth` reads (frame,line,rho,theta).",
      "oalservo edge-reference"};
  std::string pattern, out_path;
  int first = 1, last = 0;
  cli.add_option("PATTERN", pattern, "printf pattern of the frames, e.g. line/image.%04d.pgm")
      ->required();
  cli.add_option("--first", first, "first frame number")->capture_default_str();
  cli.add_option("--last", last,
                 "last frame number (0: up to the last consecutive file that exists)")
      ->capture_default_str();
  cli.add_option("--out", out_path, "the truth CSV to write")->required();
  cli.footer(
      "Example:\n"
      "  oalservo edge-reference '/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm' "
      "--out out/line-truth.csv\n"
      "  oalservo compare '/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm' "
      "--truth out/line-truth.csv --config config/visp_line_edges.yaml");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;

  // The frames: a pattern with one %d (not a single image, not a directory), a valid range.
  SequenceFramePath(pattern, first);
  if (first < 0) {
    throw std::invalid_argument("--first " + std::to_string(first) + ": must be >= 0");
  }
  if (last < 0 || (last != 0 && first > last)) {
    throw std::invalid_argument("--first " + std::to_string(first) + " is after --last " +
                                std::to_string(last) +
                                " (--last 0: up to the last consecutive file)");
  }
  if (last == 0) last = LastSequenceFrame(pattern, first);

  // The output before the work: a bad --out fails now, and the file appears only whole.
  const std::filesystem::path out(out_path);
  PrepareOutputFile(out, "--out");
  AtomicFile file(out);  // throws naming the file when it cannot be written

  const std::vector<FrameReference> references =
      FitEdgeSequence(pattern, first, last, EdgeReferenceOptions());
  std::vector<int> missing;
  for (const FrameReference& frame : references) {
    if (frame.reference.status != EdgeReferenceStatus::kFound) {
      Warn("edge-reference",
           "frame " + std::to_string(frame.frame) + ": " + frame.reference.message);
      missing.push_back(frame.frame);
      continue;
    }
    std::cout << "frame " << frame.frame << ": rho " << frame.reference.line.rho_px << " px, theta "
              << frame.reference.line.theta_rad << " rad, rms " << frame.reference.rms_residual_px
              << " px over " << frame.reference.points << " edge points\n";
  }
  if (!missing.empty()) {
    std::string frames;
    for (int frame : missing) frames += (frames.empty() ? "" : ", ") + std::to_string(frame);
    throw std::runtime_error(
        std::to_string(missing.size()) + " of " + std::to_string(references.size()) +
        " frames have no reference (frames " + frames + "); nothing written to " + out_path);
  }
  WriteTruthCsv(references, file.stream());
  file.Commit();
  std::cout << references.size() << " of " << references.size()
            << " frames have a reference; wrote " << out_path << '\n';
  return kExitOk;
}

}  // namespace oal
