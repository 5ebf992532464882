// `oalservo evaluate`: how well the tracker and the pose hold up on recorded videos, before a
// robot is servoed with them (docs/EVALUATE.md has the user's guide and the file formats).
//
// Inputs. Each INPUT is a video OpenCV reads, an image sequence (a directory of images or a
// printf pattern, io/image_source.h), a single image, or a directory of these: a directory
// holding at least one image is one image sequence; any other directory stands for its
// entries, sorted by name: each video file and each subdirectory holding images is one
// input, every other entry is skipped and listed in the report (but the companion files,
// IsCompanionFile in io/image_source.h: camera.xml, truth JSON and CSV). No input at all is
// an error. The inputs, in that order, are numbered 0, 1, ...; `--shard I/N` keeps those
// whose number is I modulo N.
//
// Outputs, in --out DIR, one directory per input (named after the input, "-2", "-3" ... for
// repeated names; the names depend on the whole input list, not on the shard):
//
//   NAME/frames.jsonl    one JSON object per frame: tracks, pose, status, truth errors
//   NAME/timing.jsonl    per frame: decode, track and pose times (microseconds)
//   NAME/annotated.avi   the frames with the tracks (ids), lines 1-4 and the target frame
//                        (XVID, half size by default; unless --no-video)
//   NAME/compare/        with --compare: `oalservo compare`'s compare.md, compare.json
//   NAME/timing.json     timing statistics, decode time against the wall time
//   NAME/report.html     the input's report: plots (Chart.js, inlined) and worst frames
//   NAME/summary.json    frames, detection rate, lost-track episodes, pose availability,
//                        truth errors; written last: its presence means the input is done
//   index.html, run.json the inputs of the run (index-I-of-N.html, run-I-of-N.json with
//                        --shard), links to the reports; failed inputs and skipped files
//
// Every file is written under a temporary name and renamed (io/atomic_file.h). Timings live
// only in timing.jsonl, timing.json and the reports' timing block, so every other file is
// byte-identical between runs with any --jobs (tests compare them).
//
// Per input, three threads: the decoder reads frames into a bounded queue, this thread tracks
// and estimates the pose, the writer draws and encodes the annotated video and the worst
// frames' thumbnails. The wall time is then close to the decoding time when the decoder is
// the slowest stage (timing.json: overhead_vs_decode).
#pragma once

#include <functional>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "base/field_names.h"
#include "eval/lines/oal_methods.h"
#include "eval/recordings/input_plan.h"
#include "io/json_io.h"

namespace oal {

struct EvaluateOptions {
  /// Videos, image sequences, or directories of these (file comment).
  std::vector<std::string> inputs;
  /// Our detector, pose and tracking, and the target the inputs show (nothing: the A3 sheet,
  /// four-line-a3); `oalservo evaluate` reads them from its configuration.
  TrackerSetup setup;
  /// ViSP camera XML for every input; "": camera.xml next to each input if there is one,
  /// else the input gets no pose (tracking only, said in its summary).
  std::string camera_path;
  /// Truth for the single input: a .csv (io/truth_file.h) or a directory of frame JSON
  /// files; "": per input, the renderer's JSON next to each image, or <video>.truth.csv next
  /// to a video. Given with several inputs it is an error.
  std::string truth_path;
  /// Also run `oalservo compare`'s methods on each input (eval/lines/compare.h).
  bool compare = false;
  /// Inputs processed at once, [1, 64].
  int jobs = 1;
  /// Keep the inputs whose number is shard_index modulo shard_count; 0 <= index < count.
  int shard_index = 0, shard_count = 1;
  /// Skip the inputs whose summary.json says they are complete; redo the others.
  bool resume = false;
  /// Write NAME/annotated.avi.
  bool write_video = true;
  /// Size of the annotated video relative to the frames, [0.1, 1]; the frames are scaled
  /// first and drawn on at that size. Encoding it is the writer's main cost: half size by
  /// default, a quarter of the pixels (docs/EVALUATE.md, figures).
  double video_scale = 0.5;
  /// The annotated video's codec: "xvid" (MPEG-4 part 2 by OpenCV's FFmpeg backend, the
  /// fastest here) or "mjpg" (OpenCV's own encoder, quality 75, every frame a key frame).
  std::string video_codec = "xvid";
  /// Lines held for the target to count as detected in a frame; 0: the configuration's
  /// target's line count (4 for the four-line target). [0, 64].
  int target_lines = 0;
  /// Frames per input at most; 0: all. >= 0.
  int max_frames = 0;
  /// Worst frames shown as thumbnails in each report, [0, 50].
  int thumbnails = 6;
  /// The report's plots keep between this many frames and twice as many, evenly spaced (a
  /// long input's are thinned out; frames.jsonl keeps every frame). [16, 1000000].
  int plot_frames = 2048;
  /// Output directory, created if missing; required.
  std::string out_dir;
  /// How the caller names these options to its user ("target_lines" -> "--lines"), in the
  /// advice the summaries and messages give; unnamed ones keep their own names.
  FieldNames names;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// What happened to one input of the shard.
struct InputOutcome {
  std::string input;
  std::string name;
  std::string status;  ///< "complete", "resumed" (done by an earlier run) or "failed"
  std::string error;   ///< why it failed
  Json summary;        ///< its summary.json (null when failed before any frame)
};

struct EvaluateResult {
  std::vector<InputOutcome> inputs;  ///< the shard's inputs, in plan order
  std::vector<std::string> skipped;  ///< from the plan
  std::string index_path;            ///< index.html written
  int frames = 0;                    ///< frames evaluated in this run (resumed inputs: 0)
};

/// Evaluates every input of the shard into options.out_dir (file comment). An input that
/// cannot be read fails alone: the others go on. `progress(done, total)` is called with the
/// frames done over the shard's inputs (total: the frames the inputs announce; 0 unknown),
/// from one thread at a time. Throws std::invalid_argument for bad options and
/// std::runtime_error for no input at all (before anything is written), a bad camera
/// file, a missing Chart.js (report.h) or an output that cannot be written.
/// Shown each annotated frame (BGR, the frame's size) with a caption, from the writer's
/// thread; returns false to stop: the input ends there, its frames so far evaluated.
using FrameViewer = std::function<bool(const cv::Mat& annotated, const std::string& caption)>;

/// As above; a `viewer` is given every frame of the one input (it needs one input and one
/// job: std::invalid_argument otherwise).
EvaluateResult Evaluate(const EvaluateOptions& options,
                        const std::function<void(int done, int total)>& progress,
                        const FrameViewer& viewer);
EvaluateResult Evaluate(const EvaluateOptions& options,
                        const std::function<void(int done, int total)>& progress = {});

}  // namespace oal
