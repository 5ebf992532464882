// The four-line target's pose over a stream of frames: where to scan, the detection, the pose,
// and the checks that keep a wrong pose from being passed on.
//
// Per frame (ScanMode::kTarget, the default):
//   1. With a prior pose (the caller's prediction, e.g. from the robot's motion, else the
//      last accepted pose), the detector scans borders concentric on the target's plane seen
//      from it (target_layout.h), seeded with the four lines where the prior puts them, and the
//      pose is estimated from the prior.
//   2. Without one, or when that fails: the target's middle cell is looked for
//      (detector/sheet_finder.h); for each candidate closed in on three sides or more, best
//      first (at most max_candidates), the borders its homography gives are scanned: as few
//      as a tracked frame's first (its lines are seeded as a prior's are), all `borders` when
//      those give no pose or lines whose widths barely identify them. A candidate that gives
//      no pose as the middle cell is also tried as a cell beyond a stripe, out to the sheet's
//      edge (closed in on three sides: its open side there; on four: each side in turn), and
//      the first one as the middle cell cut short by something lying across it
//      (target_layout.h: UncutCells). When none gives a pose, the same for the finder's later
//      looks (SheetFinder::FindLocallyLight: a hand or a glare joining the middle cell to its
//      neighbour; FindFaintlyDark: a pale hand; FindNarrowed: a stripe washed out over a short
//      stretch, a bridge a cell or two wide; FindSplitAtNecks: a crossing washed out over
//      several cells, the middle cell joined through it to paper out of view;
//      FindClippedAsPaper: over-exposed paper, clipped, not taken for a glare's core beside a
//      light bench or page that is not); then the candidates
//      closed in on two sides that meet, set aside on the way, as each of the sheet's corner cells
//      (the paper beyond one stripe of each pair, out to the sheet's corner: a glare over the
//      middle of the sheet joins the middle cell to the cells beyond all four stripes).
//   3. When no candidate gives a pose and image_fallback is set, the whole image is scanned
//      with the paper's concentric image borders. A line of the bench can stand in for a
//      stripe's edge there and tilt the pose by degrees yet pass the checks below, so the
//      borders on the target's plane seen from that pose are scanned as a candidate's (step
//      2): when both poses pass, they must lie within max_jump_m / max_jump_deg of each other
//      (else the frame is kModelMismatch), and the one whose corners fit the target better
//      (the lower residual) is the frame's; when the target's plane gives no pose at all (a
//      board seen from near, whose lines traverse the view), the whole image's stands; when it
//      gives one the image contradicts and the whole image's pose puts a stripe where too few
//      of its points lie (its stripe fit starved), the stripes are there and neither pose is
//      sure where (kModelMismatch).
// A pose is refined on the stripes' own feature points, the target held rigid (stripe_fit.h);
// a stripe keeping under half the points of the others is fitted without, and when its points
// pull the pose away from where the other three put it at a cost to theirs (their RMS doubled),
// they are not its stripe's and the pose is not taken; so is a stripe whose runs are narrower or
// wider than the others' (something along one side of it) when the image's stripe edges lie
// three times nearer where the other three stripes put them. A pose is accepted only when the image
// shows the target where it says (stripe_check.h): across each stripe, between the crossings
// and the printed ends, its dark run where the pose puts it
// (min_stripe_agreement of the samples that agree or contradict, min_stripe_seen of all the
// samples in view; one stripe with fewer than 3 agreeing samples and none contradicting, under a
// hand or out of view, only when the other three alone fix the pose tightly where it is); otherwise
// the frame's status is kModelMismatch. Without a caller's prediction, a pose found on the borders
// of the last accepted one (step 1) that moved more than max_jump_m / max_jump_deg from it is held
// (kJump) and accepted only when the next frame agrees with it: one bad frame is refused, a real
// fast move costs one frame. A pose found afresh (steps 2-3, after the last pose's borders showed
// nothing) is not held: the target has moved. ScanMode::kImage is the paper's condition: the whole
// image every frame (steps 1-2 skipped), the same checks.
//
// Coordinates: the lines and corners are in undistorted pixels when the camera has
// distortion (the detector undistorts the feature points), as pose.h states.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "detector/line_fit.h"
#include "detector/region.h"
#include "detector/sheet_finder.h"
#include "servo/pose.h"
#include "servo/stripe_check.h"
#include "servo/stripe_fit.h"
#include "servo/target_layout.h"
#include "target/line_target.h"

namespace oal {

enum class ScanMode {
  kTarget,  ///< borders on the target's plane, from a prior pose or the middle cell
  kImage,   ///< the paper's concentric image borders, every frame
};

/// How a frame's pose was found (or the last place looked).
enum class ScanSource {
  kNone,        ///< nothing was scanned
  kPrior,       ///< borders from the prior pose
  kMiddleCell,  ///< borders from a middle-cell candidate of the sheet finder
  kEdgeCell,    ///< ... from a candidate closed in on three sides taken as an edge cell
  kCornerCell,  ///< ... from a candidate closed in on two adjacent sides taken as a corner cell
  kImage,       ///< the whole image
};

enum class TargetStatus {
  kOk,             ///< a pose, checked
  kNotFound,       ///< no pose (the last attempt's PoseResult says why)
  kModelMismatch,  ///< a pose the image does not support (stripes not where it puts them)
  kJump,           ///< a pose too far from the last accepted one, held for the next frame
};

/// The one place where these enums meet strings ("target", "image"; "none", "prior",
/// "middle-cell", "edge-cell", "image"; "ok", "not-found", "model-mismatch", "jump").
std::string ToString(ScanMode mode);
std::string ToString(ScanSource source);
std::string ToString(TargetStatus status);
/// Throws std::invalid_argument naming the accepted values.
ScanMode ScanModeFromString(const std::string& text);

struct TargetTrackerOptions {
  /// Every setting in pixels (the detector's, the sheet finder's cells, the pose's pixel
  /// bounds, the model check's and the stripe fit's tolerances) is given for a camera of this
  /// focal length, pixels, and the tracker scales it by the camera's focal length over this:
  /// the stripes, their runs and their blur are that many times as many pixels across (a
  /// 1920x1080 webcam 70 degrees across, 1371 px, scans its borders 2.3 times as far apart).
  /// 0: the settings are used as they are given. Range 0 or [1, 1e5].
  double reference_focal_px = 600.0;
  ScanMode scan = ScanMode::kTarget;
  /// Borders on the target plane (target_layout.h) when the target is looked for (no prior,
  /// or the prior failed) and a candidate's first scan on tracked_borders gave no pose.
  /// Range [2, 64].
  int borders = 16;
  /// ... and when it is tracked from a prior pose, whose seeded lines need fewer votes to
  /// stand out; also a sheet finder's candidate's first scan (its lines are seeded too).
  /// Range [2, 64].
  int tracked_borders = 8;
  /// A candidate's first scan (on tracked_borders) is kept only when its lines identify with
  /// less than this cost (PoseResult::identification_cost, a chi-square over the widths and
  /// the geometry): widths measured on few borders that disagree with the target are
  /// measured again on `borders`. 0: every candidate is scanned on `borders` alone (a
  /// first frame's pose a third more accurate, its detection twice as long). Range [0, 1e9].
  double quick_max_identification_cost = 9.0;
  SheetFinderOptions finder;
  /// Middle-cell candidates scanned at most per pass of the sheet finder (two passes: its
  /// candidates, then those with locally dark cells). Range [1, 16].
  int max_candidates = 3;
  /// When no candidate gives a pose, take the candidates closed in on two sides that meet as
  /// the sheet's corner cells (guesses, each tried four ways: for a camera whose model check
  /// is strict).
  bool corner_cells = true;
  /// When no candidate gives a pose, scan the whole image as the paper does.
  bool image_fallback = true;
  /// Each of the four lines the pose uses needs at least this many feature points on it
  /// (DetectedLine::support): a line seen on a few borders only is too poorly placed to
  /// trust, unless it is the only one and the other three stripes hold the pose alone
  /// (HeldByTheOtherThree); a pose fitted to the stripes' points alone (no four lines) needs
  /// twice this in all. Range [0, 1000].
  int min_line_support = 12;
  /// The model check (stripe_check.h): of each stripe's samples that agree with the pose or
  /// contradict it, the fraction that must agree (a sample under a hand or a glare does
  /// neither). Range [0, 1].
  double min_stripe_agreement = 0.75;
  /// ... and of all the stripes' samples in view, the fraction that must agree (the target
  /// must be seen, not only not contradicted). Range [0, 1].
  double min_stripe_seen = 0.35;
  /// A stripe is darker than the paper beside it by at least this, grey levels. Range
  /// [1, 255].
  int min_stripe_contrast = 20;
  /// A sample agrees when the stripe's dark run is where the pose puts it within the larger
  /// of stripe_tolerance_px and stripe_tolerance_fraction of its width, and as wide within
  /// stripe_width_tolerance (stripe_check.h). A camera model that leaves the lens's bend in
  /// the stripes (the paper's uncorrected condition) needs a looser fraction. Ranges (0, 100],
  /// [0, 1], (0, 10].
  double stripe_tolerance_px = 1.0;
  double stripe_tolerance_fraction = 0.1;
  double stripe_width_tolerance = 0.35;
  /// The check's profiles read a point about every this many pixels (stripe_check.h's
  /// profile_step_px), scaled with the image as the tolerance is (never below it). Range
  /// [0.25, 16].
  double stripe_profile_step_px = 1.0;
  /// Largest move of the pose between consecutive frames without a prediction, metres and
  /// degrees; 0 turns the check off. Ranges [0, 100], [0, 180].
  double max_jump_m = 0.05;
  double max_jump_deg = 10.0;
  /// The intersections' pose refined on the stripes' feature points, the target held rigid
  /// (stripe_fit.h), and, where the lines give none, the pose fitted to those points from
  /// where the target was expected; false: the intersections' pose as the paper gives it.
  bool fit_stripes = true;
  /// When the four stripes' fit is poor, each stripe is checked against the pose the other
  /// three hold (something lying along a stripe moves its points and the pose). false while
  /// the camera model is still being told: a lens told from a few other views is least sure
  /// where they did not reach, and a stripe there fits poorly for the model's sake.
  bool check_stripes_on_poor_fit = true;
  StripeFitOptions stripe_fit;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
  /// The model check's options from the fields above.
  StripeCheckOptions StripeCheck() const;
  /// The factor the settings in pixels take for `camera` (reference_focal_px).
  double PixelScale(const Lens& camera) const;
  /// These options with their settings in pixels (stripe_tolerance_px, the finder's, the
  /// stripe fit's corridor and guide tolerance) times `scale`. `scale` in (0, 100].
  TargetTrackerOptions ScaledBy(double scale) const;
};

/// What the tracker did with one frame.
struct TargetFrame {
  TargetStatus status = TargetStatus::kNotFound;
  std::string message;  ///< empty when kOk; why otherwise
  PoseResult pose;      ///< the last pose estimated (kOk: the accepted one)
  ScanSource source = ScanSource::kNone;
  /// The outermost border scanned, image pixels (empty for the whole image), and how many.
  std::vector<Point2d> region;
  int borders = 0;
  int candidates = 0;  ///< middle-cell candidates scanned
  StripeAgreement agreement;
  StripeFit fit;  ///< the pose refined on the stripes' points (fit_stripes), when tried
  /// How straight lines 1-4 came out after the lens model's correction (nothing without a
  /// pose): the kdu error they show and the bend it puts on them (bend_px, the frame's
  /// straightness), over their feature points between the stripes' printed ends. Stripes bent
  /// by a lens the camera file does not describe (a distortion-free model on a wide lens, the
  /// wrong resolution) raise it. Measured for every pose with set_measure_lens(true), else
  /// only for one the model check refuses.
  RadialBend lens;
  bool lens_measured = false;  ///< whether `lens` was measured on this frame's lines
  double find_us = 0.0, detect_us = 0.0, pose_us = 0.0;  ///< time spent in each step
};

class TargetPoseTracker {
 public:
  /// Where the target is expected when its lines give no pose: a pose, and whether it may be
  /// turned by 180 degrees (a middle cell maps onto itself so turned; a prior pose does not).
  struct Expected {
    vpHomogeneousMatrix cMo;
    bool either_way = false;
  };

  /// Throws std::invalid_argument for options failing Check(), detector or pose options
  /// failing theirs, or a target that is not a '#' whose stripes reach past the crossings.
  TargetPoseTracker(const LineTarget& target, const Lens& camera, const DetectorOptions& detector,
                    const PoseOptions& pose,
                    const TargetTrackerOptions& options = TargetTrackerOptions());

  /// Forgets the previous frames (the next one is found from scratch).
  void Reset();
  /// The pose in `image`; `predicted_cMo` (the robot's motion applied to the last pose) is
  /// used as the prior instead of the last accepted pose, and the jump check is the caller's.
  const TargetFrame& Track(const GrayImageView& image,
                           const std::optional<vpHomogeneousMatrix>& predicted_cMo = std::nullopt);

  /// The feature points within `tolerance_px` of lines 1-4 of the last frame, when it has a
  /// pose (else empty), in the detector's pixels (undistorted when it undistorts): the points
  /// of four straight stripes, to tell a lens by (calibration/plumb_line.h). Only runs along
  /// one side of a border (one around a corner is off the centre line), between the stripe's
  /// printed ends as the pose puts them (beyond, the line runs over the bench), each moved
  /// along its run onto the image of the stripe's centre line as the pose projects it (under
  /// perspective a run's middle is not on it).
  std::array<std::vector<Point2d>, 4> StripePoints(double tolerance_px) const;
  /// StripePoints' feature points as the detector found them: each run's middle and the run
  /// across the stripe (FramePoint::across_u, across_v), not moved. For those who model the
  /// runs' middles themselves, through a lens the tracker's camera does not know.
  std::array<std::vector<FramePoint>, 4> StripeRuns(double tolerance_px) const;
  /// The lines of the last scan that gave the frame's pose (or of the last scan), best first.
  const std::vector<DetectedLine>& lines() const { return lines_; }
  const OalDetector& detector() const { return detector_; }
  const LineTarget& target() const { return target_; }
  const TargetTrackerOptions& options() const { return options_; }
  /// The last accepted pose, if the last frames had one.
  const std::optional<vpHomogeneousMatrix>& last_cMo() const { return last_cMo_; }
  /// Whether a sheet candidate may be scanned first on tracked_borders (the default); off,
  /// every candidate is scanned on `borders` at once: more feature points along each stripe,
  /// for those who use them (the lens told from the stripes).
  void set_quick_scan(bool allowed) { quick_scan_ = allowed; }
  bool quick_scan() const { return quick_scan_; }
  /// Whether each pose's lines are measured for the lens (TargetFrame::lens, what CheckLens
  /// judges; about 3 us a frame at 640x480); off (the default), only a pose the model check
  /// refuses is, to say whether the lens is why.
  void set_measure_lens(bool measure) { measure_lens_ = measure; }

 private:
  /// Detects in `borders` (the whole image when empty) and estimates the pose from `prior`;
  /// true when the pose is accepted by the model check.
  /// When the lines give no pose and `expected` says where the target should be (the prior,
  /// or a candidate's), the pose is fitted to the stripes' feature points from there
  /// (FitExpected).
  bool Attempt(const GrayImageView& image, const ScanBorders& borders,
               const std::vector<LineSeed>& seeds, const std::optional<vpHomogeneousMatrix>& prior,
               ScanSource source, const std::optional<Expected>& expected = std::nullopt);
  /// The pose fitted to the last scan's stripe points from `expected`, both ways round when it
  /// may be turned by 180 degrees (the one whose runs are as wide as its stripes): a stripe
  /// hidden on one side of the crossings, under a hand, gives no line (a border crosses it only
  /// there) but its points on the other side. Its four lines are the stripes' where it puts
  /// them. False (the frame's pose and message say why) when no fit holds.
  bool FitExpected(const Expected& expected);
  /// The last scan's points fitted from `start`, in corridors narrowing from wide to the
  /// fit's own, each fit from the last (the first guided by `guides`, when given): `start`
  /// may be pixels, or tens of pixels, off at the stripes' ends (a candidate's corners, a
  /// prediction).
  /// With `known`, it stops, not ok, as soon as a fit lands on that pose (a hair's breadth
  /// from it): the narrower corridors would end there too.
  StripeFit FitNarrowing(const vpHomogeneousMatrix& start, const StripeGuides* guides,
                         const vpHomogeneousMatrix* known = nullptr) const;
  /// `fit`, or the fit from the pose tilted the other way (MirroredTilt) when it keeps more of
  /// the stripes' points, or as many closer: without a prior, the planar ambiguity.
  StripeFit OtherTiltIfBetter(const StripeFit& fit) const;
  /// The checks on the frame's pose: enough points on each line, the stripes agreeing with
  /// each other, the model check; the lens told from the lines (set_measure_lens, or a pose
  /// the check refuses).
  bool Verify(const GrayImageView& image);
  /// Why the frame's pose is not taken: its stripes disagreed in earlier readings of the frame
  /// (kMaxDisagreeingReadings), or, when its fit fixes its rotation loosely, a stripe seen over
  /// a short stretch whose points alone hold the rotation (RotationHeldByFew), or the stripe
  /// whose points turn the pose from where the other three put it by more than those three's
  /// points allow.
  std::optional<std::string> DisagreeingStripe() const;
  /// Whether the pose does not rest on stripe `line` (0-3; false for -1): the other three
  /// stripes alone fix it tightly, where it is. Excuses the model check's one unseen stripe
  /// (StripeAgreement::Unseen: under a hand, out of view) and one line with too few points.
  bool HeldByTheOtherThree(int line) const;
  /// The lens told from the frame's lines (measured now if it was not), as a note to a
  /// refusal when the stripes bend as a lens the camera file misses would; empty otherwise.
  std::string LensNote();
  /// The pose the three stripes other than `line` hold (the frame's fit without its points),
  /// and how far it lies from the frame's.
  struct Pull {
    StripeFit without;
    double angle_rad = 0.0, shift = 0.0;  ///< the move, and the translation's over the distance
    /// The three fix the pose, and it lies farther than kMaxPullRad or kMaxPullFraction.
    bool Matters() const;
    std::string Describe() const;
  };
  Pull PullOf(int line) const;
  /// Why the frame's stripe fit is not taken, when a stripe keeping few points beside the
  /// others' (or any stripe, when the fit is poor) pulls the pose away from where the other
  /// three stripes alone put it.
  std::optional<std::string> WeakStripePull() const;
  /// Why, when stripe `line`'s points (`pull`: the fit without them) move the pose from the
  /// other three's at a cost to their RMS (see kMaxOthersRmsGrowth).
  std::optional<std::string> PullAgainstTheOthers(int line, const Pull& pull) const;
  /// Why, when stripe `line`, seen over a short stretch or keeping few points, holds the
  /// pose's rotation: the frame's fit fixes it to `four` (StripeFit::RotationDeviation), the
  /// other three alone to `three` (infinite when they do not fix it), far more loosely (see
  /// kHeldDeviationRatio).
  std::optional<std::string> RotationHeldByFew(int line, double four, double three) const;
  /// A stripe whose runs are narrower or wider than the others' (something light or dark
  /// along one side of it) and pull the pose away from where the other three stripes put it:
  /// why the frame's stripe fit is not taken, when the image's stripes lie where the three put
  /// them. Else, when its runs are wider or narrower than its parallel stripe's too, the fit is
  /// made again from its runs as wide as those alone, and the frame takes it; why not, when
  /// that fit fails (too few such runs).
  std::optional<std::string> LopsidedStripePull(const GrayImageView& image);
  /// The frame's pose becomes `fit`'s (and, for a pose fitted without lines, its lines and
  /// residual); SetLinesFromFit's answer, -1 for a pose from lines.
  int AdoptFit(const StripeFit& fit);
  /// lines_ and the pose's corners from frame_.fit's stripes (a pose fitted without lines); the
  /// line (0-3) the fit puts behind the camera, else -1.
  int SetLinesFromFit();
  /// frame_.lens from the frame's pose and its lines 1-4.
  void MeasureLens();
  /// Step 2 for the sheet finder's candidates `cells`: those closed in on three sides or more,
  /// at most max_candidates of them, best first (`as_middle_only`: as the middle cell alone,
  /// not also as a cell beyond a stripe or cut short); true when a pose is accepted.
  bool AttemptCells(const GrayImageView& image, const std::vector<LightQuad>& cells,
                    bool as_middle_only = false);
  /// A candidate closed in on four sides that gave no pose, taken as a cell beyond a stripe
  /// with each of its sides in turn on the sheet's edge; when none gives a pose, the frame is
  /// left as the candidate itself left it, with the time spent added.
  bool AttemptEdgeCellGuesses(const GrayImageView& image, const LightQuad& cell);
  /// A candidate closed in on three sides or more that gave no pose, taken as the middle cell cut
  /// by something lying across it (UncutCells, each side in turn); when none gives a pose, the
  /// frame is left as the candidate itself left it (its message, lines and region), with the
  /// time spent added.
  bool AttemptUncut(const GrayImageView& image, const LightQuad& cell);
  /// The candidates closed in on two adjacent sides that AttemptCells set aside, each taken
  /// as each of the layout's corner cells.
  bool AttemptCornerCells(const GrayImageView& image);
  /// frame_ and lines_ back to `saved` and `saved_lines`, an attempt since then undone but for
  /// its time and the candidates it scanned.
  void RestoreFrame(const TargetFrame& saved, const std::vector<DetectedLine>& saved_lines);
  /// `attempts`, guesses: true when they accept a pose; otherwise frame_ and lines_ are as
  /// before them (RestoreFrame), with the time they spent added.
  bool AsGuesses(const std::function<bool()>& attempts);
  /// A sheet finder's candidate: its borders scanned, first as few as a tracked frame's
  /// (tracked_borders), then `borders` when those give no pose or one identified at more
  /// than quick_max_identification_cost; true when a pose is accepted.
  bool AttemptCandidate(const GrayImageView& image, const vpHomography& plane_to_image,
                        ScanSource source);
  /// After a candidate's accepted pose whose stripe fit keeps one stripe's points over a short
  /// stretch of it: the target's borders and those across the stripes' middles scanned again
  /// from that pose, the new pose kept when it passes the checks, else the first unless a
  /// stripe of it is seen over less than kMinFittedExtent. False when no pose is kept.
  bool RescanWeakStripe(const GrayImageView& image, ScanSource source);
  /// Whether the accepted pose's stripe fit (when it has one) sees each stripe over
  /// kMinFittedExtent of it at least (`of_its_view`: of its stretch the pose puts in view);
  /// otherwise the frame is refused, saying so, `tried` added to the message. A stripe seen
  /// over less leaves the pose's tilt about it to a few runs.
  bool EachStripeSeenOverEnough(bool of_its_view, const std::string& tried);
  /// The fraction of stripe `line`'s centre line that the frame's pose puts in the image.
  double InViewFraction(int line) const;
  /// Whether the stripe fit left a stripe with too few runs as wide as it (StripeFit::
  /// starved_line) while the pose puts that stripe in view over kStarvedInViewFraction.
  bool StarvedStripeInView() const;
  /// The whole image's accepted pose scanned again on the target's plane (step 3): false when
  /// the two poses disagree; the frame keeps the better fitting one.
  bool ConfirmOnTarget(const GrayImageView& image);
  /// Each stripe's centre line from end to end where `plane_to_image` puts it, in the
  /// detector's coordinates; nothing for a stripe with an end behind the camera.
  std::array<std::optional<LineExtent>, 4> StripeEnds(const vpHomography& plane_to_image) const;
  /// The four lines where `plane_to_image` puts them, in the detector's coordinates.
  std::vector<LineSeed> SeedsFrom(const vpHomography& plane_to_image) const;
  /// The last scan's lines near where `plane_to_image` puts lines 1-4 (each the nearest of
  /// the stripe-like lines within a fraction of the way to its parallel partner, each line for
  /// one stripe at most).
  StripeGuides GuidesFrom(const vpHomography& plane_to_image) const;
  /// Whether poses `a` and `b` lie within max_jump_m and max_jump_deg of each other (a bound
  /// of 0 is no bound), and how far apart they are.
  bool WithinJump(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b, double* metres,
                  double* degrees) const;
  /// The model check and the jump check on an estimated pose: the frame's status.
  void Accept(bool predicted);

  LineTarget target_;
  Lens camera_;
  TargetLayout layout_;
  double pixel_scale_ = 1.0;  ///< TargetTrackerOptions::PixelScale for the camera
  PoseOptions pose_options_;
  TargetTrackerOptions options_;
  bool quick_scan_ = true;
  bool measure_lens_ = false;
  OalDetector detector_;
  SheetFinder finder_;
  std::vector<DetectedLine> lines_;
  /// This frame's candidates closed in on two sides, for AttemptCornerCells.
  std::vector<LightQuad> corner_guesses_;
  /// This frame's readings (attempts) whose stripes disagreed (DisagreeingStripe).
  int disagreeing_readings_ = 0;
  ScanBorders borders_;  ///< working memory for each attempt's borders
  TargetFrame frame_;
  GrayImageView image_{};
  std::optional<vpHomogeneousMatrix> last_cMo_;
  std::optional<vpHomogeneousMatrix> held_cMo_;  ///< a jump, waiting for the next frame
  int frames_since_ok_ = 0;  ///< 1: the last frame's pose was accepted; 0: none ever was
};

/// The lens kdu error a frame's lines 1-4 must show, beyond one standard deviation, to say
/// that the camera model misses the lens: a third of what a wrong or missing calibration
/// leaves (0.1 and more), where a matching model's frames stay under 0.01 (docs/BENCHMARKS.md).
inline constexpr double kLensMismatchKdu = 0.03;

/// Whether a frame's lines 1-4 were measured for the lens (set_measure_lens for a kept pose): those
/// of a pose, kept or refused by the model check (a camera model that misses the lens bends the
/// stripes off the lines the check expects; the frame then says why).
inline bool MeasuresLens(const TargetFrame& frame) {
  return frame.lens_measured &&
         (frame.status == TargetStatus::kOk ||
          (frame.status == TargetStatus::kModelMismatch && std::isfinite(frame.lens.kdu_error_sd)));
}

/// Whether one frame's lines say the camera model misses the lens.
inline bool ContradictsLens(const RadialBend& lens) {
  return std::fabs(lens.kdu_error) - lens.kdu_error_sd >= kLensMismatchKdu;
}

/// The lens check over several frames: whether their lines 1-4, after the camera model's
/// correction, bend as a lens the model misses would. A single frame can mislead (a mark
/// beside a stripe, a far sheet near the principal point that bends too little to tell), so
/// most of at least `min_frames` frames must say so.
struct LensCheck {
  int frames = 0;                 ///< frames with a pose that were counted
  int contradicting = 0;          ///< of them, those whose lines contradict the model
  double median_px = 0.0;         ///< the median of their straightness_px (RadialBend::bend_px)
  double median_kdu_error = 0.0;  ///< the median kdu error of the frames whose lines tell one
  bool mismatch = false;          ///< over half contradict, of at least min_frames frames
};
LensCheck CheckLens(const std::vector<RadialBend>& frames, int min_frames = 3);

}  // namespace oal
