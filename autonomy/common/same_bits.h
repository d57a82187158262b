#pragma once
// whether two numbers are the same bits: 0.0 and -0.0 differ, and a NaN
// equals a NaN of its own pattern (== says otherwise on both). For checks
// that a value computed elsewhere is exactly the one that would be computed
// here (the replay's results computed ahead)
#include <cstring>
#include <type_traits>

namespace paddock {

template <class T>
bool same_bits(T a, T b) {
  static_assert(std::is_floating_point_v<T>, "same_bits compares floating-point numbers");
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace paddock
