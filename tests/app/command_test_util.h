// Helpers shared by the app command tests: small rendered data sets, the message a call
// throws with, running a `Run*(argc, argv)` command on a list of arguments, and running the
// real `oalservo` binary.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdint>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/config.h"
#include "app/render_command.h"
#include "tests/test_util.h"

namespace oal::test {

/// Options rendering `count` frames of `width`x`height` into `out_dir` from `seed`, with fx
/// scaled from 600 px at 640x480 (the full-size field of view), of the 2 m four-line board;
/// the rest as RenderCommandOptions.
inline RenderCommandOptions ScaledRender(const std::string& out_dir, int count, std::uint64_t seed,
                                         int width, int height) {
  RenderCommandOptions options;
  options.target = "four-line-board";  // the paper's condition: lines traverse the image
  options.out_dir = out_dir;
  options.count = count;
  options.seed = seed;
  options.width = width;
  options.height = height;
  options.fx_px = 600.0 * width / 640.0;
  return options;
}

/// Options rendering `count` frames of the sequence `sequence` (scene/sequence.h) into `out_dir`.
inline RenderCommandOptions SequenceRender(const std::string& out_dir, const std::string& sequence,
                                           int count, std::uint64_t seed) {
  RenderCommandOptions options;
  options.target = "four-line-board";
  options.out_dir = out_dir;
  options.sequence = sequence;
  options.count = count;
  options.seed = seed;
  return options;
}

/// Renders `options`, expecting every frame to be written; returns the data set's directory.
inline std::string RenderChecked(const RenderCommandOptions& options) {
  EXPECT_EQ(RenderDataset(options), options.count);
  return options.out_dir;
}

/// The message ParseConfig throws for `yaml` read as `file_name`; empty if it is accepted.
inline std::string ConfigErrorOf(const std::string& yaml, const std::string& file_name) {
  return ErrorMessageOf<std::runtime_error>([&] { ParseConfig(yaml, file_name); });
}

/// What `run` (a command's `Run*(argc, argv)`) returns for the command line `args`.
template <typename Run>
int RunWithArgs(Run&& run, std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  return run(static_cast<int>(argv.size()), argv.data());
}

/// What the real `oalservo` binary did.
struct OalservoRun {
  int exit_code = -1;
  std::string out, err;
};

/// Runs `oalservo <args>` through the shell (args as written there); stdout goes to
/// `stdout_to` (e.g. /dev/full), or to a file of `dir` whose text is returned when empty.
inline OalservoRun RunOalservo(const TestDir& dir, const std::string& args,
                               const std::string& stdout_to = "") {
  const std::string out = stdout_to.empty() ? dir / "stdout.txt" : stdout_to;
  const std::string err = dir / "stderr.txt";
  const std::string command =
      std::string("'") + OAL_OALSERVO_PATH + "' " + args + " >'" + out + "' 2>'" + err + "'";
  const int status = std::system(command.c_str());
  OalservoRun run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (stdout_to.empty()) run.out = ReadText(out);
  run.err = ReadText(err);
  return run;
}

}  // namespace oal::test
