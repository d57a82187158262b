#pragma once
// The tyre curve's transcendental functions as tables of polynomials, built
// once per car (vehicle::Car). Pacejka's g(X) = sin(C atan(X - E (X - atan X)))
// took three dependent atan/sin evaluations, a square root and a division a
// tyre, on top of the slip angle's atan: the critical path of every
// derivative, four derivatives a physics step. Both functions the model
// needs are even in their argument, so each is tabulated in s = t^2, which
// also drops the square root:
//   curve_ratio(s) = g(sqrt s) / sqrt s  (g(X) / X -> C as X -> 0), so a
//     tyre's force is D L(fz) fz curve_ratio(X^2) times its normalised slip;
//   atan_ratio(s) = atan(sqrt s) / sqrt s, so atan(t) = t atan_ratio(t^2).
// A table holds a polynomial of degree 7 in (s - its centre) on each cell:
// [0, 2^-8], then 16 cells per octave up to 2^6 (X, t < 8: the slip caps keep
// the tyres' arguments below 5.7), found from the bits of s (exponent and top
// four mantissa bits) with no search and no division, and evaluated by
// Estrin's scheme (a chain of three multiply-adds, not Horner's seven). Each
// polynomial is the Chebyshev interpolant of the function (in long double)
// on its cell; the build measures the table against the function between
// the nodes. Measured (tests/vehicle/tyre_tables_test.cc): atan_ratio
// within 1.2e-15 relative, curve_ratio within 2e-15 for the shipped cars
// and 1.1e-14 at the corner of the parameter box (C = 2, E = -5).
// Evaluation is elementwise IEEE arithmetic without FMA, like simd_math.h:
// the AVX2 and baseline builds of the vehicle give the same bits.
#include <array>
#include <cstdint>
#include <functional>

#include "autonomy/common/simd_math.h"

namespace paddock::vehicle {

// f(s) on [0, kMax) as polynomials on cells (see above)
class EvenTable {
 public:
  static constexpr int kDegree = 7;
  static constexpr double kFirst = 1.0 / 256.0;  // the first cell, [0, kFirst)
  static constexpr double kMax = 64.0;
  static constexpr int kPerOctave = 16;
  static constexpr int kCells = 1 + 14 * kPerOctave;  // octaves 2^-8 .. 2^6

  // tabulates f; returns the largest relative error of the table against f
  // at 9 points per cell, the cell's ends included
  double build(const std::function<long double(long double)>& f);

  // f(s) lane by lane; a lane outside [0, kMax) or NaN gets f(0) instead:
  // the caller replaces it
  PADDOCK_SIMD_INLINE simd::D4 operator()(simd::D4 s) const {
    using simd::D4;
    using simd::M4;
    const M4 inside = (s >= 0.0) & (s < kMax);
    const D4 v = simd::select(inside, s, simd::splat(0.0));
    const M4 bits = reinterpret_cast<M4>(v);
    const M4 first = v < kFirst;
    const M4 cell = ((bits >> 48) - (kFirstTop - 1)) & ~first;
    const D4 centre = simd::select(first, simd::splat(0.5 * kFirst), reinterpret_cast<D4>((bits & kTopMask) | kHalfBit));
    const D4 d = v - centre;
    const double* r0 = c_[static_cast<std::size_t>(cell[0])].data();
    const double* r1 = c_[static_cast<std::size_t>(cell[1])].data();
    const double* r2 = c_[static_cast<std::size_t>(cell[2])].data();
    const double* r3 = c_[static_cast<std::size_t>(cell[3])].data();
    const auto c = [r0, r1, r2, r3](int k) { return D4{r0[k], r1[k], r2[k], r3[k]}; };
    // Estrin's scheme: the pairs, then their pairs (a shorter chain than Horner's)
    const D4 d2 = d * d;
    const D4 d4 = d2 * d2;
    const D4 p01 = c(0) + c(1) * d, p23 = c(2) + c(3) * d, p45 = c(4) + c(5) * d, p67 = c(6) + c(7) * d;
    return (p01 + p23 * d2) + (p45 + p67 * d2) * d4;
  }

  // the same for one s (the lanes' computation: for the build's check)
  double at(double s) const;

 private:
  // s's bits above the mantissa's top four (sign, exponent, four bits): cell 1
  // starts at kFirst's, 2^-8 (biased exponent 1015, mantissa 0)
  static constexpr std::int64_t kFirstTop = 1015 * kPerOctave;
  static constexpr std::int64_t kTopMask = static_cast<std::int64_t>(0xFFFF000000000000ULL);
  static constexpr std::int64_t kHalfBit = 0x0000800000000000LL;  // the next mantissa bit: half a cell
  // cell c's coefficients of (s - centre)^k, k = 0 .. kDegree
  std::array<std::array<double, kDegree + 1>, kCells> c_{};
};

// a car's two tyre tables, for its C and E
struct TyreTables {
  TyreTables(double c, double e);
  EvenTable curve_ratio;  // g(sqrt s) / sqrt s
  EvenTable atan_ratio;   // atan(sqrt s) / sqrt s
  double error = 0.0;     // the larger of the two tables' build errors (relative)
};

}  // namespace paddock::vehicle
