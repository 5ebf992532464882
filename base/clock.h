// Time spent, in the microseconds every report and benchmark counter speaks in.
#pragma once

#include <chrono>

namespace oal {

/// Microseconds from `start` to now, on the steady clock.
inline double MicrosecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace oal
