// What the Scorbot tests share: a Controller-A simulator on a real pty, started by the test,
// and a serial port opened on it; a raw pty peer that answers with exact bytes.
#pragma once

#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "robots/acl_client.h"
#include "robots/scorbot_controller_sim.h"
#include "robots/serial_port.h"

namespace oal {
namespace testing_scorbot {

/// Simulated time runs this much faster than the wall clock in the tests.
constexpr double kTimeScale = 25.0;

inline ScorbotSimOptions FastSim() {
  ScorbotSimOptions o;
  o.time_scale = kTimeScale;
  return o;
}

/// A started simulator and a port + ACL client on it.
struct SimLink {
  /// With `consume_banner`, reads "SYSTEM READY!" and its prompt first, so that no late banner
  /// can answer a test's first command.
  explicit SimLink(const ScorbotSimOptions& options = FastSim(), bool xonxoff = false,
                   double reply_timeout_s = 1.0, bool consume_banner = true)
      : sim(options) {
    sim.Start();
    SerialPortOptions serial;
    serial.xonxoff = xonxoff;
    const IoResult r = port.Open(sim.DevicePath(), serial);
    EXPECT_TRUE(r.ok()) << r.message;
    if (consume_banner) {
      std::string banner;
      const IoResult b = port.ReadUntil(&banner, "SYSTEM READY!\r\n>", 5.0);
      EXPECT_TRUE(b.ok()) << b.message;
    }
    AclClientOptions acl;
    acl.reply_timeout_s = reply_timeout_s;
    client = std::make_unique<AclClient>(port, acl);
  }
  ScorbotControllerSim sim;
  SerialPort port;
  std::unique_ptr<AclClient> client;
};

/// A raw pseudo-terminal peer: the test plays the controller with exact bytes. The host opens
/// DevicePath(); every CR the host sends takes the next scripted answer (none left: silence)
/// and writes it with one write(). Write() sends bytes at once; received() is all the host sent.
class PtyPeer {
 public:
  PtyPeer() {
    char name[256] = {0};
    if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) {
      throw std::runtime_error(std::string("PtyPeer: openpty: ") + std::strerror(errno));
    }
    termios tio{};
    ::tcgetattr(slave_, &tio);
    ::cfmakeraw(&tio);
    ::tcsetattr(slave_, TCSANOW, &tio);
    path_ = name;
    thread_ = std::thread([this] { Run(); });
  }
  ~PtyPeer() {
    stop_.store(true);
    thread_.join();
    ::close(master_);
    ::close(slave_);
  }
  PtyPeer(const PtyPeer&) = delete;
  PtyPeer& operator=(const PtyPeer&) = delete;

  const std::string& DevicePath() const { return path_; }
  /// The answer to the next CR not yet answered ("" answers nothing).
  void Script(const std::string& answer) {
    std::lock_guard<std::mutex> lock(mutex_);
    answers_.push_back(answer);
  }
  void Write(const std::string& bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    WriteAll(bytes);
  }
  std::string received() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return received_;
  }

 private:
  void WriteAll(const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
  }
  void Run() {
    while (!stop_.load()) {
      pollfd p{master_, POLLIN, 0};
      if (::poll(&p, 1, 5) <= 0) continue;
      char buf[256];
      const ssize_t n = ::read(master_, buf, sizeof buf);
      if (n <= 0) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      for (ssize_t i = 0; i < n; ++i) {
        received_.push_back(buf[i]);
        if (buf[i] == '\r' && !answers_.empty()) {
          WriteAll(answers_.front());
          answers_.pop_front();
        }
      }
    }
  }

  int master_ = -1;
  int slave_ = -1;  // kept open: the master never sees a hang-up
  std::string path_;
  mutable std::mutex mutex_;
  std::deque<std::string> answers_;
  std::string received_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// Polls `done` every millisecond for at most `timeout_s` wall seconds.
template <typename F>
bool WaitFor(F done, double timeout_s = 5.0) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long>(timeout_s * 1000));
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return done();
}

/// A directory for test files (OAL_TEST_TMP from ctest, else /tmp), created if missing.
inline std::string TestTmpDir() {
  const char* dir = std::getenv("OAL_TEST_TMP");
  const std::string path = dir ? dir : "/tmp";
  std::filesystem::create_directories(path);
  return path;
}

}  // namespace testing_scorbot
}  // namespace oal
