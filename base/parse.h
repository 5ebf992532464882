// Numbers read from text the user wrote (CSV fields, option values).
#pragma once

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace oal {

/// `text` as a finite number when all of it is one ("0.5", "-1e-3"); nullopt for anything
/// else ("", "0.5x", "nan", "inf", a number out of range).
inline std::optional<double> ParseFiniteDouble(const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace oal
