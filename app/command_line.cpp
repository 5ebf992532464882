#include "app/command_line.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "app/atomic_file.h"

namespace oal {

std::optional<int> ParseCommandLine(CLI::App& cli, int argc, char** argv) {
  try {
    cli.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << cli.help();
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    std::cout << cli.help("", CLI::AppFormatMode::All);
    return kExitOk;
  } catch (const CLI::ParseError& error) {
    throw UsageError(std::string(error.what()) + " (run with --help for usage)");
  }
  return std::nullopt;
}

std::function<void(int, int)> TerminalFrameProgress() {
  if (!isatty(fileno(stderr))) return {};
  return [](int done, int total) {
    if (done % 20 != 0 && done != total) return;
    std::cerr << "\rframe " << done << " / " << total << std::flush;
    if (done == total) std::cerr << '\n';
  };
}

void CheckFrameCommand(const char* options_name, const std::vector<std::string>& inputs,
                       int max_frames, const std::string& out_path) {
  const std::string name = options_name;
  if (inputs.empty()) throw std::invalid_argument(name + "::inputs is empty");
  if (max_frames < 0) {
    throw std::invalid_argument(name + "::max_frames = " + std::to_string(max_frames) +
                                ". Violated constraint: max_frames >= 0");
  }
  if (!out_path.empty()) CheckOutputFile(out_path);
}

void Warn(const std::string& command, const std::string& message) {
  std::cerr << "oalservo " << command << ": warning: " << message << '\n';
}

}  // namespace oal
