#include "robots/scorbot_robot.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "base/angles.h"
#include "base/check.h"
#include "base/format.h"

namespace oal {
namespace {

long AngleDiffTenths(long a, long b) {
  long d = (a - b) % 3600;
  if (d > 1800) d -= 3600;
  if (d < -1800) d += 3600;
  return std::labs(d);
}

std::string FormatPose(const AclPose& p) {
  std::ostringstream s;
  s << "X " << p.x << " Y " << p.y << " Z " << p.z << " P " << p.p << " R " << p.r;
  return s.str();
}

RobotStatus StatusOf(AclErrorKind kind) {
  switch (kind) {
    case AclErrorKind::kOutOfRange:
      return RobotStatus::kLimit;
    case AclErrorKind::kBadCartesian:
    case AclErrorKind::kBadCoordinate:
      return RobotStatus::kUnreachable;
    case AclErrorKind::kControlDisabled:
      return RobotStatus::kNotReady;
    case AclErrorKind::kImpact:
    case AclErrorKind::kHomeFailure:
    case AclErrorKind::kNumbered:
    case AclErrorKind::kOther:
    case AclErrorKind::kMalformed:
      return RobotStatus::kError;
  }
  return RobotStatus::kError;
}

}  // namespace

void ScorbotOptions::Check() const {
  const std::string p = "ScorbotOptions::";
  RequireOption(!port.empty(), p + "port", "\"\"", "not empty");
  SerialPortOptions serial;
  serial.baud = baud;
  try {
    serial.Check();
  } catch (const std::invalid_argument&) {
    RequireOption(false, p + "baud", baud,
                  "one of 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200");
  }
  RequireOption(reply_timeout_s > 0 && reply_timeout_s <= 60, p + "reply_timeout_s",
                reply_timeout_s, "0 < value <= 60");
  RequireOption(move_timeout_s > 0 && std::isfinite(move_timeout_s), p + "move_timeout_s",
                move_timeout_s, "finite and > 0");
  RequireOption(home_timeout_s > 0 && std::isfinite(home_timeout_s), p + "home_timeout_s",
                home_timeout_s, "finite and > 0");
  RequireOption(speed_percent >= 1 && speed_percent <= 100, p + "speed_percent", speed_percent,
                "1 <= value <= 100");
  RequireOption(sampling_time_s > 0 && sampling_time_s <= 10, p + "sampling_time_s",
                sampling_time_s, "0 < value <= 10");
  RequireOption(arrive_tolerance_mm >= 0.1 && std::isfinite(arrive_tolerance_mm),
                p + "arrive_tolerance_mm", arrive_tolerance_mm, "finite and >= 0.1");
  RequireOption(arrive_tolerance_deg >= 0.1 && std::isfinite(arrive_tolerance_deg),
                p + "arrive_tolerance_deg", arrive_tolerance_deg, "finite and >= 0.1");
  RequireOption(position_check_mm >= 0 && std::isfinite(position_check_mm), p + "position_check_mm",
                position_check_mm, "finite and >= 0");
  RequireOption(position_check_deg >= 0 && std::isfinite(position_check_deg),
                p + "position_check_deg", position_check_deg, "finite and >= 0");
  bool name_ok = !point_name.empty() && point_name.size() <= 5 &&
                 std::isalpha(static_cast<unsigned char>(point_name[0]));
  for (char c : point_name) name_ok = name_ok && std::isalnum(static_cast<unsigned char>(c));
  RequireOption(name_ok, p + "point_name", point_name,
                "1-5 letters and digits, starting with a letter");
  geometry.Check();
  RequireOption(eMc.isAnHomogeneousMatrix(), p + "eMc", "(matrix)", "a rigid transform");
}

ScorbotRobot::ScorbotRobot(const ScorbotOptions& options) : options_(options) {
  options_.Check();
  q_ = HomeJoints(options_.geometry);
  wMe_ = ForwardKinematics(options_.geometry, q_);
}

ScorbotRobot::~ScorbotRobot() {
  Disconnect();
}

RobotCapabilities ScorbotRobot::Capabilities() const {
  RobotCapabilities c;
  c.position = true;
  c.velocity = false;
  c.dof = 5;
  c.sampling_time_s = options_.sampling_time_s;
  return c;
}

AclStats ScorbotRobot::link_stats() const {
  AclStats s = stats_before_;
  if (client_) s.commands += client_->stats().commands;
  s.link = port_.counters();
  return s;
}

std::string ScorbotRobot::LinkSummary(int moves) const {
  const AclStats stats = link_stats();
  const double bytes = static_cast<double>(stats.link.bytes_written + stats.link.bytes_read);
  const double serial_s = bytes * 10.0 / options_.baud;  // 8N1: 10 bits a byte
  std::string summary = "ACL link: " + std::to_string(stats.commands) + " commands, " +
                        std::to_string(stats.link.bytes_written) + " bytes sent, " +
                        std::to_string(stats.link.bytes_read) + " received: " + Fixed(serial_s, 2) +
                        " s of serial time at " + std::to_string(options_.baud) + " baud";
  if (moves > 0) summary += ", " + Fixed(serial_s / moves, 2) + " s per move";
  return summary;
}

RobotResult ScorbotRobot::FromReply(const AclReply& reply, const std::string& what) {
  switch (reply.status) {
    case AclStatus::kOk:
      return RobotResult::Ok();
    case AclStatus::kTimeout:
      return RobotResult::Fail(RobotStatus::kTimeout, "scorbot: " + what + ": " + reply.message);
    case AclStatus::kLinkError:
      connected_ = false;
      enabled_ = false;
      move_active_ = false;
      link_lost_ = reply.message;
      return RobotResult::Fail(RobotStatus::kError, "scorbot: " + what + ": " + reply.message +
                                                        " (the link to the controller is lost)");
    case AclStatus::kControllerError:
      break;
  }
  point_known_ = false;  // the controller may or may not have taken the last SETPVC
  const RobotStatus status =
      reply.errors.empty() ? RobotStatus::kError : StatusOf(reply.errors.front().kind);
  if (status == RobotStatus::kNotReady) enabled_ = false;
  return RobotResult::Fail(status, "scorbot: " + what + ": " + reply.message);
}

RobotResult ScorbotRobot::Send(const std::string& command, double timeout_s) {
  return FromReply(client_->Command(command, timeout_s), command);
}

RobotResult ScorbotRobot::Connect() {
  Disconnect();
  SerialPortOptions serial;
  serial.baud = options_.baud;
  serial.xonxoff = options_.xonxoff;
  if (IoResult r = port_.Open(options_.port, serial); !r.ok()) {
    return RobotResult::Fail(RobotStatus::kError, "scorbot: " + r.message);
  }
  AclClientOptions acl;
  acl.reply_timeout_s = options_.reply_timeout_s;
  acl.echo = false;  // unknown until ECHO / NOECHO below; a prompt at a line start is enough
  client_ = std::make_unique<AclClient>(port_, acl);
  // Let output in flight (SYSTEM READY!, a message) end and drop it, before and after the
  // first exchange: a late banner's prompt could otherwise answer the ping, and the ping's own
  // prompt would then answer the next command.
  auto wait_quiet = [this] {
    const auto deadline =
        Clock::now() + std::chrono::milliseconds(static_cast<long>(options_.reply_timeout_s * 1e3));
    std::string stale;
    while (Clock::now() < deadline && port_.ReadSome(&stale, 0.05).ok()) {
    }
  };
  wait_quiet();
  if (const AclReply ping = client_->Ping();
      ping.status != AclStatus::kOk && ping.status != AclStatus::kControllerError) {
    const RobotResult r = RobotResult::Fail(
        ping.status == AclStatus::kTimeout ? RobotStatus::kTimeout : RobotStatus::kError,
        "scorbot: no prompt from the controller on " + options_.port + ": " + ping.message);
    port_.Close();
    return r;
  }
  wait_quiet();
  connected_ = true;
  const AclReply echo = client_->SetEcho(options_.echo);
  RobotResult r = FromReply(echo, options_.echo ? "ECHO" : "NOECHO");
  if (r.ok()) {
    // A controller error here most likely says the point exists already (a reconnect): HERE
    // below fails if it really is not defined.
    const AclReply defp = client_->Command("DEFP " + options_.point_name);
    if (defp.status != AclStatus::kControllerError) r = FromReply(defp, "DEFP");
  }
  if (r.ok()) r = Send("HERE " + options_.point_name);
  if (r.ok()) r = Send("SPEED " + std::to_string(options_.speed_percent));
  if (!r.ok()) {
    Disconnect();
    return r;
  }
  point_known_ = false;
  pose_fresh_ = false;
  move_active_ = false;
  link_lost_.clear();
  return RobotResult::Ok();
}

void ScorbotRobot::Disconnect() noexcept {
  // The session ends: abort; then, if asked, control off (COFF) once the controller confirmed
  // the abort, so that the arm cannot move until someone enables it again.
  if (connected_ && Stop().ok() && options_.control_off_at_end) {
    try {
      client_->Command("COFF");
    } catch (...) {
    }
  }
  connected_ = false;
  enabled_ = false;
  move_active_ = false;
  if (client_) {
    stats_before_.commands += client_->stats().commands;
    client_.reset();
  }
  port_.Close();
}

RobotResult ScorbotRobot::Enable() {
  if (!connected_) return RobotResult::Fail(RobotStatus::kNotReady, "scorbot: not connected");
  RobotResult r = Send("CON");
  enabled_ = r.ok();
  return r;
}

RobotResult ScorbotRobot::Disable() noexcept {
  RobotResult r = Stop();
  enabled_ = false;
  if (!connected_) return r;
  try {
    RobotResult off = Send("COFF");
    return r.ok() ? off : r;
  } catch (...) {
    return RobotResult::Fail(RobotStatus::kError, "scorbot: COFF failed");
  }
}

RobotResult ScorbotRobot::Stop() noexcept {
  move_active_ = false;
  pose_fresh_ = false;
  // Never connected (or disconnected cleanly): nothing can be moving.
  if (link_lost_.empty() && (!connected_ || !client_)) return RobotResult::Ok();
  try {
    if (!client_) {
      return RobotResult::Fail(RobotStatus::kError,
                               "scorbot: no stop could be sent: the link to the controller is "
                               "lost (" +
                                   link_lost_ + ")");
    }
    // After a link failure the abort is still tried: the link may be back.
    const AclReply reply = client_->Abort();
    point_known_ = false;
    if (reply.status == AclStatus::kTimeout || reply.status == AclStatus::kLinkError) {
      return FromReply(reply, "abort (Ctrl-A, CLRBUF)");
    }
    // A controller message in the reply (an impact that caused the stop) does not make the
    // stop itself fail: the controller answered.
    return RobotResult::Ok();
  } catch (...) {
    return RobotResult::Fail(RobotStatus::kError, "scorbot: abort failed");
  }
}

RobotResult ScorbotRobot::CheckEnabled() const {
  if (!connected_) return RobotResult::Fail(RobotStatus::kNotReady, "scorbot: not connected");
  if (!enabled_) return RobotResult::Fail(RobotStatus::kNotReady, "scorbot: not enabled (CON)");
  return RobotResult::Ok();
}

RobotResult ScorbotRobot::Home() {
  if (RobotResult r = CheckEnabled(); !r.ok()) return r;
  point_known_ = false;
  return Send("HOME", options_.home_timeout_s);
}

RobotResult ScorbotRobot::ReadPosition() {
  AclPositionValues v;
  const AclReply reply = client_->ListPosition("POSITION", &v);
  if (RobotResult r = FromReply(reply, "LISTPV POSITION"); !r.ok()) return r;
  if (v.has_counts) {
    const ScorbotJoints q = FromCounts(options_.geometry, v.counts);
    if (v.has_cartesian) {
      if (RobotResult r = CheckReadingAgrees(q, v.cartesian); !r.ok()) return r;
    }
    q_ = q;
    wMe_ = ForwardKinematics(options_.geometry, q_);
    pose_ = v.has_cartesian ? v.cartesian : AclPoseOfJoints(options_.geometry, q_);
  } else {
    pose_ = v.cartesian;
    wMe_ = FromAclPose(pose_);
    const ScorbotIk ik = InverseKinematics(options_.geometry, wMe_, 1e-3);
    if (ik.ok || ik.axis != 0) q_ = ik.q;
  }
  return RobotResult::Ok();
}

RobotResult ScorbotRobot::CheckReadingAgrees(const ScorbotJoints& q, const AclPose& printed) const {
  const AclPose joints = AclPoseOfJoints(options_.geometry, q);
  // ACL units: tenths of a millimetre and of a degree; R wraps at 360 deg.
  const auto off_tenths = [](long a, long b, long wrap) {
    long d = std::labs(a - b);
    if (wrap > 0) d = std::min(d, wrap - d % wrap);
    return d;
  };
  const long xyz = std::max({off_tenths(joints.x, printed.x, 0), off_tenths(joints.y, printed.y, 0),
                             off_tenths(joints.z, printed.z, 0)});
  const long pr =
      std::max(off_tenths(joints.p, printed.p, 3600), off_tenths(joints.r, printed.r, 3600));
  const bool xyz_bad = options_.position_check_mm > 0 && xyz > options_.position_check_mm * 10;
  const bool pr_bad = options_.position_check_deg > 0 && pr > options_.position_check_deg * 10;
  if (!xyz_bad && !pr_bad) return RobotResult::Ok();
  const auto text = [](const AclPose& a) {
    return "X " + std::to_string(a.x) + " Y " + std::to_string(a.y) + " Z " + std::to_string(a.z) +
           " P " + std::to_string(a.p) + " R " + std::to_string(a.r);
  };
  return RobotResult::Fail(
      RobotStatus::kError,
      "scorbot: LISTPV POSITION disagrees with itself: its joint counts put the tool at " +
          text(joints) + " but it printed " + text(printed) +
          " (ACL units): a garbled reply, or a geometry that does not match the arm "
          "(position_check_mm, position_check_deg)");
}

ScorbotJointReading ScorbotRobot::GetJoints() {
  ScorbotJointReading reading;
  if (!connected_) {
    reading.result = RobotResult::Fail(RobotStatus::kNotReady, "scorbot: not connected");
    return reading;
  }
  pose_fresh_ = false;
  reading.result = ReadPosition();
  reading.q = q_;
  reading.counts = ToCounts(options_.geometry, q_);
  reading.pose = pose_;
  return reading;
}

vpMatrix ScorbotRobot::eJe() const {
  return EndEffectorJacobian(options_.geometry, q_);
}

RobotPose ScorbotRobot::GetPosition(RobotFrame frame) {
  RobotPose p;
  if (!connected_) {
    p.result = RobotResult::Fail(RobotStatus::kNotReady, "scorbot: not connected");
    return p;
  }
  if (pose_fresh_) {
    pose_fresh_ = false;
  } else if (RobotResult r = ReadPosition(); !r.ok()) {
    p.result = r;
    return p;
  }
  p.pose = frame == RobotFrame::kCamera ? wMe_ * options_.eMc : wMe_;
  return p;
}

RobotPose ScorbotRobot::NearestReachable(RobotFrame frame, const vpHomogeneousMatrix& target) {
  RobotPose p;
  const ScorbotReach reach = frame == RobotFrame::kCamera
                                 ? oal::NearestReachable(options_.geometry, target, options_.eMc)
                                 : oal::NearestReachable(options_.geometry, target);
  if (!reach.ok) {
    p.result = RobotResult::Fail(RobotStatus::kUnreachable,
                                 "scorbot: no reachable pose near the target: " + reach.why);
    return p;
  }
  // What the controller will be given: the pose rounded to the ACL units.
  const vpHomogeneousMatrix wMe = FromAclPose(ToAclPose(reach.wMe));
  const ScorbotIk ik = InverseKinematics(options_.geometry, wMe, 1e-6);
  if (!ik.ok) {
    p.result = RobotResult::Fail(RobotStatus::kUnreachable,
                                 "scorbot: no reachable pose near the target: " + ik.why);
    return p;
  }
  p.pose = frame == RobotFrame::kCamera ? wMe * options_.eMc : wMe;
  return p;
}

RobotPose ScorbotRobot::PoseAlongMove(RobotFrame frame, const vpHomogeneousMatrix& from,
                                      const vpHomogeneousMatrix& target, double fraction) const {
  RobotPose p;
  const vpHomogeneousMatrix cMe = options_.eMc.inverse();
  const vpHomogeneousMatrix wMe_from = frame == RobotFrame::kCamera ? from * cMe : from;
  const vpHomogeneousMatrix wMe_to = frame == RobotFrame::kCamera ? target * cMe : target;
  // The start: the joints the arm stands at: those read last if `from` is their pose (the
  // runner reads it just before), else the inverse kinematics. The end: what StartMove()
  // sends, rounded to the ACL units; the controller solves it as below. A joint outside its
  // range still gives joints (StartMove() refuses such a target).
  const ScorbotIk q0 = [&] {
    const PoseDistance off_read = Distance(wMe_from, wMe_);
    if (off_read.translation_m > 1e-9 || off_read.rotation_rad > 1e-9) {
      return InverseKinematics(options_.geometry, wMe_from, 1e-6);
    }
    ScorbotIk read;
    read.ok = true;
    read.q = q_;
    return read;
  }();
  const ScorbotIk q1 = InverseKinematics(options_.geometry, FromAclPose(ToAclPose(wMe_to)), 1e-6);
  for (const ScorbotIk* ik : {&q0, &q1}) {
    if (!ik->ok && ik->axis == 0) {
      p.result = RobotResult::Fail(RobotStatus::kUnreachable,
                                   std::string("scorbot: no joints for the move's ") +
                                       (ik == &q0 ? "start" : "target") + ": " + ik->why);
      return p;
    }
  }
  ScorbotJoints q{};
  for (int i = 0; i < 5; ++i) q[i] = q0.q[i] + fraction * (q1.q[i] - q0.q[i]);
  const vpHomogeneousMatrix wMe = ForwardKinematics(options_.geometry, q);
  p.pose = frame == RobotFrame::kCamera ? wMe * options_.eMc : wMe;
  return p;
}

RobotResult ScorbotRobot::StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) {
  if (RobotResult r = CheckEnabled(); !r.ok()) return r;
  if (!target.isAnHomogeneousMatrix()) {
    return RobotResult::Fail(RobotStatus::kUnreachable, "scorbot: target is not a rigid transform");
  }
  const vpHomogeneousMatrix wMe_t =
      frame == RobotFrame::kCamera ? target * options_.eMc.inverse() : target;
  const AclPose acl = ToAclPose(wMe_t);
  const vpHomogeneousMatrix wMe_q = FromAclPose(acl);
  const PoseDistance off = Distance(wMe_t, wMe_q);
  if (off.translation_m > 2e-4 || off.rotation_rad > 0.2 * kPi / 180) {
    std::ostringstream s;
    s << "scorbot: the target is " << off.translation_m * 1e3 << " mm and "
      << off.rotation_rad * 180 / kPi
      << " deg from the nearest pose 5 axes reach (the tool's yaw follows the base): move to "
         "NearestReachable() instead";
    return RobotResult::Fail(RobotStatus::kUnreachable, s.str());
  }
  const ScorbotIk ik = InverseKinematics(options_.geometry, wMe_q, 1e-6);
  if (!ik.ok) {
    return RobotResult::Fail(ik.axis > 0 ? RobotStatus::kLimit : RobotStatus::kUnreachable,
                             "scorbot: target " + FormatPose(acl) + ": " + ik.why);
  }
  const long values[5] = {acl.x, acl.y, acl.z, acl.p, acl.r};
  const long known[5] = {point_values_.x, point_values_.y, point_values_.z, point_values_.p,
                         point_values_.r};
  const char* coords = "XYZPR";
  for (int i = 0; i < 5; ++i) {
    if (point_known_ && values[i] == known[i]) continue;
    const RobotResult r =
        Send("SETPVC " + options_.point_name + " " + coords[i] + " " + std::to_string(values[i]));
    if (!r.ok()) return r;
  }
  point_known_ = true;
  point_values_ = acl;
  if (RobotResult r = Send("MOVE " + options_.point_name); !r.ok()) return r;
  move_active_ = true;
  move_target_ = acl;
  move_start_ = Clock::now();
  last_poll_ = move_start_;
  pose_fresh_ = false;
  return RobotResult::Ok();
}

MoveProgress ScorbotRobot::PollMove() {
  MoveProgress progress;
  if (!move_active_) {
    progress.done = true;
    return progress;
  }
  if (RobotResult r = CheckEnabled(); !r.ok()) {
    move_active_ = false;
    progress.result = r;
    return progress;
  }
  const Clock::time_point due =
      last_poll_ + std::chrono::microseconds(static_cast<long>(options_.sampling_time_s * 1e6));
  std::this_thread::sleep_until(due);
  last_poll_ = Clock::now();
  if (RobotResult r = ReadPosition(); !r.ok()) {
    move_active_ = false;
    progress.result = r;
    return progress;
  }
  pose_fresh_ = true;
  const AclPose& a = pose_;
  const AclPose& t = move_target_;
  const long tol_xyz = std::lround(options_.arrive_tolerance_mm * 10);
  const long tol_pr = std::lround(options_.arrive_tolerance_deg * 10);
  if (std::labs(a.x - t.x) <= tol_xyz && std::labs(a.y - t.y) <= tol_xyz &&
      std::labs(a.z - t.z) <= tol_xyz && AngleDiffTenths(a.p, t.p) <= tol_pr &&
      AngleDiffTenths(a.r, t.r) <= tol_pr) {
    move_active_ = false;
    progress.done = true;
    return progress;
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - move_start_).count();
  if (elapsed > options_.move_timeout_s) {
    Stop();
    std::ostringstream s;
    s << "scorbot: move not at its target after " << elapsed << " s (move_timeout_s): at "
      << FormatPose(a) << ", target " << FormatPose(t);
    progress.result = RobotResult::Fail(RobotStatus::kTimeout, s.str());
  }
  return progress;
}

RobotResult ScorbotRobot::SetVelocity(RobotFrame /*frame*/, const vpColVector& v) {
  if (v.size() != 6) {
    throw std::invalid_argument("ScorbotRobot::SetVelocity: twist has " + std::to_string(v.size()) +
                                " entries, expected 6");
  }
  return RobotResult::Fail(RobotStatus::kUnsupported,
                           "scorbot: no velocity control over ACL (position moves only; eJe() "
                           "gives the Jacobian)");
}

}  // namespace oal
