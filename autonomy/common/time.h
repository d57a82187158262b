#pragma once
// time stamps: integer nanoseconds of simulation (or wall) time.
#include <cmath>
#include <cstdint>

namespace paddock {

using TimeNs = std::int64_t;

inline constexpr TimeNs kNsPerSecond = 1'000'000'000;
inline constexpr double to_seconds(TimeNs t) { return static_cast<double>(t) * 1e-9; }
inline TimeNs from_seconds(double s) { return static_cast<TimeNs>(std::llround(s * 1e9)); }

}  // namespace paddock
