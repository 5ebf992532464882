// The comparison's run and what it writes (figures, Markdown, JSON) share the per-frame
// records and the truth handling; the methods (line_method.h) and the scoring
// (line_scoring.h) live in their own files.
#include "eval/lines/compare.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "base/check.h"
#include "base/format.h"
#include "base/statistics.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "eval/lines/opencv_methods.h"
#include "io/annotate.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"
#include "io/truth_file.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

// The visible chord of a line without one: its clip to the image.
bool ClipChord(TargetLineTruth* truth, int width, int height) {
  return ClipToRect(truth->image_line, 0.0, 0.0, width - 1.0, height - 1.0, &truth->end_a,
                    &truth->end_b);
}

std::vector<TargetLineTruth> TargetsFromDetections(const std::vector<DetectedLine>& detected,
                                                   std::size_t count, bool undistorted,
                                                   const std::optional<CameraFile>& camera,
                                                   int width, int height) {
  std::vector<TargetLineTruth> targets;
  for (std::size_t i = 0; i < detected.size() && targets.size() < count; ++i) {
    TargetLineTruth target;
    target.id = static_cast<int>(i);
    target.width_px = detected[i].width_px;
    target.image_line = target.ideal_line = detected[i].line;
    if (undistorted && camera) {  // back to image pixels: two points through the lens
      const Lens& cam = camera->camera;
      auto distort = [&](const Point2d& p) {
        return cam.Pixel((p.u - cam.u0()) / cam.px(), (p.v - cam.v0()) / cam.py());
      };
      const Point2d a = distort(detected[i].end_a), b = distort(detected[i].end_b);
      if (!std::isfinite(a.u) || !std::isfinite(b.u)) continue;
      target.image_line = LineThrough(a, b);
    }
    if (!ClipChord(&target, width, height)) continue;
    targets.push_back(target);
  }
  return targets;
}

// ---------------------------------------------------------------------------------------
// Scoring.

struct Scorer {
  double max_angle_deg, max_offset_px;
  std::optional<PointUndistorter> undistorter;  // ends for the `ideal` reference

  void Score(const std::vector<LineParams>& lines, const std::vector<TargetLineTruth>& truth,
             bool ideal, MethodResult* result) const {
    std::vector<ReferenceLine> references;
    for (const TargetLineTruth& target : truth) {
      const LineParams& reference = ideal ? target.ideal_line : target.image_line;
      const Point2d a = ideal && undistorter ? undistorter->Undistort(target.end_a)
                                             : Foot(reference, target.end_a);
      const Point2d b = ideal && undistorter ? undistorter->Undistort(target.end_b)
                                             : Foot(reference, target.end_b);
      references.push_back({reference, a, b});
    }
    const std::vector<LineMatch> matches =
        MatchLines(references, lines, max_angle_deg, max_offset_px);
    for (const LineMatch& match : matches) {
      result->angle_error_deg.push_back(match.angle_deg);
      result->offset_error_px.push_back(match.offset_px);
    }
    const int found = static_cast<int>(matches.size());
    const int missed = static_cast<int>(truth.size()) - found;
    result->truth_lines += static_cast<int>(truth.size());
    result->found_lines += found;
    result->spurious_lines += static_cast<int>(lines.size()) - found;
    result->missed_per_frame.push_back(missed);
    if (missed == 0) {
      ++result->frames_all_found;
    } else {
      result->missed_frames.push_back(result->frames);
    }
  }
};

// ---------------------------------------------------------------------------------------
// Figures.

const cv::Scalar kPalette[] = {{0, 0, 255},     {255, 0, 255},  {255, 128, 0}, {0, 160, 255},
                               {0, 200, 0},     {255, 255, 0},  {0, 255, 255}, {160, 110, 255},
                               {128, 255, 128}, {255, 160, 160}};

cv::Mat Figure(const cv::Mat& gray, int frame, const CompareReport& report,
               const std::vector<std::vector<TargetLineTruth>>& truth,
               const std::vector<bool>& undistorted, const std::optional<CameraFile>& camera) {
  cv::Mat figure;
  cv::cvtColor(gray, figure, cv::COLOR_GRAY2BGR);
  const int w = gray.cols, h = gray.rows;
  auto draw = [&](const LineParams& line, bool ideal, const cv::Scalar& colour, int thickness) {
    std::optional<Lens> by;
    if (ideal && camera) by = camera->camera;
    for (const auto& polyline : LineInFrame(line, w, h, by)) {
      for (std::size_t i = 1; i < polyline.size(); ++i) {
        cv::line(figure, polyline[i - 1], polyline[i], colour, thickness, cv::LINE_AA);
      }
    }
  };
  for (const TargetLineTruth& target : truth[static_cast<std::size_t>(frame)]) {
    draw(target.image_line, false, cv::Scalar(255, 255, 255), 3);
  }
  for (std::size_t m = 0; m < report.methods.size(); ++m) {
    const auto& lines = report.methods[m].lines[static_cast<std::size_t>(frame)];
    for (const LineParams& line : lines) draw(line, undistorted[m], kPalette[m % 10], 1);
  }
  // Legend, top left.
  const double scale = 0.4;
  const int row = 14;
  std::vector<std::pair<std::string, cv::Scalar>> entries;
  if (!truth[static_cast<std::size_t>(frame)].empty()) {
    entries.emplace_back("truth", cv::Scalar(255, 255, 255));
  }
  for (std::size_t m = 0; m < report.methods.size(); ++m) {
    entries.emplace_back(report.methods[m].name, kPalette[m % 10]);
  }
  cv::rectangle(figure, cv::Rect(0, 0, 170, row * static_cast<int>(entries.size() + 1) + 4),
                cv::Scalar(40, 40, 40), cv::FILLED);
  cv::putText(figure, "frame " + std::to_string(frame), cv::Point(4, row - 2),
              cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int y = row * static_cast<int>(i + 2) - 2;
    cv::line(figure, cv::Point(4, y - 4), cv::Point(22, y - 4), entries[i].second, 2);
    cv::putText(figure, entries[i].first, cv::Point(28, y), cv::FONT_HERSHEY_SIMPLEX, scale,
                entries[i].second, 1, cv::LINE_AA);
  }
  return figure;
}

std::string FigureName(int frame) {
  std::string number = std::to_string(frame);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return "compare_frame_" + number + ".png";
}

void CopyInto(const cv::Mat& gray, vpImage<unsigned char>* image) {
  if (static_cast<int>(image->getWidth()) != gray.cols ||
      static_cast<int>(image->getHeight()) != gray.rows) {
    image->resize(static_cast<unsigned int>(gray.rows), static_cast<unsigned int>(gray.cols));
  }
  for (int r = 0; r < gray.rows; ++r) {
    std::memcpy((*image)[static_cast<unsigned int>(r)], gray.ptr(r),
                static_cast<std::size_t>(gray.cols));
  }
}

// Frame numbers as sorted ranges, "0-2, 5, 7-9", at most `max_ranges` of them then "...".
std::string FrameRanges(std::vector<int> frames, std::size_t max_ranges = 8) {
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  std::string out;
  std::size_t ranges = 0;
  for (std::size_t i = 0; i < frames.size();) {
    std::size_t j = i;
    while (j + 1 < frames.size() && frames[j + 1] == frames[j] + 1) ++j;
    if (ranges++ == max_ranges) return out + ", ...";
    out += (out.empty() ? "" : ", ") + std::to_string(frames[i]);
    if (j > i) out += "-" + std::to_string(frames[j]);
    i = j + 1;
  }
  return out.empty() ? "none" : out;
}

// The frames on which a method threw an OpenCV error (it then finds no line there).
struct MethodFailure {
  int frames = 0;
  std::string first;  // the first such frame and the error

  void Add(int index, const Frame& frame, const cv::Exception& error) {
    if (frames++ > 0) return;
    first = "frame " + std::to_string(index) + " '" + frame.source + "', " +
            std::to_string(frame.gray.cols) + "x" + std::to_string(frame.gray.rows) +
            " px: OpenCV: " + error.err;
  }
  std::string Warning(const std::string& method) const {
    return method + " could not run on " + std::to_string(frames) + " frame" +
           (frames == 1 ? "" : "s") + " (first: " + first + "); scored as finding no line there";
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------

std::string ToString(TargetKind kind) {
  switch (kind) {
    case TargetKind::kAuto:
      return "auto";
    case TargetKind::kStripes:
      return "stripes";
    case TargetKind::kEdges:
      return "edges";
  }
  return "?";
}

TargetKind TargetKindFromString(const std::string& text) {
  if (text == "auto") return TargetKind::kAuto;
  if (text == "stripes") return TargetKind::kStripes;
  if (text == "edges") return TargetKind::kEdges;
  throw std::invalid_argument("target kind '" + text + "' is not one of auto, stripes, edges");
}

void CompareOptions::Check() const {
  auto require = [](bool ok, const std::string& field, double value, const char* constraint) {
    RequireOption(ok, "CompareOptions::" + field, value, constraint);
  };
  if (input.empty()) throw std::invalid_argument("CompareOptions::input is empty");
  require(lines >= 0 && lines <= 100, "lines", lines, "0 <= lines <= 100");
  require(max_frames >= 0, "max_frames", max_frames, "max_frames >= 0");
  require(max_angle_deg > 0.0, "max_angle_deg", max_angle_deg, "max_angle_deg > 0");
  require(max_offset_px > 0.0, "max_offset_px", max_offset_px, "max_offset_px > 0");
  require(max_stripe_width_px >= 0.0, "max_stripe_width_px", max_stripe_width_px,
          "max_stripe_width_px >= 0");
  require(figures >= 0 && figures <= 10, "figures", figures, "0 <= figures <= 10");
  me.Check();
  if (!out_dir.empty() && fs::exists(out_dir) && !fs::is_directory(out_dir)) {
    throw std::invalid_argument("output '" + out_dir + "' is not a directory");
  }
}

namespace {

// The oal-target method when the frames show a known four-line target; it needs the camera
// (camera_path) for the pose. None otherwise (a warning says why when a target is known).
std::unique_ptr<LineMethod> TargetMethod(const TrackerSetup& setup,
                                         const std::optional<CameraFile>& camera,
                                         const FieldNames& names,
                                         std::vector<std::string>* warnings) {
  if (!setup.target || setup.target->lines.size() != 4) return nullptr;
  if (!camera) {
    warnings->push_back("the target of " + setup.target_origin +
                        " is not tracked (oal-target): give the camera file (" +
                        names("camera_path") + ") for its pose");
    return nullptr;
  }
  return MakeOalTargetMethod(setup, *setup.target, camera->camera);
}

}  // namespace

namespace {

// The truth options.truth names: a CSV's line rows by frame number, or a directory of frame JSON
// files; `source` says which ("csv", "json"; left empty without --truth).
struct GivenTruth {
  std::map<int, std::vector<TargetLineTruth>> csv;
  std::string json_dir;  ///< "" = next to the images
};

GivenTruth OpenGivenTruth(const CompareOptions& options, bool camera_given, std::string* source) {
  GivenTruth given;
  const bool truth_is_csv = !options.truth.empty() && fs::path(options.truth).extension() == ".csv";
  if (truth_is_csv) {
    if (camera_given) {
      throw std::invalid_argument(
          options.names("camera_path") +
          " with a CSV truth: the CSV gives image-coordinate lines only, while the camera makes "
          "our lines undistorted; drop one of them");
    }
    given.csv = LoadTruthCsv(options.truth);
    if (given.csv.empty()) {
      throw std::runtime_error("truth " + options.truth +
                               " has no line row (frame,line,rho,theta): it matches no frame");
    }
    *source = "csv";
  } else if (!options.truth.empty()) {
    if (!fs::is_directory(options.truth)) {
      throw std::runtime_error("truth '" + options.truth +
                               "' is neither a .csv file nor a directory of frame JSON files");
    }
    given.json_dir = options.truth;
    *source = "json";
  }
  return given;
}

// A CSV truth that matches none of the input's frames is an error; one that misses some, a
// warning naming them.
void CheckCsvCoverage(const CompareOptions& options,
                      const std::map<int, std::vector<TargetLineTruth>>& csv,
                      const std::vector<int>& frames_seen, const std::vector<int>& without_truth,
                      std::vector<std::string>* warnings) {
  std::vector<int> truth_frames;
  for (const auto& [number, rows] : csv) truth_frames.push_back(number);
  const std::size_t without = without_truth.size();
  if (without == frames_seen.size()) {
    throw std::runtime_error("truth " + options.truth + " matches no frame of " + options.input +
                             ": its rows are for frames " + FrameRanges(truth_frames) +
                             ", the input's frames are " + FrameRanges(frames_seen) +
                             " (frame = the last number in the file name)");
  }
  if (without > 0) {
    warnings->push_back(std::to_string(without) + " of " + std::to_string(frames_seen.size()) +
                        " frames have no row in truth " + options.truth + " (frames " +
                        FrameRanges(without_truth) + "): scored as frames without target lines");
  }
}

// The figures (first, middle, and the frame worst for us: most lines missed, then the most
// spurious lines; fetched by a second pass over the input), compare.md and compare.json in
// --out, each written atomically, all committed together.
void WriteComparisonFiles(const CompareOptions& options,
                          const std::vector<std::unique_ptr<LineMethod>>& methods,
                          const std::vector<std::vector<TargetLineTruth>>& truth_per_frame,
                          const std::optional<CameraFile>& camera, CompareReport* out) {
  CompareReport& report = *out;
  const bool has_truth = report.truth_source != "none";
  std::vector<int> chosen{0, report.frames / 2};
  if (has_truth) {
    const MethodResult& us = report.methods[0];
    int worst = 0;
    for (int f = 1; f < report.frames; ++f) {
      if (us.missed_per_frame[static_cast<std::size_t>(f)] >
          us.missed_per_frame[static_cast<std::size_t>(worst)]) {
        worst = f;
      }
    }
    chosen.push_back(worst);
  } else {
    chosen.push_back(report.frames - 1);
  }
  std::sort(chosen.begin(), chosen.end());
  chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
  if (static_cast<int>(chosen.size()) > options.figures)
    chosen.resize(static_cast<std::size_t>(options.figures));

  fs::create_directories(options.out_dir);
  const fs::path dir(options.out_dir);
  std::vector<std::unique_ptr<AtomicFile>> files;
  if (!chosen.empty()) {
    std::vector<bool> undistorted;
    for (const auto& method : methods) undistorted.push_back(method->Undistorted());
    std::unique_ptr<ImageSource> again = OpenImageSource(options.input);
    Frame frame;
    for (int f = 0; f <= chosen.back() && again->Next(&frame); ++f) {
      if (!std::binary_search(chosen.begin(), chosen.end(), f)) continue;
      const cv::Mat figure = Figure(frame.gray, f, report, truth_per_frame, undistorted, camera);
      std::vector<unsigned char> png;
      if (!cv::imencode(".png", figure, png)) {
        throw std::runtime_error("cannot encode " + (dir / FigureName(f)).string());
      }
      files.push_back(std::make_unique<AtomicFile>(dir / FigureName(f)));
      files.back()->stream().write(reinterpret_cast<const char*>(png.data()),
                                   static_cast<std::streamsize>(png.size()));
      report.figures.push_back((dir / FigureName(f)).string());
    }
  }
  files.push_back(std::make_unique<AtomicFile>(dir / "compare.md"));
  files.back()->stream() << CompareMarkdown(report);
  files.push_back(std::make_unique<AtomicFile>(dir / "compare.json"));
  files.back()->stream() << CompareJson(report).dump(2) << '\n';
  for (auto& file : files) file->Commit();
}

// The methods compared, ours first (without truth its lines are the targets of the
// trackers): the OAL detector and tracker, vpMeLine, OpenCV's detectors, the target tracker
// when the setup names a four-line target, and the caller's.
std::vector<std::unique_ptr<LineMethod>> ComparedMethods(
    const CompareOptions& options, const std::optional<CameraFile>& camera, bool stripes,
    CompareReport* report, std::vector<std::unique_ptr<LineMethod>> extra_methods) {
  std::vector<std::unique_ptr<LineMethod>> methods;
  const DetectorOptions& detector = options.setup.detector;
  methods.push_back(std::make_unique<OalMethod>(detector, camera));
  methods.push_back(MakeOalTrackerMethod(detector, camera));
  methods.push_back(MakeVpMeLineMethod(options.me, stripes));
  for (const OpenCvLineDetector kind : kOpenCvLineDetectors) {
    methods.push_back(
        MakeOpenCvMethod(kind, stripes, detector.polarity, report->max_stripe_width_px, detector));
  }
  if (auto target = TargetMethod(options.setup, camera, options.names, &report->warnings)) {
    methods.push_back(std::move(target));
  }
  for (auto& extra : extra_methods) methods.push_back(std::move(extra));
  return methods;
}

}  // namespace

namespace {

// The renderer's truth JSON of a frame: beside the image, or in --truth's directory.
std::string TruthJsonPath(const GivenTruth& given, const Frame& frame) {
  const fs::path image(frame.source);
  return (given.json_dir.empty() ? fs::path(image).replace_extension(".json")
                                 : fs::path(given.json_dir) / (image.stem().string() + ".json"))
      .string();
}

// Each frame's truth lines: from the CSV rows of its frame number (clipped to the image), or
// from the renderer's JSON (`source` "csv", "json"); none without truth ("none").
std::vector<TargetLineTruth> TruthOf(const GivenTruth& given, const std::string& source,
                                     const Frame& frame, int index) {
  if (source == "json") return LoadTruthJson(TruthJsonPath(given, frame));
  std::vector<TargetLineTruth> lines;
  if (source == "csv") {
    const auto it = given.csv.find(FrameNumber(frame.source, index));
    if (it != given.csv.end()) {
      for (TargetLineTruth target : it->second) {
        if (ClipChord(&target, frame.gray.cols, frame.gray.rows)) lines.push_back(target);
      }
    }
  }
  return lines;
}

// What the target lines are (stripes or edges) and how far apart a stripe's edges may be
// paired, from the options, else the detector's polarity and the first frame's truth widths.
void ResolveTargetKind(const CompareOptions& options, const std::vector<TargetLineTruth>& truth,
                       CompareReport* report) {
  report->target_kind = options.target_kind;
  if (report->target_kind == TargetKind::kAuto) {
    report->target_kind = options.setup.detector.polarity == Polarity::kEdges
                              ? TargetKind::kEdges
                              : TargetKind::kStripes;
  }
  report->max_stripe_width_px = options.max_stripe_width_px;
  if (report->max_stripe_width_px == 0.0) {
    double widest = 0.0;
    for (const TargetLineTruth& target : truth) widest = std::max(widest, target.width_px);
    report->max_stripe_width_px = widest > 0.0 ? 1.5 * widest + 2.0 : 30.0;
  }
}

// The methods run on the frames one after the other, each timed around its own call and
// scored; without truth, our detector's first lines are the trackers' targets.
class MethodRunner {
 public:
  MethodRunner(const CompareOptions& options, std::vector<std::unique_ptr<LineMethod>> methods,
               const std::optional<CameraFile>& camera, bool has_truth, CompareReport* report)
      : options_(options),
        methods_(std::move(methods)),
        camera_(camera),
        has_truth_(has_truth),
        report_(report),
        scorer_{options.max_angle_deg, options.max_offset_px, std::nullopt},
        failures_(methods_.size()) {
    if (camera_) scorer_.undistorter.emplace(camera_->camera);
    for (const auto& method : methods_) {
      MethodResult result;
      result.name = method->Name();
      result.reference = !has_truth_                      ? "none"
                         : report_->truth_source == "csv" ? "csv"
                         : method->Undistorted()          ? "ideal"
                                                          : "distorted_fit";
      report_->methods.push_back(std::move(result));
    }
  }

  // Frame `index` with its truth: every method's lines, time and score.
  void Run(const Frame& frame, int index, const std::vector<TargetLineTruth>& truth) {
    CopyInto(frame.gray, &image_);
    std::vector<TargetLineTruth> targets = truth;
    for (std::size_t m = 0; m < methods_.size(); ++m) {
      LineMethod& method = *methods_[m];
      if (index == 0 && m > 0) method.Start(image_, targets, has_truth_);
      const double time_us = Timed(m, frame, index);
      if (m == 0 && !has_truth_) targets = OurLinesAsTargets(frame);
      Score(time_us, truth, targets, method, &report_->methods[m]);
    }
    for (std::size_t m = 1; m < methods_.size(); ++m) {
      methods_[m]->AfterFrame(image_, targets, has_truth_);
    }
  }

  // Failures, re-initialisations and methods that could not run, into the report.
  void Finish() {
    for (std::size_t m = 0; m < methods_.size(); ++m) {
      report_->methods[m].failures = methods_[m]->failures();
      report_->methods[m].reinitialisations = methods_[m]->reinitialisations();
      if (failures_[m].frames > 0) {
        report_->warnings.push_back(failures_[m].Warning(report_->methods[m].name));
      }
    }
  }

  const std::vector<std::unique_ptr<LineMethod>>& methods() const { return methods_; }

 private:
  // Method m's call on the frame, in microseconds; its lines in lines_.
  double Timed(std::size_t m, const Frame& frame, int index) {
    const auto start = std::chrono::steady_clock::now();
    try {
      methods_[m]->Process(image_, &lines_);
    } catch (const cv::Exception& error) {  // e.g. an image too small for the method
      lines_.clear();
      failures_[m].Add(index, frame, error);
    }
    const auto stop = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::micro>(stop - start).count();
  }

  std::vector<TargetLineTruth> OurLinesAsTargets(const Frame& frame) const {
    const OalMethod& ours = static_cast<const OalMethod&>(*methods_.front());
    const std::size_t count = options_.lines > 0 ? static_cast<std::size_t>(options_.lines) : 4;
    return TargetsFromDetections(ours.last(), count, ours.Undistorted(), camera_, frame.gray.cols,
                                 frame.gray.rows);
  }

  void Score(double time_us, const std::vector<TargetLineTruth>& truth,
             const std::vector<TargetLineTruth>& targets, const LineMethod& method,
             MethodResult* result) {
    const std::size_t k =
        options_.lines > 0 ? static_cast<std::size_t>(options_.lines) : truth.size() + 2;
    if (lines_.size() > k) lines_.resize(k);
    result->time_us.push_back(time_us);
    const std::size_t per = has_truth_ ? truth.size() : targets.size();
    result->time_us_per_line.push_back(time_us /
                                       static_cast<double>(std::max<std::size_t>(1, per)));
    if (has_truth_) {
      scorer_.Score(lines_, truth, method.Undistorted(), result);
    } else {
      result->spurious_lines += static_cast<int>(lines_.size());  // lines, unscored
    }
    result->lines.push_back(lines_);
    ++result->frames;
  }

  const CompareOptions& options_;
  std::vector<std::unique_ptr<LineMethod>> methods_;
  const std::optional<CameraFile>& camera_;
  const bool has_truth_;
  CompareReport* report_;
  Scorer scorer_;
  std::vector<MethodFailure> failures_;
  vpImage<unsigned char> image_;
  std::vector<LineParams> lines_;
};

}  // namespace

CompareReport RunComparison(const CompareOptions& options,
                            std::vector<std::unique_ptr<LineMethod>> extra_methods) {
  options.Check();
  CompareReport report;
  report.options = options;
  options.setup.detector.Check();
  std::optional<CameraFile> camera;
  if (!options.camera_path.empty()) camera = LoadCameraFile(options.camera_path);
  const GivenTruth given = OpenGivenTruth(options, camera.has_value(), &report.truth_source);

  // Unexpected files skipped in a directory, and files after a pattern's gap, are warned
  // about (the truth JSON and camera.xml are expected there: no warning).
  std::unique_ptr<ImageSource> source = OpenImageSource(options.input, &report.warnings);
  Frame frame;
  if (!source->Next(&frame)) throw std::runtime_error(source->Name() + " holds no frame");
  report.width = frame.gray.cols;
  report.height = frame.gray.rows;
  if (camera) {
    if (auto warning =
            CameraSizeMismatch(*camera, frame.gray.cols, frame.gray.rows, frame.source)) {
      report.warnings.push_back(*warning);
    }
  }
  if (report.truth_source.empty()) {
    const std::string json = TruthJsonPath(given, frame);
    report.truth_source = fs::is_regular_file(json) ? "json" : "none";
    if (report.truth_source == "none") {
      report.warnings.push_back("no truth (" + json + " does not exist): only timing is measured");
    }
  }
  const bool has_truth = report.truth_source != "none";
  std::vector<TargetLineTruth> truth = TruthOf(given, report.truth_source, frame, 0);
  ResolveTargetKind(options, truth, &report);
  const bool stripes = report.target_kind == TargetKind::kStripes;
  MethodRunner runner(options,
                      ComparedMethods(options, camera, stripes, &report, std::move(extra_methods)),
                      camera, has_truth, &report);

  std::vector<std::vector<TargetLineTruth>> truth_per_frame;
  std::vector<int> csv_frames_seen, csv_frames_without_truth;  // frame numbers (CSV truth)
  int index = 0;
  do {
    if (index > 0) truth = TruthOf(given, report.truth_source, frame, index);
    if (report.truth_source == "csv") {
      const int number = FrameNumber(frame.source, index);
      csv_frames_seen.push_back(number);
      if (given.csv.count(number) == 0) csv_frames_without_truth.push_back(number);
    }
    runner.Run(frame, index, truth);
    truth_per_frame.push_back(has_truth ? truth : std::vector<TargetLineTruth>());
    ++index;
  } while ((options.max_frames == 0 || index < options.max_frames) && source->Next(&frame));
  report.frames = index;
  runner.Finish();
  if (report.truth_source == "csv") {
    CheckCsvCoverage(options, given.csv, csv_frames_seen, csv_frames_without_truth,
                     &report.warnings);
  }
  if (options.out_dir.empty()) return report;

  WriteComparisonFiles(options, runner.methods(), truth_per_frame, camera, &report);
  return report;
}

std::string CompareMarkdown(const CompareReport& report) {
  std::ostringstream out;
  const bool truth = report.truth_source != "none";
  out << "Line detectors compared on " << report.options.input << ": " << report.frames
      << " frames " << report.width << "x" << report.height << ", truth: " << report.truth_source
      << ", target lines: " << ToString(report.target_kind);
  if (truth) {
    out << ", a line is found within " << report.options.max_angle_deg << "° and "
        << report.options.max_offset_px << " px, scored lines per frame: "
        << (report.options.lines > 0 ? std::to_string(report.options.lines) : "truth + 2");
  }
  out << "\n\n";
  if (truth) {
    out << "| method | reference | frames all found | lines found | angle error mean / p95 (°) "
           "| offset error mean / p95 (px) | spurious / frame | time / frame, median (µs) | "
           "time / line, median (µs) | failures / re-inits |\n"
        << "|---|---|---|---|---|---|---|---|---|---|\n";
  } else {
    out << "| method | lines / frame | time / frame, median (µs) | time / line, median (µs) | "
           "failures / re-inits |\n|---|---|---|---|---|\n";
  }
  for (const MethodResult& m : report.methods) {
    const std::string tracker = m.reinitialisations < 0 ? "—"
                                                        : std::to_string(m.failures) + " / " +
                                                              std::to_string(m.reinitialisations);
    const double frames = std::max(1, m.frames);
    if (truth) {
      out << "| " << m.name << " | " << m.reference << " | " << m.frames_all_found << " / "
          << m.frames << " | " << m.found_lines << " / " << m.truth_lines << " | "
          << Fixed(Mean(m.angle_error_deg), 3) << " / "
          << Fixed(Quantile(m.angle_error_deg, 0.95), 3) << " | "
          << Fixed(Mean(m.offset_error_px), 2) << " / "
          << Fixed(Quantile(m.offset_error_px, 0.95), 2) << " | "
          << Fixed(m.spurious_lines / frames, 2) << " | " << Fixed(Quantile(m.time_us, 0.5), 0)
          << " | " << Fixed(Quantile(m.time_us_per_line, 0.5), 0) << " | " << tracker << " |\n";
    } else {
      out << "| " << m.name << " | " << Fixed(m.spurious_lines / frames, 2) << " | "
          << Fixed(Quantile(m.time_us, 0.5), 0) << " | "
          << Fixed(Quantile(m.time_us_per_line, 0.5), 0) << " | " << tracker << " |\n";
    }
  }
  return out.str();
}

Json CompareJson(const CompareReport& report) {
  const bool truth = report.truth_source != "none";
  Json methods = Json::array();
  for (const MethodResult& m : report.methods) {
    Json method{{"name", m.name}, {"reference", m.reference}, {"frames", m.frames}};
    if (truth) {
      method["frames_all_found"] = m.frames_all_found;
      method["truth_lines"] = m.truth_lines;
      method["found_lines"] = m.found_lines;
      method["angle_error_deg"] = {{"mean", Mean(m.angle_error_deg)},
                                   {"p95", Quantile(m.angle_error_deg, 0.95)}};
      method["offset_error_px"] = {{"mean", Mean(m.offset_error_px)},
                                   {"p95", Quantile(m.offset_error_px, 0.95)}};
      method["spurious_per_frame"] =
          m.frames ? static_cast<double>(m.spurious_lines) / m.frames : 0.0;
      method["missed_frames"] = m.missed_frames;
    } else {
      method["lines_per_frame"] = m.frames ? static_cast<double>(m.spurious_lines) / m.frames : 0.0;
    }
    method["time_us_per_frame_median"] = Quantile(m.time_us, 0.5);
    method["time_us_per_line_median"] = Quantile(m.time_us_per_line, 0.5);
    if (m.reinitialisations >= 0) {
      method["failures"] = m.failures;
      method["reinitialisations"] = m.reinitialisations;
    }
    methods.push_back(std::move(method));
  }
  const CompareOptions& o = report.options;
  return Json{{"input", o.input},
              {"truth", report.truth_source},
              {"frames", report.frames},
              {"width", report.width},
              {"height", report.height},
              {"target_kind", ToString(report.target_kind)},
              {"max_angle_deg", o.max_angle_deg},
              {"max_offset_px", o.max_offset_px},
              {"lines_scored", o.lines > 0 ? Json(o.lines) : Json("truth + 2")},
              {"max_stripe_width_px", report.max_stripe_width_px},
              {"vpme",
               {{"range_px", o.me.range_px},
                {"threshold", o.me.threshold},
                {"sample_step_px", o.me.sample_step_px},
                {"drift_angle_deg", o.me.drift_angle_deg},
                {"drift_offset_px", o.me.drift_offset_px}}},
              {"methods", std::move(methods)},
              {"figures", report.figures},
              {"warnings", report.warnings}};
}

}  // namespace oal
