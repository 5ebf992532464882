// Numbers as the user reads them in messages, logs and tables.
#pragma once

#include <cstdio>
#include <string>

namespace oal {

/// `value` with `digits` digits after the point: Fixed(0.12345, 2) is "0.12".
inline std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace oal
