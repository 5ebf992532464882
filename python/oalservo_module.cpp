// The Python module `oalservo` (pybind11): the target tracker, the bare detector, the camera
// and the target from a Python session, frames as NumPy arrays (docs/PYTHON.md). ViSP's
// conventions: cMo a 4x4 NumPy array in metres, pixels (u, v) with v down.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <array>
#include <chrono>
#include <cstring>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/config.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "io/camera_file.h"
#include "scene/bench_scene.h"
#include "scene/scene.h"
#include "servo/target_tracker.h"
#include "target/line_target.h"

namespace py = pybind11;

namespace oal {
namespace {

// A frame the C++ side reads: a view of the array's own memory when it is contiguous grey,
// else a grey copy (BGR converted as cv2 gives it). `keep` holds what the view points into.
struct PythonFrame {
  GrayImageView view;
  cv::Mat converted;
};

PythonFrame FrameOf(const py::array& array) {
  if (array.dtype().kind() != 'u' || array.itemsize() != 1) {
    throw py::value_error("the image must be uint8 (got " + std::string(py::str(array.dtype())) +
                          ")");
  }
  if (array.ndim() != 2 && !(array.ndim() == 3 && array.shape(2) == 3)) {
    throw py::value_error("the image must be H x W grey or H x W x 3 BGR (got " +
                          std::to_string(array.ndim()) + " dimensions)");
  }
  const int rows = static_cast<int>(array.shape(0)), cols = static_cast<int>(array.shape(1));
  if (rows < 16 || cols < 16) throw py::value_error("the image is smaller than 16 x 16");
  const int channels = array.ndim() == 3 ? 3 : 1;
  // Rows may be padded (a crop of a larger array); pixels within a row must be packed.
  if (array.strides(1) != channels || (channels == 3 && array.strides(2) != 1) ||
      array.strides(0) < cols * channels) {
    throw py::value_error(
        "the image's pixels must be contiguous within each row (use numpy.ascontiguousarray)");
  }
  PythonFrame frame;
  const auto* data = static_cast<const std::uint8_t*>(array.data());
  if (channels == 1) {
    frame.view = GrayImageView{data, cols, rows, static_cast<std::ptrdiff_t>(array.strides(0))};
    return frame;
  }
  const cv::Mat bgr(rows, cols, CV_8UC3, const_cast<std::uint8_t*>(data),
                    static_cast<std::size_t>(array.strides(0)));
  cv::cvtColor(bgr, frame.converted, cv::COLOR_BGR2GRAY);
  frame.view = GrayImageView{frame.converted.data, cols, rows,
                             static_cast<std::ptrdiff_t>(frame.converted.step)};
  return frame;
}

Lens CameraOfFile(const std::string& path, const std::string& name) {
  return LoadCameraFile(path, name).camera;
}

py::array_t<double> MatrixOf(const vpHomogeneousMatrix& m) {
  py::array_t<double> out({4, 4});
  auto view = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) view(r, c) = m[static_cast<unsigned>(r)][static_cast<unsigned>(c)];
  }
  return out;
}

vpHomogeneousMatrix HomogeneousOf(const py::array_t<double>& array) {
  if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
    throw py::value_error("cMo must be a 4 x 4 array");
  }
  vpHomogeneousMatrix m;
  auto view = array.unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m[static_cast<unsigned>(r)][static_cast<unsigned>(c)] = view(r, c);
  }
  return m;
}

// The tracker's options, as a configuration's detector:, pose: and tracking: sections give them.
struct TrackingOptions {
  DetectorOptions detector;
  PoseOptions pose;
  TargetTrackerOptions tracking;

  void Check() const {
    detector.Check();
    pose.Check();
    tracking.Check();
  }
};

// A configuration file read as `oalservo pose --config` reads it: its target and options.
struct ConfigFile {
  LineTarget target;
  TrackingOptions options;
};

ConfigFile LoadConfigFile(const std::string& path) {
  const AppConfig config = LoadConfig(path);
  return {config.target, {config.detector, config.pose, config.tracking}};
}

// What Python gets of a tracked frame: plain values, copied out of the tracker.
struct PyTargetFrame {
  std::string status, message;
  std::optional<py::array_t<double>> cMo;
  std::vector<std::array<double, 2>> corners_px;  ///< empty until lines 1-4 are identified
  std::array<int, 4> lines{-1, -1, -1, -1};
  double time_us = 0.0;  ///< the tracker's own time on the frame, microseconds
};

// `options`, once they pass their checks (the tracker scales some of them first, which could
// hide a bad value).
const TrackingOptions& Checked(const TrackingOptions& options) {
  options.Check();
  return options;
}

class PyTracker {
 public:
  PyTracker(const LineTarget& target, const Lens& camera, const TrackingOptions& options)
      : tracker_(target, camera, Checked(options).detector, options.pose, options.tracking) {}

  PyTargetFrame Track(const py::array& image) {
    const PythonFrame frame = FrameOf(image);
    TargetFrame result;
    double time_us = 0.0;
    {
      py::gil_scoped_release release;  // a capture thread keeps running meanwhile
      const auto start = std::chrono::steady_clock::now();
      result = tracker_.Track(frame.view);
      time_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                    .count();
    }
    PyTargetFrame out;
    out.status = ToString(result.status);
    out.message = result.message;
    if (result.status == TargetStatus::kOk) out.cMo = MatrixOf(result.pose.cMo);
    out.lines = result.pose.line_index;
    if (out.lines[0] >= 0 && out.lines[1] >= 0 && out.lines[2] >= 0 && out.lines[3] >= 0) {
      for (const Point2d& corner : result.pose.corners_px)
        out.corners_px.push_back({corner.u, corner.v});
    }
    out.time_us = time_us;
    return out;
  }
  void Reset() { tracker_.Reset(); }

 private:
  TargetPoseTracker tracker_;
};

struct PyLine {
  double rho_px, theta_rad;
  int votes, support;
  std::array<double, 2> end_a, end_b;
};

std::vector<PyLine> Detect(const py::array& image, const TrackingOptions& options) {
  const PythonFrame frame = FrameOf(image);
  OalDetector detector{options.detector};
  std::vector<DetectedLine> lines;
  {
    py::gil_scoped_release release;
    lines = detector.Detect(frame.view);
  }
  std::vector<PyLine> out;
  for (const DetectedLine& line : lines) {
    out.push_back({line.line.rho_px,
                   line.line.theta_rad,
                   line.votes,
                   line.support,
                   {line.end_a.u, line.end_a.v},
                   {line.end_b.u, line.end_b.v}});
  }
  return out;
}

// A rendered frame of `target` on the evaluation bench from a drawn pose (or `cMo`), and
// its truth: (image, cMo).
py::tuple Render(const LineTarget& target, const Lens& camera, int width, int height,
                 std::uint64_t seed, const std::optional<py::array_t<double>>& cMo) {
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.camera = camera;
  options.noise_sigma = 2.0;
  options.blur_sigma_px = 0.6;
  DressAsBench(&options, seed);
  const SceneRenderer renderer(target, options);
  std::uint64_t state = seed;
  const vpHomogeneousMatrix pose =
      cMo ? HomogeneousOf(*cMo) : SamplePose(renderer, SheetSampling(target), &state);
  const RenderedFrame frame = renderer.Render(pose, seed);
  py::array_t<std::uint8_t> image({height, width});
  std::memcpy(image.mutable_data(), frame.image.bitmap, static_cast<std::size_t>(width) * height);
  return py::make_tuple(image, MatrixOf(frame.cMo));
}

}  // namespace
}  // namespace oal

PYBIND11_MODULE(_oalservo, m) {
  using namespace oal;
  m.doc() = "oalservo: the OAL line detector and the four-line target's pose (docs/PYTHON.md)";

  py::class_<Lens>(m, "Camera", "A camera's intrinsics and lens (detector/lens.h)")
      .def(py::init(
               [](double px, double py, double u0, double v0, double kdu, int width, int height) {
                 if (kdu == 0.0) return Lens::Pinhole(px, py, u0, v0);
                 return Lens::WithKdu(px, py, u0, v0, kdu, width, height);
               }),
           py::arg("px"), py::arg("py"), py::arg("u0"), py::arg("v0"), py::arg("kdu") = 0.0,
           py::arg("width") = 640, py::arg("height") = 480)
      .def_static("from_file", &CameraOfFile, py::arg("path"), py::arg("name") = "",
                  "A camera file: ViSP's XML, OpenCV's calibration YAML or ROS's camera_info")
      .def_static("from_xml", &CameraOfFile, py::arg("path"), py::arg("name") = "",
                  "The same as from_file (any of the three formats)")
      .def_property_readonly("px", &Lens::px)
      .def_property_readonly("py", &Lens::py)
      .def_property_readonly("u0", &Lens::u0)
      .def_property_readonly("v0", &Lens::v0)
      .def("__repr__", [](const Lens& lens) {
        return "Camera(px=" + std::to_string(lens.px()) + ", py=" + std::to_string(lens.py()) +
               ", u0=" + std::to_string(lens.u0()) + ", v0=" + std::to_string(lens.v0()) + ", " +
               LensModelName(lens) + ")";
      });

  py::class_<LineTarget>(m, "Target", "A planar line target (target/line_target.h)")
      .def_static("builtin", &TargetByName, py::arg("name") = "four-line-a3",
                  "A built-in target by name: four-line-a3, four-line-a4, ...")
      .def_static(
          "from_yaml", [](const std::string& path) { return LoadConfig(path).target; },
          py::arg("path"), "The target: section of a configuration (config/four-line-a3.yaml)")
      .def_readonly("name", &LineTarget::name);

  py::class_<DetectorOptions>(m, "DetectorOptions",
                              "The detector's options, as a configuration's detector: section")
      .def(py::init<>())
      .def_readwrite("start_px", &DetectorOptions::start_px)
      .def_readwrite("step_px", &DetectorOptions::step_px)
      .def_property(
          "polarity", [](const DetectorOptions& o) { return ToString(o.polarity); },
          [](DetectorOptions& o, const std::string& text) {
            o.polarity = PolarityFromString(text);
          })
      .def_readwrite("fixed_threshold", &DetectorOptions::fixed_threshold)
      .def_readwrite("min_contrast", &DetectorOptions::min_contrast)
      .def_readwrite("min_relative_contrast", &DetectorOptions::min_relative_contrast)
      .def_readwrite("min_width_px", &DetectorOptions::min_width_px)
      .def_readwrite("max_width_px", &DetectorOptions::max_width_px)
      .def_readwrite("min_crossing_angle_deg", &DetectorOptions::min_crossing_angle_deg)
      .def_readwrite("max_points_per_border", &DetectorOptions::max_points_per_border)
      .def("check", &DetectorOptions::Check,
           "Raises ValueError naming the field, its value and the constraint");

  py::class_<TrackingOptions>(m, "Options",
                              "The tracker's options: detector (a DetectorOptions), and the "
                              "pose's and the tracking's, as a configuration's sections")
      .def(py::init<>())
      .def_readwrite("detector", &TrackingOptions::detector)
      .def("check", &TrackingOptions::Check,
           "Raises ValueError naming the field, its value and the constraint");

  py::class_<ConfigFile>(m, "Config", "A configuration file's target and options")
      .def_readonly("target", &ConfigFile::target)
      .def_readonly("options", &ConfigFile::options);
  m.def("load_config", &LoadConfigFile, py::arg("path"),
        "A YAML configuration as `oalservo pose --config` reads it (config/pose.yaml): its "
        "target and options; errors name the file, the line and the key");

  py::class_<PyTargetFrame>(m, "TargetFrame", "What the tracker found in one frame")
      .def_readonly("status", &PyTargetFrame::status)
      .def_readonly("message", &PyTargetFrame::message)
      .def_readonly("cMo", &PyTargetFrame::cMo)
      .def_readonly("corners_px", &PyTargetFrame::corners_px)
      .def_readonly("lines", &PyTargetFrame::lines)
      .def_readonly("time_us", &PyTargetFrame::time_us);

  py::class_<PyTracker>(m, "TargetPoseTracker",
                        "The four-line target's pose over a stream of frames "
                        "(servo/target_tracker.h)")
      .def(py::init([](const LineTarget& target, const Lens& camera,
                       const std::optional<TrackingOptions>& options) {
             return PyTracker(target, camera, options.value_or(TrackingOptions()));
           }),
           py::arg("target"), py::arg("camera"), py::arg("options") = py::none())
      .def("track", &PyTracker::Track, py::arg("image"),
           "The pose in `image` (uint8 H x W grey, read in place, or H x W x 3 BGR)")
      .def("reset", &PyTracker::Reset, "Forget the previous frames");

  py::class_<PyLine>(m, "Line", "A detected line: rho, theta (ViSP's convention), votes, ends")
      .def_readonly("rho_px", &PyLine::rho_px)
      .def_readonly("theta_rad", &PyLine::theta_rad)
      .def_readonly("votes", &PyLine::votes)
      .def_readonly("support", &PyLine::support)
      .def_readonly("end_a", &PyLine::end_a)
      .def_readonly("end_b", &PyLine::end_b);

  m.def(
      "detect",
      [](const py::array& image, const std::optional<TrackingOptions>& options) {
        return Detect(image, options.value_or(TrackingOptions()));
      },
      py::arg("image"), py::arg("options") = py::none(), "The OAL detector's lines in `image`");
  m.def("render", &Render, py::arg("target"), py::arg("camera"), py::arg("width") = 640,
        py::arg("height") = 480, py::arg("seed") = 1, py::arg("cMo") = py::none(),
        "A rendered frame of `target` on a bench and its true cMo: (image, cMo)");
}
