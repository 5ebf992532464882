// What every `oalservo` subcommand shares: the command table entry, the two kinds of error
// main() tells apart, and CLI11 parsing that turns --help into a normal exit.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace CLI {
class App;
}  // namespace CLI

namespace oal {

/// One row of main()'s command table. `run` gets argv with argv[0] = the command name and
/// returns the process exit code; it throws on error (main() prints and maps the error).
struct Command {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* help;  ///< one line, shown by `oalservo --help`
};

/// Exit codes of `oalservo`.
enum ExitCode : int {
  kExitOk = 0,
  kExitError = 1,  ///< bad input, bad configuration, I/O failure
  kExitUsage = 2,  ///< bad command line
};

/// A bad command line (unknown option, missing argument...): exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses argv into `cli`. Returns an exit code when the command should stop here (--help
/// was printed: kExitOk), std::nullopt to go on. Throws UsageError on a bad command line.
std::optional<int> ParseCommandLine(CLI::App& cli, int argc, char** argv);

/// Runs `check` (a library Options' Check()) and, when it throws std::invalid_argument,
/// throws the same message in the command line's words: each {"Options::field", "--option"}
/// pair's qualified field, and its bare name in the constraint, become the option that set it.
void CheckInOptionWords(const std::function<void()>& check,
                        const std::vector<std::pair<std::string, std::string>>& fields);

/// "frame N / total, R frames/s, ETA m:ss" on stderr, redrawn in place (at most 5 times a
/// second, and at the end), when stderr is a terminal; nothing otherwise (logs stay clean).
std::function<void(int done, int total)> TerminalFrameProgress();

/// As TerminalFrameProgress, with `label` instead of "frame"; when stderr is not a terminal,
/// a plain line "label N / total, R <unit>/s, ETA m:ss" every `plain_every_s` seconds and at
/// the end. total <= 0: unknown (no ETA). Not thread-safe: callers serialise the calls.
std::function<void(int done, int total)> FrameProgress(const std::string& label,
                                                       double plain_every_s = 10.0,
                                                       const std::string& unit = "frames");

/// The checks every command over image sources shares: at least one input, --max-frames >= 0
/// and a writable --out. Throws std::invalid_argument naming the option.
void CheckFrameCommand(const std::vector<std::string>& inputs, int max_frames,
                       const std::string& out_path);

/// While one lives, the signals that ask a program to stop — SIGINT (Ctrl-C), SIGTERM (kill,
/// `systemctl stop`, `timeout`) and SIGHUP (the terminal or the SSH session closed) — set
/// interrupted() instead of ending the process, and then call `also` if given (which must be
/// async-signal-safe: store to lock-free atomics only); the previous handlers come back after.
/// signal_number() says which signal came first. One at a time: the flag is process-wide.
class StopSignalScope {
 public:
  explicit StopSignalScope(void (*also)() = nullptr);
  ~StopSignalScope();
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;

  /// Set by any of the stop signals; false when the scope begins.
  const std::atomic<bool>* interrupted() const;
  /// The first stop signal received since the scope began (SIGINT, SIGTERM, SIGHUP); 0: none.
  int signal_number() const;

 private:
  static constexpr int kSignals = 3;
  void (*previous_[kSignals])(int);
};

/// A stop signal for the user: "Ctrl-C (SIGINT)", "SIGTERM (a request to terminate)",
/// "SIGHUP (the terminal or session was closed)"; "signal N" for another.
std::string StopSignalName(int signal_number);

/// A warning for the user on stderr: "oalservo <command>: warning: <message>". Libraries
/// never print; commands report through this.
void Warn(const std::string& command, const std::string& message);

}  // namespace oal
