#include "robots/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "base/check.h"

namespace oal {
namespace {

using Clock = std::chrono::steady_clock;

speed_t BaudConstant(int baud) {
  switch (baud) {
    case 1200:
      return B1200;
    case 2400:
      return B2400;
    case 4800:
      return B4800;
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    default:
      return B0;
  }
}

std::string Errno(const std::string& what) {
  return what + ": " + std::strerror(errno);
}

int RemainingMs(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return static_cast<int>(std::max<long long>(0, left.count()));
}

Clock::time_point Deadline(double timeout_s) {
  return Clock::now() + std::chrono::microseconds(static_cast<long long>(timeout_s * 1e6));
}

}  // namespace

std::string ToString(IoStatus status) {
  switch (status) {
    case IoStatus::kOk:
      return "ok";
    case IoStatus::kTimeout:
      return "timeout";
    case IoStatus::kClosed:
      return "closed";
    case IoStatus::kError:
      return "error";
  }
  return "unknown";
}

IoResult ByteLink::ReadUntil(std::string* buffer, const std::string& terminator, double timeout_s,
                             std::size_t from) {
  const Clock::time_point deadline = Deadline(timeout_s);
  while (buffer->find(terminator, from) == std::string::npos) {
    const double left_s = std::chrono::duration<double>(deadline - Clock::now()).count();
    if (left_s <= 0) return {IoStatus::kTimeout, "no '" + terminator + "' within the timeout"};
    if (IoResult r = ReadSome(buffer, left_s); !r.ok()) return r;
  }
  return {};
}

void SerialPortOptions::Check() const {
  RequireOption(BaudConstant(baud) != B0, "SerialPortOptions::baud", baud,
                "one of 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200");
}

SerialPort::~SerialPort() {
  Close();
}

void SerialPort::Close() noexcept {
  if (fd_ >= 0) {
    // The exclusive flag belongs to the tty, which outlives our descriptor when another one is
    // open (the simulator keeps its pty slave open): clear it, or we could not open it again.
    ::ioctl(fd_, TIOCNXCL);
    ::close(fd_);  // releases the lock
  }
  fd_ = -1;
}

IoResult SerialPort::Open(const std::string& path, const SerialPortOptions& options) {
  options.Check();
  Close();
  path_ = path;
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == EBUSY) {
      return {IoStatus::kError,
              Errno("cannot open " + path) + " (another program has it open exclusively)"};
    }
    return {IoStatus::kError, Errno("cannot open " + path)};
  }
  // One program at a time talks to the controller: an advisory lock (also among root
  // processes, and within one process), then the tty's exclusive mode (TIOCEXCL: further
  // open()s fail with EBUSY, except for root).
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const IoResult r{IoStatus::kError,
                     errno == EWOULDBLOCK
                         ? "cannot open " + path +
                               ": in use by another program (or another port in this one): "
                               "it holds the lock on the device; close it first"
                         : Errno("cannot lock " + path)};
    ::close(fd);
    return r;
  }
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) {
    const IoResult r{IoStatus::kError, Errno(path + " is not a serial port (tcgetattr)")};
    ::close(fd);
    return r;
  }
  if (::ioctl(fd, TIOCEXCL) != 0) {
    const IoResult r{IoStatus::kError, Errno("cannot open " + path + " exclusively (TIOCEXCL)")};
    ::close(fd);
    return r;
  }
  ::cfmakeraw(&tio);  // 8 data bits, no parity, no echo, no line editing
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
  tio.c_cflag |= CLOCAL | CREAD | CS8;
  if (options.xonxoff) {
    tio.c_iflag |= IXON | IXOFF;
  } else {
    tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  }
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  const speed_t speed = BaudConstant(options.baud);
  if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0 ||
      ::tcsetattr(fd, TCSANOW, &tio) != 0) {
    const IoResult r{IoStatus::kError, Errno("cannot configure " + path)};
    ::ioctl(fd, TIOCNXCL);
    ::close(fd);
    return r;
  }
  fd_ = fd;
  return {};
}

IoResult SerialPort::WriteUrgent(const std::string& bytes, double timeout_s) {
  termios tio{};
  const bool ixon = fd_ >= 0 && ::tcgetattr(fd_, &tio) == 0 && (tio.c_iflag & IXON) != 0;
  if (!ixon) return Write(bytes, timeout_s);
  // Clearing IXON restarts output that an XOFF stopped (TCOON only undoes TCOOFF); flow
  // control is back on once the bytes are out.
  termios without = tio;
  without.c_iflag &= ~static_cast<tcflag_t>(IXON);
  ::tcsetattr(fd_, TCSANOW, &without);
  const IoResult result = Write(bytes, timeout_s);
  ::tcsetattr(fd_, TCSANOW, &tio);
  return result;
}

IoResult SerialPort::Write(const std::string& bytes, double timeout_s) {
  if (fd_ < 0) return {IoStatus::kError, "port not open"};
  const Clock::time_point deadline = Deadline(timeout_s);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      counters_.bytes_written += static_cast<std::uint64_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EIO) return {IoStatus::kClosed, "the link to " + path_ + " is closed"};
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
      return {IoStatus::kError, Errno("write to " + path_)};
    }
    pollfd p{fd_, POLLOUT, 0};
    const int ms = RemainingMs(deadline);
    if (ms <= 0) {
      return {IoStatus::kTimeout, "write to " + path_ + " blocked (flow control?): " +
                                      std::to_string(bytes.size() - done) + " bytes not sent"};
    }
    if (::poll(&p, 1, ms) < 0 && errno != EINTR) return {IoStatus::kError, Errno("poll")};
  }
  return {};
}

IoResult SerialPort::ReadSome(std::string* out, double timeout_s) {
  if (fd_ < 0) return {IoStatus::kError, "port not open"};
  const Clock::time_point deadline = Deadline(timeout_s);
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, RemainingMs(deadline));
    if (ready < 0) {
      if (errno == EINTR) continue;
      return {IoStatus::kError, Errno("poll")};
    }
    if (ready == 0) return {IoStatus::kTimeout, "nothing received within the timeout"};
    char chunk[512];
    const ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n > 0) {
      out->append(chunk, static_cast<std::size_t>(n));
      counters_.bytes_read += static_cast<std::uint64_t>(n);
      return {};
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n == 0 || errno == EIO || (p.revents & POLLHUP)) {
      return {IoStatus::kClosed, "the link to " + path_ + " is closed"};
    }
    return {IoStatus::kError, Errno("read from " + path_)};
  }
}

std::string SerialPort::DrainInput() {
  std::string stale;
  if (fd_ < 0) return stale;
  char chunk[512];
  for (;;) {
    const ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n <= 0) break;
    stale.append(chunk, static_cast<std::size_t>(n));
    counters_.bytes_read += static_cast<std::uint64_t>(n);
  }
  return stale;
}

}  // namespace oal
