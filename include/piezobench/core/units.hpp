#pragma once
// Constants shared by every module.
#include <numbers>

namespace piezobench {

inline constexpr double kPi = std::numbers::pi;       // rad per half cycle
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;  // rad per cycle: omega [rad/s] = kTwoPi f [Hz]

}  // namespace piezobench
