#include "app/command_line.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <mutex>
#include <new>
#include <stdexcept>
#include <streambuf>

#include "io/atomic_file.h"

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

namespace {

// `text` with every whole-word occurrence of `word` replaced by `by` (a word: not preceded
// or followed by a letter, digit, '_', ':' or '-', so that an option already named, "--lines",
// is not renamed again).
std::string ReplaceWord(std::string text, const std::string& word, const std::string& by) {
  auto part_of_word = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == ':' || c == '-';
  };
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at)) {
    const std::size_t end = at + word.size();
    if ((at > 0 && part_of_word(text[at - 1])) || (end < text.size() && part_of_word(text[end]))) {
      at = end;
      continue;
    }
    text.replace(at, word.size(), by);
    at += by.size();
  }
  return text;
}

}  // namespace

void CheckInOptionWords(const std::function<void()>& check,
                        const std::vector<std::pair<std::string, std::string>>& fields) {
  try {
    check();
  } catch (const std::invalid_argument& error) {
    std::string message = error.what();
    for (const auto& [qualified, option] : fields) {
      message = ReplaceWord(message, qualified, option);
      const std::size_t scope = qualified.rfind("::");
      if (scope != std::string::npos) {
        message = ReplaceWord(message, qualified.substr(scope + 2), option);
      }
    }
    throw std::invalid_argument(message);
  }
}

namespace {

// The progress printer: `terminal` redraws one line, else one line per `every_s` seconds.
std::function<void(int, int)> ProgressPrinter(const std::string& label, bool terminal,
                                              double every_s, const std::string& unit = "frames") {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  auto last = std::make_shared<Clock::time_point>(start);
  return [=](int done, int total) {
    const Clock::time_point now = Clock::now();
    const bool end = total > 0 && done >= total;
    if (!end && std::chrono::duration<double>(now - *last).count() < every_s) return;
    *last = now;
    const double elapsed_s = std::chrono::duration<double>(now - start).count();
    const double rate = elapsed_s > 0.0 ? done / elapsed_s : 0.0;
    char text[160];
    int length = std::snprintf(text, sizeof text, "%s %d / %d, %.1f %s/s", label.c_str(), done,
                               total, rate, unit.c_str());
    if (total > 0 && rate > 0.0 && length > 0 && length < static_cast<int>(sizeof text)) {
      const long left_s = std::lround(std::max(0, total - done) / rate);
      std::snprintf(text + length, sizeof text - static_cast<std::size_t>(length),
                    ", ETA %ld:%02ld", left_s / 60, left_s % 60);
    }
    if (terminal) {
      std::cerr << "\r" << text << "\x1b[K" << (end ? "\n" : "") << std::flush;
    } else {
      std::cerr << text << '\n';
    }
  };
}

}  // namespace

std::function<void(int, int)> TerminalFrameProgress() {
  if (!isatty(fileno(stderr))) return {};
  return ProgressPrinter("frame", true, 0.2);
}

std::function<void(int, int)> FrameProgress(const std::string& label, double plain_every_s,
                                            const std::string& unit) {
  const bool terminal = isatty(fileno(stderr));
  return ProgressPrinter(label, terminal, terminal ? 0.2 : plain_every_s, unit);
}

void CheckFrameCommand(const std::vector<std::string>& inputs, int max_frames,
                       const std::string& out_path) {
  if (inputs.empty()) {
    throw std::invalid_argument("no input: give an image, a directory, a pattern or a video");
  }
  if (max_frames < 0) {
    throw std::invalid_argument("--max-frames = " + std::to_string(max_frames) +
                                ". Violated constraint: --max-frames >= 0");
  }
  if (!out_path.empty()) CheckOutputFile(out_path);
}

void Warn(const std::string& command, const std::string& message) {
  std::cerr << "oalservo " << command << ": warning: " << message << '\n';
}

namespace {

// The handler can reach only globals; all are lock-free atomics (async-signal-safe).
std::atomic<bool> g_stop_signal{false};
std::atomic<int> g_stop_signal_number{0};
std::atomic<void (*)()> g_stop_signal_also{nullptr};
static_assert(std::atomic<void (*)()>::is_always_lock_free, "the callback must be lock-free");
static_assert(std::atomic<int>::is_always_lock_free, "the signal number must be lock-free");

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void OnStopSignal(int signal_number) {
  int none = 0;
  g_stop_signal_number.compare_exchange_strong(none, signal_number);  // the first one wins
  g_stop_signal.store(true);
  if (void (*also)() = g_stop_signal_also.load()) also();
}

}  // namespace

StopSignalScope::StopSignalScope(void (*also)()) {
  static_assert(sizeof(kStopSignals) / sizeof(kStopSignals[0]) == kSignals);
  g_stop_signal.store(false);
  g_stop_signal_number.store(0);
  g_stop_signal_also.store(also);
  for (int i = 0; i < kSignals; ++i) previous_[i] = std::signal(kStopSignals[i], &OnStopSignal);
}

StopSignalScope::~StopSignalScope() {
  for (int i = 0; i < kSignals; ++i) std::signal(kStopSignals[i], previous_[i]);
  g_stop_signal_also.store(nullptr);
}

const std::atomic<bool>* StopSignalScope::interrupted() const {
  return &g_stop_signal;
}

int StopSignalScope::signal_number() const {
  return g_stop_signal_number.load();
}

std::string StopSignalName(int signal_number) {
  switch (signal_number) {
    case SIGINT:
      return "Ctrl-C (SIGINT)";
    case SIGTERM:
      return "SIGTERM (a request to terminate)";
    case SIGHUP:
      return "SIGHUP (the terminal or session was closed)";
    default:
      return "signal " + std::to_string(signal_number);
  }
}

}  // namespace oal
