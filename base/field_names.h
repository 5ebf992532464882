// How a caller names a library's options to its user. A library's messages and hints name
// its own fields ("max_step_m", "target_lines"); the program that set them from a command
// line or a configuration gives the words its user typed ("--lines", "servo.max_step_m"),
// and a field it gives no word for keeps its own name.
#pragma once

#include <initializer_list>
#include <map>
#include <string>
#include <utility>

namespace oal {

class FieldNames {
 public:
  FieldNames() = default;
  FieldNames(std::initializer_list<std::pair<const std::string, std::string>> words)
      : words_(words) {}

  /// The user's word for `field`, or `field` itself.
  std::string operator()(const std::string& field) const {
    const auto word = words_.find(field);
    return word == words_.end() ? field : word->second;
  }

  /// `text`, followed by " (WORD)" when the caller gave `field` a word (a command, a key).
  std::string With(const std::string& text, const std::string& field) const {
    const auto word = words_.find(field);
    return word == words_.end() ? text : text + " (" + word->second + ")";
  }

 private:
  std::map<std::string, std::string> words_;
};

}  // namespace oal
