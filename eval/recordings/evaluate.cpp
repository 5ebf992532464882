// One object per input, InputEvaluation, runs the tracking stage and owns what the input's
// steps share (its tracker, truth, tallies, plot series and output files); the pipeline's other
// stages and the judging of frames are in their own files (frame_decoder.h, annotated_output.h,
// input_truth.h, frame_judgement.h, plot_series.h).
#include "eval/recordings/evaluate.h"

#include <visp3/core/vpImage.h>
#include <visp3/core/vpThetaUVector.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include "base/angles.h"
#include "base/check.h"
#include "base/format.h"
#include "base/statistics.h"
#include "detector/lens.h"
#include "detector/options.h"
#include "detector/tracker.h"
#include "eval/lines/compare.h"
#include "eval/recordings/annotated_output.h"
#include "eval/recordings/frame_decoder.h"
#include "eval/recordings/frame_judgement.h"
#include "eval/recordings/input_truth.h"
#include "eval/recordings/pipeline.h"
#include "eval/recordings/plot_series.h"
#include "eval/recordings/report.h"
#include "io/annotate.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"
#include "io/quiet_stderr.h"
#include "io/rendered_dataset.h"
#include "io/truth_file.h"
#include "loop/lens_estimate.h"
#include "scene/bench_scene.h"  // IsSheet
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kQueueFrames = 8;         // decoded frames waiting for the tracker
constexpr std::size_t kListedUnreadable = 100;  // unreadable frames named in the summary
constexpr std::size_t kListedJumps = 100;       // jump frames named in the summary

// The options are named as the user gives them, on evaluate's command line.
template <typename T>
void Require(bool ok, const char* option, const T& value, const char* constraint) {
  RequireOption(ok, option, value, constraint);
}

// {count, mean, median, p95, max}; nulls for no values.
Json Stats(const SampleStats& values) {
  if (values.size() == 0) {
    return Json{
        {"count", 0}, {"mean", nullptr}, {"median", nullptr}, {"p95", nullptr}, {"max", nullptr}};
  }
  return Json{{"count", values.size()},
              {"mean", values.mean()},
              {"median", values.Quantile(0.5)},
              {"p95", values.Quantile(0.95)},
              {"max", values.max()}};
}

// ---------------------------------------------------------------------------------------
// Stage 2: tracking, pose and truth, per input.

// What every input shares.
struct RunContext {
  const EvaluateOptions& options;
  TrackerSetup setup;
  LineTarget target;                 ///< setup.target, else the A3 sheet
  std::optional<CameraFile> camera;  ///< --camera
  std::string chart_js;
  std::size_t target_lines = 4;  ///< lines held for the target to count as detected
};

// The camera of an input: --camera, else camera.xml next to it (or in it), else none.
std::optional<CameraFile> CameraFor(const RunContext& run, const PlannedInput& input,
                                    std::string* path) {
  if (run.camera) {
    *path = run.options.camera_path;
    return run.camera;
  }
  const fs::path spec(input.spec);
  const fs::path dir = fs::is_directory(spec) ? spec : spec.parent_path();
  const std::optional<fs::path> found = FindDatasetCamera(dir);
  if (!found) return std::nullopt;
  const fs::path candidate = *found;
  *path = candidate.string();
  static std::mutex xml_mutex;  // XML parsing (libxml2, ViSP) from several jobs: one at a time
  std::lock_guard<std::mutex> lock(xml_mutex);
  return LoadCameraFile(candidate.string());
}

Json TrackJson(const TrackedLine& track) {
  return Json{{"id", track.id},
              {"status", ToString(track.status)},
              {"rho", track.line.line.rho_px},
              {"theta", track.line.line.theta_rad},
              {"support", track.line.support},
              {"frames_seen", track.frames_seen},
              {"frames_lost", track.frames_lost}};
}

Json PoseFrameJson(const PoseResult& pose, const std::vector<int>& ids,
                   const std::optional<PoseJump>& jump, std::optional<double> straightness_px) {
  Json lines = Json::array();
  for (int track : IdentifiedTracks(pose, ids)) lines.push_back(track);
  const bool ok = pose.status == PoseStatus::kOk;
  // Step 1 ran to its end: an assignment was scored (kOk, kNotIdentifiable, or kDegenerate
  // after the identification).
  const bool identified = pose.line_index[0] >= 0;
  Json t, tu;
  if (ok) {
    const vpTranslationVector tv = pose.cMo.getTranslationVector();
    const vpThetaUVector r = pose.cMo.getThetaUVector();
    t = Json::array({tv[0], tv[1], tv[2]});
    tu = Json::array({r[0], r[1], r[2]});
  }
  return Json{{"status", ToString(pose.status)},
              {"message", pose.message},
              {"tracks", std::move(lines)},
              {"t_m", std::move(t)},
              {"thetau_rad", std::move(tu)},
              {"residual_px", ok ? Json(pose.residual_px) : Json()},
              {"straightness_px", ok && straightness_px ? Json(*straightness_px) : Json()},
              {"identification", identified ? Json{{"cost", pose.identification_cost},
                                                   {"margin", pose.identification_margin}}
                                            : Json()},
              {"jump", jump ? Json{{"from_frame", jump->from_frame},
                                   {"rotation_deg", jump->rotation_deg},
                                   {"translation_mm", jump->translation_mm},
                                   {"relabelled", jump->relabelled}}
                            : Json()}};
}

// Counters of one input, turned into its summary.
struct Tally {
  int frames = 0, readable = 0, detected = 0, pose_ok = 0;
  int lost_episodes = 0, longest_lost = 0, current_lost = 0, track_losses = 0;
  bool ever_detected = false, was_detected = false;
  int width = 0, height = 0;
  std::map<std::string, int> pose_status;
  std::vector<Json> unreadable;
  int unreadable_count = 0;
  int truth_frames = 0, truth_lines = 0, found_lines = 0, pose_truth_frames = 0;
  SampleStats angle_deg, offset_px, pose_t_mm, pose_r_deg;
  std::set<int> track_ids;
  int pose_jumps = 0;
  std::vector<int> jump_frames;
  std::vector<RadialBend> lens;                     ///< of the target tracker's frames with a pose
  std::map<std::size_t, int> frames_by_lines_held;  ///< readable frames by lines held
};

// The evaluation of one input: decoder, tracker and writer (file comment of evaluate.h).
class InputEvaluation {
 public:
  InputEvaluation(const RunContext& run, const PlannedInput& input, fs::path dir)
      : run_(run), input_(input), dir_(std::move(dir)), truth_(run.options.truth_path, input.spec) {
    camera_ = CameraFor(run, input, &camera_path_);
    series_.capacity = static_cast<std::size_t>(run.options.plot_frames);
  }

  void AddWarnings(const std::vector<std::string>& warnings) {
    warnings_.insert(warnings_.end(), warnings.begin(), warnings.end());
  }

  // Evaluates and writes every file; `on_frame` after each frame.
  Json Run(ImageSource* source, const std::function<void()>& on_frame, const FrameViewer& viewer,
           Json* timing) {
    const StageClock::time_point start = StageClock::now();
    fs::create_directories(dir_);
    TrackerOptions tracker_options;
    tracker_options.detector = run_.setup.detector;
    OalLineTracker tracker = camera_ ? OalLineTracker(tracker_options, camera_->camera)
                                     : OalLineTracker(tracker_options);
    undistorts_ = tracker.detector().Undistorts();
    if (undistorts_) {
      undistorted_by_ = camera_->camera;
      undistorter_.emplace(camera_->camera);
    }
    PoseOptions pose_options = run_.setup.pose;
    if (camera_) {
      pose_options.camera = camera_->camera;
      pose_options.lines_undistorted = undistorts_;
    }
    // A printed sheet's pose comes from the target tracker (borders on the target's plane, the
    // model check), as `pose` finds it: the line tracker's image borders cross a sheet's
    // stripes only where they reach far enough. The 2 m board's lines traverse the image, the
    // paper's condition the tracks are made for: its pose stays on them, as does any pose
    // with `tracking: {scan: image}`. The tracks stay the detection's measure either way.
    if (camera_ && IsSheet(run_.target) && run_.target.lines.size() == 4 &&
        run_.setup.tracking.scan == ScanMode::kTarget) {
      PoseOptions target_pose = pose_options;
      target_pose.compute_covariance = false;
      target_tracker_.emplace(run_.target, camera_->camera, run_.setup.detector, target_pose,
                              run_.setup.tracking);
      target_tracker_->set_measure_lens(true);  // every pose's lines feed the lens check
    }

    AtomicFile frames_file(dir_ / "frames.jsonl");
    AtomicFile timing_file(dir_ / "timing.jsonl");
    std::optional<AnnotatedVideo> video;
    if (run_.options.write_video) {
      video.emplace(dir_ / "annotated.avi", run_.options.video_scale, run_.options.video_codec,
                    run_.options.names("video_codec"));
    }

    BoundedQueue<DecodedFrame> decoded(kQueueFrames);
    BoundedQueue<TrackedFrame> tracked(kQueueFrames);
    DecodeStats decode_stats;
    WriterResult writer_result;
    std::atomic<bool> stop{false};  // the viewer's request
    Joined decoder(
        std::thread(DecodeFrames, source, run_.options.max_frames, &decoded, &decode_stats, &stop));
    Joined writer(std::thread(WriteFrames, &tracked, video ? &*video : nullptr,
                              static_cast<std::size_t>(run_.options.thumbnails), std::cref(camera_),
                              std::cref(undistorted_by_), &writer_result, std::cref(viewer),
                              &stop));
    SampleStats track_us, pose_us;
    try {
      while (std::optional<DecodedFrame> frame = decoded.Pop()) {
        if (!frame->error.empty()) {
          Unreadable(*frame, frames_file.stream(), timing_file.stream());
        } else {
          TrackedFrame out = Process(*frame, &tracker, pose_options, frames_file.stream(),
                                     timing_file.stream(), &track_us, &pose_us);
          if (!tracked.Push(std::move(out))) break;  // the writer failed
        }
        if (on_frame) on_frame();
      }
    } catch (...) {
      decoded.Close();
      tracked.Close();
      throw;
    }
    decoded.Close();
    tracked.Close();
    decoder.Join();
    writer.Join();
    if (!writer_result.error.empty()) throw std::runtime_error(writer_result.error);
    if (tally_.frames == 0) throw std::runtime_error(source->Name() + " holds no frame");
    frames_file.Commit();
    timing_file.Commit();
    if (video) video->Commit();

    Json summary = Summary(source, decode_stats);
    if (run_.options.compare) summary["compare"] = Compare();
    const double wall_us = Microseconds(StageClock::now() - start);
    *timing =
        Json{{"input", input_.spec},
             {"frames", tally_.frames},
             {"video", run_.options.write_video},
             {"video_scale", run_.options.video_scale},
             {"video_codec", run_.options.write_video ? Json(run_.options.video_codec) : Json()},
             {"decode_us", Stats(decode_us_)},
             {"track_us", Stats(track_us)},
             {"pose_us", Stats(pose_us)},
             {"decode_total_s", decode_stats.total_us * 1e-6},
             {"writer_busy_s", writer_result.busy_us * 1e-6},
             {"writer",
              {{"frames_annotated", writer_result.annotated},
               {"annotate_s", writer_result.annotate_us * 1e-6},
               {"encode_s", writer_result.encode_us * 1e-6},
               {"thumbnails_s", writer_result.thumbnail_us * 1e-6}}},
             {"wall_s", wall_us * 1e-6},
             {"overhead_vs_decode",
              decode_stats.total_us > 0 ? wall_us / decode_stats.total_us - 1.0 : 0.0}};
    Json timing_with_series = *timing;
    timing_with_series["series"] = series_.TimingJson();
    WriteFileAtomically(dir_ / "report.html",
                        InputReportHtml(summary, series_.ToJson(), timing_with_series,
                                        writer_result.thumbnails, run_.chart_js));
    WriteFileAtomically(dir_ / "timing.json", timing->dump(2) + "\n");
    WriteFileAtomically(dir_ / "summary.json", summary.dump(2) + "\n");
    return summary;
  }

 private:
  void Unreadable(const DecodedFrame& frame, std::ostream& frames, std::ostream& timing) {
    ++tally_.frames;
    ++tally_.unreadable_count;
    if (tally_.unreadable.size() < kListedUnreadable) {
      tally_.unreadable.push_back(
          Json{{"frame", frame.index}, {"source", frame.source}, {"error", frame.error}});
    }
    WriteJsonLine(frames,
                  Json{{"frame", frame.index},
                       {"source", frame.source},
                       {"status", ToString(FrameStatus::kUnreadable)},
                       {"error", frame.error}},
                  false);
    WriteJsonLine(timing, Json{{"frame", frame.index}, {"decode_us", frame.decode_us}}, false);
    decode_us_.push_back(frame.decode_us);
    PlotSeries::Row row;
    row.frame = frame.index;
    row.decode_us = frame.decode_us;
    series_.Add(std::move(row));
  }

  // The target tracker's pose of the frame, its lines 1-4 given as the held tracks' lines they
  // are (-1: no track holds it), so that the tracks' identities, jumps and drawings read it as
  // they read EstimatePose's. A frame the tracker refuses has a non-ok status and its reason.
  PoseResult TargetPose(const vpImage<unsigned char>& image,
                        const std::vector<DetectedLine>& held) {
    const TargetFrame& found = target_tracker_->Track(ViewOf(image));
    lens_ = found.lens;
    PoseResult pose = found.pose;
    if (found.status != TargetStatus::kOk) {
      if (pose.status == PoseStatus::kOk) pose.status = PoseStatus::kDegenerate;
      pose.message = ToString(found.status) + ": " + found.message;
    }
    const std::vector<DetectedLine>& lines = target_tracker_->lines();
    for (int& index : pose.line_index) {
      if (index < 0 || index >= static_cast<int>(lines.size())) {
        index = -1;
        continue;
      }
      const LineParams& line = lines[static_cast<std::size_t>(index)].line;
      index = -1;
      // The point of the line nearest the image's centre: a held line through it, at about
      // its angle, is the same line.
      const double centre_u = 0.5 * (image.getWidth() - 1.0);
      const double centre_v = 0.5 * (image.getHeight() - 1.0);
      const double off = line.SignedDistance(centre_u, centre_v);
      const double foot_u = centre_u - off * std::cos(line.theta_rad);
      const double foot_v = centre_v - off * std::sin(line.theta_rad);
      for (std::size_t i = 0; i < held.size(); ++i) {
        const bool same = AngleBetween(held[i].line, line) < vpMath::rad(1.0) &&
                          std::fabs(held[i].line.SignedDistance(foot_u, foot_v)) < 3.0;
        if (same) {
          index = static_cast<int>(i);
          break;
        }
      }
    }
    return pose;
  }

  // A frame's lines and pose against its truth, counted in the tally; the lines' errors also
  // into `plotted`.
  struct TruthComparison {
    Json json;  ///< null when the frame has no truth
    double worst_offset_px = 0.0;
    int missed = 0;
    std::optional<std::pair<double, double>> pose_error;  ///< mm, deg
  };
  TruthComparison CompareWithTruth(const FrameTruth& truth, const TrackedFrame& out, bool pose_ok,
                                   std::vector<PlotSeries::TruthLine>* plotted) {
    TruthComparison result;
    if (!truth.known) return result;
    ++tally_.truth_frames;
    Json lines = Json::array();
    for (const LineError& e :
         MatchTruth(truth.lines, out.held, out.ids, undistorter_, truth_.kind() == "json")) {
      const bool found = e.track >= 0;
      ++tally_.truth_lines;
      tally_.found_lines += found;
      result.missed += !found;
      if (found) {
        tally_.angle_deg.push_back(e.angle_deg);
        tally_.offset_px.push_back(e.offset_px);
        result.worst_offset_px = std::max(result.worst_offset_px, e.offset_px);
      }
      lines.push_back(Json{{"line", e.line},
                           {"track", e.track},
                           {"angle_deg", found ? Json(e.angle_deg) : Json()},
                           {"offset_px", found ? Json(e.offset_px) : Json()}});
      PlotSeries::TruthLine line;
      line.line = e.line;
      if (found) line.offset_px = e.offset_px, line.angle_deg = e.angle_deg;
      plotted->push_back(line);
    }
    Json pose_error_json;
    if (pose_ok && truth.cMo) {
      result.pose_error = PoseError(out.pose->cMo, *truth.cMo);
      ++tally_.pose_truth_frames;
      tally_.pose_t_mm.push_back(result.pose_error->first);
      tally_.pose_r_deg.push_back(result.pose_error->second);
      pose_error_json = Json{{"translation_mm", result.pose_error->first},
                             {"rotation_deg", result.pose_error->second}};
    }
    result.json = Json{{"lines", std::move(lines)}, {"pose", std::move(pose_error_json)}};
    return result;
  }

  // The frame's pose from the lines held (or the target tracker's), checked for a jump from
  // the last trusted pose, counted; its JSON.
  Json PoseOfFrame(const vpImage<unsigned char>& image, int index, const PoseOptions& pose_options,
                   TrackedFrame* out, std::optional<PoseJump>* jump) {
    // The last trusted pose (ok, no jump) of at most kJumpFrames before seeds the pose: the
    // previous frame's, or across frames without one the one before them; it holds the
    // identity of lines 1-4 (PoseOptions::previous_max_deg). A pose turned by 180 degrees
    // never becomes the seed.
    std::optional<vpHomogeneousMatrix> seed;
    if (trusted_ && index - trusted_->frame <= kJumpFrames) seed = trusted_->cMo;
    out->pose = target_tracker_ ? TargetPose(image, out->held)
                                : EstimatePose(out->held, run_.target, pose_options, seed);
    if (out->pose->status == PoseStatus::kOk) {
      const std::array<int, 4> identified = IdentifiedTracks(*out->pose, out->ids);
      *jump = JumpFrom(trusted_, index, out->pose->cMo, identified);
      if (*jump) {
        ++tally_.pose_jumps;
        if (tally_.jump_frames.size() < kListedJumps) tally_.jump_frames.push_back(index);
      } else {
        trusted_ = TrustedPose{index, out->pose->cMo, identified};
      }
    }
    if (!target_tracker_) return PoseFrameJson(*out->pose, out->ids, *jump, std::nullopt);
    if (out->pose->status == PoseStatus::kOk) tally_.lens.push_back(lens_);
    return PoseFrameJson(*out->pose, out->ids, *jump, lens_.bend_px);
  }

  // A readable frame in the tally: detected, posed, and the episodes of loss.
  void CountFrame(bool detected, bool pose_ok, const std::optional<PoseResult>& pose) {
    ++tally_.frames;
    ++tally_.readable;
    tally_.detected += detected;
    tally_.pose_ok += pose_ok;
    if (pose) ++tally_.pose_status[ToString(pose->status)];
    if (detected) {
      tally_.ever_detected = true;
      tally_.current_lost = 0;
    } else if (tally_.ever_detected) {
      if (tally_.was_detected) ++tally_.lost_episodes;
      tally_.longest_lost = std::max(tally_.longest_lost, ++tally_.current_lost);
    }
    tally_.was_detected = detected;
  }

  TrackedFrame Process(DecodedFrame& frame, OalLineTracker* tracker, PoseOptions pose_options,
                       std::ostream& frames, std::ostream& timing, SampleStats* track_times,
                       SampleStats* pose_times) {
    const int w = frame.gray.cols, h = frame.gray.rows;
    if (tally_.readable == 0) tally_.width = w, tally_.height = h;
    // A view of the frame for ViSP, no copy (the decoder's clone is continuous).
    const vpImage<unsigned char> image(frame.gray.data, static_cast<unsigned int>(h),
                                       static_cast<unsigned int>(w), false);
    const StageClock::time_point t0 = StageClock::now();
    tracker->track(image);
    const StageClock::time_point t1 = StageClock::now();

    TrackedFrame out;
    out.index = frame.index;
    std::vector<const TrackedLine*> held;
    Json tracks = Json::array();
    for (const TrackedLine& track : tracker->getLines()) {
      tracks.push_back(TrackJson(track));
      tally_.track_ids.insert(track.id);
      if (track.status == TrackStatus::kLost) {
        tally_.track_losses += track.frames_lost == 1;
      } else {
        held.push_back(&track);
      }
    }
    std::stable_sort(held.begin(), held.end(), [](const TrackedLine* a, const TrackedLine* b) {
      return a->line.support > b->line.support;
    });
    for (const TrackedLine* track : held) {
      out.held.push_back(track->line);
      out.ids.push_back(track->id);
    }
    Json pose_json;
    std::optional<PoseJump> jump;
    const StageClock::time_point t2 = StageClock::now();
    if (camera_) {
      pose_options.image_width = w;
      pose_options.image_height = h;
      pose_json = PoseOfFrame(image, frame.index, pose_options, &out, &jump);
    }
    const StageClock::time_point t3 = StageClock::now();
    const double track_us = Microseconds(t1 - t0), pose_us = Microseconds(t3 - t2);
    track_times->push_back(track_us);
    if (camera_) pose_times->push_back(pose_us);

    // Status and counters.
    const bool pose_ok = out.pose && out.pose->status == PoseStatus::kOk;
    const bool detected = held.size() >= run_.target_lines;
    const FrameStatus status = pose_ok        ? FrameStatus::kPose
                               : detected     ? FrameStatus::kDetected
                               : held.empty() ? FrameStatus::kLost
                                              : FrameStatus::kPartial;
    CountFrame(detected, pose_ok, out.pose);
    ++tally_.frames_by_lines_held[held.size()];

    const FrameTruth truth = truth_.Get(frame.source, frame.index, w, h);
    PlotSeries::Row row;
    const TruthComparison compared = CompareWithTruth(truth, out, pose_ok, &row.truth);
    const Json& truth_json = compared.json;
    const double worst_offset = compared.worst_offset_px;
    const int missed = compared.missed;
    const std::optional<std::pair<double, double>>& pose_error = compared.pose_error;

    FrameJudgement judgement;
    judgement.status = status;
    judgement.held = held.size();
    judgement.pose = camera_ ? &*out.pose : nullptr;
    judgement.jump = jump;
    judgement.missed = missed;
    judgement.worst_offset_px = worst_offset;
    judgement.pose_error = pose_error;
    judgement.truth_known = truth.known;
    Judge(judgement, &out.badness, &out.why);

    WriteJsonLine(frames,
                  Json{{"frame", frame.index},
                       {"source", frame.source},
                       {"status", ToString(status)},
                       {"held", held.size()},
                       {"tracks", std::move(tracks)},
                       {"pose", std::move(pose_json)},
                       {"truth", truth_json}},
                  false);
    WriteJsonLine(timing,
                  Json{{"frame", frame.index},
                       {"decode_us", frame.decode_us},
                       {"track_us", track_us},
                       {"pose_us", camera_ ? Json(pose_us) : Json()}},
                  false);
    decode_us_.push_back(frame.decode_us);

    row.frame = frame.index;
    row.status = status;
    row.held = static_cast<double>(held.size());
    if (camera_) row.pose_ok = pose_ok ? 1.0 : 0.0;
    if (pose_error) row.pose_t_mm = pose_error->first, row.pose_r_deg = pose_error->second;
    for (const TrackedLine* track : held) {
      row.tracks.push_back(
          {track->id, track->line.line.rho_px, track->line.line.theta_rad * kDegPerRad});
    }
    row.decode_us = frame.decode_us;
    row.track_us = track_us;
    if (camera_) row.pose_us = pose_us;
    series_.Add(std::move(row));

    out.gray = std::move(frame.gray);
    return out;
  }

  // Nearly nothing detected: what the detector looked for, and what to try, likeliest first,
  // never what the run already does: when most frames held fewer lines than asked, that
  // number; a single edge needs the edge polarity, unless it is the one used.
  std::string LowDetectionHint(const Tally& t) const {
    const DetectorOptions& detector = run_.setup.detector;
    const bool edges = detector.polarity == Polarity::kEdges;
    const std::string looked_for =
        edges ? "straight light/dark edges"
              : std::string(detector.polarity == Polarity::kLightLines ? "light" : "dark") +
                    " stripes " + std::to_string(static_cast<int>(detector.min_width_px)) + "-" +
                    std::to_string(static_cast<int>(detector.max_width_px)) + " px wide";
    std::string hint = "the target's " + std::to_string(run_.target_lines) +
                       " lines were found in only " + std::to_string(t.detected) + " of " +
                       std::to_string(t.readable) + " frames; the detector looked for " +
                       looked_for + " (the config's detector: section)";
    std::size_t usual = 0;
    int usual_frames = 0;
    for (const auto& [lines, frames] : t.frames_by_lines_held) {
      if (frames > usual_frames) usual = lines, usual_frames = frames;
    }
    std::vector<std::string> tries;
    if (usual > 0 && usual < run_.target_lines) {
      tries.push_back(std::to_string(usual) + " line" + (usual == 1 ? " was" : "s were") +
                      " held in " + std::to_string(usual_frames) + " of " +
                      std::to_string(t.readable) + " frames: if the scene has " +
                      std::to_string(usual) + ", evaluate with " +
                      run_.options.names("target_lines") + " " + std::to_string(usual));
    }
    if (!edges) {
      tries.push_back(
          "a single edge, as in ViSP's line/ sequence, needs polarity: edges "
          "(config/visp_line_edges.yaml)");
    } else if (usual == 0) {
      tries.push_back(
          "no edge was held: lower the detector's min_contrast, or check that the "
          "frames show one");
    }
    for (std::size_t k = 0; k < tries.size(); ++k) hint += (k == 0 ? ". " : "; or ") + tries[k];
    return hint;
  }

  Json Summary(const ImageSource* source, const DecodeStats& decode) const {
    const Tally& t = tally_;
    const int expected = source->ExpectedFrames();
    const double readable = std::max(1, t.readable);
    // Frames the container announced but that never came are unreadable too (truncation).
    const int missing =
        expected > 0 && run_.options.max_frames == 0 ? std::max(0, expected - t.frames) : 0;
    Json warnings = Json::array();
    for (const std::string& warning : warnings_) warnings.push_back(warning);
    if (missing > 0) {
      warnings.push_back(source->Name() + " announces " + std::to_string(expected) +
                         " frames but only " + std::to_string(t.frames) +
                         " could be read (truncated or corrupt)");
    }
    if (!decode.stop_reason.empty()) warnings.push_back(decode.stop_reason);
    if (t.readable > 0 && t.detected < 0.1 * t.readable) warnings.push_back(LowDetectionHint(t));
    const LensCheck lens = CheckLens(t.lens);
    if (lens.mismatch) {
      warnings.push_back(
          LensMismatchWarning(lens, "'" + camera_path_ + "'",
                              run_.options.names.With("Calibrate the camera", "calibrate")));
    }
    Json pose;
    if (camera_) {
      Json by_status = Json::object();
      for (const auto& [status, count] : t.pose_status) by_status[status] = count;
      pose = Json{{"frames_ok", t.pose_ok},
                  {"availability", t.pose_ok / readable},
                  {"straightness_px_median", lens.frames > 0 ? Json(lens.median_px) : Json()},
                  {"lens_kdu_error_median", lens.frames > 0 ? Json(lens.median_kdu_error) : Json()},
                  {"lens_frames_contradicting", lens.contradicting},
                  {"by_status", std::move(by_status)},
                  {"jumps", t.pose_jumps},
                  {"jump_frames", t.jump_frames}};
    }
    Json truth;
    if (truth_.kind() != "none" && truth_.kind() != "auto") {
      truth = Json{{"kind", truth_.kind()},
                   {"path", truth_.path()},
                   {"frames", t.truth_frames},
                   {"truth_lines", t.truth_lines},
                   {"found_lines", t.found_lines},
                   {"match_bounds",
                    {{"angle_deg", kTruthMatchAngleDeg}, {"offset_px", kTruthMatchOffsetPx}}},
                   {"angle_deg", Stats(t.angle_deg)},
                   {"offset_px", Stats(t.offset_px)},
                   {"pose_frames", t.pose_truth_frames},
                   {"pose_translation_mm", Stats(t.pose_t_mm)},
                   {"pose_rotation_deg", Stats(t.pose_r_deg)}};
    }
    return Json{{"input", input_.spec},
                {"name", input_.name},
                {"status", "complete"},
                {"source", source->Name()},
                {"width", t.width},
                {"height", t.height},
                {"frames_expected", expected > 0 ? Json(expected) : Json()},
                {"frames", t.frames},
                {"frames_readable", t.readable},
                {"frames_unreadable", t.unreadable_count + missing},
                {"unreadable", t.unreadable},
                {"camera", camera_ ? Json(camera_path_) : Json()},
                {"lines_undistorted", undistorts_},
                {"detection",
                 {{"target_lines", run_.target_lines},
                  {"frames_detected", t.detected},
                  {"rate", t.detected / readable},
                  {"lost_episodes", t.lost_episodes},
                  {"longest_lost_frames", t.longest_lost},
                  {"tracks_started", t.track_ids.size()},
                  {"track_losses", t.track_losses}}},
                {"pose", std::move(pose)},
                {"truth", std::move(truth)},
                {"compare", nullptr},
                {"warnings", std::move(warnings)}};
  }

  // The line comparison (eval/lines) on the input, its own pass over the frames, into
  // NAME/compare.
  Json Compare() const {
    CompareOptions compare;
    compare.names = run_.options.names;
    compare.input = input_.spec;
    compare.setup = run_.setup;
    compare.max_frames = run_.options.max_frames;
    compare.out_dir = (dir_ / "compare").string();
    if (truth_.kind() == "csv") {
      compare.truth = truth_.path();  // compare reads its line rows (CSV lines: no camera)
    } else {
      compare.camera_path = camera_ ? camera_path_ : "";
      if (truth_.kind() == "json") compare.truth = truth_.path();
    }
    try {
      const QuietStderr quiet;  // vpMeLine's failure messages: compare counts them
      return CompareJson(RunComparison(compare));
    } catch (const std::exception& error) {
      return Json{{"error", error.what()}};
    }
  }

  const RunContext& run_;
  const PlannedInput& input_;
  fs::path dir_;
  TruthReader truth_;
  std::optional<CameraFile> camera_;
  std::string camera_path_;
  bool undistorts_ = false;
  std::optional<Lens> undistorted_by_;
  std::optional<PointUndistorter> undistorter_;
  std::vector<std::string> warnings_;
  RadialBend lens_;  // the target tracker's last frame
  Tally tally_;
  std::optional<TrustedPose> trusted_;               ///< the last trusted pose (JumpFrom)
  std::optional<TargetPoseTracker> target_tracker_;  ///< the pose of a '#' target
  PlotSeries series_;
  SampleStats decode_us_;
};

// Removes temporary files a killed run left in `dir` (any pid: that run is gone).
void RemoveStaleTemporaries(const fs::path& dir) {
  std::error_code error;
  if (!fs::is_directory(dir, error)) return;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir, error)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) {
      RemoveQuietly(entry.path());
    }
  }
}

// A complete input's summary.json, or null.
Json CompletedSummary(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  if (!in) return Json();
  try {
    Json summary = Json::parse(in);
    if (summary.value("status", "") == "complete") return summary;
  } catch (const Json::exception&) {
  }
  return Json();
}

Json ReadJsonOrNull(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return Json();
  try {
    return Json::parse(in);
  } catch (const Json::exception&) {
    return Json();
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------

void EvaluateOptions::Check() const {
  Require(!inputs.empty(), "EvaluateOptions::inputs", "none", "videos, directories or patterns");
  Require(!out_dir.empty(), "EvaluateOptions::out_dir", "''", "an output directory is given");
  Require(jobs >= 1 && jobs <= 64, "EvaluateOptions::jobs", jobs, "1 <= jobs <= 64");
  const std::string shard = std::to_string(shard_index) + "/" + std::to_string(shard_count);
  Require(shard_count >= 1 && shard_index >= 0 && shard_index < shard_count,
          "EvaluateOptions::shard", shard, "shard I/N with 0 <= I < N");
  Require(max_frames >= 0, "EvaluateOptions::max_frames", max_frames, "max_frames >= 0");
  Require(video_scale >= 0.1 && video_scale <= 1.0, "EvaluateOptions::video_scale", video_scale,
          "0.1 <= video_scale <= 1");
  Require(video_codec == "xvid" || video_codec == "mjpg", "EvaluateOptions::video_codec",
          video_codec, "xvid or mjpg");
  Require(thumbnails >= 0 && thumbnails <= 50, "EvaluateOptions::thumbnails", thumbnails,
          "0 <= thumbnails <= 50");
  Require(plot_frames >= 16 && plot_frames <= 1000000, "EvaluateOptions::plot_frames", plot_frames,
          "16 <= plot_frames <= 1000000");
  Require(target_lines >= 0 && target_lines <= 64, "EvaluateOptions::target_lines", target_lines,
          "0 <= target_lines <= 64");
  if (fs::exists(out_dir) && !fs::is_directory(out_dir)) {
    throw std::invalid_argument("output '" + out_dir + "' is not a directory");
  }
}

EvaluateResult Evaluate(const EvaluateOptions& options,
                        const std::function<void(int, int)>& progress) {
  return Evaluate(options, progress, FrameViewer());
}

EvaluateResult Evaluate(const EvaluateOptions& options,
                        const std::function<void(int, int)>& progress, const FrameViewer& viewer) {
  options.Check();
  RunContext run{options,      options.setup, options.setup.target.value_or(FourLineA3Target()),
                 std::nullopt, LoadChartJs(), 4};
  run.setup.detector.Check();
  if (!options.camera_path.empty()) run.camera = LoadCameraFile(options.camera_path);
  run.target_lines = options.target_lines > 0 ? static_cast<std::size_t>(options.target_lines)
                                              : std::max<std::size_t>(1, run.target.lines.size());
  {
    PoseOptions check = run.setup.pose;
    check.Check();
  }
  const InputPlan plan = PlanInputs(options.inputs);
  if (plan.inputs.empty()) throw std::runtime_error(NoInputsMessage(options.inputs, plan));
  if (viewer && (plan.inputs.size() != 1 || options.jobs != 1)) {
    throw std::invalid_argument("a viewer shows one input evaluated alone, but there are " +
                                std::to_string(plan.inputs.size()) + " inputs and " +
                                std::to_string(options.jobs) + " jobs");
  }
  if (!options.truth_path.empty() && plan.inputs.size() != 1) {
    throw std::invalid_argument(
        options.names("truth_path") + " applies to one input, but there are " +
        std::to_string(plan.inputs.size()) + " (give each video a <video>.truth.csv instead)");
  }
  const fs::path out(options.out_dir);
  fs::create_directories(out);

  EvaluateResult result;
  result.skipped = plan.skipped;
  std::vector<const PlannedInput*> shard;
  for (std::size_t i = 0; i < plan.inputs.size(); ++i) {
    if (static_cast<int>(i % static_cast<std::size_t>(options.shard_count)) ==
        options.shard_index) {
      shard.push_back(&plan.inputs[i]);
    }
  }
  result.inputs.resize(shard.size());
  std::vector<Json> timings(shard.size());

  // Resumed inputs; the others' frame counts for the progress.
  std::vector<std::size_t> todo;
  int total_frames = 0;
  for (std::size_t i = 0; i < shard.size(); ++i) {
    InputOutcome& outcome = result.inputs[i];
    outcome.input = shard[i]->spec;
    outcome.name = shard[i]->name;
    const fs::path dir = out / shard[i]->name;
    if (options.resume) {
      Json summary = CompletedSummary(dir);
      if (!summary.is_null()) {
        outcome.status = "resumed";
        outcome.summary = std::move(summary);
        timings[i] = ReadJsonOrNull(dir / "timing.json");
        continue;
      }
    }
    RemoveStaleTemporaries(dir);
    todo.push_back(i);
    try {
      const int expected = OpenImageSource(shard[i]->spec)->ExpectedFrames();
      if (expected > 0) {
        total_frames += options.max_frames > 0 ? std::min(expected, options.max_frames) : expected;
      }
    } catch (const std::exception&) {
      // reported when the input is evaluated
    }
  }

  std::mutex progress_mutex;
  std::atomic<int> frames_done{0};
  std::atomic<std::size_t> next{0};
  auto on_frame = [&] {
    const int done = ++frames_done;
    if (!progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    progress(done, total_frames);
  };
  auto worker = [&] {
    for (std::size_t k = next++; k < todo.size(); k = next++) {
      const std::size_t i = todo[k];
      InputOutcome& outcome = result.inputs[i];
      try {
        std::vector<std::string> warnings;
        std::unique_ptr<ImageSource> source = OpenImageSource(shard[i]->spec, &warnings);
        InputEvaluation evaluation(run, *shard[i], out / shard[i]->name);
        evaluation.AddWarnings(warnings);
        outcome.summary = evaluation.Run(source.get(), on_frame, viewer, &timings[i]);
        outcome.status = "complete";
      } catch (const std::exception& error) {
        outcome.status = "failed";
        outcome.error = error.what();
      }
    }
  };
  {
    std::vector<std::thread> threads;
    const std::size_t count = std::min<std::size_t>(static_cast<std::size_t>(options.jobs),
                                                    std::max<std::size_t>(1, todo.size()));
    for (std::size_t t = 1; t < count; ++t) threads.emplace_back(worker);
    worker();
    for (std::thread& thread : threads) thread.join();
  }
  if (progress && frames_done > 0 && frames_done != total_frames) {
    progress(frames_done, frames_done);  // ends the progress line
  }
  result.frames = frames_done;

  Json inputs = Json::array();
  for (const InputOutcome& outcome : result.inputs) {
    inputs.push_back(Json{{"input", outcome.input},
                          {"name", outcome.name},
                          {"status", outcome.status == "resumed" ? "complete" : outcome.status},
                          {"error", outcome.error},
                          {"summary", outcome.summary}});
  }
  const bool sharded = options.shard_count > 1;
  const std::string suffix = sharded ? "-" + std::to_string(options.shard_index) + "-of-" +
                                           std::to_string(options.shard_count)
                                     : "";
  const Json run_json{{"inputs", std::move(inputs)},
                      {"skipped", result.skipped},
                      {"shard", sharded ? Json(std::to_string(options.shard_index) + "/" +
                                               std::to_string(options.shard_count))
                                        : Json()}};
  result.index_path = (out / ("index" + suffix + ".html")).string();
  WriteFileAtomically(out / ("run" + suffix + ".json"), run_json.dump(2) + "\n");
  WriteFileAtomically(result.index_path, IndexHtml(run_json, timings, run.chart_js));
  return result;
}

}  // namespace oal
