// What the Scorbot tests share: a Controller-A simulator on a real pty, started by the test,
// and a serial port opened on it.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
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
