// The serial transport of the Scorbot driver: a byte link with timeouts.
//
// ByteLink is the small interface the ACL command layer depends on (shared/STYLE.md: "the
// serial driver depends on a small transport interface"), so tests can run the command layer
// against a fault-injecting link as well as against the simulator on a real pseudo-terminal.
// SerialPort is the POSIX implementation: an RAII file descriptor opened non-blocking and
// exclusively (flock + TIOCEXCL: one program at a time talks to the controller), termios
// raw 8N1 at a configurable baud rate, optional XON/XOFF flow control (IXON | IXOFF: the kernel
// pauses our output on XOFF from the controller and resumes on XON), writes and reads with
// timeouts through poll(2), and byte counters for the link budget.
// I/O failures are values (IoResult), never exceptions: a Robot must report them as
// RobotResult. Not thread-safe.
#pragma once

#include <cstdint>
#include <string>

namespace oal {

enum class IoStatus {
  kOk,
  kTimeout,  ///< nothing (or not enough) within the time allowed
  kClosed,   ///< the other end hung up (pty master closed, cable unplugged with DCD...)
  kError,    ///< a system call failed; message says which and why
};

/// "ok", "timeout", "closed", "error".
std::string ToString(IoStatus status);

struct IoResult {
  IoStatus status = IoStatus::kOk;
  std::string message;  ///< when not ok: one line
  bool ok() const { return status == IoStatus::kOk; }
};

/// Bytes that went over a link.
struct LinkCounters {
  std::uint64_t bytes_written = 0;
  std::uint64_t bytes_read = 0;
};

class ByteLink {
 public:
  virtual ~ByteLink() = default;
  /// Writes all of `bytes` within `timeout_s` seconds.
  virtual IoResult Write(const std::string& bytes, double timeout_s) = 0;
  /// Writes `bytes` even while the other end holds our output with XOFF: an emergency stop
  /// must not wait for an XON that a faulty controller may never send. Default: Write().
  virtual IoResult WriteUrgent(const std::string& bytes, double timeout_s) {
    return Write(bytes, timeout_s);
  }
  /// Waits up to `timeout_s` for at least one byte, then appends whatever is available to
  /// `*out` without waiting further.
  virtual IoResult ReadSome(std::string* out, double timeout_s) = 0;
  /// Discards (returns) the bytes already received and not yet read; never waits.
  virtual std::string DrainInput() = 0;
  virtual LinkCounters counters() const = 0;

  /// Reads into `*buffer` until `buffer->find(terminator, from) != npos` or `timeout_s` passes.
  IoResult ReadUntil(std::string* buffer, const std::string& terminator, double timeout_s,
                     std::size_t from = 0);
};

struct SerialPortOptions {
  /// Baud rate: one of 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200. ACL: 9600.
  int baud = 9600;
  /// Software flow control (XON/XOFF) in both directions. The ACL manual specifies it; many
  /// labs run without it.
  bool xonxoff = false;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

class SerialPort final : public ByteLink {
 public:
  SerialPort() = default;
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Opens `path` (a tty or a pty slave) exclusively and configures it. Closes a port already
  /// open. Exclusive: an advisory lock (flock; a second Open() of the same device, in this or
  /// another process, fails saying it is in use) and the tty's exclusive mode (TIOCEXCL: other
  /// programs' open() fails with EBUSY unless they run as root); Close() undoes both.
  /// Throws std::invalid_argument on bad options; I/O failures come back as the result.
  IoResult Open(const std::string& path, const SerialPortOptions& options);
  void Close() noexcept;
  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }

  IoResult Write(const std::string& bytes, double timeout_s) override;
  /// Writes with IXON off, which resumes output an XOFF held (then restores it).
  IoResult WriteUrgent(const std::string& bytes, double timeout_s) override;
  IoResult ReadSome(std::string* out, double timeout_s) override;
  std::string DrainInput() override;
  LinkCounters counters() const override { return counters_; }

 private:
  int fd_ = -1;
  std::string path_;
  LinkCounters counters_;
};

}  // namespace oal
