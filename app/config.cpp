#include "app/config.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

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

// Check() names the field as "DetectorOptions::<field> = ..."; point at the line that set it.
template <typename Options>
void CheckAt(const Options& options, const std::string& file, const std::string& name,
             const Lines& lines) {
  try {
    options.Check();
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    const std::size_t begin = message.find("::");
    const std::size_t end = message.find(" = ");
    if (begin != std::string::npos && end != std::string::npos && begin < end) {
      const std::string field = message.substr(begin + 2, end - begin - 2);
      const auto line = lines.find(field);
      if (line != lines.end()) {
        throw std::runtime_error(file + ":" + std::to_string(line->second) + ": '" + name + "." +
                                 field + "' is invalid: " + message);
      }
    }
    throw std::runtime_error(file + ": section '" + name + "' is invalid: " + message);
  }
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
      DoubleField("min_width_px", &O::min_width_px),
      DoubleField("max_width_px", &O::max_width_px),
      DoubleField("min_crossing_angle_deg", &O::min_crossing_angle_deg),
      IntField("max_points_per_border", &O::max_points_per_border),
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

struct Section {
  const char* name;
  void (*read)(const YAML::Node& section, const std::string& file, AppConfig* config);
};

constexpr Section kSections[] = {
    {"detector", &ReadDetectorSection},
};

// Sections later versions will read: rejected with a message that says so.
constexpr const char* kReservedSections[] = {"camera", "servo", "robot", "pose", "render"};

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
  return config;
}

YAML::Node LoadYaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    throw std::runtime_error(file + ":" + std::to_string(error.mark.line + 1) +
                             ": YAML syntax error: " + error.msg);
  }
}

}  // namespace

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
