#pragma once
// atan2 to within about one unit in the last place, about twice as fast as
// glibc's, which rounds correctly (bench/fast_math_bench.cc: 2.0x on an AMD
// EPYC).
// FastSLAM's measurement model calls atan2 three times per particle and
// associated cone (~18,000 times a frame with 200 particles): glibc's was a
// fifth of a FastSLAM update.
//
// The method is Cephes' atan (S. L. Moshier, "Methods and Programs for
// Mathematical Functions", 1989): atan(x) = x + x z P(z)/Q(z), z = x^2, on
// [0, 0.66], P of degree 4 and Q of degree 5 (monic); (0.66, 1] is folded
// onto [-0.21, 0] by atan(x) = pi/4 + atan((x - 1)/(x + 1)).
//
// atan2(y, x): atan of t = min(|x|, |y|) / max(|x|, |y|) in [0, 1] (no
// overflow, no division by zero but at the origin; the fold taken as
// (n - d)/(n + d), one division, n - d exact), then the octant's multiple
// of pi/2 with pi/2's low part added back. Measured against
// std::atan2 over 10^6 argument pairs: within 1.0 ulp, 4.4e-16 rad; the same
// signs of zero (atan2(+-0, -x) = +-pi), 0 at (0, 0) and (0, -0) as
// std::atan2 (+-pi for x = -0 as well), NaN in, NaN out, and NaN for two
// infinities (std::atan2: an odd multiple of pi/4). Deterministic:
// plain double arithmetic, no library call (built with -ffp-contract=off,
// no FMA contraction, so every machine gives the same bits).
//
// coarse_atan2: to within 2e-6 rad, cheaper still (Hastings' odd polynomial),
// for what only needs a sector (the ground segmenter's 0.2 rad sectors, on
// every return of every scan).
#include <algorithm>
#include <cmath>

#include "autonomy/common/geometry.h"

namespace paddock {

namespace fast_math_detail {

constexpr double kPio2 = 0.5 * kPi;   // pi/2, rounded (exactly half of kPi)
constexpr double kPio4 = 0.25 * kPi;  // pi/4, rounded
constexpr double kMoreBits = 6.123233995736765886130e-17;  // pi/2 - kPio2

// x + x z P(z)/Q(z), z = x^2: atan(x) for |x| <= 0.66; T a double, or four
// (simd_math.h: the same operations lane by lane; always inlined, so that an
// AVX2 build of the caller keeps it in one register)
template <class T>
__attribute__((always_inline)) inline T atan_kernel(T x) {
  const T z = x * x;
  const T p = (((-8.750608600031904122785e-1 * z - 1.615753718733365076637e1) * z - 7.500855792314704667340e1) * z -
               1.228866684490136173410e2) * z - 6.485021904942025371773e1;
  const T q = ((((z + 2.485846490142306297962e1) * z + 1.650270098316988542046e2) * z + 4.328810604912902668951e2) * z +
               4.853903996359136964868e2) * z + 1.945506571482613964425e2;
  return x * (z * p / q) + x;
}

// atan(n / d) for 0 <= n <= d, d > 0: one division for the fold as well
// ((n/d - 1)/(n/d + 1) = (n - d)/(n + d), where n - d is exact)
inline double atan_ratio(double n, double d) {
  if (n > 0.66 * d) return kPio4 + (atan_kernel((n - d) / (n + d)) + 0.5 * kMoreBits);
  return atan_kernel(n / d);
}

}  // namespace fast_math_detail

// atan2(y, x), within ~1 ulp (see the header)
inline double fast_atan2(double y, double x) {
  using namespace fast_math_detail;
  const double ax = std::abs(x), ay = std::abs(y);
  // the octant's multiple of pi/2 (and its low part) plus or minus atan of
  // the smaller over the larger
  double a;
  if (ay <= ax) {
    const double r = ax == 0.0 ? 0.0 : atan_ratio(ay, ax);  // (0, 0): 0, as atan2
    a = std::signbit(x) ? (2.0 * kPio2 - r) + 2.0 * kMoreBits : r;
  } else if (ay > ax) {
    const double r = atan_ratio(ax, ay);
    a = (std::signbit(x) ? kPio2 + r : kPio2 - r) + kMoreBits;
  } else {
    return x + y;  // a NaN
  }
  return std::signbit(y) ? -a : a;
}

// atan2(y, x) to within 2e-6 rad: Hastings' odd polynomial for atan on
// [0, 1] folded into the octants; 0 at the origin
inline double coarse_atan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay);
  if (mx == 0.0) return 0.0;
  const double z = std::min(ax, ay) / mx, z2 = z * z;
  double a = z * (0.99997726 + z2 * (-0.33262347 + z2 * (0.19354346 + z2 * (-0.11643287 + z2 * (0.05265332 + z2 * -0.01172120)))));
  if (ay > ax) a = 0.5 * kPi - a;
  if (x < 0.0) a = kPi - a;
  return y < 0.0 ? -a : a;
}

}  // namespace paddock
