// The ACL command layer of the Scorbot driver: one command at a time over a ByteLink.
//
// A command is sent as its text plus CR. The controller echoes what it receives (unless NOECHO),
// runs the command, prints its reply lines and prompts with '>' at the start of a line.
// Command():
//   1. after a timeout, first resynchronises (below);
//   2. takes the bytes that arrived since the last reply (asynchronous messages such as
//      "*** IMPACT PROTECTION axis 2" printed during a move): their complete lines are
//      asynchronous output, an unterminated line is kept and completed by what follows;
//   3. writes the command and CR;
//   4. reads until the prompt: with echo on, the prompt must come after the echo of the command
//      (text before the echo is asynchronous output); with echo off, the first '>' at the start
//      of a line;
//   5. keeps what came after the prompt in the same read: its complete lines are asynchronous
//      output reported with this reply, an unterminated line waits for the next command;
//   6. strips XON/XOFF bytes (0x11, 0x13: they reach us when flow control is off), splits the
//      reply into lines and parses every error line into an AclError.
// An error anywhere in the asynchronous or reply text makes the reply a controller error, so an
// error line is reported once, with the reply it arrived with or, if it was cut by a read
// boundary, with the next one. Buffers are bounded (an unterminated line: 512 bytes; output
// without a prompt: 64 KiB, then a link error).
//
// Resynchronisation. After a command timed out (or its write failed) the controller may still
// answer it later: with echo off, its late prompt would end the next command's reply. So the
// next Command() first sends "NOECHO CR ECHO CR LISTPV POSITION CR" (plus "NOECHO CR" when echo
// is off) and reads until the output of exactly that sequence: two prompts (NOECHO's and
// ECHO's, CR/LF between allowed), the echo of "LISTPV POSITION", its reply and prompt (then the
// echo of NOECHO and its prompt). Earlier commands produce no such pattern (their echo, if any,
// is not preceded by two bare prompts), and the controller runs its input in order, so
// everything before it answered earlier commands: it is dropped (its error lines are
// reported). Only then is the command sent. If the sequence is not answered within
// reply_timeout_s, the command is not sent (kTimeout) and the next Command() waits for the same
// sequence again: no second one is sent, since its output could not be told from the first's.
// A controller that lost the sequence (bytes lost on the line) therefore stays out of step
// until a new client (ScorbotRobot::Connect()).
// Abort() is Ctrl-A (0x01, stops all motion immediately, sent even when out of step and even
// while the controller holds our output with XOFF) followed by CLRBUF (clears the movement
// buffer). Not thread-safe.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "robots/scorbot_kinematics.h"
#include "robots/serial_port.h"

namespace oal {

/// The controller errors the driver tells apart.
enum class AclErrorKind {
  kImpact,           ///< "*** IMPACT PROTECTION axis n": the axis group is disabled until CON
  kOutOfRange,       ///< "*** OUT OF RANGE axis n"
  kHomeFailure,      ///< "*** HOME FAILURE AXIS n"
  kControlDisabled,  ///< "CONTROL DISABLED": motors off (COFF, or after an impact)
  kBadCartesian,     ///< "317 BAD CARTESIAN POINT"
  kBadCoordinate,    ///< "312 BAD POINT COORDINATE"
  kNumbered,         ///< another numbered error "NNN TEXT"
  kOther,            ///< any other "*** TEXT" line
  kMalformed,        ///< an error line whose number cannot be right (an axis not 1..5, a code
                     ///< beyond 4 digits): the link is garbled, and the line still an error
};

/// "impact", "out-of-range", "home-failure", "control-disabled", "bad-cartesian-point",
/// "bad-point-coordinate", "numbered", "other", "malformed".
std::string ToString(AclErrorKind kind);

struct AclError {
  AclErrorKind kind = AclErrorKind::kOther;
  int axis = 0;         ///< 1..5 when the message names an axis, else 0
  int code = 0;         ///< the number of a numbered error, else 0
  std::string text;     ///< the controller's line, trimmed
  std::string problem;  ///< kMalformed: what is wrong with the line; else empty
};

/// The error lines of `text` (any line starting, after any prompt '>', with "***",
/// "CONTROL DISABLED", or a number followed by an upper-case word). Other lines are ignored.
std::vector<AclError> ParseAclErrors(const std::string& text);

/// What LISTPV prints for a position: joint encoder counts and, when it has them, the Cartesian
/// coordinates.
struct AclPositionValues {
  std::string name;  ///< from "Position NAME" (empty if the line is missing)
  ScorbotCounts counts{};
  bool has_counts = false;
  AclPose cartesian;
  bool has_cartesian = false;
};

/// Parses a LISTPV reply ("Position P1" / "1:0 2: 5 3: 13926 4:0 5:0" /
/// "X: 5197 Y:0 Z: 9963 P: 623 R:-3"; spaces after the colons optional). Returns false with
/// `why` when neither the counts of axes 1..5 nor X Y Z P R are all present.
bool ParseListpv(const std::string& text, AclPositionValues* out, std::string* why);

enum class AclStatus {
  kOk,
  kControllerError,  ///< the controller printed an error (errors[] says which)
  kTimeout,          ///< no prompt within the timeout (controller silent or busy)
  kLinkError,        ///< the link failed or closed
};

/// "ok", "controller-error", "timeout", "link-error".
std::string ToString(AclStatus status);

struct AclReply {
  AclStatus status = AclStatus::kOk;
  std::vector<std::string> lines;  ///< the reply lines (no echo, no prompt), trimmed, non-empty
  std::vector<AclError> errors;    ///< errors in the reply and in asynchronous output before it
  std::string message;             ///< when not ok: one line for the user
  bool ok() const { return status == AclStatus::kOk; }
  /// The reply lines joined with '\n'.
  std::string text() const;
};

struct AclClientOptions {
  /// Longest wait for a reply (echo + prompt), s; > 0.
  double reply_timeout_s = 2.0;
  /// Whether the controller echoes our input (ACL's default; NOECHO turns it off).
  bool echo = true;

  void Check() const;
};

/// Counts over the life of a client.
struct AclStats {
  long commands = 0;
  long resyncs = 0;   ///< resynchronisation sequences sent after timeouts
  LinkCounters link;  ///< bytes over the link (from the ByteLink)
};

class AclClient {
 public:
  /// `link` must outlive the client. Throws std::invalid_argument on bad options.
  AclClient(ByteLink& link, const AclClientOptions& options);

  /// Sends `command` (without CR) and reads the reply; `timeout_s` > 0 overrides the reply
  /// timeout (HOME takes long).
  AclReply Command(const std::string& command, double timeout_s = 0);
  /// An empty line: the controller answers with a prompt. Checks that it is alive.
  AclReply Ping();
  /// Ctrl-A (abort all motion), then CLRBUF.
  AclReply Abort();
  /// Sends ECHO / NOECHO and remembers the state.
  AclReply SetEcho(bool on);
  bool echo() const { return options_.echo; }
  /// LISTPV `position` ("POSITION" for the current one), parsed.
  AclReply ListPosition(const std::string& position, AclPositionValues* values);

  /// Asynchronous output seen so far (its last 4096 bytes), and clears it.
  std::string TakeAsyncText();
  /// False after a timeout until the resynchronisation has been answered.
  bool in_sync() const { return sync_ == Sync::kInSync; }
  AclStats stats() const;

 private:
  enum class Sync { kInSync, kNeeded, kSent };
  AclReply Finish(AclReply reply, const std::string& async, const std::string& body);
  // Brings the exchange back in step after a timeout; false (with `*reply` set) if it could not.
  bool Resynchronise(const std::string& command, std::string* async, AclReply* reply);

  ByteLink& link_;
  AclClientOptions options_;
  // Bytes received after the last prompt not yet consumed: an unterminated line while in step,
  // everything since the resynchronisation was sent while waiting for it.
  std::string pending_;
  std::size_t pending_scanned_ = 0;  // bytes of pending_ already handed over as asynchronous text
  std::string async_text_;
  Sync sync_ = Sync::kInSync;
  bool resync_noecho_ = false;  // the resynchronisation sent ends with NOECHO
  long commands_ = 0;
  long resyncs_ = 0;
};

}  // namespace oal
