// Pi and the degree, for the code that works in radians and the messages, reports and options
// that speak in degrees.
#pragma once

namespace oal {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegPerRad = 57.29577951308232087680;  // 180 / pi
inline constexpr double kRadPerDeg = kPi / 180.0;

}  // namespace oal
