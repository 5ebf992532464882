#include "io/quiet_stderr.h"

#include <cstdio>
#include <iostream>
#include <mutex>
#include <new>
#include <streambuf>

namespace oal {

namespace {

thread_local int quiet_depth = 0;  // QuietStderr objects alive on this thread

// std::cerr's buffer once installed: the original one, but for what a quiet thread writes.
class QuietableBuffer : public std::streambuf {
 public:
  explicit QuietableBuffer(std::streambuf* target) : target_(target) {}

 protected:
  int_type overflow(int_type c) override {
    if (quiet_depth > 0 || traits_type::eq_int_type(c, traits_type::eof())) {
      return traits_type::not_eof(c);
    }
    return target_->sputc(traits_type::to_char_type(c));
  }
  std::streamsize xsputn(const char* text, std::streamsize n) override {
    return quiet_depth > 0 ? n : target_->sputn(text, n);
  }
  int sync() override { return target_->pubsync(); }

 private:
  std::streambuf* target_;
};

// C's stderr once installed: writes go to the original stream, but for a quiet thread's.
ssize_t QuietableWrite(void* original, const char* data, size_t size) {
  if (quiet_depth > 0) return static_cast<ssize_t>(size);
  FILE* stream = static_cast<FILE*>(original);
  const size_t written = std::fwrite(data, 1, size, stream);
  std::fflush(stream);
  return written == 0 && size > 0 ? -1 : static_cast<ssize_t>(written);
}

}  // namespace

void InstallQuietableStderr() {
  static std::once_flag once;
  std::call_once(once, [] {
    std::cerr.flush();
    std::fflush(stderr);
    // Never destroyed: std::cerr may be written to until the very end of the process.
    alignas(QuietableBuffer) static unsigned char storage[sizeof(QuietableBuffer)];
    std::cerr.rdbuf(::new (storage) QuietableBuffer(std::cerr.rdbuf()));
    cookie_io_functions_t io{};
    io.write = QuietableWrite;
    FILE* quietable = ::fopencookie(stderr, "w", io);
    if (quietable == nullptr) return;  // stderr stays as it is: nothing is dropped
    std::setvbuf(quietable, nullptr, _IONBF, 0);
    stderr = quietable;
  });
}

QuietStderr::QuietStderr() {
  InstallQuietableStderr();
  ++quiet_depth;
}

QuietStderr::~QuietStderr() {
  --quiet_depth;
}

}  // namespace oal
