// Numbers as the user reads them in messages, logs and tables.
#pragma once

#include <cstdio>
#include <sstream>
#include <string>

namespace oal {

/// `value` with `digits` digits after the point: Fixed(0.12345, 2) is "0.12".
inline std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

/// `value` as a stream prints it, with `significant` significant digits: Number(0.5) is
/// "0.5", Number(1e-6) "1e-06", Number(2.0 / 3.0, 3) "0.667".
inline std::string Number(double value, int significant = 6) {
  std::ostringstream text;
  text.precision(significant);
  text << value;
  return text.str();
}

/// `text` in lower case (ASCII): file extensions, names compared without case.
inline std::string Lowercase(std::string text) {
  for (char& c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return text;
}

/// `text` with & < > " ' escaped, for HTML and XML (SVG) text and attribute values.
inline std::string MarkupEscaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace oal
