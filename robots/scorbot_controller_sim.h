// A simulator of the Scorbot ER-VII's Controller-A speaking ACL on a pseudo-terminal,
// so that the real driver (SerialPort + AclClient + ScorbotRobot) runs against it unchanged.
//
// Start() opens a pty pair (openpty, raw mode), optionally points a symlink at the slave, prints
// "SYSTEM READY!" and serves the master end from a background thread until Stop() (or the
// destructor) closes it. Open DevicePath() (or the link) as the serial port.
//
// WHAT IT DOES (docs/SCORBOT.md says which parts follow the manual and which are our guesses)
//   - Echoes every received character (CR as CR LF) unless NOECHO; ECHO turns it back on.
//     Commands end with CR; LF is ignored; commands are case-insensitive. After each command
//     its reply lines (each ending CR LF), then the prompt '>'.
//   - Position table: DEFP P, HERE P (joint point), SETPV P axis counts (joint), SETPVC P X|Y|Z|P|R
//     value (makes the point Cartesian), LISTPV P / LISTPV POSITION in the format
//     "Position P" / " 1:c1 2:c2 3:c3 4:c4 5:c5" / " X:x Y:y Z:z P:p R:r".
//   - CON / COFF (control on / off), SPEED n (1..100 %), HOME (moves to encoder zero at the
//     configured homing speed, then "Homing complete(ROBOT)"; the prompt comes after),
//     MOVE P [t] / MOVEL P [t] / MOVED P [t] (queued, the command returns at once (MOVED too:
//     its waiting is not simulated); executed in order,
//     joint-interpolated with a smooth cosine profile over max(t/100 s, the time the slowest
//     joint needs at SPEED % of its maximum speed); MOVEL is executed like MOVE), CLRBUF (clears
//     queued moves), A (abort), Ctrl-A (0x01: stops motion where it is, clears the queue,
//     discards the partial input line; prints nothing), SHOW PAR n ("PAR n = v" from a small
//     table of made-up values), ECHO / NOECHO.
//   - Errors: MOVE to a Cartesian point the arm cannot reach: "317 BAD CARTESIAN POINT"; to a
//     point whose joints (or whose IK) leave a range: "*** OUT OF RANGE axis n"; a bad SETPVC /
//     SETPV argument: "312 BAD POINT COORDINATE"; MOVE or HOME with control off:
//     "*** CONTROL DISABLED"; unknown commands "*** INVALID COMMAND", undefined points
//     "*** POSITION P NOT DEFINED", points without values "*** POSITION P HAS NO VALUES".
//   - Asynchronous messages (impact) are printed between commands (never inside an echoed
//     line), as "\r\n*** IMPACT PROTECTION axis n\r\n", without a new prompt.
//   - Time: simulated time = wall time x time_scale (tests run moves fast). With
//     throttle_to_baud, every byte in each direction takes 10 bits at the baud rate (8N1), the
//     two directions independently (full duplex), so link timing is realistic.
// FAULT INJECTION (thread-safe, for tests and the fault campaign): an impact on axis n halfway
// through the next move, or now; an impact on axis n during the current move right after the
// next command's prompt (in the same write); silence (a hung controller: input discarded,
// nothing executed, echoed or answered); a late answer (the next command's reply and prompt
// held back until the host sends another line); a reply cut short (its second half and the
// prompt lost); line noise (bytes amid the output); "317 BAD CARTESIAN POINT" for the next
// MOVE; a home failure on axis n for the next HOME; XOFF / XON sent to the host. Stop() is
// the port closed (the cable pulled). With log_input, heard() is what the host sent, timed.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "robots/scorbot_kinematics.h"

namespace oal {

struct ScorbotSimOptions {
  /// The arm (joint ranges, encoder scale, home) the simulator moves.
  ScorbotGeometry geometry;
  /// Simulated seconds per wall-clock second; in [0.01, 1000]. Tests use 10-50.
  double time_scale = 1.0;
  /// Pace every byte at 10 bits per baud period, both directions.
  bool throttle_to_baud = false;
  /// The baud rate for throttle_to_baud; > 0.
  int baud = 9600;
  /// Maximum joint speeds at SPEED 100, deg/s; > 0.
  std::array<double, 5> max_joint_speed_dps{60.0, 60.0, 75.0, 110.0, 160.0};
  /// Speed of HOME, % of the maximum; in [1, 100].
  int home_speed_percent = 50;
  /// If not empty, a symlink created at Start() pointing at the pty slave (replaced if it is
  /// already a symlink), removed at Stop().
  std::string link_path;
  /// Joint angles at start-up, degrees (default: the home position, encoders at 0).
  std::array<double, 5> start_deg{0.0, 60.0, -90.0, -60.0, 0.0};
  /// Keep every line received (and each Ctrl-A) with its arrival time, also while silent: a
  /// tap on the wire for tests and the fault campaign (heard()). Off: nothing is kept.
  bool log_input = false;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// A line the controller received (without its CR), or "^A" for a Ctrl-A, and when it arrived.
struct HeardLine {
  std::chrono::steady_clock::time_point at;
  std::string text;
};

/// Byte and command counts of a simulator run.
struct ScorbotSimStats {
  std::uint64_t bytes_received = 0;
  std::uint64_t bytes_sent = 0;
  long commands = 0;
  long moves_started = 0;
  long moves_completed = 0;
};

class ScorbotControllerSim {
 public:
  /// Throws std::invalid_argument on bad options.
  explicit ScorbotControllerSim(const ScorbotSimOptions& options = ScorbotSimOptions());
  /// Stops the thread and closes the pty.
  ~ScorbotControllerSim();
  ScorbotControllerSim(const ScorbotControllerSim&) = delete;
  ScorbotControllerSim& operator=(const ScorbotControllerSim&) = delete;

  /// Opens the pty, prints "SYSTEM READY!" and starts serving. Throws std::runtime_error if the
  /// pty or the symlink cannot be created. A stopped simulator can be started again (a new
  /// pty; the arm keeps its joints); the symlink then points at the new slave.
  void Start();
  /// Stops serving and closes the pty (the host sees the link closed). Idempotent.
  void Stop() noexcept;
  bool running() const { return running_.load(); }
  /// The pty slave to open (valid after Start()).
  std::string DevicePath() const;
  /// link_path if set, else DevicePath().
  std::string ConnectPath() const;

  // --- fault injection ---
  /// The next move stops halfway with "*** IMPACT PROTECTION axis n"; control goes off.
  void InjectImpact(int axis);
  /// While a move runs, the next command executed is answered as usual and the move then stops
  /// with "*** IMPACT PROTECTION axis n" written right after that command's prompt, in the same
  /// write (control goes off). Deterministic, unlike InjectImpact().
  void InjectImpactAfterNextPrompt(int axis);
  /// The reply and prompt of the next command (its echo is not held) are held back and sent
  /// when the host's next CR arrives, before that line is executed: a busy controller that
  /// answers after the host gave up.
  void InjectLateReply();
  /// While silent, input is discarded unexecuted and nothing is sent (no echo, no reply, no
  /// prompt, no asynchronous message): a hung controller.
  void SetSilent(bool silent);
  /// The next MOVE answers "317 BAD CARTESIAN POINT" and does not move.
  void InjectBadCartesianPoint();
  /// The next HOME fails with "*** HOME FAILURE AXIS n".
  void InjectHomeFailure(int axis);
  /// The arm hits something now: a move under way stops at once with "*** IMPACT PROTECTION
  /// axis n" (control goes off); with the arm still, the next move stops halfway.
  void InjectImpactNow(int axis);
  /// The next command's reply (after its echo) is cut short: its first half is sent, the rest
  /// and the prompt are lost.
  void InjectCutReply();
  /// Line noise: `bytes` go out now, amid whatever the controller is sending (inside a reply
  /// still on its way at the baud rate), silence or not.
  void InjectNoise(const std::string& bytes);
  /// Sends XOFF (0x13) / XON (0x11) to the host: a host with XON/XOFF stops / resumes sending.
  void SendXoff();
  void SendXon();

  // --- state (thread-safe snapshots) ---
  ScorbotJoints joints() const;
  bool moving() const;
  bool control_enabled() const;
  bool echo() const;
  int speed_percent() const;
  /// The last command line executed, upper-cased ("" before the first).
  std::string last_command() const;
  ScorbotSimStats stats() const;
  /// What the host sent, line by line (options log_input; else empty).
  std::vector<HeardLine> heard() const;

 private:
  struct Point {
    bool has_values = false;
    bool cartesian = false;
    ScorbotCounts counts{};
    AclPose pose;
  };
  struct Move {
    ScorbotJoints target{};  // the point's joints when MOVE was received
    double duration_s = -1;  // requested (MOVE P t), < 0: from SPEED
  };
  struct Motion {
    bool active = false;
    bool homing = false;
    ScorbotJoints from{}, to{};
    double start_s = 0, duration_s = 0;
    double impact_at_s = -1;  // sim time of an injected impact, < 0: none
    int impact_axis = 0;
  };

  void Run();
  // A copy of a member taken under the lock (the state getters).
  template <typename T>
  T Snapshot(const T& member) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return member;
  }
  double SimTime() const;  // s
  void Hear(char c);       // the wire tap (options_.log_input)
  void Receive(char c);
  void Execute(const std::string& line);
  void Emit(const std::string& text);  // reply text, subject to silence
  void EmitAsync(const std::string& text);
  void Prompt();
  void StartNextMove();
  void Advance();
  void FlushOutput();
  ScorbotJoints CurrentJoints() const;
  std::string ListPoint(const std::string& name, const Point& p) const;
  bool PointJoints(const Point& p, ScorbotJoints* q, std::string* error) const;
  // The point `name`, or null after emitting why not (not defined, no values).
  Point* PointWithValues(const std::string& name);
  void CmdMove(const std::string& arg, bool linear);
  void CmdSetpvc(const std::string& args);
  void CmdSetpv(const std::string& args);
  void AbortMotion();

  ScorbotSimOptions options_;
  mutable std::mutex mutex_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  int master_ = -1;
  int slave_ = -1;
  std::string slave_path_;
  std::chrono::steady_clock::time_point epoch_;

  // Controller state (under mutex_).
  ScorbotJoints joints_{};
  Motion motion_;
  std::deque<Move> queue_;
  std::map<std::string, Point> points_;
  bool control_ = true;
  bool echo_ = true;
  int speed_ = 50;
  std::string line_;
  std::string pending_async_;
  bool silent_ = false;
  int impact_axis_ = 0;
  int impact_after_prompt_axis_ = 0;
  bool late_reply_armed_ = false;
  bool cut_reply_armed_ = false;
  bool cutting_reply_ = false;  // the reply being held is to be cut, not sent late
  std::string heard_line_;      // the line being received, for heard_
  std::vector<HeardLine> heard_;
  bool holding_reply_ = false;
  std::string held_;  // output held back by a late reply
  std::string last_command_;
  bool bad_cartesian_ = false;
  int home_failure_axis_ = 0;
  bool homing_reply_pending_ = false;
  std::string out_;  // bytes to send
  // Baud pacing: when the next byte may leave / the last received byte has arrived.
  double tx_free_s_ = 0;
  std::deque<std::pair<double, char>> rx_;  // received bytes with their arrival times
  double rx_last_s_ = 0;
  ScorbotSimStats stats_;
};

}  // namespace oal
