// Degrees per radian, for the messages, reports and options that speak in degrees (the code
// itself works in radians; pi is detector/line.h's kPi).
#pragma once

namespace oal {

inline constexpr double kDegPerRad = 57.29577951308232087680;  // 180 / pi

}  // namespace oal
