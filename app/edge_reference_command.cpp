#include "app/edge_reference_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include "app/command_line.h"
#include "app/edge_reference.h"

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
  cli.add_option("--last", last, "last frame number (0: up to the last file that exists)")
      ->capture_default_str();
  cli.add_option("--out", out_path, "the truth CSV to write")->required();
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;

  if (last == 0) {
    // The last consecutive frame that exists.
    for (last = first;; ++last) {
      char name[4096];
      std::snprintf(name, sizeof(name), pattern.c_str(), last + 1);
      if (!std::ifstream(name)) break;
    }
  }
  const std::vector<FrameReference> references =
      FitEdgeSequence(pattern, first, last, EdgeReferenceOptions());
  int found = 0;
  for (const FrameReference& frame : references) {
    if (frame.reference.status != EdgeReferenceStatus::kFound) {
      Warn("edge-reference",
           "frame " + std::to_string(frame.frame) + ": " + frame.reference.message);
      continue;
    }
    ++found;
    std::cout << "frame " << frame.frame << ": rho " << frame.reference.line.rho_px << " px, theta "
              << frame.reference.line.theta_rad << " rad, rms " << frame.reference.rms_residual_px
              << " px over " << frame.reference.points << " edge points\n";
  }
  WriteTruthCsv(references, out_path);
  std::cout << found << " of " << references.size() << " frames have a reference; wrote "
            << out_path << '\n';
  return found == static_cast<int>(references.size()) ? kExitOk : kExitError;
}

}  // namespace oal
