#include "robots/acl_client.h"

#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>

#include "base/check.h"

namespace oal {
namespace {

constexpr char kXon = 0x11;
constexpr char kXoff = 0x13;
constexpr char kCtrlA = 0x01;
// An unterminated line longer than this is taken as a line.
constexpr std::size_t kMaxPartialLine = 512;
// Output without a prompt longer than this fails the command (not a Controller-A?).
constexpr std::size_t kMaxReply = 65536;
// While waiting for the resynchronisation: stale output beyond this is dropped, keeping the
// last kResyncKeep bytes (where its output may have begun).
constexpr std::size_t kMaxResyncBuffer = 16384;
constexpr std::size_t kResyncKeep = 1024;
constexpr std::size_t kMaxAsyncText = 4096;
constexpr std::size_t kMaxErrors = 16;
// A read-only command; its echo after two bare prompts marks the resynchronisation's output.
constexpr char kResyncMarker[] = "LISTPV POSITION";
constexpr char kResyncWhat[] = "NOECHO, ECHO, LISTPV POSITION";

std::string Trim(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string StripFlowControl(std::string s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    if (c != kXon && c != kXoff) out.push_back(c);
  }
  return out;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    line = Trim(line);
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// The number of 1 to `max_digits` digits at s[i..] (no sign) and where it ends; nothing when
// there is no digit there or the run is longer (a number std::atoi would wrap).
std::optional<int> BoundedNumber(const std::string& s, std::size_t i, std::size_t max_digits,
                                 std::size_t* end = nullptr) {
  std::size_t j = i;
  int value = 0;
  while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) {
    if (j - i == max_digits) return std::nullopt;
    value = 10 * value + (s[j] - '0');
    ++j;
  }
  if (j == i) return std::nullopt;
  if (end != nullptr) *end = j;
  return value;
}

// The axis after "AXIS" in an upper-cased line: 0 when the line names none; when it names
// one that is not 1..5 (signed, too long, out of range), nothing, and *problem says why.
std::optional<int> AxisOf(const std::string& upper, std::string* problem) {
  const std::size_t at = upper.find("AXIS");
  if (at == std::string::npos) return 0;
  std::size_t i = at + 4;
  while (i < upper.size() && (upper[i] == ' ' || upper[i] == ':')) ++i;
  if (i == upper.size()) return 0;
  const std::optional<int> axis = BoundedNumber(upper, i, 1);
  if (axis && *axis >= 1 && *axis <= 5) return axis;
  std::size_t end = i;
  while (end < upper.size() && upper[end] != ' ') ++end;
  *problem = "axis '" + upper.substr(i, std::min<std::size_t>(end - i, 24)) + "' is not 1..5";
  return std::nullopt;
}

// Position of the first '>' that starts a line in s[from..], npos if none.
std::size_t FindPrompt(const std::string& s, std::size_t from) {
  for (std::size_t i = from; i < s.size(); ++i) {
    if (s[i] == '>' && (i == from || s[i - 1] == '\n' || s[i - 1] == '\r')) return i;
  }
  return std::string::npos;
}

// Moves the complete lines of `*pending` (up to its last CR or LF) and the prompts that start
// the rest to `*async`; the rest, an unterminated line, stays (unless it is too long).
void SplitOffCompleteLines(std::string* pending, std::string* async) {
  const std::size_t last = pending->find_last_of("\r\n");
  std::size_t keep_from = last == std::string::npos ? 0 : last + 1;
  while (keep_from < pending->size() && (*pending)[keep_from] == '>') ++keep_from;
  if (pending->size() - keep_from > kMaxPartialLine) keep_from = pending->size();
  async->append(*pending, 0, keep_from);
  pending->erase(0, keep_from);
}

// The end (after the last prompt) of the resynchronisation's output in `s`: two prompts with
// only CR/LF between and after them, the echo of the marker, its reply and prompt and, when
// `noecho`, the echo of NOECHO and its prompt. npos while not (yet) all there.
std::size_t FindResyncEnd(const std::string& s, bool noecho) {
  const std::string echo = std::string(kResyncMarker) + "\r\n";
  for (std::size_t at = s.find(echo); at != std::string::npos; at = s.find(echo, at + 1)) {
    std::size_t i = at;
    int prompts = 0;
    while (i > 0 && prompts < 2) {
      const char c = s[i - 1];
      if (c == '>') {
        ++prompts;
      } else if (c != '\r' && c != '\n') {
        break;
      }
      --i;
    }
    if (prompts < 2) continue;
    std::size_t end = FindPrompt(s, at + echo.size());
    if (end == std::string::npos) return end;
    ++end;
    if (noecho) {
      const std::string noecho_echo = "NOECHO\r\n";
      const std::size_t n = s.find(noecho_echo, end);
      if (n == std::string::npos) return n;
      end = FindPrompt(s, n + noecho_echo.size());
      if (end == std::string::npos) return end;
      ++end;
    }
    return end;
  }
  return std::string::npos;
}

AclStatus StatusOf(const IoResult& r) {
  return r.status == IoStatus::kTimeout ? AclStatus::kTimeout : AclStatus::kLinkError;
}

// Reads a signed integer after `key` (e.g. "X:", "3:") in `s`; spaces allowed after the colon.
bool ValueAfter(const std::string& s, std::size_t at, long* value) {
  std::size_t i = at;
  while (i < s.size() && s[i] == ' ') ++i;
  if (i >= s.size()) return false;
  const char* begin = s.c_str() + i;
  char* end = nullptr;
  const long v = std::strtol(begin, &end, 10);
  if (end == begin) return false;
  *value = v;
  return true;
}

}  // namespace

std::string ToString(AclErrorKind kind) {
  switch (kind) {
    case AclErrorKind::kImpact:
      return "impact";
    case AclErrorKind::kOutOfRange:
      return "out-of-range";
    case AclErrorKind::kHomeFailure:
      return "home-failure";
    case AclErrorKind::kControlDisabled:
      return "control-disabled";
    case AclErrorKind::kBadCartesian:
      return "bad-cartesian-point";
    case AclErrorKind::kBadCoordinate:
      return "bad-point-coordinate";
    case AclErrorKind::kNumbered:
      return "numbered";
    case AclErrorKind::kOther:
      return "other";
    case AclErrorKind::kMalformed:
      return "malformed";
  }
  return "unknown";
}

std::string ToString(AclStatus status) {
  switch (status) {
    case AclStatus::kOk:
      return "ok";
    case AclStatus::kControllerError:
      return "controller-error";
    case AclStatus::kTimeout:
      return "timeout";
    case AclStatus::kLinkError:
      return "link-error";
  }
  return "unknown";
}

std::vector<AclError> ParseAclErrors(const std::string& text) {
  std::vector<AclError> errors;
  for (const std::string& raw : Lines(StripFlowControl(text))) {
    std::string line = raw;
    while (!line.empty() && line[0] == '>') line.erase(0, 1);  // a prompt before the message
    line = Trim(line);
    const std::string shown = line;
    bool starred = false;
    while (!line.empty() && line[0] == '*') {
      starred = true;
      line.erase(0, 1);
    }
    line = Trim(line);
    const std::string up = Upper(line);
    AclError e;
    e.text = shown;
    // A numbered error: digits, a space, then an upper-case word.
    std::size_t digits = 0;
    while (digits < up.size() && std::isdigit(static_cast<unsigned char>(up[digits]))) ++digits;
    const bool numbered = digits > 0 && digits < up.size() && up[digits] == ' ' &&
                          digits + 1 < up.size() &&
                          std::isupper(static_cast<unsigned char>(up[digits + 1]));
    std::optional<int> axis = 0;
    if (up.find("IMPACT PROTECTION") != std::string::npos) {
      e.kind = AclErrorKind::kImpact;
      axis = AxisOf(up, &e.problem);
    } else if (up.find("OUT OF RANGE") != std::string::npos) {
      e.kind = AclErrorKind::kOutOfRange;
      axis = AxisOf(up, &e.problem);
    } else if (up.find("HOME FAILURE") != std::string::npos) {
      e.kind = AclErrorKind::kHomeFailure;
      axis = AxisOf(up, &e.problem);
    } else if (up.find("CONTROL DISABLED") != std::string::npos) {
      e.kind = AclErrorKind::kControlDisabled;
    } else if (numbered) {
      // ACL's error codes have three digits; a longer run is noise on the line.
      const std::optional<int> code = BoundedNumber(up, 0, 4);
      if (code) {
        e.code = *code;
        e.kind = e.code == 317   ? AclErrorKind::kBadCartesian
                 : e.code == 312 ? AclErrorKind::kBadCoordinate
                                 : AclErrorKind::kNumbered;
      } else {
        e.problem = "error number '" + up.substr(0, std::min<std::size_t>(digits, 24)) +
                    "' has more than 4 digits";
      }
    } else if (starred) {
      e.kind = AclErrorKind::kOther;
    } else {
      continue;
    }
    if (axis) {
      e.axis = *axis;
    }
    if (!e.problem.empty()) e.kind = AclErrorKind::kMalformed;
    errors.push_back(e);
  }
  return errors;
}

bool ParseListpv(const std::string& text, AclPositionValues* out, std::string* why) {
  AclPositionValues v;
  bool have[5] = {false, false, false, false, false};
  bool have_c[5] = {false, false, false, false, false};
  long* cart[5] = {&v.cartesian.x, &v.cartesian.y, &v.cartesian.z, &v.cartesian.p, &v.cartesian.r};
  const char* keys = "XYZPR";
  for (const std::string& line : Lines(StripFlowControl(text))) {
    const std::string up = Upper(line);
    if (up.rfind("POSITION", 0) == 0) {
      v.name = Trim(line.substr(8));
      continue;
    }
    for (std::size_t i = 0; i + 1 < up.size(); ++i) {
      if (up[i + 1] != ':') continue;
      const bool token_start = i == 0 || up[i - 1] == ' ' || up[i - 1] == '\t';
      if (!token_start) continue;
      const char c = up[i];
      if (c >= '1' && c <= '5') {
        long value = 0;
        if (ValueAfter(up, i + 2, &value)) {
          v.counts[c - '1'] = value;
          have[c - '1'] = true;
        }
      } else if (const char* k = std::strchr(keys, c); k != nullptr && c != '\0') {
        long value = 0;
        if (ValueAfter(up, i + 2, &value)) {
          *cart[k - keys] = value;
          have_c[k - keys] = true;
        }
      }
    }
  }
  v.has_counts = have[0] && have[1] && have[2] && have[3] && have[4];
  v.has_cartesian = have_c[0] && have_c[1] && have_c[2] && have_c[3] && have_c[4];
  if (!v.has_counts && !v.has_cartesian) {
    if (why) *why = "LISTPV reply without the counts of axes 1-5 or X Y Z P R: '" + text + "'";
    return false;
  }
  *out = v;
  return true;
}

std::string AclReply::text() const {
  std::string s;
  for (const std::string& line : lines) {
    if (!s.empty()) s += '\n';
    s += line;
  }
  return s;
}

void AclClientOptions::Check() const {
  RequireOption(reply_timeout_s > 0 && reply_timeout_s <= 600, "AclClientOptions::reply_timeout_s",
                reply_timeout_s, "0 < value <= 600");
}

AclClient::AclClient(ByteLink& link, const AclClientOptions& options)
    : link_(link), options_(options) {
  options_.Check();
}

AclReply AclClient::Finish(AclReply reply, const std::string& async, const std::string& body) {
  if (!async.empty()) {
    async_text_ += async;
    if (async_text_.size() > kMaxAsyncText)
      async_text_.erase(0, async_text_.size() - kMaxAsyncText);
  }
  std::vector<AclError> errors = ParseAclErrors(async);
  for (const AclError& e : ParseAclErrors(body)) errors.push_back(e);
  if (errors.size() > kMaxErrors) errors.resize(kMaxErrors);
  reply.lines = Lines(StripFlowControl(body));
  reply.errors = std::move(errors);
  if (reply.errors.empty()) return reply;
  auto described = [](const AclError& e) {
    return e.problem.empty() ? e.text : e.text + " (malformed: " + e.problem + ")";
  };
  std::string texts = described(reply.errors.front());
  for (std::size_t i = 1; i < reply.errors.size(); ++i) texts += "; " + described(reply.errors[i]);
  if (reply.status == AclStatus::kOk) {
    reply.status = AclStatus::kControllerError;
    reply.message = "controller: " + texts;
  } else {
    reply.message += " (the controller printed: " + texts + ")";
  }
  return reply;
}

bool AclClient::Resynchronise(const std::string& command, std::string* async, AclReply* reply) {
  if (sync_ == Sync::kInSync) return true;
  const double timeout = options_.reply_timeout_s;
  if (sync_ == Sync::kNeeded) {
    pending_ += StripFlowControl(link_.DrainInput());
    resync_noecho_ = !options_.echo;
    std::string sequence = std::string("NOECHO\rECHO\r") + kResyncMarker + "\r";
    if (resync_noecho_) sequence += "NOECHO\r";
    if (IoResult w = link_.Write(sequence, timeout); !w.ok()) {
      reply->status = StatusOf(w);
      reply->message = "'" + command + "' not sent: resynchronising after a timeout (" +
                       kResyncWhat + "): " + w.message;
      return false;
    }
    sync_ = Sync::kSent;
    ++resyncs_;
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(static_cast<long long>(timeout * 1e6));
  for (;;) {
    pending_ = StripFlowControl(pending_);
    const std::size_t end = FindResyncEnd(pending_, resync_noecho_);
    if (end != std::string::npos) {
      // All before answered earlier commands, or is the resynchronisation's own output.
      async->append(pending_, pending_scanned_, end - pending_scanned_);
      pending_.erase(0, end);
      pending_scanned_ = 0;
      SplitOffCompleteLines(&pending_, async);
      sync_ = Sync::kInSync;
      return true;
    }
    if (pending_.size() > kMaxResyncBuffer) {
      const std::size_t cut = pending_.size() - kResyncKeep;
      if (cut > pending_scanned_) async->append(pending_, pending_scanned_, cut - pending_scanned_);
      pending_.erase(0, cut);
      pending_scanned_ = pending_scanned_ > cut ? pending_scanned_ - cut : 0;
    }
    const double left_s =
        std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    const IoResult r =
        left_s > 0 ? link_.ReadSome(&pending_, left_s) : IoResult{IoStatus::kTimeout, "timeout"};
    if (r.ok()) continue;
    // Report the error lines received so far; keep the text (the answer may have begun).
    const std::size_t last = pending_.find_last_of("\r\n");
    if (last != std::string::npos && last + 1 > pending_scanned_) {
      async->append(pending_, pending_scanned_, last + 1 - pending_scanned_);
      pending_scanned_ = last + 1;
    }
    reply->status = StatusOf(r);
    std::ostringstream s;
    s << "'" << command << "' not sent: out of step with the controller since an earlier "
      << "timeout, and ";
    if (r.status == IoStatus::kTimeout) {
      s << "no answer to the resynchronisation (" << kResyncWhat << ") within " << timeout
        << " s (controller silent or busy? if it lost our input, connect again)";
    } else {
      s << "waiting for the resynchronisation: " << r.message;
    }
    reply->message = s.str();
    return false;
  }
}

AclReply AclClient::Command(const std::string& command, double timeout_s) {
  ++commands_;
  const double timeout = timeout_s > 0 ? timeout_s : options_.reply_timeout_s;
  AclReply reply;
  std::string async;
  if (!Resynchronise(command, &async, &reply)) return Finish(reply, async, "");
  // What arrived since the last reply is asynchronous; an unterminated line stays pending and
  // is completed by what follows.
  pending_ += StripFlowControl(link_.DrainInput());
  SplitOffCompleteLines(&pending_, &async);
  if (IoResult w = link_.Write(command + "\r", timeout); !w.ok()) {
    sync_ = Sync::kNeeded;  // part of the command may have left
    reply.status = StatusOf(w);
    reply.message = "sending '" + command + "': " + w.message;
    return Finish(reply, async, "");
  }
  const std::string echo = command + "\r\n";
  std::string in = std::move(pending_);
  pending_.clear();
  // Where what answers this command begins: a line start even after an unterminated line kept
  // from before (a stray byte must not hide the prompt that follows it).
  const std::size_t fresh_from = in.size();
  std::size_t body_from = 0;
  bool echo_seen = !options_.echo;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(static_cast<long long>(timeout * 1e6));
  for (;;) {
    in = StripFlowControl(in);
    if (!echo_seen) {
      const std::size_t at = in.find(echo);
      if (at != std::string::npos) {
        async += in.substr(0, at);
        body_from = at + echo.size();
        echo_seen = true;
      }
    }
    if (echo_seen) {
      std::size_t prompt = FindPrompt(in, body_from);
      if (fresh_from > body_from && fresh_from < prompt && in.size() > fresh_from &&
          in[fresh_from] == '>') {
        prompt = fresh_from;
      }
      if (prompt != std::string::npos) {
        const std::string body = in.substr(body_from, prompt - body_from);
        // What came with the prompt: complete lines (an error printed right after it) are
        // reported now, an unterminated line with the next command.
        pending_ = in.substr(prompt + 1);
        SplitOffCompleteLines(&pending_, &async);
        return Finish(reply, async, body);
      }
    }
    const double left_s =
        std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    IoResult r = left_s > 0 ? link_.ReadSome(&in, left_s) : IoResult{IoStatus::kTimeout, "timeout"};
    if (r.ok() && in.size() > kMaxReply) {
      r = {IoStatus::kError, "more than " + std::to_string(kMaxReply) +
                                 " bytes without a prompt (is this a Controller-A at the "
                                 "right baud rate?)"};
    }
    if (!r.ok()) {
      sync_ = Sync::kNeeded;  // a late answer must not be taken for the next command's
      std::ostringstream s;
      if (r.status == IoStatus::kTimeout) {
        reply.status = AclStatus::kTimeout;
        s << "no reply to '" << command << "' within " << timeout << " s ("
          << (echo_seen ? "no prompt" : "no echo") << "; controller silent?)";
      } else {
        reply.status = AclStatus::kLinkError;
        s << "'" << command << "': " << r.message;
      }
      reply.message = s.str();
      return Finish(reply, async, echo_seen ? in.substr(body_from) : in);
    }
  }
}

AclReply AclClient::Ping() {
  return Command("");
}

AclReply AclClient::Abort() {
  // Ctrl-A first, on its own: the controller acts on it as it arrives. Urgent: a controller
  // that holds our output with XOFF longer than a reply takes is faulty, and the stop must go.
  if (IoResult w = link_.WriteUrgent(std::string(1, kCtrlA), options_.reply_timeout_s); !w.ok()) {
    AclReply reply;
    reply.status = StatusOf(w);
    reply.message = "sending Ctrl-A: " + w.message;
    return reply;
  }
  return Command("CLRBUF");
}

AclReply AclClient::SetEcho(bool on) {
  // The command itself is echoed or not depending on the state before it, which may be
  // unknown (at Connect): read it as if without echo (the prompt at a line start ends the
  // reply; an echo would only add a reply line).
  const bool before = options_.echo;
  options_.echo = false;
  AclReply reply = Command(on ? "ECHO" : "NOECHO");
  if (reply.status == AclStatus::kOk || reply.status == AclStatus::kControllerError) {
    options_.echo = on;
  } else {
    options_.echo = before;
  }
  return reply;
}

AclReply AclClient::ListPosition(const std::string& position, AclPositionValues* values) {
  AclReply reply = Command("LISTPV " + position);
  if (!reply.ok()) return reply;
  std::string why;
  if (!ParseListpv(reply.text(), values, &why)) {
    reply.status = AclStatus::kControllerError;
    reply.message = why;
  }
  return reply;
}

std::string AclClient::TakeAsyncText() {
  std::string s = std::move(async_text_);
  async_text_.clear();
  return s;
}

AclStats AclClient::stats() const {
  AclStats s;
  s.commands = commands_;
  s.resyncs = resyncs_;
  s.link = link_.counters();
  return s;
}

}  // namespace oal
