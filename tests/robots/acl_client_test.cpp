// The ACL command layer: parsing (LISTPV, every error kind) and the command exchange against
// the Controller-A simulator on a real pty (echo, NOECHO, prompt, errors, silence, XON/XOFF,
// a closed link), and against a fault-injecting link.
#include "robots/acl_client.h"

#include <gtest/gtest.h>

#include <deque>
#include <thread>

#include "scorbot_test_util.h"

namespace oal {
namespace {

using testing_scorbot::SimLink;
using testing_scorbot::WaitFor;

TEST(AclParse, ListpvInTheManualsFormat) {
  AclPositionValues v;
  std::string why;
  ASSERT_TRUE(ParseListpv(
      "Position P1\r\n1:0 2: 5 3: 13926 4:0 5:0\r\nX: 5197 Y:0 Z: 9963 P: 623 R:-3\r\n", &v, &why))
      << why;
  EXPECT_EQ(v.name, "P1");
  ASSERT_TRUE(v.has_counts);
  EXPECT_EQ(v.counts, (ScorbotCounts{0, 5, 13926, 0, 0}));
  ASSERT_TRUE(v.has_cartesian);
  EXPECT_EQ(v.cartesian, (AclPose{5197, 0, 9963, 623, -3}));
}

TEST(AclParse, ListpvWithoutValuesIsRejected) {
  AclPositionValues v;
  std::string why;
  EXPECT_FALSE(ParseListpv("Position P1\r\n1:0 2:5\r\n", &v, &why));
  EXPECT_NE(why.find("LISTPV"), std::string::npos);
}

TEST(AclParse, EveryErrorKind) {
  const std::vector<AclError> e = ParseAclErrors(
      "Position P\r\n"
      "*** IMPACT PROTECTION axis 2\r\n"
      "*** OUT OF RANGE axis 4\r\n"
      "*** HOME FAILURE AXIS 1\r\n"
      "CONTROL DISABLED\r\n"
      "317 BAD CARTESIAN POINT\r\n"
      "312 BAD POINT COORDINATE\r\n"
      "*** 200 SOMETHING ELSE\r\n"
      "*** INVALID COMMAND\r\n"
      "X:1 Y:2 Z:3 P:4 R:5\r\n");
  ASSERT_EQ(e.size(), 8u);
  EXPECT_EQ(e[0].kind, AclErrorKind::kImpact);
  EXPECT_EQ(e[0].axis, 2);
  EXPECT_EQ(e[1].kind, AclErrorKind::kOutOfRange);
  EXPECT_EQ(e[1].axis, 4);
  EXPECT_EQ(e[2].kind, AclErrorKind::kHomeFailure);
  EXPECT_EQ(e[2].axis, 1);
  EXPECT_EQ(e[3].kind, AclErrorKind::kControlDisabled);
  EXPECT_EQ(e[4].kind, AclErrorKind::kBadCartesian);
  EXPECT_EQ(e[4].code, 317);
  EXPECT_EQ(e[5].kind, AclErrorKind::kBadCoordinate);
  EXPECT_EQ(e[5].code, 312);
  EXPECT_EQ(e[6].kind, AclErrorKind::kNumbered);
  EXPECT_EQ(e[6].code, 200);
  EXPECT_EQ(e[7].kind, AclErrorKind::kOther);
  EXPECT_EQ(e[7].text, "*** INVALID COMMAND");
}

TEST(AclClient, EchoPromptAndReply) {
  SimLink link(testing_scorbot::FastSim(), false, 1.0, /*consume_banner=*/false);
  // Let the banner arrive (a prompt of its own): text before our echo is asynchronous output.
  ASSERT_TRUE(WaitFor([&] { return link.sim.stats().bytes_sent >= 16; }));
  const AclReply reply = link.client->Command("SHOW PAR 1");
  ASSERT_TRUE(reply.ok()) << reply.message;
  ASSERT_EQ(reply.lines.size(), 1u);
  EXPECT_EQ(reply.lines[0], "PAR 1 = 9600");
  // The power-up banner came before the first echo: kept as asynchronous output.
  EXPECT_NE(link.client->TakeAsyncText().find("SYSTEM READY!"), std::string::npos);
  AclPositionValues v;
  const AclReply pos = link.client->ListPosition("POSITION", &v);
  ASSERT_TRUE(pos.ok()) << pos.message;
  EXPECT_EQ(v.counts, (ScorbotCounts{0, 0, 0, 0, 0}));  // at home
  EXPECT_EQ(v.cartesian.p, -900);
  EXPECT_TRUE(link.client->Ping().ok());
}

TEST(AclClient, NoEchoAndBackAndTheBytesItSaves) {
  SimLink link;
  ASSERT_TRUE(link.client->Ping().ok());
  const auto before = link.port.counters().bytes_read;
  ASSERT_TRUE(link.client->Command("SPEED 40").ok());
  const auto with_echo = link.port.counters().bytes_read - before;
  ASSERT_TRUE(link.client->SetEcho(false).ok());
  EXPECT_FALSE(link.sim.echo());
  const auto before2 = link.port.counters().bytes_read;
  ASSERT_TRUE(link.client->Command("SPEED 50").ok());
  EXPECT_EQ(link.port.counters().bytes_read - before2, 1u);  // the prompt only
  EXPECT_EQ(with_echo, std::string("SPEED 40\r\n>").size());
  EXPECT_EQ(link.sim.speed_percent(), 50);
  AclPositionValues v;
  ASSERT_TRUE(link.client->ListPosition("POSITION", &v).ok());
  EXPECT_TRUE(v.has_counts);
  ASSERT_TRUE(link.client->SetEcho(true).ok());
  EXPECT_TRUE(link.sim.echo());
  EXPECT_TRUE(link.client->Command("SPEED 60").ok());
}

TEST(AclClient, ControllerErrorsBecomeTypedErrors) {
  SimLink link;
  ASSERT_TRUE(link.client->Command("DEFP P1").ok());
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  AclReply r = link.client->Command("SETPVC P1 Q 10");
  EXPECT_EQ(r.status, AclStatus::kControllerError);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kBadCoordinate);
  EXPECT_NE(r.message.find("312 BAD POINT COORDINATE"), std::string::npos) << r.message;
  // Unreachable Cartesian point.
  ASSERT_TRUE(link.client->Command("SETPVC P1 X 11000").ok());
  r = link.client->Command("MOVE P1");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kBadCartesian);
  // Reachable in space, but the base would turn past its range.
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  ASSERT_TRUE(link.client->Command("SETPV P1 1 20000").ok());  // +200 deg
  r = link.client->Command("MOVE P1");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kOutOfRange);
  EXPECT_EQ(r.errors[0].axis, 1);
  // Control off.
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  ASSERT_TRUE(link.client->Command("COFF").ok());
  r = link.client->Command("MOVE P1");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kControlDisabled);
  ASSERT_TRUE(link.client->Command("CON").ok());
  // Injected bad Cartesian point and home failure.
  link.sim.InjectBadCartesianPoint();
  r = link.client->Command("MOVE P1");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kBadCartesian);
  link.sim.InjectHomeFailure(3);
  r = link.client->Command("HOME", 5.0);
  ASSERT_EQ(r.errors.size(), 1u) << r.message;
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kHomeFailure);
  EXPECT_EQ(r.errors[0].axis, 3);
  r = link.client->Command("FROBNICATE");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kOther);
  EXPECT_TRUE(link.client->Command("HOME", 5.0).ok());
}

TEST(AclClient, ImpactDuringAMoveIsReportedWithTheNextCommand) {
  SimLink link;
  ASSERT_TRUE(link.client->Command("DEFP P1").ok());
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  ASSERT_TRUE(link.client->Command("SETPV P1 1 3000").ok());  // base +30 deg
  link.sim.InjectImpact(2);
  ASSERT_TRUE(link.client->Command("MOVE P1").ok());
  ASSERT_TRUE(WaitFor([&] { return !link.sim.moving(); }));
  EXPECT_FALSE(link.sim.control_enabled());
  const double base = link.sim.joints()[0];
  EXPECT_GT(base, 0.0);
  EXPECT_LT(base, 30 * 3.14159265358979323846 / 180 - 1e-3);  // stopped on the way
  AclPositionValues v;
  const AclReply r = link.client->ListPosition("POSITION", &v);
  ASSERT_EQ(r.status, AclStatus::kControllerError);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kImpact);
  EXPECT_EQ(r.errors[0].axis, 2);
  EXPECT_NE(r.message.find("IMPACT PROTECTION axis 2"), std::string::npos) << r.message;
  // Reported once.
  EXPECT_TRUE(link.client->ListPosition("POSITION", &v).ok());
}

TEST(AclClient, SilentControllerTimesOutAndRecovers) {
  SimLink link(testing_scorbot::FastSim(), false, 0.2);
  ASSERT_TRUE(link.client->Ping().ok());
  link.sim.SetSilent(true);
  const AclReply r = link.client->Command("SPEED 30");
  EXPECT_EQ(r.status, AclStatus::kTimeout);
  EXPECT_NE(r.message.find("no reply to 'SPEED 30'"), std::string::npos) << r.message;
  link.sim.SetSilent(false);
  EXPECT_TRUE(link.client->Command("SPEED 40").ok());
  EXPECT_EQ(link.sim.speed_percent(), 40);
}

TEST(AclClient, ClosedLinkIsALinkError) {
  SimLink link;
  ASSERT_TRUE(link.client->Ping().ok());
  link.sim.Stop();
  const AclReply r = link.client->Command("SPEED 30");
  EXPECT_EQ(r.status, AclStatus::kLinkError) << r.message;
  EXPECT_NE(r.message.find("closed"), std::string::npos) << r.message;
}

TEST(AclClient, XoffHoldsOurOutputUntilXon) {
  SimLink link(testing_scorbot::FastSim(), /*xonxoff=*/true, 0.3);
  ASSERT_TRUE(link.client->Ping().ok());
  link.sim.SendXoff();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the line discipline acts
  const auto received = link.sim.stats().bytes_received;
  // Our output is stopped: the command cannot leave the host and times out, saying why.
  const AclReply held = link.client->Command("SPEED 30");
  EXPECT_EQ(held.status, AclStatus::kTimeout) << held.message;
  EXPECT_NE(held.message.find("flow control"), std::string::npos) << held.message;
  EXPECT_EQ(link.sim.stats().bytes_received, received);  // nothing left the host
  EXPECT_EQ(link.sim.speed_percent(), 50);
  link.sim.SendXon();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const AclReply next = link.client->Command("SPEED 35");
  EXPECT_TRUE(next.ok()) << next.message;
  EXPECT_EQ(link.sim.speed_percent(), 35);
}

TEST(AclClient, FlowControlBytesAreIgnoredWhenFlowControlIsOff) {
  SimLink link;
  ASSERT_TRUE(link.client->Ping().ok());
  link.sim.SendXoff();
  link.sim.SendXon();
  const AclReply r = link.client->Command("SHOW PAR 2");
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.lines.size(), 1u);
  EXPECT_EQ(r.lines[0], "PAR 2 = 5");
}

TEST(AclClient, AbortStopsAMoveAndClearsTheBuffer) {
  SimLink link;
  ASSERT_TRUE(link.client->Command("SPEED 5").ok());
  ASSERT_TRUE(link.client->Command("DEFP P1").ok());
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  ASSERT_TRUE(link.client->Command("SETPV P1 1 9000").ok());
  ASSERT_TRUE(link.client->Command("MOVE P1").ok());
  ASSERT_TRUE(link.client->Command("MOVE P1").ok());  // queued behind
  ASSERT_TRUE(link.sim.moving());
  ASSERT_TRUE(link.client->Abort().ok());
  EXPECT_FALSE(link.sim.moving());
  const double at = link.sim.joints()[0];
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(link.sim.joints()[0], at);
}

// A link that replays scripted input and records what was written.
class ScriptedLink final : public ByteLink {
 public:
  std::deque<std::string> replies;  // one per Write
  std::string written;
  IoResult Write(const std::string& bytes, double /*timeout_s*/) override {
    written += bytes;
    if (!replies.empty()) {
      pending_ += replies.front();
      replies.pop_front();
    }
    return {};
  }
  IoResult ReadSome(std::string* out, double /*timeout_s*/) override {
    if (pending_.empty()) return {IoStatus::kTimeout, "scripted: nothing"};
    // One byte at a time: the parser must not depend on chunking.
    out->push_back(pending_[0]);
    pending_.erase(0, 1);
    return {};
  }
  std::string DrainInput() override { return {}; }
  LinkCounters counters() const override { return {}; }

 private:
  std::string pending_;
};

TEST(AclClient, ByteByByteRepliesWithFlowControlBytesAndAsyncText) {
  ScriptedLink link;
  link.replies.push_back(
      "\r\n*** IMPACT PROTECTION axis 3\r\nLISTPV POS\x13ITION\r\nPosition POSITION\r\n"
      " 1:1 2:2 3:3\x11 4:4 5:5\r\n X:1 Y:2 Z:3 P:4 R:5\r\n>");
  AclClient client(link, AclClientOptions());
  AclPositionValues v;
  const AclReply r = client.ListPosition("POSITION", &v);
  EXPECT_EQ(link.written, "LISTPV POSITION\r");
  EXPECT_EQ(r.status, AclStatus::kControllerError);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, AclErrorKind::kImpact);
  EXPECT_EQ(r.lines.size(), 3u);
  AclPositionValues parsed;
  ASSERT_TRUE(ParseListpv(r.text(), &parsed, nullptr));
  EXPECT_EQ(parsed.counts, (ScorbotCounts{1, 2, 3, 4, 5}));
}

}  // namespace
}  // namespace oal
