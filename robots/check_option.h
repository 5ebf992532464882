// The ceres-style message every Options::Check() of robots/ gives (robots/ may not use
// detector/, whose RequireOption is the same helper).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace oal {

/// Throws std::invalid_argument "FIELD = VALUE. Violated constraint: CONSTRAINT" unless `ok`.
template <typename T>
void RequireRobotOption(bool ok, const std::string& field, const T& value,
                        const std::string& constraint) {
  if (ok) return;
  std::ostringstream message;
  message << field << " = " << value << ". Violated constraint: " << constraint;
  throw std::invalid_argument(message.str());
}

}  // namespace oal
