// Other libraries' messages on stderr, silenced for one thread while it calls them.
#pragma once

namespace oal {

/// While one lives, what its own thread writes to std::cerr and to C's stderr is dropped;
/// other threads' messages still reach the user. For ViSP's vpMeLine, which reports every
/// tracking failure on stderr itself (vpERROR_TRACE, through both std::cerr and stderr): a
/// comparison counts those failures instead. They nest. The first one installs, for the rest
/// of the process, a filter in front of std::cerr's buffer and C's stderr (glibc lets a
/// program set `stderr`); main() installs it at start-up, before any thread
/// (InstallQuietableStderr), so that no thread reads `stderr` while it is set.
void InstallQuietableStderr();
class QuietStderr {
 public:
  QuietStderr();
  ~QuietStderr();
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;
};

}  // namespace oal
