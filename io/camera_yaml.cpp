#include "io/camera_yaml.h"

#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace oal {
namespace {

// A key of the file and where it is, for messages: "cam.yaml:7: 'camera_matrix.data'".
struct Key {
  const std::string& path;
  YAML::Node node;
  std::string name;

  [[noreturn]] void Fail(const std::string& message) const {
    throw std::runtime_error(path + ":" + std::to_string(node.Mark().line + 1) + ": '" + name +
                             "' " + message);
  }
};

std::string Text(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a sequence of " + std::to_string(node.size());
  if (node.IsMap()) return "a map";
  return "nothing";
}

double Number(const Key& key) {
  double value = 0.0;
  if (!key.node.IsScalar() || !YAML::convert<double>::decode(key.node, value) ||
      !std::isfinite(value)) {
    key.Fail("must be a finite number, got " + Text(key.node));
  }
  return value;
}

unsigned int Size(const Key& key) {
  int value = 0;
  if (!key.node.IsScalar() || !YAML::convert<int>::decode(key.node, value) || value < 1 ||
      value > 65535) {
    key.Fail("must be an image size in pixels (1 to 65535), got " + Text(key.node));
  }
  return static_cast<unsigned int>(value);
}

// The `data` of a matrix {rows, cols, (dt,) data}, rows x cols numbers row by row.
std::vector<double> MatrixData(const std::string& path, const YAML::Node& root,
                               const std::string& name) {
  const Key matrix{path, root[name], name};
  if (!matrix.node.IsMap()) {
    matrix.Fail("must be a matrix {rows, cols, data}, got " + Text(matrix.node));
  }
  const Key data{path, matrix.node["data"], name + ".data"};
  if (!data.node) matrix.Fail("has no 'data'");
  if (!data.node.IsSequence()) data.Fail("must be a sequence of numbers, got " + Text(data.node));
  std::vector<double> values;
  for (std::size_t i = 0; i < data.node.size(); ++i) {
    values.push_back(Number(Key{path, data.node[i], data.name + "[" + std::to_string(i) + "]"}));
  }
  for (const char* dimension : {"rows", "cols"}) {
    if (!matrix.node[dimension]) continue;
    Size(Key{path, matrix.node[dimension], name + "." + dimension});
  }
  if (matrix.node["rows"] && matrix.node["cols"]) {
    const unsigned int count = Size(Key{path, matrix.node["rows"], name + ".rows"}) *
                               Size(Key{path, matrix.node["cols"], name + ".cols"});
    if (count != values.size()) {
      data.Fail("has " + std::to_string(values.size()) + " numbers where rows x cols is " +
                std::to_string(count));
    }
  }
  return values;
}

struct Intrinsics {
  double px, py, u0, v0;
};

Intrinsics CameraMatrix(const std::string& path, const YAML::Node& root) {
  const std::vector<double> k = MatrixData(path, root, "camera_matrix");
  const Key data{path, root["camera_matrix"]["data"], "camera_matrix.data"};
  if (k.size() != 9) {
    data.Fail("must be 3 x 3 (fx, 0, cx, 0, fy, cy, 0, 0, 1), got " + std::to_string(k.size()) +
              " numbers");
  }
  if (!(k[0] > 0.0) || !(k[4] > 0.0)) {
    data.Fail("has fx = " + std::to_string(k[0]) + ", fy = " + std::to_string(k[4]) +
              ": focal lengths in pixels must be > 0");
  }
  if (k[1] != 0.0) data.Fail("has a skew of " + std::to_string(k[1]) + ": a skew is not supported");
  if (k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    data.Fail("must end its rows as a camera matrix does: (0, fy, cy) and (0, 0, 1)");
  }
  return Intrinsics{k[0], k[4], k[2], k[5]};
}

// OpenCV's coefficients in calib3d's order: 4, 5 or 8, or 12 or 14 whose terms beyond the
// eighth (thin prism, tilted sensor) are zero.
Distortion Coefficients(const std::string& path, const YAML::Node& root) {
  if (!root["distortion_coefficients"]) return Distortion();
  const std::vector<double> d = MatrixData(path, root, "distortion_coefficients");
  const Key data{path, root["distortion_coefficients"]["data"], "distortion_coefficients.data"};
  const std::size_t n = d.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    data.Fail("must hold 4, 5, 8, 12 or 14 coefficients (k1, k2, p1, p2, k3, ...), got " +
              std::to_string(n));
  }
  for (std::size_t i = 8; i < n; ++i) {
    if (d[i] != 0.0) {
      data.Fail("has thin-prism or tilted-sensor terms (coefficient " + std::to_string(i + 1) +
                " = " + std::to_string(d[i]) +
                "): only k1, k2, p1, p2, k3 and k4-k6 are supported");
    }
  }
  std::array<double, 8> c{};
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 8); ++i) c[i] = d[i];
  return Distortion::FromArray(c);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("camera file '" + path + "' cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// OpenCV writes "%YAML:1.0", which YAML 1.2 parsers refuse; the line is blanked (the lines
// keep their numbers).
std::string WithoutOpenCvDirective(std::string text) {
  if (text.rfind("%YAML:", 0) == 0) text.replace(0, text.find('\n'), "#");
  return text;
}

std::string Formatted(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  std::string text = buffer;
  // A YAML reader (and OpenCV's) needs a number with a point or an exponent to read a double.
  if (text.find_first_of(".eEn") == std::string::npos) text += ".";
  return text;
}

std::string List(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    text += (i == 0 ? " " : ", ") + Formatted(values[i]);
  }
  return text + " ]";
}

std::vector<double> CameraMatrixOf(const Lens& lens) {
  return {lens.px(), 0.0, lens.u0(), 0.0, lens.py(), lens.v0(), 0.0, 0.0, 1.0};
}

std::vector<double> CoefficientsOf(const Lens& lens) {
  if (lens.model() == Lens::Model::kViSP) {
    throw std::invalid_argument(
        "a lens in ViSP's model is written to a YAML camera file through its OpenCV "
        "approximation (Lens::OpenCvCamera)");
  }
  const auto c = lens.distortion().ToArray();
  return std::vector<double>(c.begin(), c.begin() + (lens.distortion().IsRational() ? 8 : 5));
}

std::string Comments(const std::vector<std::string>& comments) {
  std::string text;
  for (const std::string& comment : comments) text += "# " + comment + "\n";
  return text;
}

}  // namespace

YamlCamera ReadYamlCamera(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(WithoutOpenCvDirective(ReadText(path)));
  } catch (const YAML::Exception& error) {
    throw std::runtime_error(path + ":" + std::to_string(error.mark.line + 1) +
                             ": not valid YAML: " + error.msg);
  }
  if (!root.IsMap() || !root["camera_matrix"]) {
    throw std::runtime_error(
        "camera file '" + path +
        "' has no 'camera_matrix': it is neither OpenCV's calibration YAML nor ROS's "
        "camera_info");
  }
  YamlCamera camera;
  camera.ros = static_cast<bool>(root["distortion_model"]);
  const Intrinsics k = CameraMatrix(path, root);
  if (camera.ros) {
    const Key model{path, root["distortion_model"], "distortion_model"};
    const std::string name = model.node.IsScalar() ? model.node.Scalar() : "";
    if (name != "plumb_bob" && name != "rational_polynomial") {
      model.Fail("is " + Text(model.node) +
                 ": only plumb_bob and rational_polynomial (OpenCV's model) are supported, not "
                 "the fisheye (equidistant) model");
    }
    if (root["camera_name"]) {
      const Key camera_name{path, root["camera_name"], "camera_name"};
      if (!camera_name.node.IsScalar())
        camera_name.Fail("must be a name, got " + Text(camera_name.node));
      camera.name = camera_name.node.Scalar();
    }
  }
  camera.lens = Lens::WithDistortion(k.px, k.py, k.u0, k.v0, Coefficients(path, root));
  for (const char* key : {"image_width", "image_height"}) {
    if (!root[key]) {
      if (camera.ros) {
        throw std::runtime_error("camera file '" + path + "' (ROS's camera_info) has no '" + key +
                                 "'");
      }
      continue;
    }
    (std::string(key) == "image_width" ? camera.width : camera.height) =
        Size(Key{path, root[key], key});
  }
  return camera;
}

std::string OpenCvYamlText(const Lens& lens, unsigned int width, unsigned int height,
                           const std::vector<std::string>& comments) {
  const std::vector<double> d = CoefficientsOf(lens);
  std::ostringstream out;
  out << "%YAML:1.0\n---\n" << Comments(comments);
  if (width > 0 && height > 0) {
    out << "image_width: " << width << "\nimage_height: " << height << "\n";
  }
  out << "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: "
      << List(CameraMatrixOf(lens)) << "\n";
  out << "distortion_coefficients: !!opencv-matrix\n   rows: " << d.size()
      << "\n   cols: 1\n   dt: d\n   data: " << List(d) << "\n";
  return out.str();
}

std::string RosCameraInfoText(const Lens& lens, const std::string& name, unsigned int width,
                              unsigned int height, const std::vector<std::string>& comments) {
  const std::vector<double> d = CoefficientsOf(lens);
  const std::vector<double> k = CameraMatrixOf(lens);
  std::ostringstream out;
  out << Comments(comments);
  out << "image_width: " << width << "\nimage_height: " << height << "\n";
  out << "camera_name: " << YAML::Node(name.empty() ? std::string("camera") : name) << "\n";
  out << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: " << List(k) << "\n";
  out << "distortion_model: " << (d.size() == 8 ? "rational_polynomial" : "plumb_bob") << "\n";
  out << "distortion_coefficients:\n  rows: 1\n  cols: " << d.size() << "\n  data: " << List(d)
      << "\n";
  out << "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: "
      << List({1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) << "\n";
  out << "projection_matrix:\n  rows: 3\n  cols: 4\n  data: "
      << List({k[0], 0.0, k[2], 0.0, 0.0, k[4], k[5], 0.0, 0.0, 0.0, 1.0, 0.0}) << "\n";
  return out.str();
}

}  // namespace oal
