// One class, the Controller-A simulator: its pseudo-terminal loop, the ACL commands it answers,
// its motion model and the faults tests inject, all on the same private state.
#include "robots/scorbot_controller_sim.h"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "base/angles.h"
#include "base/check.h"

namespace oal {
namespace {

constexpr char kCtrlA = 0x01;
constexpr char kXon = 0x11;
constexpr char kXoff = 0x13;

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> words;
  std::istringstream in(s);
  std::string w;
  while (in >> w) words.push_back(w);
  return words;
}

bool ParseLong(const std::string& s, long* value) {
  if (s.empty()) return false;
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (end == s.c_str() || *end != '\0') return false;
  *value = v;
  return true;
}

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Made-up system parameters for SHOW PAR (documented as invented in docs/SCORBOT.md).
long ParameterValue(int n) {
  switch (n) {
    case 1:
      return 9600;  // baud rate
    case 2:
      return 5;  // axes
    default:
      return 0;
  }
}

}  // namespace

void ScorbotSimOptions::Check() const {
  geometry.Check();
  const std::string p = "ScorbotSimOptions::";
  RequireOption(time_scale >= 0.01 && time_scale <= 1000, p + "time_scale", time_scale,
                "0.01 <= value <= 1000");
  RequireOption(baud > 0, p + "baud", baud, "> 0");
  RequireOption(home_speed_percent >= 1 && home_speed_percent <= 100, p + "home_speed_percent",
                home_speed_percent, "1 <= value <= 100");
  for (int i = 0; i < 5; ++i) {
    const std::string idx = "[" + std::to_string(i) + "]";
    RequireOption(max_joint_speed_dps[i] > 0 && std::isfinite(max_joint_speed_dps[i]),
                  p + "max_joint_speed_dps" + idx, max_joint_speed_dps[i], "finite and > 0");
    RequireOption(
        start_deg[i] >= geometry.joint_min_deg[i] && start_deg[i] <= geometry.joint_max_deg[i],
        p + "start_deg" + idx, start_deg[i], "inside the joint range");
  }
}

ScorbotControllerSim::ScorbotControllerSim(const ScorbotSimOptions& options) : options_(options) {
  options_.Check();
  for (int i = 0; i < 5; ++i) joints_[i] = options_.start_deg[i] * kPi / 180.0;
}

ScorbotControllerSim::~ScorbotControllerSim() {
  Stop();
}

void ScorbotControllerSim::Start() {
  if (running_.load()) return;
  int master = -1, slave = -1;
  char name[256] = {0};
  if (::openpty(&master, &slave, name, nullptr, nullptr) != 0) {
    throw std::runtime_error(std::string("the Scorbot controller simulator: openpty failed: ") +
                             std::strerror(errno));
  }
  termios tio{};
  ::tcgetattr(slave, &tio);
  ::cfmakeraw(&tio);
  ::cfsetispeed(&tio, B9600);
  ::cfsetospeed(&tio, B9600);
  ::tcsetattr(slave, TCSANOW, &tio);
  ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
  ::fcntl(master, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave, F_SETFD, FD_CLOEXEC);
  if (!options_.link_path.empty()) {
    struct stat st {};
    if (::lstat(options_.link_path.c_str(), &st) == 0) {
      if (!S_ISLNK(st.st_mode)) {
        ::close(master);
        ::close(slave);
        throw std::runtime_error("the Scorbot controller simulator: " + options_.link_path +
                                 " exists and is not a symlink");
      }
      ::unlink(options_.link_path.c_str());
    }
    if (::symlink(name, options_.link_path.c_str()) != 0) {
      const std::string why = std::strerror(errno);
      ::close(master);
      ::close(slave);
      throw std::runtime_error("the Scorbot controller simulator: cannot create the link " +
                               options_.link_path + ": " + why);
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    master_ = master;
    slave_ = slave;  // kept open so the master never sees a hang-up between host sessions
    slave_path_ = name;
    epoch_ = std::chrono::steady_clock::now();
    motion_ = Motion();
    queue_.clear();
    line_.clear();
    out_.clear();
    rx_.clear();
    pending_async_.clear();
    tx_free_s_ = 0;
    rx_last_s_ = 0;
    echo_ = true;
    silent_ = false;
    homing_reply_pending_ = false;
    holding_reply_ = false;
    cutting_reply_ = false;
    held_.clear();
    heard_line_.clear();
    Emit("SYSTEM READY!\r\n");
    Prompt();
  }
  stop_requested_.store(false);
  running_.store(true);
  thread_ = std::thread(&ScorbotControllerSim::Run, this);
}

void ScorbotControllerSim::Stop() noexcept {
  stop_requested_.store(true);
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_.load()) {
    // Motion state freezes where it is.
    joints_ = CurrentJoints();
    motion_ = Motion();
    queue_.clear();
  }
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
  master_ = slave_ = -1;
  if (!options_.link_path.empty() && running_.load()) ::unlink(options_.link_path.c_str());
  running_.store(false);
}

std::string ScorbotControllerSim::DevicePath() const {
  return Snapshot(slave_path_);
}

std::string ScorbotControllerSim::ConnectPath() const {
  return options_.link_path.empty() ? DevicePath() : options_.link_path;
}

void ScorbotControllerSim::InjectImpact(int axis) {
  std::lock_guard<std::mutex> lock(mutex_);
  impact_axis_ = std::max(1, std::min(5, axis));
}

void ScorbotControllerSim::InjectImpactAfterNextPrompt(int axis) {
  std::lock_guard<std::mutex> lock(mutex_);
  impact_after_prompt_axis_ = std::max(1, std::min(5, axis));
}

void ScorbotControllerSim::InjectImpactNow(int axis) {
  std::lock_guard<std::mutex> lock(mutex_);
  const int clamped = std::max(1, std::min(5, axis));
  if (motion_.active && !motion_.homing) {
    motion_.impact_at_s = SimTime();
    motion_.impact_axis = clamped;
  } else {
    impact_axis_ = clamped;
  }
}

void ScorbotControllerSim::InjectCutReply() {
  std::lock_guard<std::mutex> lock(mutex_);
  cut_reply_armed_ = true;
}

void ScorbotControllerSim::InjectNoise(const std::string& bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Into the middle of what is still to go out, else now.
  out_.insert(out_.size() / 2, bytes);
}

std::vector<HeardLine> ScorbotControllerSim::heard() const {
  return Snapshot(heard_);
}

void ScorbotControllerSim::InjectLateReply() {
  std::lock_guard<std::mutex> lock(mutex_);
  late_reply_armed_ = true;
}

std::string ScorbotControllerSim::last_command() const {
  return Snapshot(last_command_);
}

void ScorbotControllerSim::SetSilent(bool silent) {
  std::lock_guard<std::mutex> lock(mutex_);
  silent_ = silent;
}

void ScorbotControllerSim::InjectBadCartesianPoint() {
  std::lock_guard<std::mutex> lock(mutex_);
  bad_cartesian_ = true;
}

void ScorbotControllerSim::InjectHomeFailure(int axis) {
  std::lock_guard<std::mutex> lock(mutex_);
  home_failure_axis_ = std::max(1, std::min(5, axis));
}

void ScorbotControllerSim::SendXoff() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (master_ >= 0 && ::write(master_, &kXoff, 1) == 1) ++stats_.bytes_sent;
}

void ScorbotControllerSim::SendXon() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (master_ >= 0 && ::write(master_, &kXon, 1) == 1) ++stats_.bytes_sent;
}

ScorbotJoints ScorbotControllerSim::joints() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return CurrentJoints();
}

bool ScorbotControllerSim::moving() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return motion_.active || !queue_.empty();
}

bool ScorbotControllerSim::control_enabled() const {
  return Snapshot(control_);
}

bool ScorbotControllerSim::echo() const {
  return Snapshot(echo_);
}

int ScorbotControllerSim::speed_percent() const {
  return Snapshot(speed_);
}

ScorbotSimStats ScorbotControllerSim::stats() const {
  return Snapshot(stats_);
}

double ScorbotControllerSim::SimTime() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count() *
         options_.time_scale;
}

// --- the serving thread ---------------------------------------------------------------------

void ScorbotControllerSim::Run() {
  const double byte_s = 10.0 / options_.baud;
  while (!stop_requested_.load()) {
    int timeout_ms = 20;
    short events = POLLIN;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
      char buf[512];
      for (;;) {
        const ssize_t n = ::read(master_, buf, sizeof buf);
        if (n <= 0) break;
        stats_.bytes_received += static_cast<std::uint64_t>(n);
        for (ssize_t i = 0; i < n; ++i) {
          double arrival = wall;
          if (options_.throttle_to_baud) {
            arrival = std::max(wall, rx_last_s_) + byte_s;
            rx_last_s_ = arrival;
          }
          rx_.emplace_back(arrival, buf[i]);
        }
      }
      while (!rx_.empty() && rx_.front().first <= wall) {
        const char c = rx_.front().second;
        rx_.pop_front();
        Receive(c);
      }
      Advance();
      if (line_.empty() && !pending_async_.empty()) {
        if (!silent_) {
          if (out_.empty() && tx_free_s_ < wall) tx_free_s_ = wall;
          out_ += pending_async_;
        }
        pending_async_.clear();
      }
      FlushOutput();
      double wake_s = motion_.active ? 0.002 : 0.02;
      if (!rx_.empty()) wake_s = std::min(wake_s, rx_.front().first - wall);
      if (!out_.empty()) {
        if (options_.throttle_to_baud) {
          wake_s = std::min(wake_s, tx_free_s_ + byte_s - wall);
        } else {
          events |= POLLOUT;
        }
      }
      timeout_ms = std::max(0, static_cast<int>(std::ceil(wake_s * 1000)));
    }
    pollfd p{master_, events, 0};
    ::poll(&p, 1, timeout_ms);
    if (p.revents & (POLLHUP | POLLERR)) {
      // No host on the slave (our own slave fd keeps this rare): do not spin.
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
}

void ScorbotControllerSim::FlushOutput() {
  if (out_.empty() || master_ < 0) return;
  std::size_t allowed = out_.size();
  if (options_.throttle_to_baud) {
    const double byte_s = 10.0 / options_.baud;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
    if (wall < tx_free_s_ + byte_s) return;
    allowed = std::min(out_.size(), static_cast<std::size_t>((wall - tx_free_s_) / byte_s));
  }
  const ssize_t n = ::write(master_, out_.data(), allowed);
  if (n > 0) {
    stats_.bytes_sent += static_cast<std::uint64_t>(n);
    out_.erase(0, static_cast<std::size_t>(n));
    tx_free_s_ += static_cast<double>(n) * 10.0 / options_.baud;
  }
}

void ScorbotControllerSim::Emit(const std::string& text) {
  if (silent_) return;
  if (holding_reply_) {
    held_ += text;
    return;
  }
  if (out_.empty()) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
    if (tx_free_s_ < wall) tx_free_s_ = wall;
  }
  out_ += text;
}

void ScorbotControllerSim::EmitAsync(const std::string& text) {
  pending_async_ += "\r\n" + text + "\r\n";
}

void ScorbotControllerSim::Prompt() {
  Emit(">");
}

void ScorbotControllerSim::Hear(char c) {
  if (!options_.log_input) return;
  if (c == kCtrlA) {
    heard_.push_back({std::chrono::steady_clock::now(), "^A"});
  } else if (c == '\r') {
    heard_.push_back({std::chrono::steady_clock::now(), heard_line_});
    heard_line_.clear();
  } else if (c != '\n' && heard_line_.size() < 256) {
    heard_line_.push_back(c);
  }
}

void ScorbotControllerSim::Receive(char c) {
  Hear(c);
  if (silent_) return;  // a hung controller: nothing is executed
  if (c == kCtrlA) {
    AbortMotion();
    line_.clear();
    return;
  }
  if (c == kXon || c == kXoff || c == '\n' || c == '\0') return;
  if (c == '\r') {
    if (holding_reply_) {  // the late answer goes out before this line is executed
      holding_reply_ = false;
      Emit(held_);
      held_.clear();
    }
    if (echo_) Emit("\r\n");
    const std::string line = line_;
    line_.clear();
    if (cut_reply_armed_ && !holding_reply_) {
      cut_reply_armed_ = false;
      cutting_reply_ = holding_reply_ = true;  // the echo went; the reply is held and cut
    }
    Execute(line);
    if (cutting_reply_) {
      cutting_reply_ = holding_reply_ = false;
      const std::string sent = held_.substr(0, held_.size() / 2);
      held_.clear();
      Emit(sent);
    }
    return;
  }
  if (c == '\b' || c == 0x7f) {
    if (!line_.empty()) line_.pop_back();
    return;
  }
  line_.push_back(c);
  if (echo_) Emit(std::string(1, c));
}

ScorbotJoints ScorbotControllerSim::CurrentJoints() const {
  if (!motion_.active) return joints_;
  const double t = SimTime();
  double end = motion_.start_s + motion_.duration_s;
  if (motion_.impact_at_s >= 0) end = std::min(end, motion_.impact_at_s);
  const double s =
      motion_.duration_s <= 0
          ? 1.0
          : std::max(0.0, std::min(1.0, (std::min(t, end) - motion_.start_s) / motion_.duration_s));
  const double w = 0.5 * (1 - std::cos(kPi * s));
  ScorbotJoints q{};
  for (int i = 0; i < 5; ++i) q[i] = motion_.from[i] + w * (motion_.to[i] - motion_.from[i]);
  return q;
}

void ScorbotControllerSim::AbortMotion() {
  if (motion_.active) {
    joints_ = CurrentJoints();
    motion_ = Motion();
  }
  queue_.clear();
  if (homing_reply_pending_) {
    homing_reply_pending_ = false;
    Prompt();
  }
}

void ScorbotControllerSim::StartNextMove() {
  if (motion_.active || queue_.empty()) return;
  const Move move = queue_.front();
  queue_.pop_front();
  const ScorbotJoints& target = move.target;
  Motion m;
  m.active = true;
  m.from = joints_;
  m.to = target;
  m.start_s = SimTime();
  double needed = 0;
  for (int i = 0; i < 5; ++i) {
    const double v = options_.max_joint_speed_dps[i] * kPi / 180.0 * speed_ / 100.0;
    needed = std::max(needed, std::abs(target[i] - joints_[i]) / v);
  }
  // A cosine profile peaks at pi/2 times the mean speed: keep the peak within the limit.
  needed *= kPi / 2;
  m.duration_s = std::max(needed, move.duration_s);
  if (impact_axis_ > 0) {
    m.impact_at_s = m.start_s + m.duration_s / 2;
    m.impact_axis = impact_axis_;
    impact_axis_ = 0;
  }
  motion_ = m;
  ++stats_.moves_started;
}

void ScorbotControllerSim::Advance() {
  const double t = SimTime();
  if (motion_.active) {
    if (motion_.impact_at_s >= 0 && t >= motion_.impact_at_s) {
      joints_ = CurrentJoints();
      const Motion m = motion_;
      motion_ = Motion();
      queue_.clear();
      if (m.homing) {
        homing_reply_pending_ = false;
        Emit("*** HOME FAILURE AXIS " + std::to_string(m.impact_axis) + "\r\n");
        Prompt();
      } else {
        control_ = false;
        EmitAsync("*** IMPACT PROTECTION axis " + std::to_string(m.impact_axis));
      }
    } else if (t >= motion_.start_s + motion_.duration_s) {
      joints_ = motion_.to;
      const bool homing = motion_.homing;
      motion_ = Motion();
      ++stats_.moves_completed;
      if (homing && homing_reply_pending_) {
        homing_reply_pending_ = false;
        Emit("Homing complete(ROBOT)\r\n");
        Prompt();
      }
    }
  }
  StartNextMove();
}

// --- commands ---------------------------------------------------------------------------------

bool ScorbotControllerSim::PointJoints(const Point& p, ScorbotJoints* q, std::string* error) const {
  if (!p.cartesian) {
    *q = FromCounts(options_.geometry, p.counts);
    if (const int axis = JointLimitViolation(options_.geometry, *q)) {
      *error = "*** OUT OF RANGE axis " + std::to_string(axis);
      return false;
    }
    return true;
  }
  const ScorbotIk ik = InverseKinematics(options_.geometry, FromAclPose(p.pose), 1e-3);
  if (!ik.ok) {
    *error = ik.axis == 0 ? "317 BAD CARTESIAN POINT"
                          : "*** OUT OF RANGE axis " + std::to_string(ik.axis);
    return false;
  }
  *q = ik.q;
  return true;
}

std::string ScorbotControllerSim::ListPoint(const std::string& name, const Point& p) const {
  std::ostringstream s;
  s << "Position " << name << "\r\n";
  ScorbotCounts counts = p.counts;
  bool has_counts = !p.cartesian;
  AclPose pose = p.pose;
  if (p.cartesian) {
    const ScorbotIk ik = InverseKinematics(options_.geometry, FromAclPose(p.pose), 1e-3);
    if (ik.ok || ik.axis != 0) {
      counts = ToCounts(options_.geometry, ik.q);
      has_counts = ik.ok;
    }
  } else {
    pose = AclPoseOfJoints(options_.geometry, FromCounts(options_.geometry, p.counts));
  }
  if (has_counts) {
    s << " 1:" << counts[0] << " 2:" << counts[1] << " 3:" << counts[2] << " 4:" << counts[3]
      << " 5:" << counts[4] << "\r\n";
  }
  s << " X:" << pose.x << " Y:" << pose.y << " Z:" << pose.z << " P:" << pose.p << " R:" << pose.r
    << "\r\n";
  return s.str();
}

ScorbotControllerSim::Point* ScorbotControllerSim::PointWithValues(const std::string& name) {
  auto it = points_.find(name);
  if (it == points_.end()) {
    Emit("*** POSITION " + name + " NOT DEFINED\r\n");
    return nullptr;
  }
  if (!it->second.has_values) {
    Emit("*** POSITION " + name + " HAS NO VALUES\r\n");
    return nullptr;
  }
  return &it->second;
}

void ScorbotControllerSim::CmdSetpvc(const std::string& args) {
  const std::vector<std::string> w = Split(args);
  if (w.size() != 3) {
    Emit("312 BAD POINT COORDINATE\r\n");
    return;
  }
  if (points_.count(w[0]) == 0) {
    Emit("*** POSITION " + w[0] + " NOT DEFINED\r\n");
    return;
  }
  long value = 0;
  const std::string coords = "XYZPR";
  if (w[1].size() != 1 || coords.find(w[1][0]) == std::string::npos || !ParseLong(w[2], &value)) {
    Emit("312 BAD POINT COORDINATE\r\n");
    return;
  }
  Point* point = PointWithValues(w[0]);
  if (point == nullptr) return;
  Point& p = *point;
  if (!p.cartesian) {
    p.pose = AclPoseOfJoints(options_.geometry, FromCounts(options_.geometry, p.counts));
    p.cartesian = true;
  }
  long* field[5] = {&p.pose.x, &p.pose.y, &p.pose.z, &p.pose.p, &p.pose.r};
  *field[coords.find(w[1][0])] = value;
}

void ScorbotControllerSim::CmdSetpv(const std::string& args) {
  const std::vector<std::string> w = Split(args);
  long axis = 0, value = 0;
  if (w.size() != 3 || !ParseLong(w[1], &axis) || axis < 1 || axis > 5 ||
      !ParseLong(w[2], &value)) {
    Emit("312 BAD POINT COORDINATE\r\n");
    return;
  }
  Point* point = PointWithValues(w[0]);
  if (point == nullptr) return;
  Point& p = *point;
  if (p.cartesian) {
    const ScorbotIk ik = InverseKinematics(options_.geometry, FromAclPose(p.pose), 1e-3);
    if (!ik.ok && ik.axis == 0) {
      Emit("317 BAD CARTESIAN POINT\r\n");
      return;
    }
    p.counts = ToCounts(options_.geometry, ik.q);
    p.cartesian = false;
  }
  p.counts[axis - 1] = value;
}

void ScorbotControllerSim::CmdMove(const std::string& args, bool /*linear*/) {
  const std::vector<std::string> w = Split(args);
  long hundredths = -1;
  if (w.empty() || w.size() > 2 ||
      (w.size() == 2 && (!ParseLong(w[1], &hundredths) || hundredths < 0))) {
    Emit("*** INVALID COMMAND\r\n");
    return;
  }
  const Point* point = PointWithValues(w[0]);
  if (point == nullptr) return;
  if (!control_) {
    Emit("*** CONTROL DISABLED\r\n");
    return;
  }
  if (bad_cartesian_) {
    bad_cartesian_ = false;
    Emit("317 BAD CARTESIAN POINT\r\n");
    return;
  }
  ScorbotJoints q{};
  std::string error;
  if (!PointJoints(*point, &q, &error)) {
    Emit(error + "\r\n");
    return;
  }
  queue_.push_back({q, hundredths < 0 ? -1.0 : hundredths / 100.0});
  StartNextMove();
}

void ScorbotControllerSim::Execute(const std::string& raw) {
  const std::string line = Upper(raw);
  const std::vector<std::string> w = Split(line);
  ++stats_.commands;
  last_command_ = line;
  if (late_reply_armed_) {
    late_reply_armed_ = false;
    holding_reply_ = true;  // from here on, output is held (the echo already went)
  }
  if (w.empty()) {
    Prompt();
    return;
  }
  const std::string& cmd = w[0];
  const std::string args = line.substr(std::min(line.size(), line.find(cmd) + cmd.size()));
  if (cmd == "ECHO") {
    echo_ = true;
  } else if (cmd == "NOECHO") {
    echo_ = false;
  } else if (cmd == "CON") {
    control_ = true;
  } else if (cmd == "COFF") {
    AbortMotion();
    control_ = false;
  } else if (cmd == "SPEED") {
    long v = 0;
    if (w.size() == 1) {
      Emit("SPEED " + std::to_string(speed_) + "\r\n");
    } else if (w.size() == 2 && ParseLong(w[1], &v) && v >= 1 && v <= 100) {
      speed_ = static_cast<int>(v);
    } else {
      Emit("*** ILLEGAL VALUE\r\n");
    }
  } else if (cmd == "DEFP" && w.size() == 2) {
    points_.emplace(w[1], Point());
  } else if (cmd == "HERE" && w.size() == 2) {
    auto it = points_.find(w[1]);
    if (it == points_.end()) {
      Emit("*** POSITION " + w[1] + " NOT DEFINED\r\n");
    } else {
      it->second.has_values = true;
      it->second.cartesian = false;
      it->second.counts = ToCounts(options_.geometry, CurrentJoints());
    }
  } else if (cmd == "SETPVC") {
    CmdSetpvc(args);
  } else if (cmd == "SETPV") {
    CmdSetpv(args);
  } else if (cmd == "LISTPV" && w.size() == 2) {
    if (w[1] == "POSITION") {
      Point p;
      p.has_values = true;
      p.counts = ToCounts(options_.geometry, CurrentJoints());
      Emit(ListPoint("POSITION", p));
    } else if (const Point* point = PointWithValues(w[1])) {
      Emit(ListPoint(w[1], *point));
    }
  } else if (cmd == "MOVE" || cmd == "MOVEL" || cmd == "MOVED") {
    CmdMove(args, cmd == "MOVEL");
  } else if (cmd == "CLRBUF") {
    queue_.clear();
  } else if (cmd == "A") {
    AbortMotion();
  } else if (cmd == "HOME") {
    if (!control_) {
      Emit("*** CONTROL DISABLED\r\n");
    } else {
      AbortMotion();
      Motion m;
      m.active = true;
      m.homing = true;
      m.from = joints_;
      m.to = HomeJoints(options_.geometry);
      m.start_s = SimTime();
      double needed = 0.5;  // searching the switches takes a while even from home
      for (int i = 0; i < 5; ++i) {
        const double v =
            options_.max_joint_speed_dps[i] * kPi / 180.0 * options_.home_speed_percent / 100.0;
        needed = std::max(needed, std::abs(m.to[i] - m.from[i]) / v * kPi / 2);
      }
      m.duration_s = needed;
      if (home_failure_axis_ > 0) {
        m.impact_at_s = m.start_s + needed / 2;
        m.impact_axis = home_failure_axis_;
        home_failure_axis_ = 0;
      }
      motion_ = m;
      homing_reply_pending_ = true;
      return;  // the prompt comes when homing ends
    }
  } else if (cmd == "SHOW" && w.size() == 3 && w[1] == "PAR") {
    long n = 0;
    if (!ParseLong(w[2], &n)) {
      Emit("*** ILLEGAL VALUE\r\n");
    } else {
      Emit("PAR " + std::to_string(n) + " = " +
           std::to_string(ParameterValue(static_cast<int>(n))) + "\r\n");
    }
  } else {
    Emit("*** INVALID COMMAND\r\n");
  }
  Prompt();
  if (impact_after_prompt_axis_ > 0 && motion_.active && !motion_.homing) {
    joints_ = CurrentJoints();
    motion_ = Motion();
    queue_.clear();
    control_ = false;
    Emit("\r\n*** IMPACT PROTECTION axis " + std::to_string(impact_after_prompt_axis_) + "\r\n");
    impact_after_prompt_axis_ = 0;
  }
}

}  // namespace oal
