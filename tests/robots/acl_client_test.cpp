// The ACL command layer: parsing (LISTPV, every error kind) and the command exchange against
// the Controller-A simulator on a real pty (echo, NOECHO, prompt, errors, silence, XON/XOFF,
// a closed link), against a fault-injecting link, and against a raw pty peer sending exact
// bytes (errors after a prompt or split across writes, late answers and the resynchronisation,
// the exclusive port).
#include "robots/acl_client.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <deque>
#include <thread>

#include "base/angles.h"
#include "scorbot_test_util.h"

namespace oal {
namespace {

using testing_scorbot::PtyPeer;
using testing_scorbot::SimLink;
using testing_scorbot::WaitFor;

// What the simulator prints for LISTPV POSITION at home, and with other values.
const char kListpvHome[] =
    "Position POSITION\r\n 1:0 2:0 3:0 4:0 5:0\r\n X:4165 Y:0 Z:2423 P:-900 R:0\r\n";
const char kListpvOther[] =
    "Position POSITION\r\n 1:7 2:0 3:0 4:0 5:0\r\n X:4160 Y:30 Z:2423 P:-900 R:0\r\n";
const char kImpact[] = "\r\n*** IMPACT PROTECTION axis 2\r\n";

// A client without echo on a port opened on `peer`.
struct PeerLink {
  explicit PeerLink(PtyPeer& peer, double reply_timeout_s = 1.0) {
    const IoResult r = port.Open(peer.DevicePath(), SerialPortOptions());
    EXPECT_TRUE(r.ok()) << r.message;
    AclClientOptions acl;
    acl.echo = false;
    acl.reply_timeout_s = reply_timeout_s;
    client = std::make_unique<AclClient>(port, acl);
  }
  SerialPort port;
  std::unique_ptr<AclClient> client;
};

int CountImpacts(const AclReply& reply) {
  int n = 0;
  for (const AclError& e : reply.errors) n += e.kind == AclErrorKind::kImpact && e.axis == 2;
  return n;
}

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

// A number that cannot be right is not wrapped into one that looks right (std::atoi read
// "4294967613" as 317 and "99999999999" as an axis): the line stays an error, marked
// malformed with the reason, and no axis or code is taken from it.
TEST(AclParse, NumbersOutOfRangeAreMalformedErrors) {
  const std::vector<AclError> e = ParseAclErrors(
      "4294967613 BAD CARTESIAN POINT\r\n"
      "*** IMPACT PROTECTION axis 99999999999\r\n"
      "*** OUT OF RANGE axis -7\r\n"
      "*** HOME FAILURE AXIS 9\r\n"
      "*** IMPACT PROTECTION axis 5\r\n");
  ASSERT_EQ(e.size(), 5u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(e[i].kind, AclErrorKind::kMalformed) << e[i].text;
    EXPECT_EQ(e[i].axis, 0) << e[i].text;
    EXPECT_EQ(e[i].code, 0) << e[i].text;
  }
  EXPECT_EQ(e[0].problem, "error number '4294967613' has more than 4 digits");
  EXPECT_EQ(e[1].problem, "axis '99999999999' is not 1..5");
  EXPECT_EQ(e[2].problem, "axis '-7' is not 1..5");
  EXPECT_EQ(e[3].problem, "axis '9' is not 1..5");
  EXPECT_EQ(e[4].kind, AclErrorKind::kImpact);
  EXPECT_EQ(e[4].axis, 5);
  EXPECT_TRUE(e[4].problem.empty());
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
  EXPECT_LT(base, 30 * kRadPerDeg - 1e-3);  // stopped on the way
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

// A controller that holds our output with XOFF and never releases it must not keep the stop
// from leaving: Ctrl-A overrides the held output, and the arm stops.
TEST(AclClient, AbortGoesOutThroughAHeldXoff) {
  SimLink link(testing_scorbot::FastSim(), /*xonxoff=*/true, 0.3);
  ASSERT_TRUE(link.client->Command("SPEED 5").ok());
  ASSERT_TRUE(link.client->Command("DEFP P1").ok());
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  ASSERT_TRUE(link.client->Command("SETPV P1 1 9000").ok());
  ASSERT_TRUE(link.client->Command("MOVE P1").ok());
  ASSERT_TRUE(link.sim.moving());
  link.sim.SendXoff();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the line discipline acts
  EXPECT_EQ(link.client->Command("SPEED 30").status, AclStatus::kTimeout);  // held
  const AclReply abort = link.client->Abort();
  EXPECT_TRUE(abort.ok()) << abort.message;
  EXPECT_FALSE(link.sim.moving());
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

TEST(AclClient, AbortStopsAMoveAndClearsTheBufferWithClrbuf) {
  SimLink link;
  ASSERT_TRUE(link.client->Command("SPEED 5").ok());
  ASSERT_TRUE(link.client->Command("DEFP P1").ok());
  ASSERT_TRUE(link.client->Command("HERE P1").ok());
  ASSERT_TRUE(link.client->Command("SETPV P1 1 9000").ok());
  ASSERT_TRUE(link.client->Command("MOVE P1").ok());
  ASSERT_TRUE(link.client->Command("MOVE P1").ok());  // queued behind
  ASSERT_TRUE(link.sim.moving());
  const long commands = link.sim.stats().commands;
  const AclReply abort = link.client->Abort();
  ASSERT_TRUE(abort.ok()) << abort.message;
  EXPECT_TRUE(abort.lines.empty());
  // Ctrl-A is not a command; CLRBUF is, and its answer (echo, prompt) ended the abort.
  EXPECT_EQ(link.sim.stats().commands, commands + 1);
  EXPECT_EQ(link.sim.last_command(), "CLRBUF");
  EXPECT_FALSE(link.sim.moving());
  const double at = link.sim.joints()[0];
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(link.sim.joints()[0], at);
  EXPECT_TRUE(link.client->Ping().ok());  // the exchange is still in step
}

TEST(AclClient, AbortWritesCtrlAThenClrbufAndWaitsForClrbufsPrompt) {
  PtyPeer peer;
  PeerLink link(peer);
  peer.Script(">");  // CLRBUF
  const AclReply abort = link.client->Abort();
  ASSERT_TRUE(abort.ok()) << abort.message;
  EXPECT_EQ(peer.received(),
            "\x01"
            "CLRBUF\r");
  // Unanswered, the abort is not confirmed.
  const AclReply silent = link.client->Abort();
  EXPECT_EQ(silent.status, AclStatus::kTimeout);
  EXPECT_NE(silent.message.find("no reply to 'CLRBUF'"), std::string::npos) << silent.message;
}

// A link that replays scripted input and records what was written.
class ScriptedLink final : public ByteLink {
 public:
  std::deque<std::string> replies;  // one per Write
  std::string written;
  bool chunked = false;  // ReadSome returns all pending bytes at once (else one byte)
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
    if (chunked) {
      *out += pending_;
      pending_.clear();
      return {};
    }
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

TEST(AclClient, ErrorRightAfterThePromptInTheSameReadFailsThatReply) {
  // A poll's LISTPV answered, and an impact printed right after the prompt, in one read.
  ScriptedLink link;
  link.chunked = true;
  link.replies.push_back(std::string(kListpvHome) + ">" + kImpact);
  link.replies.push_back(">");
  AclClientOptions options;
  options.echo = false;
  AclClient client(link, options);
  AclPositionValues v;
  const AclReply r = client.ListPosition("POSITION", &v);
  EXPECT_EQ(r.status, AclStatus::kControllerError);
  EXPECT_EQ(CountImpacts(r), 1);
  EXPECT_NE(r.message.find("*** IMPACT PROTECTION axis 2"), std::string::npos) << r.message;
  const AclReply next = client.Ping();  // reported once
  EXPECT_TRUE(next.ok()) << next.message;
}

TEST(AclClient, ErrorAfterThePromptOnAPtyIsReportedOnce) {
  // The same bytes in one write on a real pty: reported with the LISTPV or, if the read was
  // cut after the prompt, with the next command; never lost, never twice.
  PtyPeer peer;
  PeerLink link(peer);
  peer.Script(std::string(kListpvHome) + ">" + kImpact);
  peer.Script(">");
  AclPositionValues v;
  const AclReply listpv = link.client->ListPosition("POSITION", &v);
  const AclReply ping = link.client->Ping();
  EXPECT_EQ(CountImpacts(listpv) + CountImpacts(ping), 1)
      << listpv.message << " / " << ping.message;
  EXPECT_EQ(peer.received(), "LISTPV POSITION\r\r");
}

TEST(AclClient, ErrorLineSplitAcrossTwoWritesIsReported) {
  PtyPeer peer;
  PeerLink link(peer);
  peer.Script(std::string(kListpvHome) + ">\r\n*** IMP");
  AclPositionValues v;
  const AclReply listpv = link.client->ListPosition("POSITION", &v);
  ASSERT_TRUE(listpv.ok()) << listpv.message;  // the line is not complete yet
  EXPECT_EQ(v.counts, (ScorbotCounts{0, 0, 0, 0, 0}));
  peer.Write("ACT PROTECTION axis 2\r\n");
  peer.Script(">");
  const AclReply ping = link.client->Ping();
  EXPECT_EQ(ping.status, AclStatus::kControllerError);
  ASSERT_EQ(CountImpacts(ping), 1) << ping.message;
  EXPECT_EQ(ping.errors[0].text, "*** IMPACT PROTECTION axis 2");
  // The same with the second half arriving while the next command waits for its prompt.
  peer.Script(std::string(kListpvHome) + ">\r\n*** OUT OF RAN");
  ASSERT_TRUE(link.client->ListPosition("POSITION", &v).ok());
  peer.Script("GE axis 4\r\n>");
  const AclReply next = link.client->Ping();
  ASSERT_EQ(next.errors.size(), 1u) << next.message;
  EXPECT_EQ(next.errors[0].kind, AclErrorKind::kOutOfRange);
  EXPECT_EQ(next.errors[0].axis, 4);
}

TEST(AclClient, StrayByteAfterAPromptDoesNotHideTheNextPrompt) {
  // Line noise after a prompt is kept as an unterminated line; the next prompt, right after
  // it, still ends the next command.
  PtyPeer peer;
  PeerLink link(peer, 0.5);
  peer.Script(">~");
  ASSERT_TRUE(link.client->Ping().ok());
  peer.Script(">");
  const AclReply next = link.client->Ping();
  EXPECT_TRUE(next.ok()) << next.message;
  EXPECT_TRUE(link.client->in_sync());
}

TEST(AclClient, LateAnswerAfterATimeoutIsNotTakenForTheNextReply) {
  // Without echo: LISTPV is answered only after the host gave up; the host then aborts. The
  // late prompt must not end CLRBUF's wait, nor CLRBUF's prompt the next LISTPV's.
  PtyPeer peer;
  PeerLink link(peer, 0.2);
  peer.Script("");  // LISTPV POSITION: no answer in time
  AclPositionValues v;
  const AclReply late = link.client->ListPosition("POSITION", &v);
  ASSERT_EQ(late.status, AclStatus::kTimeout) << late.message;
  EXPECT_FALSE(link.client->in_sync());
  // What a controller without echo answers to the resynchronisation, the late answer first.
  peer.Script(std::string(kListpvHome) + ">" + ">");                    // NOECHO
  peer.Script(">");                                                     // ECHO
  peer.Script(std::string("LISTPV POSITION\r\n") + kListpvHome + ">");  // LISTPV, echoed
  peer.Script("NOECHO\r\n>");                                           // NOECHO, echoed
  peer.Script(">");                                                     // CLRBUF
  const AclReply abort = link.client->Abort();
  ASSERT_TRUE(abort.ok()) << abort.message;
  EXPECT_TRUE(abort.lines.empty()) << abort.text();  // not the late LISTPV's lines
  EXPECT_EQ(peer.received(),
            "LISTPV POSITION\r"
            "\x01"
            "NOECHO\rECHO\rLISTPV POSITION\rNOECHO\r"
            "CLRBUF\r");
  EXPECT_TRUE(link.client->in_sync());
  EXPECT_EQ(link.client->stats().resyncs, 1);
  peer.Script(std::string(kListpvOther) + ">");
  const AclReply now = link.client->ListPosition("POSITION", &v);
  ASSERT_TRUE(now.ok()) << now.message;
  EXPECT_EQ(v.counts, (ScorbotCounts{7, 0, 0, 0, 0}));
  EXPECT_EQ(v.cartesian.y, 30);
}

TEST(AclClient, UnansweredResynchronisationHoldsCommandsBackUntilItIsAnswered) {
  PtyPeer peer;
  PeerLink link(peer, 0.2);
  peer.Script("");  // SPEED 30: no answer
  ASSERT_EQ(link.client->Command("SPEED 30").status, AclStatus::kTimeout);
  for (int i = 0; i < 4; ++i) peer.Script("");  // the resynchronisation: no answer either
  const AclReply held = link.client->Command("SPEED 40");
  EXPECT_EQ(held.status, AclStatus::kTimeout);
  EXPECT_NE(held.message.find("'SPEED 40' not sent"), std::string::npos) << held.message;
  EXPECT_NE(held.message.find("resynchronisation"), std::string::npos) << held.message;
  // The controller wakes up and answers everything in order, with an impact on the way.
  peer.Write(std::string(">") + kImpact + ">>LISTPV POSITION\r\n" + kListpvHome + ">NOECHO\r\n>");
  peer.Script(">");  // SPEED 50
  const AclReply next = link.client->Command("SPEED 50");
  EXPECT_EQ(next.status, AclStatus::kControllerError) << next.message;
  EXPECT_EQ(CountImpacts(next), 1) << next.message;
  EXPECT_TRUE(link.client->in_sync());
  EXPECT_EQ(link.client->stats().resyncs, 1);  // one sequence: a second could not be told apart
  EXPECT_EQ(peer.received(),
            "SPEED 30\r"
            "NOECHO\rECHO\rLISTPV POSITION\rNOECHO\r"
            "SPEED 50\r");
  peer.Script(">");
  EXPECT_TRUE(link.client->Command("SPEED 60").ok());
}

TEST(AclClient, LateAnswerFromTheSimulatorWithAndWithoutEcho) {
  for (const bool echo : {true, false}) {
    SCOPED_TRACE(echo ? "echo" : "noecho");
    SimLink link(testing_scorbot::FastSim(), false, 0.2);
    ASSERT_TRUE(link.client->SetEcho(echo).ok());
    link.sim.InjectLateReply();
    AclPositionValues v;
    ASSERT_EQ(link.client->ListPosition("POSITION", &v).status, AclStatus::kTimeout);
    const AclReply speed = link.client->Command("SPEED 30");
    ASSERT_TRUE(speed.ok()) << speed.message;
    EXPECT_TRUE(speed.lines.empty()) << speed.text();
    EXPECT_EQ(link.sim.speed_percent(), 30);
    EXPECT_EQ(link.sim.echo(), echo);
    const AclReply now = link.client->ListPosition("POSITION", &v);
    ASSERT_TRUE(now.ok()) << now.message;
    EXPECT_EQ(v.name, "POSITION");
    EXPECT_EQ(link.client->stats().resyncs, 1);
  }
}

TEST(SerialPort, SecondOpenOfTheSameDeviceFailsSayingItIsInUse) {
  PtyPeer peer;
  SerialPort first;
  ASSERT_TRUE(first.Open(peer.DevicePath(), SerialPortOptions()).ok());
  SerialPort second;
  const IoResult r = second.Open(peer.DevicePath(), SerialPortOptions());
  EXPECT_EQ(r.status, IoStatus::kError);
  EXPECT_NE(r.message.find(peer.DevicePath()), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("in use by another program"), std::string::npos) << r.message;
  EXPECT_FALSE(second.is_open());
  // The tty is in exclusive mode (other programs' open() fails with EBUSY, root's does not).
  const int probe = ::open(peer.DevicePath().c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(probe, 0);
  int exclusive = 0;
  ASSERT_EQ(::ioctl(probe, TIOCGEXCL, &exclusive), 0);
  EXPECT_EQ(exclusive, 1);
  // Closing undoes both: the port can be opened again.
  first.Close();
  ASSERT_EQ(::ioctl(probe, TIOCGEXCL, &exclusive), 0);
  EXPECT_EQ(exclusive, 0);
  ::close(probe);
  const IoResult again = second.Open(peer.DevicePath(), SerialPortOptions());
  EXPECT_TRUE(again.ok()) << again.message;
}

}  // namespace
}  // namespace oal
