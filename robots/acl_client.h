// The ACL command layer of the Scorbot driver (issue 6): one command at a time over a ByteLink.
//
// A command is sent as its text plus CR. The controller echoes what it receives (unless NOECHO),
// runs the command, prints its reply lines and prompts with '>' at the start of a line.
// Command():
//   1. drains bytes that arrived since the last command (asynchronous messages such as
//      "*** IMPACT PROTECTION axis 2" printed during a move) and keeps them;
//   2. writes the command and CR;
//   3. reads until the prompt: with echo on, the prompt must come after the echo of the command
//      (text before the echo is asynchronous output, parsed for errors like the reply); with
//      echo off, the first '>' at the start of a line;
//   4. strips XON/XOFF bytes (0x11, 0x13: they reach us when flow control is off), splits the
//      reply into lines and parses every error line into an AclError.
// An error anywhere in the drained, skipped or reply text makes the reply a controller error.
// Abort() is Ctrl-A (0x01, stops all motion immediately) followed by CLRBUF (clears the
// movement buffer). Not thread-safe.
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
};

/// "impact", "out-of-range", "home-failure", "control-disabled", "bad-cartesian-point",
/// "bad-point-coordinate", "numbered", "other".
std::string ToString(AclErrorKind kind);

struct AclError {
  AclErrorKind kind = AclErrorKind::kOther;
  int axis = 0;      ///< 1..5 when the message names an axis, else 0
  int code = 0;      ///< the number of a numbered error, else 0
  std::string text;  ///< the controller's line, trimmed
};

/// The error lines of `text` (any line starting with "***", "CONTROL DISABLED", or a number
/// followed by an upper-case word). Other lines are ignored.
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

  /// Asynchronous output seen so far (drained before commands or skipped before an echo),
  /// and clears it.
  std::string TakeAsyncText();
  AclStats stats() const;

 private:
  AclReply Finish(AclReply reply, const std::string& async, const std::string& body);

  ByteLink& link_;
  AclClientOptions options_;
  std::string async_text_;
  long commands_ = 0;
};

}  // namespace oal
