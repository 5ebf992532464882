// The one message every Options::Check() of the libraries gives.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace oal {

/// Throws std::invalid_argument "FIELD = VALUE. Violated constraint: CONSTRAINT" unless `ok`
/// (ceres' style). The names are views: a check that passes builds no string (the pose
/// checks its options on every frame).
template <typename T>
void RequireOption(bool ok, std::string_view field, const T& value, std::string_view constraint) {
  if (ok) return;
  std::ostringstream message;
  message << field << " = " << value << ". Violated constraint: " << constraint;
  throw std::invalid_argument(message.str());
}

}  // namespace oal
