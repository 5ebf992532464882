#include "app/command_line.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

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

void Warn(const std::string& command, const std::string& message) {
  std::cerr << "oalservo " << command << ": warning: " << message << '\n';
}

}  // namespace oal
