#pragma once
// atan, sin and cos of four doubles at once (GCC's and clang's vector
// extensions: one AVX2 register where the function is built for AVX2, two
// SSE2 registers on baseline x86-64, plain scalar code elsewhere), for the
// vehicle model's four tyres: twelve atan and four sin a derivative, four
// derivatives a physics step, were a third of a run on the true state with
// the oracle planner (glibc's atan, sin and sincos, by perf).
//
// Every operation is elementwise IEEE double arithmetic with no fused
// multiply-add (the project builds with -ffp-contract=off) and no library
// call, so the lanes give the same bits in every build, on every machine and
// whatever the register width: a function built twice, for AVX2 and for
// baseline x86-64 (sim/vehicle/vehicle.cc), computes the same result.
//
// atan: Cephes' (S. L. Moshier, "Methods and Programs for Mathematical
// Functions", 1989), fast_math.h's kernel: x + x z P(z)/Q(z), z = x^2, on
// [0, 0.66], with (0.66, tan(3 pi/8)] folded by pi/4 + atan((x - 1)/(x + 1))
// and the rest by pi/2 + atan(-1/x); the three cases selected lane by lane,
// not branched on. sin and cos: the argument reduced by the nearest multiple
// j of pi/2 (pi/2 in three parts of 33 bits, Cody and Waite: exact for
// |j| < 2^20, so |x| < 1.6e6), then the minimax polynomials of fdlibm's
// __kernel_sin and __kernel_cos on [-pi/4, pi/4] and the quadrant j mod 4.
// Measured against glibc (tests/common/simd_math_test.cc): atan within 1
// ulp, sin and cos within 2 (1.1e-16 absolute: the reduced argument's
// rounding is not carried into the kernels); NaN in, NaN out;
// atan(+-inf) = +-pi/2.
#include <cstdint>
#include <cstring>

#include "autonomy/common/fast_math.h"

namespace paddock::simd {

using D4 = double __attribute__((vector_size(32)));
using M4 = std::int64_t __attribute__((vector_size(32)));  // lane masks: -1 true, 0 false

#define PADDOCK_SIMD_INLINE __attribute__((always_inline)) inline

PADDOCK_SIMD_INLINE D4 splat(double v) { return D4{v, v, v, v}; }

PADDOCK_SIMD_INLINE D4 load(const double* p) {
  D4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

PADDOCK_SIMD_INLINE void store(double* p, D4 v) { std::memcpy(p, &v, sizeof v); }

// lane by lane: m ? a : b
PADDOCK_SIMD_INLINE D4 select(M4 m, D4 a, D4 b) {
  return reinterpret_cast<D4>((reinterpret_cast<M4>(a) & m) | (reinterpret_cast<M4>(b) & ~m));
}

namespace detail {
constexpr M4 kMagnitude = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};  // every bit but the sign
}  // namespace detail

PADDOCK_SIMD_INLINE D4 abs(D4 x) { return reinterpret_cast<D4>(reinterpret_cast<M4>(x) & detail::kMagnitude); }

// the sign of s on the magnitude of x
PADDOCK_SIMD_INLINE D4 copysign(D4 x, D4 s) {
  return reinterpret_cast<D4>((reinterpret_cast<M4>(x) & detail::kMagnitude) |
                              (reinterpret_cast<M4>(s) & ~detail::kMagnitude));
}

// a < b ? a : b and a > b ? a : b, lane by lane (b where a is NaN)
PADDOCK_SIMD_INLINE D4 min(D4 a, D4 b) { return select(a < b, a, b); }
PADDOCK_SIMD_INLINE D4 max(D4 a, D4 b) { return select(a > b, a, b); }

namespace detail {

constexpr double kPio2 = 1.57079632679489661923;   // pi/2, rounded
constexpr double kPio4 = 0.78539816339744830962;   // pi/4, rounded
constexpr double kMoreBits = 6.123233995736765886130e-17;  // pi/2 - kPio2
constexpr double kT3P8 = 2.41421356237309504880;    // tan(3 pi/8)
// pi/2 in three parts (fdlibm's pio2_1, pio2_2, pio2_2t): the first two of
// 33 bits, so j times each is exact
constexpr double kPio2Hi = 1.57079632673412561417e+00;
constexpr double kPio2Mid = 6.07710050630396597660e-11;
constexpr double kPio2Lo = 2.02226624879595063154e-21;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;
constexpr double kRoundMagic = 6755399441055744.0;  // 1.5 * 2^52: x + it - it rounds x to an integer

// fdlibm's __kernel_sin and __kernel_cos (with no tail) on [-pi/4, pi/4]
PADDOCK_SIMD_INLINE D4 sin_kernel(D4 x) {
  const D4 z = x * x;
  const D4 v = z * x;
  const D4 r = 8.33333333332248946124e-03 +
               z * (-1.98412698298579493134e-04 +
                    z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));
  return x + v * (-1.66666666666666324348e-01 + z * r);
}

PADDOCK_SIMD_INLINE D4 cos_kernel(D4 x) {
  const D4 z = x * x;
  const D4 r = z * (4.16666666666666019037e-02 +
                    z * (-1.38888888888741095749e-03 +
                         z * (2.48015872894767294178e-05 +
                              z * (-2.75573143513906633035e-07 +
                                   z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
  const D4 hz = 0.5 * z;
  const D4 w = 1.0 - hz;
  return w + (((1.0 - w) - hz) + z * r);
}

}  // namespace detail

// atan(x), lane by lane
PADDOCK_SIMD_INLINE D4 atan(D4 x) {
  using namespace detail;
  const D4 a = abs(x);
  const M4 big = a > kT3P8;
  const M4 mid = (a > 0.66) & ~big;
  // the folded argument num / den, one division for all three cases
  const D4 num = select(big, splat(-1.0), select(mid, a - 1.0, a));
  const D4 den = select(big, a, select(mid, a + 1.0, splat(1.0)));
  const D4 base = select(big, splat(kPio2), select(mid, splat(kPio4), splat(0.0)));
  const D4 extra = select(big, splat(kMoreBits), select(mid, splat(0.5 * kMoreBits), splat(0.0)));
  const D4 r = base + (fast_math_detail::atan_kernel(num / den) + extra);
  return copysign(r, x);
}

// sin(x) and cos(x), lane by lane
PADDOCK_SIMD_INLINE void sincos(D4 x, D4& s, D4& c) {
  using namespace detail;
  const D4 shifted = x * kTwoOverPi + kRoundMagic;  // j in the low bits
  const D4 j = shifted - kRoundMagic;
  const D4 r = ((x - j * kPio2Hi) - j * kPio2Mid) - j * kPio2Lo;
  const M4 quadrant = reinterpret_cast<M4>(shifted) & 3;
  const D4 sr = sin_kernel(r), cr = cos_kernel(r);
  const M4 odd = (quadrant & 1) != 0;
  const D4 s0 = select(odd, cr, sr);   // sin for quadrants 0, 1; minus it for 2, 3
  const D4 c0 = select(odd, -sr, cr);  // cos likewise
  const M4 upper = (quadrant & 2) != 0;
  s = select(upper, -s0, s0);
  c = select(upper, -c0, c0);
}

PADDOCK_SIMD_INLINE D4 sin(D4 x) {
  D4 s, c;
  sincos(x, s, c);
  return s;
}

}  // namespace paddock::simd
