// The Scorbot ER-VII on its Controller-A over RS-232 in ACL, as a Robot (robot.h).
//
// Layers: SerialPort (serial_port.h) -> AclClient (acl_client.h) -> ScorbotRobot, with the
// arm's kinematics from scorbot_kinematics.h. Position-only: a move is a Cartesian ACL point
// and a MOVE; there is no velocity interface over ACL (SetVelocity: kUnsupported), but eJe()
// gives the manipulator Jacobian for laws that want one.
//
// What each call sends (P = options.point_name):
//   Connect()     waits for the line to go quiet, drains it, sends an empty line (the prompt
//                 answers), ECHO or NOECHO (options.echo), DEFP P, HERE P, SPEED n. No motion.
//   Enable()      CON.          Disable()   Ctrl-A, CLRBUF, COFF.
//   Disconnect() (and the destructor, at the end of a session) Ctrl-A, CLRBUF and, with
//                 control_off_at_end and if the controller answered them, COFF; then the port
//                 is closed.
//   Stop()        Ctrl-A, CLRBUF (AclClient::Abort). noexcept, safe in any state.
//   GetPosition() LISTPV POSITION -> encoder counts -> joints -> wMe (forward kinematics);
//                 wMc = wMe * eMc; refused when the counts and the X Y Z P R of the same reply
//                 disagree (position_check_mm, position_check_deg: a garbled reply). The pose read
//                 by the last PollMove() is reused once by the next GetPosition() (SafeRobot reads
//                 the pose right after every poll), which halves the bytes per poll.
//   StartMove()   the target (wMc or wMe) must be reachable by 5 axes up to the ACL resolution
//                 (use NearestReachable()); IK and joint ranges are checked here before anything
//                 is sent; then SETPVC P X|Y|Z|P|R value for each coordinate that differs from
//                 what the controller holds for P, and MOVE P. Returns at once.
//   PollMove()    waits until one sampling period has passed since the last poll, then
//                 LISTPV POSITION; done when X Y Z are within arrive_tolerance_mm and P R within
//                 arrive_tolerance_deg of the target; kTimeout (and an abort) after
//                 move_timeout_s.
//   NearestReachable() the kinematics' projection (scorbot_kinematics.h), rounded to the ACL
//                 units (0.1 mm, 0.1 deg), checked against the joint ranges.
//   PoseAlongMove() nothing sent: MOVE is joint-interpolated, so the path is the forward
//                 kinematics of the joints linear between the inverse kinematics of both ends
//                 (the target rounded to the ACL units as StartMove() sends it): the tool swings
//                 on an arc about the base axis, not along the chord.
// Errors: a controller error anywhere in a reply (or printed asynchronously before it, or right
// after its prompt: then at the latest with the next command) becomes the result, with the
// controller's text in the message, so a poll reports an impact at once: IMPACT PROTECTION,
// HOME FAILURE -> kError; OUT OF RANGE -> kLimit; 317 BAD CARTESIAN POINT, 312 BAD POINT
// COORDINATE -> kUnreachable; CONTROL DISABLED -> kNotReady; no prompt within reply_timeout_s
// -> kTimeout (the next command first resynchronises the exchange: acl_client.h); a
// closed or failed link -> kError, and the robot counts as disconnected (Connect() again);
// until a Connect() succeeds, Stop() still tries the abort but, if it cannot be sent, fails
// (the arm may still be moving: nothing confirmed it stopped).
#pragma once

#include <visp3/core/vpMatrix.h>

#include <chrono>
#include <memory>
#include <string>

#include "robots/acl_client.h"
#include "robots/robot.h"
#include "robots/scorbot_kinematics.h"
#include "robots/serial_port.h"

namespace oal {

struct ScorbotOptions {
  /// The serial device (or the simulator's pty / symlink).
  std::string port = "/dev/ttyUSB0";
  /// Baud rate; ACL: 9600. One of 1200 ... 115200.
  int baud = 9600;
  /// XON/XOFF flow control (the ACL manual has it on; many labs run without).
  bool xonxoff = false;
  /// Keep the controller's echo on (ACL's default). false sends NOECHO at Connect(): about
  /// half the received bytes.
  bool echo = true;
  /// Longest wait for a reply to one command, s; in (0, 60].
  double reply_timeout_s = 2.0;
  /// Longest a move may take before it is aborted (kTimeout), s; > 0.
  double move_timeout_s = 30.0;
  /// Longest HOME may take, s; > 0.
  double home_timeout_s = 180.0;
  /// SPEED sent at Connect(), % of the maximum; in [1, 100].
  int speed_percent = 20;
  /// Period of one PollMove(), s; in (0, 10].
  double sampling_time_s = 0.1;
  /// A move is done when X, Y, Z are this close to the target, mm; >= 0.1 (the ACL unit).
  double arrive_tolerance_mm = 0.2;
  /// ... and P, R, deg; >= 0.1. With SafeRobot, set SafetyOptions::reach_tolerance_rad to at
  /// least 0.005 (the ACL resolution of 0.1 deg on P and on R, plus the encoders).
  double arrive_tolerance_deg = 0.1;
  /// LISTPV gives both the joints' encoder counts and X Y Z P R: a reading whose two disagree
  /// by more than this on X, Y or Z (the counts through the geometry's forward kinematics), mm,
  /// is refused, since a position read wrong moves the arm wrong (a garbled reply; or a
  /// geometry that does not match the arm). 0: no check.
  double position_check_mm = 2.0;
  /// ... and by more than this on P or R, deg (these follow from the joints alone). 0: no check.
  double position_check_deg = 0.5;
  /// The ACL position variable used for targets: 1-5 letters and digits, starting with a letter.
  std::string point_name = "OALT";
  /// At the end of a session (Disconnect(), the destructor), after the abort was confirmed:
  /// false leaves control on, so the servos hold the arm where it stopped; true sends COFF,
  /// so nothing moves it until the next CON, but an axis its load can back-drive may sag
  /// (unverified on hardware: docs/SCORBOT.md).
  bool control_off_at_end = false;
  /// The arm.
  ScorbotGeometry geometry;
  /// Hand-eye: the camera in the TCP frame e.
  vpHomogeneousMatrix eMc;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// Joints read back from the controller.
struct ScorbotJointReading {
  RobotResult result;
  ScorbotCounts counts{};
  ScorbotJoints q{};
  AclPose pose;  ///< as the controller reported it (or computed from the joints)
};

class ScorbotRobot final : public Robot {
 public:
  /// Throws std::invalid_argument on bad options. Does not open the port.
  explicit ScorbotRobot(const ScorbotOptions& options);
  /// Disconnect(): aborts any motion (Ctrl-A, CLRBUF), COFF if control_off_at_end, closes
  /// the port.
  ~ScorbotRobot() override;
  ScorbotRobot(const ScorbotRobot&) = delete;
  ScorbotRobot& operator=(const ScorbotRobot&) = delete;

  std::string Name() const override { return "scorbot-er7"; }
  RobotCapabilities Capabilities() const override;
  RobotResult Connect() override;
  RobotResult Enable() override;
  RobotResult Disable() noexcept override;
  RobotResult Stop() noexcept override;
  RobotPose GetPosition(RobotFrame frame) override;
  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override;
  MoveProgress PollMove() override;
  /// kUnsupported: ACL has no velocity interface. Throws std::invalid_argument if v is not 6.
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override;
  RobotPose NearestReachable(RobotFrame frame, const vpHomogeneousMatrix& target) override;
  /// The joint-interpolated path of MOVE (see the file comment).
  RobotPose PoseAlongMove(RobotFrame frame, const vpHomogeneousMatrix& from,
                          const vpHomogeneousMatrix& target, double fraction) const override;
  vpHomogeneousMatrix eMc() const override { return options_.eMc; }
  /// The ACL commands, the bytes each way and their serial time at the configured baud rate.
  std::string LinkSummary(int moves) const override;

  /// HOME (blocking, up to home_timeout_s). Needs Enable(). Moves the arm!
  RobotResult Home();
  /// LISTPV POSITION, parsed into counts, joints and the ACL pose.
  ScorbotJointReading GetJoints();
  /// The manipulator Jacobian (6 x 5, twist of e in e per joint rate) at the joints read last
  /// (home before any read); see EndEffectorJacobian().
  vpMatrix eJe() const;
  /// Ends the session: aborts motion (Ctrl-A, CLRBUF) and, with control_off_at_end once the
  /// controller confirmed the abort, turns control off (COFF); then closes the port.
  /// Connect() opens it again.
  void Disconnect() noexcept;
  bool connected() const { return connected_; }
  bool enabled() const { return enabled_; }
  /// Commands and bytes over the link since construction.
  AclStats link_stats() const;
  const ScorbotOptions& options() const { return options_; }

 private:
  using Clock = std::chrono::steady_clock;
  RobotResult FromReply(const AclReply& reply, const std::string& what);
  RobotResult Send(const std::string& command, double timeout_s = 0);
  RobotResult CheckEnabled() const;
  RobotResult ReadPosition();
  // The counts and the X Y Z P R of one LISTPV reply agree (position_check_mm, _deg).
  RobotResult CheckReadingAgrees(const ScorbotJoints& q, const AclPose& printed) const;

  ScorbotOptions options_;
  SerialPort port_;
  std::unique_ptr<AclClient> client_;
  AclStats stats_before_;  // of clients before the current one
  bool connected_ = false;
  bool enabled_ = false;
  // Why the link failed since the last successful Connect() ("" while it works).
  std::string link_lost_;
  // What the controller holds for the target point (valid when point_known_).
  bool point_known_ = false;
  AclPose point_values_;
  // The queued move.
  bool move_active_ = false;
  AclPose move_target_;
  Clock::time_point move_start_;
  Clock::time_point last_poll_;
  // The last joint reading.
  ScorbotJoints q_{};
  AclPose pose_;
  vpHomogeneousMatrix wMe_;
  bool pose_fresh_ = false;  // read by PollMove(), not yet handed to GetPosition()
};

}  // namespace oal
