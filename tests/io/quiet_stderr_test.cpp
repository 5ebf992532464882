#include "io/quiet_stderr.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <visp3/core/vpDebug.h>

#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <thread>

#include "base/format.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// What the process writes on descriptor 2 while `write` runs, through std::cerr and C's stderr.
std::string CapturedStderr(const std::string& path, const std::function<void()>& write) {
  std::cerr.flush();
  std::fflush(stderr);
  const int saved = ::dup(2);
  const int file = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  EXPECT_GE(saved, 0);
  EXPECT_GE(file, 0);
  ::dup2(file, 2);
  ::close(file);
  write();
  std::cerr.flush();
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  return test::ReadText(path);
}

TEST(QuietStderr, SilencesItsOwnThreadOnly) {
  const test::TestDir dir;
  const std::string written = CapturedStderr(dir / "stderr.txt", [] {
    {
      const QuietStderr quiet;
      {
        const QuietStderr nested;  // as a comparison inside an evaluation would
        std::cerr << "quiet cerr\n";
      }
      std::fprintf(stderr, "quiet stdio\n");
      vpERROR_TRACE("quiet visp");  // vpMeLine's way: std::cerr and C's stderr
      // Another thread (another evaluate job) meanwhile: heard.
      std::thread other([] {
        std::cerr << "other cerr\n";
        std::fprintf(stderr, "other stdio\n");
      });
      other.join();
    }
    std::cerr << "after cerr\n";
    std::fprintf(stderr, "after stdio\n");
  });
  EXPECT_THAT(written, Not(HasSubstr("quiet")));
  EXPECT_THAT(written, HasSubstr("other cerr\nother stdio\n"));
  EXPECT_THAT(written, HasSubstr("after cerr\nafter stdio\n"));
}

TEST(MarkupEscaped, EscapesTheFiveCharacters) {
  EXPECT_EQ(MarkupEscaped("a<b>&\"c\"'d'"), "a&lt;b&gt;&amp;&quot;c&quot;&apos;d&apos;");
  EXPECT_EQ(MarkupEscaped("plain é"), "plain é");
}

}  // namespace
}  // namespace oal
