// The one message every Options::Check() of the libraries gives.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace oal {

/// Throws std::invalid_argument "FIELD = VALUE. Violated constraint: CONSTRAINT" unless `ok`
/// (ceres' style).
template <typename T>
void RequireOption(bool ok, const std::string& field, const T& value,
                   const std::string& constraint) {
  if (ok) return;
  std::ostringstream message;
  message << field << " = " << value << ". Violated constraint: " << constraint;
  throw std::invalid_argument(message.str());
}

}  // namespace oal
