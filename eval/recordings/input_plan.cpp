#include "eval/recordings/input_plan.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "io/image_source.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

bool HoldsImages(const fs::path& dir) {
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    if (entry.is_regular_file() && HasImageExtension(entry.path().string())) return true;
  }
  return false;
}

// A file-system-safe name for the input's output directory.
std::string BaseName(const std::string& spec) {
  fs::path path = fs::path(spec).lexically_normal();
  if (path.filename().empty()) path = path.parent_path();
  std::string name;
  if (spec.find('%') != std::string::npos && !fs::exists(spec)) {
    name = path.parent_path().filename().string();  // frames/img%04d.png -> frames
    if (name.empty() || name == "." || name == "..") name = path.stem().string();
  } else if (fs::is_directory(path)) {
    name = fs::absolute(path).lexically_normal().filename().string();
    if (name.empty())
      name = fs::absolute(path).lexically_normal().parent_path().filename().string();
  } else {
    name = path.stem().string();
  }
  for (char& c : name) {
    const bool safe =
        std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
    if (!safe) c = '_';
  }
  if (name.empty() || name[0] == '.') name = "input" + name;
  return name;
}

}  // namespace

std::string NoInputsMessage(const std::vector<std::string>& inputs, const InputPlan& plan) {
  std::string names;
  for (const std::string& input : inputs) names += (names.empty() ? "'" : ", '") + input + "'";
  std::string message = "no inputs found in " + names +
                        " (expected videos, image sequences, or directories of these)";
  constexpr std::size_t kListed = 5;
  for (std::size_t k = 0; k < plan.skipped.size() && k < kListed; ++k) {
    message += "; " + plan.skipped[k];
  }
  if (plan.skipped.size() > kListed) {
    message += "; and " + std::to_string(plan.skipped.size() - kListed) + " more";
  }
  return message;
}

std::pair<int, int> ParseShard(const std::string& text) {
  const auto slash = text.find('/');
  int index = -1, count = 0;
  try {
    if (slash != std::string::npos) {
      std::size_t used_index = 0, used_count = 0;
      index = std::stoi(text.substr(0, slash), &used_index);
      count = std::stoi(text.substr(slash + 1), &used_count);
      if (used_index != slash || used_count != text.size() - slash - 1) index = -1;
    }
  } catch (const std::exception&) {
    index = -1;
  }
  if (index < 0 || count < 1 || index >= count) {
    throw std::invalid_argument(
        "'" + text + "' is no shard: expected I/N with 0 <= I < N, e.g. 0/4 (I is 0-based)");
  }
  return {index, count};
}

InputPlan PlanInputs(const std::vector<std::string>& inputs) {
  InputPlan plan;
  std::vector<std::string> specs;
  for (const std::string& input : inputs) {
    std::error_code error;
    if (!fs::is_directory(input, error) || HoldsImages(input)) {
      specs.push_back(input);
      continue;
    }
    std::vector<fs::path> entries;
    for (const fs::directory_entry& entry : fs::directory_iterator(input, error)) {
      entries.push_back(entry.path());
    }
    std::sort(entries.begin(), entries.end());
    const std::size_t before = specs.size();
    for (const fs::path& entry : entries) {
      if (fs::is_regular_file(entry) && HasVideoExtension(entry.string())) {
        specs.push_back(entry.string());
      } else if (fs::is_directory(entry) && HoldsImages(entry)) {
        specs.push_back(entry.string());
      } else if (!(fs::is_regular_file(entry) && IsCompanionFile(entry.string()))) {
        plan.skipped.push_back(entry.string() + ": not a video or a directory of images");
      }
    }
    if (specs.size() == before) {
      plan.skipped.push_back(input + ": holds no video and no directory of images");
    }
  }
  std::set<std::string> used;
  for (const std::string& spec : specs) {
    const std::string base = BaseName(spec);
    std::string name = base;
    for (int k = 2; used.count(name) != 0; ++k) name = base + "-" + std::to_string(k);
    used.insert(name);
    plan.inputs.push_back({spec, name});
  }
  return plan;
}

}  // namespace oal
