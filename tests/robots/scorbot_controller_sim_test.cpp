// The Controller-A simulator byte by byte on a real pty: banner, echo, prompt, LISTPV format,
// queued moves executed over simulated time, HOME, the symlink, stop and restart.
#include "robots/scorbot_controller_sim.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <visp3/core/vpMath.h>

#include <stdexcept>

#include "scorbot_test_util.h"

namespace oal {
namespace {

using testing_scorbot::FastSim;
using testing_scorbot::SimLink;
using testing_scorbot::WaitFor;

// Reads until `terminator` appears; returns what was read.
std::string ReadTo(SerialPort& port, const std::string& terminator, double timeout_s = 2.0) {
  std::string in;
  const IoResult r = port.ReadUntil(&in, terminator, timeout_s);
  EXPECT_TRUE(r.ok()) << r.message << " (read so far: '" << in << "')";
  return in;
}

TEST(ScorbotControllerSim, BannerEchoPromptAndListpvFormat) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  SerialPort port;
  ASSERT_TRUE(port.Open(sim.DevicePath(), SerialPortOptions()).ok());
  EXPECT_EQ(ReadTo(port, ">"), "SYSTEM READY!\r\n>");
  ASSERT_TRUE(port.Write("listpv position\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, ">"),
            "listpv position\r\n"
            "Position POSITION\r\n"
            " 1:0 2:0 3:0 4:0 5:0\r\n"
            " X:4165 Y:0 Z:2423 P:-900 R:0\r\n"
            ">");
  ASSERT_TRUE(port.Write("\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, ">"), "\r\n>");
  ASSERT_TRUE(port.Write("NOECHO\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, ">"), "NOECHO\r\n>");
  ASSERT_TRUE(port.Write("SPEED\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, ">"), "SPEED 50\r\n>");
  const ScorbotSimStats stats = sim.stats();
  EXPECT_EQ(stats.commands, 4);
  EXPECT_EQ(stats.bytes_received, port.counters().bytes_written);
  EXPECT_EQ(stats.bytes_sent, port.counters().bytes_read);
}

TEST(ScorbotControllerSim, MovesAreQueuedAndExecutedInOrder) {
  SimLink link;
  AclClient& acl = *link.client;
  ASSERT_TRUE(acl.Command("SPEED 100").ok());
  ASSERT_TRUE(acl.Command("DEFP A1").ok());
  ASSERT_TRUE(acl.Command("DEFP A2").ok());
  ASSERT_TRUE(acl.Command("HERE A1").ok());
  ASSERT_TRUE(acl.Command("HERE A2").ok());
  ASSERT_TRUE(acl.Command("SETPV A1 1 1000").ok());   // base +10 deg
  ASSERT_TRUE(acl.Command("SETPV A2 1 -1000").ok());  // base -10 deg
  ASSERT_TRUE(acl.Command("MOVE A1").ok());
  ASSERT_TRUE(acl.Command("MOVE A2 50").ok());  // 0.5 s
  EXPECT_TRUE(link.sim.moving());
  ASSERT_TRUE(WaitFor([&] { return !link.sim.moving(); }));
  EXPECT_NEAR(link.sim.joints()[0], vpMath::rad(-10), 1e-12);
  EXPECT_EQ(link.sim.stats().moves_completed, 2);
  AclPositionValues v;
  ASSERT_TRUE(acl.ListPosition("POSITION", &v).ok());
  EXPECT_EQ(v.counts[0], -1000);
  // A Cartesian point: SETPVC on a recorded point, then MOVE; LISTPV of it gives both.
  ASSERT_TRUE(acl.Command("HERE A1").ok());
  ASSERT_TRUE(acl.Command("SETPVC A1 Z 2000").ok());
  ASSERT_TRUE(acl.ListPosition("A1", &v).ok());
  EXPECT_TRUE(v.has_counts);
  EXPECT_EQ(v.cartesian.z, 2000);
  ASSERT_TRUE(acl.Command("MOVE A1").ok());
  ASSERT_TRUE(WaitFor([&] { return !link.sim.moving(); }));
  ASSERT_TRUE(acl.ListPosition("POSITION", &v).ok());
  EXPECT_NEAR(static_cast<double>(v.cartesian.z), 2000, 1);
}

TEST(ScorbotControllerSim, HomeGoesToEncoderZero) {
  ScorbotSimOptions o = FastSim();
  o.start_deg = {20, 40, -60, -30, 45};
  SimLink link(o);
  const AclReply r = link.client->Command("HOME", 10.0);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.lines.size(), 1u);
  EXPECT_EQ(r.lines[0], "Homing complete(ROBOT)");
  AclPositionValues v;
  ASSERT_TRUE(link.client->ListPosition("POSITION", &v).ok());
  EXPECT_EQ(v.counts, (ScorbotCounts{0, 0, 0, 0, 0}));
}

TEST(ScorbotControllerSim, SymlinkFollowsARestart) {
  ScorbotSimOptions o = FastSim();
  o.link_path =
      testing_scorbot::TestTmpDir() + "/scorbot-sim-test-link-" + std::to_string(::getpid());
  ::unlink(o.link_path.c_str());
  ScorbotControllerSim sim(o);
  sim.Start();
  EXPECT_EQ(sim.ConnectPath(), o.link_path);
  char target[256] = {0};
  ASSERT_GT(::readlink(o.link_path.c_str(), target, sizeof target - 1), 0);
  EXPECT_EQ(std::string(target), sim.DevicePath());
  sim.Stop();
  EXPECT_FALSE(sim.running());
  EXPECT_NE(::access(o.link_path.c_str(), F_OK), 0);  // removed
  sim.Start();
  SerialPort port;
  ASSERT_TRUE(port.Open(o.link_path, SerialPortOptions()).ok());
  AclClient client(port, AclClientOptions());
  EXPECT_TRUE(client.Ping().ok());
  sim.Stop();
  sim.Stop();  // idempotent
}

TEST(ScorbotControllerSim, OptionsCheckNamesTheField) {
  ScorbotSimOptions o;
  o.time_scale = 0;
  try {
    ScorbotControllerSim sim(o);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ScorbotSimOptions::time_scale = 0"), std::string::npos)
        << e.what();
  }
}

TEST(ScorbotControllerSim, ThrottledLinkCarriesTheSameBytes) {
  ScorbotSimOptions o = FastSim();
  o.throttle_to_baud = true;
  o.baud = 115200;  // keep the test fast; the pacing code is the same at 9600
  SimLink link(o);
  AclPositionValues v;
  const AclReply r = link.client->ListPosition("POSITION", &v);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(v.cartesian.p, -900);
}

TEST(ScorbotControllerSim, ImpactAfterThePromptComesInTheSameOutput) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  SerialPort port;
  ASSERT_TRUE(port.Open(sim.DevicePath(), SerialPortOptions()).ok());
  ReadTo(port, ">");
  for (const char* command : {"SPEED 2", "DEFP P1", "HERE P1", "SETPV P1 1 3000", "MOVE P1"}) {
    ASSERT_TRUE(port.Write(std::string(command) + "\r", 1.0).ok());
    ReadTo(port, ">");
  }
  ASSERT_TRUE(sim.moving());
  sim.InjectImpactAfterNextPrompt(4);
  ASSERT_TRUE(port.Write("SPEED\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, "axis 4\r\n"),
            "SPEED\r\nSPEED 2\r\n>\r\n*** IMPACT PROTECTION axis 4\r\n");
  EXPECT_FALSE(sim.moving());
  EXPECT_FALSE(sim.control_enabled());
  EXPECT_EQ(sim.last_command(), "SPEED");
}

TEST(ScorbotControllerSim, LateReplyGoesOutWhenTheNextLineArrives) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  SerialPort port;
  ASSERT_TRUE(port.Open(sim.DevicePath(), SerialPortOptions()).ok());
  ReadTo(port, ">");
  ASSERT_TRUE(port.Write("NOECHO\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, ">"), "NOECHO\r\n>");
  sim.InjectLateReply();
  const long commands = sim.stats().commands;
  const auto sent = sim.stats().bytes_sent;
  ASSERT_TRUE(port.Write("SPEED\r", 1.0).ok());
  ASSERT_TRUE(WaitFor([&] { return sim.stats().commands == commands + 1; }));
  EXPECT_EQ(sim.stats().bytes_sent, sent);  // executed, answer held back
  ASSERT_TRUE(port.Write("SPEED 30\r", 1.0).ok());
  EXPECT_EQ(ReadTo(port, ">>"), "SPEED 50\r\n>>");  // the late answer, then SPEED 30's prompt
  EXPECT_EQ(sim.speed_percent(), 30);
}

TEST(ScorbotControllerSim, ACutReplyLosesItsSecondHalfAndThePrompt) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  SerialPort port;
  ASSERT_TRUE(port.Open(sim.DevicePath(), SerialPortOptions()).ok());
  ReadTo(port, ">");
  sim.InjectCutReply();
  ASSERT_TRUE(port.Write("LISTPV POSITION\r", 1.0).ok());
  std::string in;
  EXPECT_EQ(port.ReadUntil(&in, ">", 0.3).status, IoStatus::kTimeout);
  // The echo, then half of "Position POSITION\r\n 1:0 2:0 ...\r\n X:... R:0\r\n>".
  EXPECT_EQ(in.rfind("LISTPV POSITION\r\nPosition POSITION\r\n", 0), 0u) << in;
  EXPECT_EQ(in.find(" X:"), std::string::npos) << in;
  ASSERT_TRUE(port.Write("SPEED\r", 1.0).ok());  // the next command is answered in full
  EXPECT_EQ(ReadTo(port, ">"), "SPEED\r\nSPEED 50\r\n>");
}

TEST(ScorbotControllerSim, NoiseGoesOutAmidTheOutputAndImpactNowStopsTheMove) {
  ScorbotSimOptions options = FastSim();
  options.log_input = true;
  ScorbotControllerSim sim(options);
  sim.Start();
  SerialPort port;
  ASSERT_TRUE(port.Open(sim.DevicePath(), SerialPortOptions()).ok());
  ReadTo(port, ">");
  sim.InjectNoise("#~");
  EXPECT_EQ(ReadTo(port, "#~"), "#~");
  for (const char* command : {"SPEED 2", "DEFP P1", "HERE P1", "SETPV P1 1 3000", "MOVE P1"}) {
    ASSERT_TRUE(port.Write(std::string(command) + "\r", 1.0).ok());
    ReadTo(port, ">");
  }
  ASSERT_TRUE(sim.moving());
  sim.InjectImpactNow(2);
  EXPECT_EQ(ReadTo(port, "axis 2\r\n"), "\r\n*** IMPACT PROTECTION axis 2\r\n");
  EXPECT_FALSE(sim.moving());
  EXPECT_FALSE(sim.control_enabled());
  ASSERT_TRUE(port.Write(std::string(1, 0x01), 1.0).ok());
  ASSERT_TRUE(WaitFor([&] { return sim.heard().size() == 6; }));
  const std::vector<HeardLine> heard = sim.heard();
  EXPECT_EQ(heard[0].text, "SPEED 2");
  EXPECT_EQ(heard[4].text, "MOVE P1");
  EXPECT_EQ(heard[5].text, "^A");
  EXPECT_LE(heard[4].at, heard[5].at);
}

}  // namespace
}  // namespace oal
