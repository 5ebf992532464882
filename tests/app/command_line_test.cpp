// The command line's own parts shared by the commands: the interrupt they stop on.
#include "app/command_line.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <csignal>

namespace oal {
namespace {

std::atomic<int> g_sigint_callbacks{0};

TEST(CommandLine, StopSignalScopeSetsItsFlagCallsBackAndRestoresTheHandler) {
  const auto previous = std::signal(SIGINT, SIG_IGN);
  {
    const StopSignalScope sigint([] { g_sigint_callbacks.fetch_add(1); });
    EXPECT_FALSE(sigint.interrupted()->load());
    std::raise(SIGINT);  // handled: the test process goes on
    EXPECT_TRUE(sigint.interrupted()->load());
    EXPECT_EQ(g_sigint_callbacks.load(), 1);
  }
  EXPECT_EQ(std::signal(SIGINT, previous), SIG_IGN);  // the scope put SIG_IGN back
  const StopSignalScope again;                        // a new scope starts clear
  EXPECT_FALSE(again.interrupted()->load());
}

}  // namespace
}  // namespace oal
