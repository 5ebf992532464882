// The YAML reader of every configuration section: one table of fields per section, read by one
// machinery (Value, Field, ReadFields, CheckAt) that gives every message its file, line and key;
// kept in one file so that a new key is one line beside its kin and the machinery stays private.
#include "app/config.h"

#include <visp3/core/vpMath.h>
#include <visp3/core/vpRxyzVector.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "base/format.h"
#include "detector/lens.h"
#include "io/camera_file.h"
#include "io/image_source.h"

namespace oal {
namespace {

// A value being read: where it is, for messages.
struct Value {
  const YAML::Node& node;
  const std::string& file;
  std::string key;  ///< full key, "detector.step_px"

  [[noreturn]] void Fail(const std::string& message) const {
    throw std::runtime_error(file + ":" + std::to_string(node.Mark().line + 1) + ": " + message);
  }

  std::string Text() const {
    if (node.IsScalar()) return node.Scalar();
    if (node.IsSequence()) return "a sequence";
    if (node.IsMap()) return "a map";
    return "";
  }

  template <typename T>
  T As(const char* what) const {
    T value{};
    if (!node.IsScalar() || !YAML::convert<T>::decode(node, value)) {
      Fail("'" + key + "' must be " + what + ", got '" + Text() + "'");
    }
    return value;
  }

  int Int() const { return As<int>("an integer"); }
  double Double() const { return As<double>("a number"); }
  bool Bool() const { return As<bool>("true or false"); }
  double FiniteDouble() const {
    const double value = Double();
    if (!std::isfinite(value)) Fail("'" + key + "' must be a finite number, got '" + Text() + "'");
    return value;
  }

  // Enum from text through a mapping that says nullopt for an unknown word.
  template <typename Enum>
  Enum OneOf(std::optional<Enum> (*from_string)(const std::string&), const char* choices) const {
    const std::string word = As<std::string>("a string");
    const std::optional<Enum> value = from_string(word);
    if (!value) Fail("'" + key + "' is invalid: '" + word + "' is not one of " + choices);
    return *value;
  }

  // Enum from text through the one place that maps strings to enums (options.h).
  template <typename Enum>
  Enum Choice(Enum (*from_string)(const std::string&), const char* choices) const {
    if (node.IsScalar()) {
      try {
        return from_string(node.Scalar());
      } catch (const std::invalid_argument&) {
        // reported below, with the file and line
      }
    }
    Fail("'" + key + "' must be one of " + choices + ", got '" + Text() + "'");
  }
};

// One key of a section and how to store it.
template <typename Options>
struct Field {
  const char* key;
  std::function<void(const Value&, Options*)> read;
};

template <typename Options>
Field<Options> IntField(const char* key, int Options::*member) {
  return {key, [member](const Value& value, Options* options) { options->*member = value.Int(); }};
}

template <typename Options>
Field<Options> DoubleField(const char* key, double Options::*member) {
  return {key,
          [member](const Value& value, Options* options) { options->*member = value.Double(); }};
}

template <typename Options>
Field<Options> BoolField(const char* key, bool Options::*member) {
  return {key, [member](const Value& value, Options* options) { options->*member = value.Bool(); }};
}

using Lines = std::map<std::string, int>;  // key -> 1-based line where the file sets it

std::string At(const std::string& file, const YAML::Node& node) {
  return file + ":" + std::to_string(node.Mark().line + 1);
}

template <typename Options>
std::string KnownKeys(const std::vector<Field<Options>>& fields) {
  std::string known;
  for (const Field<Options>& field : fields)
    known += (known.empty() ? "" : ", ") + std::string(field.key);
  return known;
}

// Reads every key of `section` through `fields`: unknown and repeated keys are errors.
// `skip` names keys the caller has already handled.
template <typename Options>
void ReadFields(const YAML::Node& section, const std::string& file, const std::string& name,
                const std::vector<Field<Options>>& fields, const std::string& skip,
                Options* options, Lines* lines) {
  for (const auto& entry : section) {
    const std::string key = entry.first.Scalar();
    const std::string full_key = name + "." + key;
    const int line = entry.first.Mark().line + 1;
    const auto [seen, inserted] = lines->emplace(key, line);
    if (!inserted) {
      throw std::runtime_error(At(file, entry.first) + ": key '" + full_key +
                               "' is repeated (first at line " + std::to_string(seen->second) +
                               ")");
    }
    if (key == skip) continue;
    const Field<Options>* field = nullptr;
    for (const Field<Options>& candidate : fields) {
      if (key == candidate.key) field = &candidate;
    }
    if (field == nullptr) {
      throw std::runtime_error(At(file, entry.first) + ": key '" + full_key +
                               "' is unknown (known: " + (skip.empty() ? "" : skip + ", ") +
                               KnownKeys(fields) + ")");
    }
    field->read(Value{entry.second, file, full_key}, options);
  }
}

// The keys a Check() message names: "a" for "a", "a" and "b" for "a/b [x]" (a constraint
// between two keys, on one axis).
std::vector<std::string> FieldKeys(std::string field) {
  field = field.substr(0, field.find(" ["));
  std::vector<std::string> keys;
  for (std::size_t begin = 0; begin <= field.size();) {
    const std::size_t end = std::min(field.find('/', begin), field.size());
    keys.push_back(field.substr(begin, end - begin));
    begin = end + 1;
  }
  return keys;
}

// A Check() message "Options::field = VALUE. Violated constraint: C" in the user's words:
// "VALUE (needs C)", with "section.field = " first when the key is not named already; other
// messages as they are.
std::string InUserWords(const std::string& message, const std::string& section, bool key_named) {
  const std::string violated = ". Violated constraint: ";
  const std::size_t equals = message.find(" = ");
  const std::size_t because = message.rfind(violated);
  if (equals == std::string::npos || because == std::string::npos || because < equals) {
    return message;
  }
  std::string field = message.substr(0, equals);
  const std::size_t scope = field.find_last_of(":.");
  if (scope != std::string::npos) field = field.substr(scope + 1);
  const std::string value = message.substr(equals + 3, because - equals - 3);
  const std::string constraint = message.substr(because + violated.size());
  // A field with an index ("workspace_min_m/workspace_max_m [x]") keeps its name for the index.
  const bool name_it = !key_named || field.find('[') != std::string::npos;
  return (name_it ? section + "." + field + " = " : "") + value + " (needs " + constraint + ")";
}

// Check() names the field as "DetectorOptions::<field> = ..."; point at the line that set it
// (else at the section's line, when given).
template <typename Options>
void CheckAt(const Options& options, const std::string& file, const std::string& name,
             const Lines& lines, int section_line = 0) {
  try {
    options.Check();
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    // "Options::field = ..." (most Check()s) or "Options.field = ..." (ServoOptions).
    const std::size_t end = message.find(" = ");
    std::size_t begin = message.find("::");
    std::size_t skip = 2;
    if (begin == std::string::npos || begin > end) {
      begin = message.rfind('.', end);
      skip = 1;
    }
    if (begin != std::string::npos && end != std::string::npos && begin < end) {
      for (const std::string& field : FieldKeys(message.substr(begin + skip, end - begin - skip))) {
        const auto line = lines.find(field);
        if (line != lines.end()) {
          throw std::runtime_error(file + ":" + std::to_string(line->second) + ": '" + name + "." +
                                   field + "' is invalid: " + InUserWords(message, name, true));
        }
      }
    }
    const std::string at = section_line > 0 ? ":" + std::to_string(section_line) : "";
    throw std::runtime_error(file + at + ": section '" + name +
                             "' is invalid: " + InUserWords(message, name, false));
  }
}

// A section that is exactly one Options struct: its fields, then its Check() reported at
// the line of the field it names.
template <typename Options>
void ReadCheckedSection(const YAML::Node& section, const std::string& file, const char* name,
                        const std::vector<Field<Options>>& fields, Options* options) {
  Lines lines;
  ReadFields(section, file, name, fields, "", options, &lines);
  CheckAt(*options, file, name, lines, section.Mark().line + 1);
}

const std::vector<Field<DetectorOptions>>& DetectorFields() {
  using O = DetectorOptions;
  static const std::vector<Field<O>> fields = {
      IntField("start_px", &O::start_px),
      IntField("step_px", &O::step_px),
      {"polarity",
       [](const Value& value, O* options) {
         options->polarity = value.Choice(&PolarityFromString, "dark, light, edges");
       }},
      {"threshold_mode",
       [](const Value& value, O* options) {
         options->threshold_mode = value.Choice(&ThresholdModeFromString, "fixed, otsu");
       }},
      IntField("fixed_threshold", &O::fixed_threshold),
      IntField("min_contrast", &O::min_contrast),
      DoubleField("min_relative_contrast", &O::min_relative_contrast),
      DoubleField("min_width_px", &O::min_width_px),
      DoubleField("max_width_px", &O::max_width_px),
      DoubleField("min_crossing_angle_deg", &O::min_crossing_angle_deg),
      IntField("max_points_per_border", &O::max_points_per_border),
      BoolField("centre_from_background", &O::centre_from_background),
      IntField("region_max_borders", &O::region_max_borders),
      IntField("region_sample_step", &O::region_sample_step),
      BoolField("skip_same_side_pairs", &O::skip_same_side_pairs),
      DoubleField("max_pair_width_ratio", &O::max_pair_width_ratio),
      DoubleField("angle_change_deg", &O::angle_change_deg),
      DoubleField("r_change_px", &O::r_change_px),
      IntField("max_lines", &O::max_lines),
      BoolField("count_visible_borders_only", &O::count_visible_borders_only),
      BoolField("refit_lines", &O::refit_lines),
      BoolField("rank_by_support", &O::rank_by_support),
      DoubleField("support_tolerance_px", &O::support_tolerance_px),
      IntField("max_output_lines", &O::max_output_lines),
      IntField("min_votes", &O::min_votes),
      IntField("min_support", &O::min_support),
      DoubleField("duplicate_angle_deg", &O::duplicate_angle_deg),
      DoubleField("duplicate_r_px", &O::duplicate_r_px),
  };
  return fields;
}

// `detector:`; `paper` is applied first, whatever its position, since it picks the base
// the other keys modify.
void ReadDetectorSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  if (const YAML::Node paper = section["paper"]) {
    const bool from_paper = Value{paper, file, "detector.paper"}.Bool();
    config->detector = from_paper ? DetectorOptions::Paper() : DetectorOptions();
  }
  Lines lines;
  ReadFields(section, file, "detector", DetectorFields(), "paper", &config->detector, &lines);
  CheckAt(config->detector, file, "detector", lines);
}

// ------------------------------------------------------------------------------------------
// `target:`: a shipped target by name, or a full description (config/four-line-board.yaml).

// A point [x, y] in metres.
struct PointValue {
  double x = 0.0, y = 0.0;
};

PointValue ReadPoint(const Value& value) {
  const YAML::Node& node = value.node;
  if (!node.IsSequence() || node.size() != 2) {
    value.Fail("'" + value.key + "' must be a point [x, y] in metres, got '" +
               (node.IsSequence() ? "a sequence of " + std::to_string(node.size()) : value.Text()) +
               "'");
  }
  PointValue point;
  point.x = Value{node[0], value.file, value.key + "[0]"}.FiniteDouble();
  point.y = Value{node[1], value.file, value.key + "[1]"}.FiniteDouble();
  return point;
}

// One entry of `lines:`, {from: [x, y], to: [x, y], width: w}, all keys required.
TargetLine ReadTargetLine(const Value& value) {
  if (!value.node.IsMap()) {
    value.Fail("'" + value.key + "' must be a map {from: [x, y], to: [x, y], width: w}, got '" +
               value.Text() + "'");
  }
  struct Parts {
    std::optional<PointValue> from, to;
    std::optional<double> width;
  };
  static const std::vector<Field<Parts>> fields = {
      {"from", [](const Value& item, Parts* parts) { parts->from = ReadPoint(item); }},
      {"to", [](const Value& item, Parts* parts) { parts->to = ReadPoint(item); }},
      {"width",
       [](const Value& item, Parts* parts) {
         parts->width = item.FiniteDouble();
         if (*parts->width <= 0.0) {
           item.Fail("'" + item.key + "' must be > 0 (metres), got '" + item.Text() + "'");
         }
       }},
  };
  Parts parts;
  Lines lines;
  ReadFields(value.node, value.file, value.key, fields, "", &parts, &lines);
  for (const char* key : {"from", "to", "width"}) {
    if (lines.count(key) == 0) {
      value.Fail("'" + value.key + "' has no '" + key + "' (a line needs from, to, width)");
    }
  }
  const PointValue& from = *parts.from;
  const PointValue& to = *parts.to;
  if (from.x == to.x && from.y == to.y) {
    value.Fail("'" + value.key + "' has from == to = [" + Number(from.x) + ", " + Number(from.y) +
               "]: a line needs two different ends");
  }
  return TargetLine{from.x, from.y, to.x, to.y, *parts.width};
}

const std::vector<Field<LineTarget>>& TargetFields() {
  using T = LineTarget;
  static const std::vector<Field<T>> fields = {
      {"name",
       [](const Value& value, T* target) {
         target->name = value.As<std::string>("a string");
         if (target->name.empty()) value.Fail("'" + value.key + "' must not be empty");
       }},
      {"board_width_m",
       [](const Value& value, T* target) { target->board_width_m = value.FiniteDouble(); }},
      {"board_height_m",
       [](const Value& value, T* target) { target->board_height_m = value.FiniteDouble(); }},
      IntField("board_grey", &T::board_grey),
      IntField("line_grey", &T::line_grey),
      {"lines",
       [](const Value& value, T* target) {
         if (!value.node.IsSequence()) {
           value.Fail("'" + value.key +
                      "' must be a sequence of {from: [x, y], to: [x, y], width: w} ([] for none), "
                      "got '" +
                      value.Text() + "'");
         }
         target->lines.clear();
         for (std::size_t i = 0; i < value.node.size(); ++i) {
           target->lines.push_back(ReadTargetLine(
               Value{value.node[i], value.file, value.key + "[" + std::to_string(i) + "]"}));
         }
       }},
  };
  return fields;
}

// Both ends of every line on the board (edges included; the board is centred on the origin).
void CheckLinesOnBoard(const YAML::Node& section, const std::string& file,
                       const LineTarget& target) {
  const double hw = 0.5 * target.board_width_m, hh = 0.5 * target.board_height_m;
  const double slack = 1e-9;  // metres: ends written on the edge stay on it
  const YAML::Node lines = section["lines"];
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    const TargetLine& line = target.lines[i];
    for (const auto& [end, x, y] :
         {std::tuple<const char*, double, double>{"from", line.x1_m, line.y1_m},
          {"to", line.x2_m, line.y2_m}}) {
      if (std::fabs(x) <= hw + slack && std::fabs(y) <= hh + slack) continue;
      const std::string key = "target.lines[" + std::to_string(i) + "]." + end;
      throw std::runtime_error(At(file, lines[i][end]) + ": '" + key + "' = [" + Number(x) + ", " +
                               Number(y) + "] lies outside the board (|x| <= " + Number(hw) +
                               ", |y| <= " + Number(hh) +
                               " m: the board is centred on the origin)");
    }
  }
}

// `target:` with `lines` is a full description (name, board_width_m, board_height_m and lines
// required; the greys default to LineTarget's); without, only `name`, a shipped target.
void ReadTargetSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  LineTarget target;
  Lines lines;
  ReadFields(section, file, "target", TargetFields(), "", &target, &lines);
  if (lines.count("lines") == 0) {
    for (const auto& entry : section) {
      const std::string key = entry.first.Scalar();
      if (key == "name") continue;
      throw std::runtime_error(
          At(file, entry.first) + ": key 'target." + key +
          "' needs a full target description: give 'lines' too, or only 'name' for a shipped "
          "target (" +
          TargetNameList() + ")");
    }
    if (lines.count("name") == 0) {
      throw std::runtime_error(At(file, section) + ": section 'target' needs 'name' (" +
                               TargetNameList() + ") or a full description with 'lines'");
    }
    try {
      config->target = TargetByName(target.name);
    } catch (const std::invalid_argument&) {
      throw std::runtime_error(file + ":" + std::to_string(lines.at("name")) +
                               ": 'target.name' = '" + target.name + "' is not a shipped target (" +
                               TargetNameList() +
                               "); describe it in full with board_width_m, board_height_m and "
                               "lines");
    }
    return;
  }
  for (const char* required : {"name", "board_width_m", "board_height_m"}) {
    if (lines.count(required) == 0) {
      throw std::runtime_error(At(file, section) + ": 'target." + required +
                               "' is missing (a full target description needs name, "
                               "board_width_m, board_height_m and lines)");
    }
  }
  LineTarget board = target;  // the board first, so that the lines are checked against it
  board.lines.clear();
  CheckAt(board, file, "target", lines);
  CheckLinesOnBoard(section, file, target);
  CheckAt(target, file, "target", lines);
  config->target = std::move(target);
}

// ------------------------------------------------------------------------------------------
// `pose:`: PoseOptions' tunables. camera, lines_undistorted, image_width and image_height are
// not keys: the command sets them from --camera, the detector and the frame.

const std::vector<Field<PoseOptions>>& PoseFields() {
  using O = PoseOptions;
  static const std::vector<Field<O>> fields = {
      IntField("max_candidate_lines", &O::max_candidate_lines),
      DoubleField("min_group_angle_deg", &O::min_group_angle_deg),
      DoubleField("max_outside_px", &O::max_outside_px),
      DoubleField("max_intersection_radius", &O::max_intersection_radius),
      DoubleField("min_side_px", &O::min_side_px),
      DoubleField("ortho_sigma", &O::ortho_sigma),
      DoubleField("width_sigma", &O::width_sigma),
      DoubleField("max_identification_cost", &O::max_identification_cost),
      DoubleField("min_identification_margin", &O::min_identification_margin),
      DoubleField("previous_max_deg", &O::previous_max_deg),
      DoubleField("max_residual_px", &O::max_residual_px),
      DoubleField("previous_tolerance_px", &O::previous_tolerance_px),
      DoubleField("min_depth_m", &O::min_depth_m),
      BoolField("correct_stripe_centres", &O::correct_stripe_centres),
      DoubleField("dementhon_above_px", &O::dementhon_above_px),
      DoubleField("previous_accept_px", &O::previous_accept_px),
      DoubleField("homography_accept_px", &O::homography_accept_px),
      BoolField("compute_covariance", &O::compute_covariance),
      IntField("vvs_max_iterations", &O::vvs_max_iterations),
  };
  return fields;
}

void ReadPoseSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  ReadCheckedSection(section, file, "pose", PoseFields(), &config->pose);
}

// ------------------------------------------------------------------------------------------
// The servo app's sections: camera, robot, servo, goal, target_pose.

// [x, y, z], finite.
std::array<double, 3> ReadVector3(const Value& value, const char* unit) {
  const YAML::Node& node = value.node;
  if (!node.IsSequence() || node.size() != 3) {
    value.Fail("'" + value.key + "' must be [x, y, z] in " + unit + ", got '" +
               (node.IsSequence() ? "a sequence of " + std::to_string(node.size()) : value.Text()) +
               "'");
  }
  std::array<double, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) {
    v[i] = Value{node[i], value.file, value.key + "[" + std::to_string(i) + "]"}.FiniteDouble();
  }
  return v;
}

// OpenCV's distortion coefficients in calib3d's order: [k1, k2, p1, p2], [k1, k2, p1, p2, k3]
// or [k1, k2, p1, p2, k3, k4, k5, k6], finite.
Distortion ReadDistortion(const Value& value) {
  const YAML::Node& node = value.node;
  const std::size_t n = node.IsSequence() ? node.size() : 0;
  if (n != 4 && n != 5 && n != 8) {
    value.Fail("'" + value.key +
               "' must be OpenCV's distortion coefficients [k1, k2, p1, p2, k3] (4, 5 or 8 "
               "numbers), got '" +
               (node.IsSequence() ? "a sequence of " + std::to_string(n) : value.Text()) + "'");
  }
  std::array<double, 8> c{};
  for (std::size_t i = 0; i < n; ++i) {
    c[i] = Value{node[i], value.file, value.key + "[" + std::to_string(i) + "]"}.FiniteDouble();
  }
  return Distortion::FromArray(c);
}

// {translation_m: [x, y, z], rxyz_deg: [rx, ry, rz]}, R = Rx·Ry·Rz; both keys required (one
// missing, silently read as zeros, would put the robot or the goal somewhere else).
vpHomogeneousMatrix ReadPose(const Value& value) {
  if (!value.node.IsMap()) {
    value.Fail("'" + value.key +
               "' must be a pose {translation_m: [x, y, z], rxyz_deg: [rx, ry, rz]}, got '" +
               value.Text() + "'");
  }
  struct Parts {
    std::array<double, 3> t{}, r{};
  };
  static const std::vector<Field<Parts>> fields = {
      {"translation_m",
       [](const Value& item, Parts* parts) { parts->t = ReadVector3(item, "metres"); }},
      {"rxyz_deg",
       [](const Value& item, Parts* parts) { parts->r = ReadVector3(item, "degrees"); }},
  };
  Parts parts;
  Lines lines;
  ReadFields(value.node, value.file, value.key, fields, "", &parts, &lines);
  for (const char* key : {"translation_m", "rxyz_deg"}) {
    if (lines.count(key) == 0) {
      value.Fail("'" + value.key + "' has no '" + key +
                 "' (a pose needs translation_m: [x, y, z] and rxyz_deg: [rx, ry, rz]; give "
                 "[0, 0, 0] for none)");
    }
  }
  const std::array<double, 3>& t = parts.t;
  const std::array<double, 3>& r = parts.r;
  const vpRxyzVector rxyz(vpMath::rad(r[0]), vpMath::rad(r[1]), vpMath::rad(r[2]));
  return vpHomogeneousMatrix(vpTranslationVector(t[0], t[1], t[2]), vpRotationMatrix(rxyz));
}

template <typename Options>
Field<Options> PoseField(const char* key, vpHomogeneousMatrix Options::*member) {
  return {key,
          [member](const Value& value, Options* options) { options->*member = ReadPose(value); }};
}

// A path in the config file: relative ones are relative to the file's directory.
std::string PathNextTo(const std::string& file, const Value& value) {
  const std::string text = value.As<std::string>("a path");
  if (text.empty()) value.Fail("'" + value.key + "' must not be empty");
  const std::filesystem::path path(text);
  if (path.is_absolute() || text.rfind("/dev/", 0) == 0) return text;
  return (std::filesystem::path(file).parent_path() / path).lexically_normal().string();
}

const std::vector<Field<CameraConfig>>& CameraFields() {
  using O = CameraConfig;
  static const std::vector<Field<O>> fields = {
      DoubleField("px", &O::px),
      DoubleField("py", &O::py),
      DoubleField("u0", &O::u0),
      DoubleField("v0", &O::v0),
      DoubleField("kdu", &O::kdu),
      {"distortion",
       [](const Value& value, O* camera) { camera->distortion = ReadDistortion(value); }},
      BoolField("correct_distortion", &O::correct_distortion),
      BoolField("estimate_distortion", &O::estimate_distortion),
      IntField("width", &O::width),
      IntField("height", &O::height),
      DoubleField("noise", &O::noise),
      DoubleField("blur", &O::blur),
      DoubleField("exposure_s", &O::exposure_s),
      DoubleField("latency_s", &O::latency_s),
      PoseField("eMc", &O::eMc),
      {"true_eMc", [](const Value& value, O* camera) { camera->true_eMc = ReadPose(value); }},
      {"file", [](const Value& value, O* camera) { camera->file = PathNextTo(value.file, value); }},
      {"name", [](const Value& value,
                  O* camera) { camera->file_camera = value.As<std::string>("a camera's name"); }},
  };
  return fields;
}

// camera.file: the intrinsics from the ViSP camera file, and its image size, which inline
// width and height must then equal (a camera calibrated at one size does not fit another).
void ApplyCameraFile(const std::string& yaml, const Lines& lines, CameraConfig* camera) {
  const auto at = [&yaml, &lines](const char* key) {
    return yaml + ":" + std::to_string(lines.at(key));
  };
  for (const char* key : {"px", "py", "u0", "v0", "kdu", "distortion"}) {
    if (lines.count(key) == 0) continue;
    throw std::runtime_error(at(key) + ": 'camera." + key + "' and 'camera.file' (line " +
                             std::to_string(lines.at("file")) +
                             ") are both given: the file holds the camera's intrinsics; remove "
                             "one of them");
  }
  CameraFile loaded;
  try {
    loaded = LoadCameraFile(camera->file, camera->file_camera);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(at("file") + ": camera.file: " + error.what());
  }
  const Lens& read = loaded.camera;
  camera->px = read.px();
  camera->py = read.py();
  camera->u0 = read.u0();
  camera->v0 = read.v0();
  camera->kdu = read.kdu();
  camera->distortion = read.distortion();
  if (loaded.width == 0 || loaded.height == 0) return;
  const int width = static_cast<int>(loaded.width), height = static_cast<int>(loaded.height);
  for (const char* key : {"width", "height"}) {
    if (lines.count(key) == 0 || (camera->width == width && camera->height == height)) continue;
    throw std::runtime_error(
        at(key) + ": camera.width x camera.height is " + std::to_string(camera->width) + "x" +
        std::to_string(camera->height) + " but camera.file '" + camera->file + "' (line " +
        std::to_string(lines.at("file")) + ") was calibrated for " + std::to_string(width) + "x" +
        std::to_string(height) +
        " images: calibrate the camera at the size it runs at, or remove width and height");
  }
  camera->width = width;
  camera->height = height;
}

void ReadCameraSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  CameraConfig& camera = config->camera;
  Lines lines;
  ReadFields(section, file, "camera", CameraFields(), "", &camera, &lines);
  if (lines.count("file") > 0) {
    ApplyCameraFile(file, lines, &camera);
  } else if (lines.count("name") > 0) {
    throw std::runtime_error(file + ":" + std::to_string(lines.at("name")) +
                             ": 'camera.name' picks a camera of camera.file, which is not given");
  }
  CheckAt(camera, file, "camera", lines, section.Mark().line + 1);
}

template <typename T>
Field<RobotConfig> SafetyField(const char* key, T SafetyOptions::*member) {
  return {key, [member](const Value& value, RobotConfig* robot) {
            if constexpr (std::is_same_v<T, bool>) {
              robot->safety.*member = value.Bool();
            } else if constexpr (std::is_same_v<T, double>) {
              robot->safety.*member = value.Double();
            } else {
              robot->safety.*member = ReadVector3(value, "metres");
            }
          }};
}

// [a, b, c, d, e], finite (the Scorbot's five axes).
std::array<double, 5> ReadArray5(const Value& value, const char* unit) {
  const YAML::Node& node = value.node;
  if (!node.IsSequence() || node.size() != 5) {
    value.Fail("'" + value.key + "' must be a list of 5 numbers (" + unit + "), one per axis");
  }
  std::array<double, 5> v{};
  for (std::size_t i = 0; i < 5; ++i) {
    v[i] = Value{node[i], value.file, value.key + "[" + std::to_string(i) + "]"}.FiniteDouble();
  }
  return v;
}

template <typename Options>
Field<Options> Array5Field(const char* key, std::array<double, 5> Options::*member,
                           const char* unit) {
  return {key, [member, unit](const Value& value, Options* options) {
            options->*member = ReadArray5(value, unit);
          }};
}

template <typename Options>
Field<Options> StringField(const char* key, std::string Options::*member) {
  return {key, [member](const Value& value, Options* options) {
            options->*member = value.As<std::string>("a string");
          }};
}

// A map nested in a section (robot.scorbot, robot.scorbot.geometry): its own fields, the
// whole key in messages.
template <typename Options>
Lines ReadNested(const Value& value, const std::vector<Field<Options>>& fields, Options* options) {
  if (!value.node.IsMap()) value.Fail("'" + value.key + "' must be a map of keys");
  Lines lines;
  ReadFields(value.node, value.file, value.key, fields, "", options, &lines);
  return lines;
}

const std::vector<Field<ScorbotGeometry>>& ScorbotGeometryFields() {
  using O = ScorbotGeometry;
  static const std::vector<Field<O>> fields = {
      DoubleField("shoulder_height_m", &O::shoulder_height_m),
      DoubleField("shoulder_offset_m", &O::shoulder_offset_m),
      DoubleField("upper_arm_m", &O::upper_arm_m),
      DoubleField("forearm_m", &O::forearm_m),
      DoubleField("pitch_to_flange_m", &O::pitch_to_flange_m),
      DoubleField("tool_length_m", &O::tool_length_m),
      Array5Field("joint_min_deg", &O::joint_min_deg, "degrees"),
      Array5Field("joint_max_deg", &O::joint_max_deg, "degrees"),
      Array5Field("home_deg", &O::home_deg, "degrees"),
      Array5Field("counts_per_deg", &O::counts_per_deg, "encoder counts per degree"),
  };
  return fields;
}

const std::vector<Field<ScorbotSimOptions>>& ScorbotSimFields() {
  using O = ScorbotSimOptions;
  static const std::vector<Field<O>> fields = {
      DoubleField("time_scale", &O::time_scale),
      BoolField("throttle_to_baud", &O::throttle_to_baud),
      Array5Field("max_joint_speed_dps", &O::max_joint_speed_dps, "degrees per second"),
      IntField("home_speed_percent", &O::home_speed_percent),
      StringField("link_path", &O::link_path),
  };
  return fields;
}

const std::vector<Field<RobotConfig>>& ScorbotFields() {
  using O = RobotConfig;
  const auto option = [](const char* key, auto ScorbotOptions::*member) -> Field<O> {
    return {key, [member](const Value& value, O* robot) {
              using T = std::remove_reference_t<decltype(robot->scorbot.*member)>;
              if constexpr (std::is_same_v<T, bool>) {
                robot->scorbot.*member = value.Bool();
              } else if constexpr (std::is_same_v<T, int>) {
                robot->scorbot.*member = value.Int();
              } else if constexpr (std::is_same_v<T, double>) {
                robot->scorbot.*member = value.Double();
              } else {
                robot->scorbot.*member = value.As<std::string>("a string");
              }
            }};
  };
  static const std::vector<Field<O>> fields = {
      option("port", &ScorbotOptions::port),
      option("baud", &ScorbotOptions::baud),
      option("xonxoff", &ScorbotOptions::xonxoff),
      option("echo", &ScorbotOptions::echo),
      option("reply_timeout_s", &ScorbotOptions::reply_timeout_s),
      option("move_timeout_s", &ScorbotOptions::move_timeout_s),
      option("home_timeout_s", &ScorbotOptions::home_timeout_s),
      option("speed_percent", &ScorbotOptions::speed_percent),
      option("sampling_time_s", &ScorbotOptions::sampling_time_s),
      option("arrive_tolerance_mm", &ScorbotOptions::arrive_tolerance_mm),
      option("arrive_tolerance_deg", &ScorbotOptions::arrive_tolerance_deg),
      option("position_check_mm", &ScorbotOptions::position_check_mm),
      option("position_check_deg", &ScorbotOptions::position_check_deg),
      option("point_name", &ScorbotOptions::point_name),
      option("control_off_at_end", &ScorbotOptions::control_off_at_end),
      {"geometry",
       [](const Value& value, O* robot) {
         const Lines lines = ReadNested(value, ScorbotGeometryFields(), &robot->scorbot.geometry);
         CheckAt(robot->scorbot.geometry, value.file, value.key, lines);
       }},
      {"simulator",
       [](const Value& value, O* robot) {
         const Lines lines = ReadNested(value, ScorbotSimFields(), &robot->simulator);
         CheckAt(robot->simulator, value.file, value.key, lines);
       }},
  };
  return fields;
}

const std::vector<Field<RobotConfig>>& RobotFields() {
  using O = RobotConfig;
  static const std::vector<Field<O>> fields = {
      {"type",
       [](const Value& value, O* robot) {
         const std::string word = value.As<std::string>("a string");
         const std::optional<RobotType> type = RobotTypeFromString(word);
         if (!type) {
           value.Fail("'" + value.key + "' must be one of simulated, scorbot, got '" + word + "'");
         }
         robot->type = *type;
       }},
      {"scorbot",
       [](const Value& value, O* robot) {
         const Lines lines = ReadNested(value, ScorbotFields(), robot);
         CheckAt(robot->scorbot, value.file, value.key, lines);
       }},
      PoseField("start", &O::start_wMc),
      DoubleField("sampling_time_s", &O::sampling_time_s),
      SafetyField("max_translation_mps", &SafetyOptions::max_translation_mps),
      SafetyField("max_rotation_radps", &SafetyOptions::max_rotation_radps),
      SafetyField("workspace_enabled", &SafetyOptions::workspace_enabled),
      SafetyField("workspace_min_m", &SafetyOptions::workspace_min_m),
      SafetyField("workspace_max_m", &SafetyOptions::workspace_max_m),
      SafetyField("reach_tolerance_m", &SafetyOptions::reach_tolerance_m),
      SafetyField("reach_tolerance_rad", &SafetyOptions::reach_tolerance_rad),
  };
  return fields;
}

void ReadRobotSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  ReadCheckedSection(section, file, "robot", RobotFields(), &config->robot);
}

Field<ServoLoopOptions> LawDouble(const char* key, double ServoOptions::*member) {
  return {key, [member](const Value& value, ServoLoopOptions* options) {
            options->law.*member = value.Double();
          }};
}

const std::vector<Field<ServoLoopOptions>>& ServoFields() {
  using O = ServoLoopOptions;
  static const std::vector<Field<O>> fields = {
      {"mode",
       [](const Value& value, O* options) {
         options->law.mode =
             value.Choice(&ServoModeFromString, "point-and-go, exponential, velocity");
       }},
      LawDouble("delta", &ServoOptions::delta),
      LawDouble("gain", &ServoOptions::gain),
      {"adaptive_gain",
       [](const Value& value, O* options) { options->law.adaptive_gain = value.Bool(); }},
      LawDouble("gain_at_zero", &ServoOptions::gain_at_zero),
      LawDouble("gain_at_infinity", &ServoOptions::gain_at_infinity),
      LawDouble("gain_slope_at_zero", &ServoOptions::gain_slope_at_zero),
      LawDouble("translation_tolerance_m", &ServoOptions::translation_tolerance_m),
      LawDouble("rotation_tolerance_deg", &ServoOptions::rotation_tolerance_deg),
      IntField("max_iterations", &O::max_iterations),
      DoubleField("max_time_s", &O::max_time_s),
      DoubleField("max_pose_jump_m", &O::max_pose_jump_m),
      DoubleField("max_pose_jump_deg", &O::max_pose_jump_deg),
      DoubleField("max_step_m", &O::max_step_m),
      DoubleField("max_step_deg", &O::max_step_deg),
      DoubleField("max_lost_s", &O::max_lost_s),
      IntField("max_lost_frames", &O::max_lost_frames),
  };
  return fields;
}

void ReadServoSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  ReadCheckedSection(section, file, "servo", ServoFields(), &config->servo);
}

struct Goal {
  vpHomogeneousMatrix cdMo;
  std::string image, origin;
};

void ReadGoalSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  static const std::vector<Field<Goal>> fields = {
      {"cdMo", [](const Value& value, Goal* goal) { goal->cdMo = ReadPose(value); }},
      {"image",
       [](const Value& value, Goal* goal) {
         goal->image = PathNextTo(value.file, value);
         goal->origin = value.file + ":" + std::to_string(value.node.Mark().line + 1);
       }},
  };
  Lines lines;
  Goal goal{config->goal_cdMo, config->goal_image, config->goal_image_origin};
  ReadFields(section, file, "goal", fields, "", &goal, &lines);
  if (lines.count("cdMo") && lines.count("image")) {
    throw std::runtime_error(file + ":" + std::to_string(lines["image"]) +
                             ": 'goal.image' and 'goal.cdMo' (line " +
                             std::to_string(lines["cdMo"]) + ") both set the goal: give one");
  }
  if (goal.cdMo[2][3] <= 0.0) {
    throw std::runtime_error(file + ":" + std::to_string(lines.count("cdMo") ? lines["cdMo"] : 0) +
                             ": 'goal.cdMo' puts the target at z = " + Number(goal.cdMo[2][3]) +
                             " m: it must lie in front of the goal camera (z > 0)");
  }
  if (lines.count("cdMo")) goal.image.clear();  // a later file's cdMo replaces a taught goal
  config->goal_cdMo = goal.cdMo;
  config->goal_image = goal.image;
  config->goal_image_origin = goal.image.empty() ? "" : goal.origin;
}

const std::vector<Field<SourceConfig>>& SourceFields() {
  using O = SourceConfig;
  static const std::vector<Field<O>> fields = {
      {"type",
       [](const Value& value, O* source) {
         source->type = value.OneOf(&SourceTypeFromString, "simulated, v4l2, replay");
       }},
      {"device",
       [](const Value& value, O* source) { source->device = value.As<std::string>("a path"); }},
      {"format",
       [](const Value& value, O* source) {
         source->format = value.OneOf(&CameraFormatFromString, "auto, mjpeg, yuyv, grey");
       }},
      IntField("width", &O::width),
      IntField("height", &O::height),
      IntField("fps", &O::fps),
      {"path", [](const Value& value, O* source) { source->path = PathNextTo(value.file, value); }},
  };
  return fields;
}

void ReadSourceSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  ReadCheckedSection(section, file, "source", SourceFields(), &config->source);
}

const std::vector<Field<OutputConfig>>& OutputFields() {
  using O = OutputConfig;
  static const std::vector<Field<O>> fields = {
      {"directory",
       [](const Value& value, O* output) { output->directory = value.As<std::string>("a path"); }},
      {"display",
       [](const Value& value, O* output) {
         output->display = value.OneOf(&DisplayModeFromString, "auto, on, off");
       }},
      BoolField("save_frames", &O::save_frames),
  };
  return fields;
}

void ReadOutputSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  ReadCheckedSection(section, file, "output", OutputFields(), &config->output);
}

void ReadTargetPoseSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  config->target_wMo = ReadPose(Value{section, file, "target_pose"});
}

// ------------------------------------------------------------------------------------------
// `tracking:`: TargetTrackerOptions, with the sheet finder's options as `tracking.finder`.

const std::vector<Field<SheetFinderOptions>>& FinderFields() {
  using O = SheetFinderOptions;
  static const std::vector<Field<O>> fields = {
      IntField("cell_px", &O::cell_px),
      DoubleField("min_area_fraction", &O::min_area_fraction),
      IntField("min_contrast", &O::min_contrast),
      DoubleField("min_relative_contrast", &O::min_relative_contrast),
      IntField("max_candidates", &O::max_candidates),
  };
  return fields;
}

const std::vector<Field<TargetTrackerOptions>>& TrackingFields() {
  using O = TargetTrackerOptions;
  static const std::vector<Field<O>> fields = {
      {"scan",
       [](const Value& value, O* options) {
         options->scan = value.Choice(&ScanModeFromString, "target, image");
       }},
      DoubleField("reference_focal_px", &O::reference_focal_px),
      IntField("borders", &O::borders),
      IntField("tracked_borders", &O::tracked_borders),
      DoubleField("quick_max_identification_cost", &O::quick_max_identification_cost),
      IntField("max_candidates", &O::max_candidates),
      BoolField("corner_cells", &O::corner_cells),
      BoolField("image_fallback", &O::image_fallback),
      IntField("min_line_support", &O::min_line_support),
      DoubleField("min_stripe_agreement", &O::min_stripe_agreement),
      IntField("min_stripe_contrast", &O::min_stripe_contrast),
      DoubleField("min_stripe_seen", &O::min_stripe_seen),
      DoubleField("stripe_tolerance_px", &O::stripe_tolerance_px),
      DoubleField("stripe_tolerance_fraction", &O::stripe_tolerance_fraction),
      DoubleField("stripe_width_tolerance", &O::stripe_width_tolerance),
      BoolField("fit_stripes", &O::fit_stripes),
      DoubleField("max_jump_m", &O::max_jump_m),
      DoubleField("max_jump_deg", &O::max_jump_deg),
      {"finder",
       [](const Value& value, O* options) {
         if (!value.node.IsMap()) value.Fail("'" + value.key + "' must be a map of keys");
         ReadCheckedSection(value.node, value.file, "tracking.finder", FinderFields(),
                            &options->finder);
       }},
  };
  return fields;
}

void ReadTrackingSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  ReadCheckedSection(section, file, "tracking", TrackingFields(), &config->tracking);
}

// ------------------------------------------------------------------------------------------
// `scene:`: SceneOptions.

// A range [lo, hi] of a drawn value.
DrawRange ReadRange(const Value& value) {
  const YAML::Node& node = value.node;
  if (!node.IsSequence() || node.size() != 2) {
    value.Fail("'" + value.key + "' must be a range [lo, hi] of two numbers, got '" +
               (node.IsSequence() ? "a sequence of " + std::to_string(node.size()) : value.Text()) +
               "'");
  }
  return DrawRange{Value{node[0], value.file, value.key + "[0]"}.FiniteDouble(),
                   Value{node[1], value.file, value.key + "[1]"}.FiniteDouble()};
}

template <typename Options>
Field<Options> RangeField(const char* key, DrawRange Options::*member) {
  return {key,
          [member](const Value& value, Options* options) { options->*member = ReadRange(value); }};
}

// One subsection of the lived-in conditions, checked as LivedInOptions checks it, its message
// naming the key as the subsection writes it ("LivedInOptions::glare.fraction" -> "fraction").
struct LivedInCheck {
  const LivedInOptions& options;
  std::string subsection;  // "glare"
  void Check() const {
    try {
      options.Check();
    } catch (const std::invalid_argument& error) {
      std::string message = error.what();
      const std::string named = "LivedInOptions::" + subsection + ".";
      if (message.rfind(named, 0) == 0) {
        message = "LivedInOptions::" + message.substr(named.size());
      }
      throw std::invalid_argument(message);
    }
  }
};

// `scene.<subsection>: {...}`: one condition of a lived-in scene, read into `part` of
// scene->lived_in through `fields` and checked at the line of the key it names.
template <typename Part>
Field<SceneOptions> LivedInField(const char* subsection, Part LivedInOptions::*part,
                                 std::vector<Field<Part>> (*fields)()) {
  return {subsection, [subsection, part, fields](const Value& value, SceneOptions* scene) {
            if (!value.node.IsMap()) value.Fail("'" + value.key + "' must be a map of keys");
            Lines lines;
            ReadFields(value.node, value.file, value.key, fields(), "", &(scene->lived_in.*part),
                       &lines);
            CheckAt(LivedInCheck{scene->lived_in, subsection}, value.file, value.key, lines,
                    value.node.Mark().line + 1);
          }};
}

std::vector<Field<LivedInOptions::Occluders>> OccluderFields() {
  using O = LivedInOptions::Occluders;
  return {
      DoubleField("fraction", &O::fraction),
      {"kinds",
       [](const Value& value, O* options) {
         if (!value.node.IsSequence() || value.node.size() == 0) {
           value.Fail("'" + value.key +
                      "' must be a sequence of kinds (hand, pen, cable, tool), got '" +
                      value.Text() + "'");
         }
         options->kinds.clear();
         for (std::size_t i = 0; i < value.node.size(); ++i) {
           options->kinds.push_back(
               Value{value.node[i], value.file, value.key + "[" + std::to_string(i) + "]"}.Choice(
                   &OccluderKindFromString, "hand, pen, cable, tool"));
         }
       }},
      RangeField("grey", &O::grey),
      DoubleField("texture_grey", &O::texture_grey),
      DoubleField("shadow_darkness", &O::shadow_darkness)};
}

std::vector<Field<LivedInOptions::Glare>> GlareFields() {
  using O = LivedInOptions::Glare;
  return {DoubleField("fraction", &O::fraction), RangeField("sigma_m", &O::sigma_m),
          RangeField("peak_grey", &O::peak_grey)};
}

std::vector<Field<LivedInOptions::Exposure>> ExposureFields() {
  using O = LivedInOptions::Exposure;
  return {DoubleField("fraction", &O::fraction), RangeField("gain", &O::gain)};
}

std::vector<Field<LivedInOptions::MotionBlur>> MotionBlurFields() {
  using O = LivedInOptions::MotionBlur;
  return {DoubleField("fraction", &O::fraction), RangeField("length_px", &O::length_px)};
}

std::vector<Field<LivedInOptions::Jpeg>> JpegFields() {
  using O = LivedInOptions::Jpeg;
  return {DoubleField("fraction", &O::fraction), RangeField("quality", &O::quality)};
}

const std::vector<Field<SceneOptions>>& SceneFields() {
  using O = SceneOptions;
  static const std::vector<Field<O>> fields = {
      {"background",
       [](const Value& value, O* scene) {
         scene->background = PathNextTo(value.file, value);
         scene->background_origin = value.file + ":" + std::to_string(value.node.Mark().line + 1);
       }},
      DoubleField("background_texel_m", &O::background_texel_m),
      IntField("background_grey", &O::background_grey),
      DoubleField("background_gain", &O::background_gain),
      DoubleField("background_offset", &O::background_offset),
      DoubleField("gradient", &O::gradient),
      DoubleField("gradient_angle_deg", &O::gradient_angle_deg),
      DoubleField("vignetting", &O::vignetting),
      DoubleField("hot_spot_gain", &O::hot_spot_gain),
      DoubleField("hot_spot_u", &O::hot_spot_u),
      DoubleField("hot_spot_v", &O::hot_spot_v),
      DoubleField("hot_spot_sigma", &O::hot_spot_sigma),
      DoubleField("shadow_darkness", &O::shadow_darkness),
      DoubleField("shadow_offset_m", &O::shadow_offset_m),
      DoubleField("shadow_angle_deg", &O::shadow_angle_deg),
      DoubleField("shadow_softness_m", &O::shadow_softness_m),
      DoubleField("paper_texture_grey", &O::paper_texture_grey),
      BoolField("annotations", &O::annotations),
      IntField("clutter_sheets", &O::clutter_sheets),
      IntField("clutter_objects", &O::clutter_objects),
      DoubleField("clutter_reach_m", &O::clutter_reach_m),
      IntField("seed", &O::seed),
      LivedInField("occluders", &LivedInOptions::occluders, &OccluderFields),
      LivedInField("glare", &LivedInOptions::glare, &GlareFields),
      LivedInField("exposure", &LivedInOptions::exposure, &ExposureFields),
      LivedInField("motion_blur", &LivedInOptions::motion_blur, &MotionBlurFields),
      LivedInField("jpeg", &LivedInOptions::jpeg, &JpegFields),
      RangeField("episode_s", &O::episode_s),
      IntField("episode_seed", &O::episode_seed),
  };
  return fields;
}

// The scene's values are checked by RenderOptions::Check(): through a render of its own,
// named by the keys (RenderOptions' fields are the keys but for the units at the edge).
struct SceneCheck {
  const SceneOptions& scene;
  void Check() const {
    if (scene.seed < 0) {
      throw std::invalid_argument("SceneOptions::seed = " + std::to_string(scene.seed) +
                                  ". Violated constraint: seed >= 0");
    }
    RequireOption(scene.background_gain >= 0.0 && scene.background_gain <= 4.0,
                  "SceneOptions::background_gain", scene.background_gain,
                  "0 <= background_gain <= 4");
    RequireOption(std::fabs(scene.background_offset) <= 255.0, "SceneOptions::background_offset",
                  scene.background_offset, "-255 <= background_offset <= 255");
    RequireOption(scene.episode_seed >= 0, "SceneOptions::episode_seed", scene.episode_seed,
                  "episode_seed >= 0");
    RequireOption(scene.episode_s.lo > 0.0 && scene.episode_s.lo <= scene.episode_s.hi &&
                      scene.episode_s.hi <= 3600.0,
                  "SceneOptions::episode_s", scene.episode_s.lo,
                  "0 < episode_s[0] <= episode_s[1] <= 3600");
    RenderOptions render;
    SceneOptions without_image = scene;
    without_image.background.clear();  // read when used, with its own message
    without_image.ApplyTo(&render);
    try {
      render.Check();
    } catch (const std::invalid_argument& error) {
      std::string message = error.what();
      // "RenderOptions::shadow_angle_rad = ..." -> the key the user wrote.
      const std::string prefix = "RenderOptions::";
      if (message.rfind(prefix, 0) == 0) message = "SceneOptions::" + message.substr(prefix.size());
      for (const auto& [field, key] :
           {std::pair<const char*, const char*>{"illumination_gradient", "gradient"},
            {"gradient_angle_rad", "gradient_angle_deg"},
            {"shadow_angle_rad", "shadow_angle_deg"},
            {"scene_seed", "seed"}}) {
        const std::string from = std::string("SceneOptions::") + field + " ";
        if (message.rfind(from, 0) == 0)
          message = std::string("SceneOptions::") + key + message.substr(from.size() - 1);
      }
      throw std::invalid_argument(message);
    }
  }
};

void ReadSceneSection(const YAML::Node& section, const std::string& file, AppConfig* config) {
  Lines lines;
  SceneOptions scene = config->scene;
  ReadFields(section, file, "scene", SceneFields(), "", &scene, &lines);
  CheckAt(SceneCheck{scene}, file, "scene", lines);
  config->scene = std::move(scene);
}

struct Section {
  const char* name;
  void (*read)(const YAML::Node& section, const std::string& file, AppConfig* config);
};

constexpr Section kSections[] = {
    {"detector", &ReadDetectorSection}, {"target", &ReadTargetSection},
    {"pose", &ReadPoseSection},         {"camera", &ReadCameraSection},
    {"robot", &ReadRobotSection},       {"servo", &ReadServoSection},
    {"goal", &ReadGoalSection},         {"target_pose", &ReadTargetPoseSection},
    {"source", &ReadSourceSection},     {"output", &ReadOutputSection},
    {"tracking", &ReadTrackingSection}, {"scene", &ReadSceneSection},
};

// Sections later versions will read: rejected with a message that says so.
constexpr const char* kReservedSections[] = {"render"};

std::string SectionNames() {
  std::string names;
  for (const Section& section : kSections)
    names += (names.empty() ? "" : ", ") + std::string(section.name);
  return names;
}

void ReadSection(const std::string& name, const YAML::Node& key, const YAML::Node& body,
                 const std::string& file, AppConfig* config) {
  for (const Section& section : kSections) {
    if (name != section.name) continue;
    if (body.IsNull()) return;  // an empty section changes nothing
    if (!body.IsMap()) {
      throw std::runtime_error(At(file, body) + ": section '" + name + "' must be a map of keys");
    }
    section.read(body, file, config);
    return;
  }
  for (const char* reserved : kReservedSections) {
    if (name == reserved) {
      throw std::runtime_error(
          At(file, key) + ": section '" + name +
          "' is not supported by this version of oalservo (supported: " + SectionNames() + ")");
    }
  }
  throw std::runtime_error(At(file, key) + ": section '" + name +
                           "' is unknown (known: " + SectionNames() + ")");
}

// Records where every key of `node` (a map, recursively) is set, as "FILE:LINE" by full key.
void RecordOrigins(const YAML::Node& node, const std::string& prefix, const std::string& file,
                   std::map<std::string, std::string>* origins) {
  if (!node.IsMap()) return;
  for (const auto& entry : node) {
    const std::string key = (prefix.empty() ? "" : prefix + ".") + entry.first.Scalar();
    (*origins)[key] = At(file, entry.first);
    RecordOrigins(entry.second, key, file, origins);
  }
}

// A configured start pose (the simulated robot's, or the Scorbot simulator's) outside the
// workspace box: the run would begin where no move is allowed.
void CheckStartInWorkspace(const AppConfig& config, const std::string& file) {
  const RobotConfig& robot = config.robot;
  if (robot.type != RobotType::kSimulated && robot.scorbot.port != "simulator")
    return;  // a real arm
  const vpHomogeneousMatrix wMx = robot.safety.workspace_frame == RobotFrame::kCamera
                                      ? robot.start_wMc
                                      : robot.start_wMc * config.camera.eMc.inverse();
  const std::string why = robot.safety.OutsideWorkspace(wMx.getTranslationVector());
  if (why.empty()) return;
  // Lead with a line of this file: the start's if it set it, else the box's.
  const auto in_file = [&](const std::string& origin) { return origin.rfind(file + ":", 0) == 0; };
  const std::string start_at = config.Origin("robot.start");
  std::string at = in_file(start_at) ? start_at : "";
  for (const char* key : {"robot.workspace_min_m", "robot.workspace_max_m",
                          "robot.workspace_enabled", "robot.scorbot.port", "robot.type"}) {
    if (at.empty() && in_file(config.Origin(key))) at = config.Origin(key);
  }
  throw std::runtime_error((at.empty() ? file : at) + ": 'robot.start'" +
                           (start_at.empty() || start_at == at ? "" : " (" + start_at + ")") +
                           " puts the " + ToString(robot.safety.workspace_frame) +
                           " outside the workspace box: " + why +
                           " (robot.workspace_min_m / workspace_max_m); move the start into the "
                           "box or widen the box");
}

AppConfig ReadConfig(const YAML::Node& root, const std::string& file, AppConfig config) {
  if (root.IsNull()) return config;  // an empty file changes nothing
  if (!root.IsMap()) {
    throw std::runtime_error(At(file, root) + ": the top level must be a map of sections (" +
                             SectionNames() + ")");
  }
  std::map<std::string, int> seen;
  for (const auto& entry : root) {
    const std::string name = entry.first.Scalar();
    const auto [first, inserted] = seen.emplace(name, entry.first.Mark().line + 1);
    if (!inserted) {
      throw std::runtime_error(At(file, entry.first) + ": section '" + name +
                               "' is repeated (first at line " + std::to_string(first->second) +
                               ")");
    }
    ReadSection(name, entry.first, entry.second, file, &config);
  }
  RecordOrigins(root, "", file, &config.origins);
  CheckStartInWorkspace(config, file);
  return config;
}

YAML::Node LoadYaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    // An unclosed bracket or quote is found at the end of the text, past its last line: the
    // last line is where the user looks.
    const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n')) +
                      (!text.empty() && text.back() != '\n' ? 1 : 0);
    const bool past_the_end = error.mark.line + 1 > lines && lines > 0;
    const int line = past_the_end ? lines : error.mark.line + 1;
    throw std::runtime_error(file + ":" + std::to_string(line) + ": YAML syntax error: " +
                             error.msg + (past_the_end ? " (at the end of the file)" : ""));
  }
}

}  // namespace

namespace {

[[noreturn]] void Violated(const std::string& field, const std::string& value,
                           const std::string& constraint) {
  throw std::invalid_argument(field + " = " + value + ". Violated constraint: " + constraint);
}

}  // namespace

std::string AppConfig::Origin(const std::string& key) const {
  const auto origin = origins.find(key);
  return origin == origins.end() ? "" : origin->second;
}

Lens CameraConfig::Camera() const {
  if (!distortion.IsZero()) return Lens::WithDistortion(px, py, u0, v0, distortion);
  if (kdu != 0.0) return Lens::WithKdu(px, py, u0, v0, kdu, width, height);
  return Lens::Pinhole(px, py, u0, v0);
}

void CameraConfig::Check() const {
  if (!(px > 0.0) || !std::isfinite(px)) Violated("CameraConfig::px", Number(px), "px > 0");
  if (!(py > 0.0) || !std::isfinite(py)) Violated("CameraConfig::py", Number(py), "py > 0");
  if (!std::isfinite(u0)) Violated("CameraConfig::u0", Number(u0), "finite");
  if (!std::isfinite(v0)) Violated("CameraConfig::v0", Number(v0), "finite");
  // The same range as every command line's --kdu.
  if (!(kdu > -1.0 && kdu < 1.0)) {
    Violated("CameraConfig::kdu", Number(kdu), "-1 < kdu < 1");
  }
  if (kdu != 0.0 && !distortion.IsZero()) {
    Violated("CameraConfig::kdu", Number(kdu),
             "kdu = 0 when distortion (OpenCV's coefficients) is given: one lens model");
  }
  if (width < 16 || width > 8192)
    Violated("CameraConfig::width", Number(width), "16 <= width <= 8192");
  if (height < 16 || height > 8192) {
    Violated("CameraConfig::height", Number(height), "16 <= height <= 8192");
  }
  if (!(noise >= 0.0 && noise <= 100.0)) {
    Violated("CameraConfig::noise", Number(noise), "0 <= noise <= 100");
  }
  if (!(blur >= 0.0 && blur <= 20.0))
    Violated("CameraConfig::blur", Number(blur), "0 <= blur <= 20");
  if (!(exposure_s >= 0.0 && exposure_s <= 1.0))
    Violated("CameraConfig::exposure_s", Number(exposure_s), "0 <= exposure_s <= 1");
  if (!(latency_s >= 0.0 && latency_s <= 1.0))
    Violated("CameraConfig::latency_s", Number(latency_s), "0 <= latency_s <= 1");
}

void RobotConfig::Check() const {
  if (!(sampling_time_s > 0.0 && sampling_time_s <= 1.0)) {
    Violated("RobotConfig::sampling_time_s", Number(sampling_time_s), "0 < sampling_time_s <= 1");
  }
  safety.Check();
  if (type == RobotType::kScorbot) {
    scorbot.Check();
    if (scorbot.port == "simulator") simulator.Check();
  }
}

void SourceConfig::Check() const {
  if (type == SourceType::kV4l2 && device.empty())
    Violated("SourceConfig::device", "''", "a device path");
  if (fps < 0 || fps > 1000) {
    Violated("SourceConfig::fps", Number(fps), "fps is 0 (the mode's highest) or up to 1000");
  }
  if (width < 0 || height < 0 || (width > 0) != (height > 0)) {
    Violated("SourceConfig::width", std::to_string(width) + "x" + std::to_string(height),
             "width and height both above 0, or both 0 (camera.width, camera.height)");
  }
  if (type == SourceType::kReplay && path.empty()) {
    Violated("SourceConfig::path", "''", "a video, directory or pattern to replay");
  }
}

void OutputConfig::Check() const {}

std::string ToString(RobotType type) {
  return type == RobotType::kScorbot ? "scorbot" : "simulated";
}

std::string ToString(SourceType type) {
  switch (type) {
    case SourceType::kV4l2:
      return "v4l2";
    case SourceType::kReplay:
      return "replay";
    case SourceType::kSimulated:
      break;
  }
  return "simulated";
}

std::string ToString(DisplayMode mode) {
  switch (mode) {
    case DisplayMode::kOn:
      return "on";
    case DisplayMode::kOff:
      return "off";
    case DisplayMode::kAuto:
      break;
  }
  return "auto";
}

namespace {

// The value among `values` whose word (ToString) is `word`.
template <typename Enum>
std::optional<Enum> FromWord(const std::string& word, std::initializer_list<Enum> values) {
  for (const Enum value : values) {
    if (word == ToString(value)) return value;
  }
  return std::nullopt;
}

}  // namespace

std::optional<RobotType> RobotTypeFromString(const std::string& word) {
  return FromWord(word, {RobotType::kSimulated, RobotType::kScorbot});
}

std::optional<SourceType> SourceTypeFromString(const std::string& word) {
  return FromWord(word, {SourceType::kSimulated, SourceType::kV4l2, SourceType::kReplay});
}

std::optional<DisplayMode> DisplayModeFromString(const std::string& word) {
  return FromWord(word, {DisplayMode::kAuto, DisplayMode::kOn, DisplayMode::kOff});
}

std::string TargetYaml(const LineTarget& target) {
  auto number = [](double value) {
    std::ostringstream text;
    text.precision(17);
    text << value;
    return text.str();
  };
  std::ostringstream yaml;
  yaml << "# The target of this data set, as `oalservo render` drew it (a config's target:\n"
          "# section; config/four-line-board.yaml documents the keys).\n"
       << "target:\n"
       << "  name: \"" << target.name << "\"\n"
       << "  board_width_m: " << number(target.board_width_m) << "\n"
       << "  board_height_m: " << number(target.board_height_m) << "\n"
       << "  board_grey: " << target.board_grey << "\n"
       << "  line_grey: " << target.line_grey << "\n"
       << "  lines:" << (target.lines.empty() ? " []" : "") << "\n";
  for (const TargetLine& line : target.lines) {
    yaml << "    - {from: [" << number(line.x1_m) << ", " << number(line.y1_m) << "], to: ["
         << number(line.x2_m) << ", " << number(line.y2_m) << "], width: " << number(line.width_m)
         << "}\n";
  }
  return yaml.str();
}

std::string PoseYaml(const vpHomogeneousMatrix& pose) {
  const vpTranslationVector t = pose.getTranslationVector();
  const vpRxyzVector r(pose.getRotationMatrix());
  std::ostringstream yaml;
  yaml.precision(12);
  yaml << "{translation_m: [" << t[0] << ", " << t[1] << ", " << t[2] << "], rxyz_deg: ["
       << vpMath::deg(r[0]) << ", " << vpMath::deg(r[1]) << ", " << vpMath::deg(r[2]) << "]}";
  return yaml.str();
}

AppConfig ParseConfig(const std::string& yaml_text, const std::string& file_name,
                      const AppConfig& base) {
  return ReadConfig(LoadYaml(yaml_text, file_name), file_name, base);
}

AppConfig LoadConfig(const std::string& path, const AppConfig& base) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("config file '" + path + "' does not exist or is not a file");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw std::runtime_error("cannot read config file '" + path + "'");
  return ParseConfig(text.str(), path, base);
}

}  // namespace oal
