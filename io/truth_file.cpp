#include "io/truth_file.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "base/parse.h"
#include "detector/lens.h"

namespace oal {
namespace {

[[noreturn]] void Fail(const std::string& path, int line, const std::string& message) {
  throw std::runtime_error(path + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
}

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r") - begin + 1);
}

// The comma-separated fields of `text`, trimmed.
std::vector<std::string> Fields(const std::string& text) {
  std::vector<std::string> fields;
  std::stringstream row(text);
  for (std::string field; std::getline(row, field, ',');) fields.push_back(Trim(field));
  return fields;
}

// One CSV row being parsed: its numbers, with errors naming the file, line and field.
struct Row {
  const std::string& path;
  int number;
  const std::vector<std::string>& fields;

  double Number(std::size_t i, const char* name) const {
    const std::optional<double> value = ParseFiniteDouble(fields[i]);
    if (!value) {
      Fail(path, number, std::string("field ") + name + " is not a number: '" + fields[i] + "'");
    }
    return *value;
  }
  int Index(std::size_t i, const char* name) const {
    const double value = Number(i, name);
    if (value < 0 || value != std::floor(value) || value > 1e9) {
      Fail(path, number, std::string("field ") + name + " must be an integer >= 0");
    }
    return static_cast<int>(value);
  }
};

}  // namespace

TruthCsv LoadTruthCsvWithPoses(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path, 0, "cannot open the truth file");
  TruthCsv truth;
  int number = 0;
  for (std::string text; std::getline(in, text);) {
    ++number;
    const std::string line = Trim(text);
    if (line.empty() || line[0] == '#' || line.rfind("frame", 0) == 0) continue;
    const std::vector<std::string> fields = Fields(line);
    const Row row{path, number, fields};
    if (fields.size() == 8 && fields[1] == "pose") {
      const int frame = row.Index(0, "frame");
      const char* names[] = {"tx", "ty", "tz", "tux", "tuy", "tuz"};
      double v[6];
      for (std::size_t i = 0; i < 6; ++i) v[i] = row.Number(i + 2, names[i]);
      if (!truth.poses.emplace(frame, vpHomogeneousMatrix(v[0], v[1], v[2], v[3], v[4], v[5]))
               .second) {
        Fail(path, number, "the pose of frame " + std::to_string(frame) + " appears twice");
      }
      continue;
    }
    if (fields.size() != 4) {
      Fail(path, number,
           "expected 4 comma-separated fields frame,line,rho,theta (or 8: "
           "frame,pose,tx,ty,tz,tux,tuy,tuz), got " +
               std::to_string(fields.size()));
    }
    const int frame = row.Index(0, "frame");
    TargetLineTruth target;
    target.id = row.Index(1, "line");
    const double rho = row.Number(2, "rho"), theta = row.Number(3, "theta");
    if (std::fabs(theta) > 2.0 * kPi) {
      std::ostringstream message;
      message << "field theta = " << theta
              << " is outside [-2 pi, 2 pi]: theta is the angle of the line's normal in radians "
                 "(degrees given?)";
      Fail(path, number, message.str());
    }
    target.image_line = target.ideal_line = Normalized(rho, theta);
    std::vector<TargetLineTruth>& lines = truth.lines[frame];
    for (const TargetLineTruth& other : lines) {
      if (other.id == target.id) {
        Fail(path, number,
             "line " + std::to_string(target.id) + " of frame " + std::to_string(frame) +
                 " appears twice");
      }
    }
    lines.push_back(target);
  }
  return truth;
}

std::optional<vpHomogeneousMatrix> LoadTruthPoseJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path, 0, "cannot open the truth file");
  try {
    const nlohmann::json json = nlohmann::json::parse(in);
    if (!json.contains("cMo")) return std::nullopt;
    const nlohmann::json& matrix = json.at("cMo").at("matrix");
    vpHomogeneousMatrix cMo;
    for (unsigned int r = 0; r < 4; ++r) {
      for (unsigned int c = 0; c < 4; ++c) cMo[r][c] = matrix.at(r).at(c).get<double>();
    }
    return cMo;
  } catch (const nlohmann::json::exception& error) {
    Fail(path, 0, std::string("malformed truth: ") + error.what());
  }
}

int FrameNumber(const std::string& source, int position) {
  const std::string name = std::filesystem::path(source).filename().string();
  const auto last = name.find_last_of("0123456789");
  if (last == std::string::npos) return position;
  auto first = last;
  while (first > 0 && std::isdigit(static_cast<unsigned char>(name[first - 1]))) --first;
  if (last - first >= 9) return position;
  return std::stoi(name.substr(first, last - first + 1));
}

std::map<int, std::vector<TargetLineTruth>> LoadTruthCsv(const std::string& path) {
  return LoadTruthCsvWithPoses(path).lines;
}

std::vector<TargetLineTruth> LoadTruthJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path, 0, "cannot open the truth file");
  std::vector<TargetLineTruth> lines;
  try {
    const nlohmann::json json = nlohmann::json::parse(in);
    auto line_of = [](const nlohmann::json& j) {
      return Normalized(j.at("rho").get<double>(), j.at("theta").get<double>());
    };
    auto point_of = [](const nlohmann::json& j) {
      return Point2d{j.at(0).get<double>(), j.at(1).get<double>()};
    };
    for (const nlohmann::json& line : json.at("lines")) {
      if (!line.at("visible").get<bool>()) continue;
      TargetLineTruth target;
      target.id = line.at("index").get<int>();
      target.image_line = line_of(line.at("distorted_fit"));
      target.ideal_line = line_of(line.at("ideal"));
      target.end_a = point_of(line.at("end_a"));
      target.end_b = point_of(line.at("end_b"));
      target.width_px = line.value("width_px", 0.0);
      lines.push_back(target);
    }
  } catch (const nlohmann::json::exception& error) {
    Fail(path, 0, std::string("malformed truth: ") + error.what());
  }
  return lines;
}

Json FrameTruthJson(const RenderedFrame& frame, int index, const std::string& image,
                    const std::string& target, std::uint64_t seed, std::uint64_t noise_seed,
                    const Lens& camera, int width, int height) {
  Json lines = Json::array();
  for (const TruthLine& line : frame.truth) lines.push_back(TruthLineJson(line));
  return Json{{"frame", index},
              {"image", image},
              {"target", target},
              {"seed", seed},
              {"noise_seed", noise_seed},
              {"camera", CameraJson(camera, width, height)},
              {"cMo", PoseJson(frame.cMo)},
              {"lines", std::move(lines)}};
}

}  // namespace oal
