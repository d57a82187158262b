#include "sim/vehicle/tyre_tables.h"

#include <algorithm>
#include <cmath>

namespace paddock::vehicle {

namespace {

constexpr int kNodes = EvenTable::kDegree + 1;

// a cell's centre and half width
struct Cell {
  double centre, half;
};

Cell cell_bounds(int cell) {
  if (cell == 0) return {0.5 * EvenTable::kFirst, 0.5 * EvenTable::kFirst};
  const int j = cell - 1;
  const double octave = std::ldexp(1.0, j / EvenTable::kPerOctave - 8);
  const double width = octave / EvenTable::kPerOctave;
  return {octave + (j % EvenTable::kPerOctave + 0.5) * width, 0.5 * width};
}

}  // namespace

double EvenTable::build(const std::function<long double(long double)>& f) {
  // the Chebyshev nodes u_j = cos(pi (j + 1/2) / N) and T_k(u_j) = cos(pi k (j + 1/2) / N)
  std::array<std::array<long double, kNodes>, kNodes> basis{};
  for (int k = 0; k < kNodes; ++k)
    for (int j = 0; j < kNodes; ++j) basis[k][j] = std::cos(static_cast<long double>(M_PI) * k * (j + 0.5L) / kNodes);
  double worst = 0.0;
  for (int cell = 0; cell < kCells; ++cell) {
    const Cell b = cell_bounds(cell);
    // Chebyshev interpolation on the cell, u = (s - centre) / half in [-1, 1]
    std::array<long double, kNodes> value{};
    for (int j = 0; j < kNodes; ++j)
      value[j] = f(static_cast<long double>(b.centre) + static_cast<long double>(b.half) * basis[1][j]);
    std::array<long double, kNodes> cheb{};
    for (int k = 0; k < kNodes; ++k) {
      long double sum = 0.0L;
      for (int j = 0; j < kNodes; ++j) sum += value[j] * basis[k][j];
      cheb[k] = (k == 0 ? 1.0L : 2.0L) * sum / kNodes;
    }
    // sum_k cheb_k T_k(u) as powers of u (T_{k+1} = 2 u T_k - T_{k-1}), then of
    // s - centre: u^k = (s - centre)^k / half^k, half a power of two
    std::array<long double, kNodes> mono{}, t_prev{}, t_cur{};
    t_prev[0] = 1.0L;  // T_0
    t_cur[1] = 1.0L;   // T_1
    for (int k = 0; k < kNodes; ++k) {
      const std::array<long double, kNodes>& t = k == 0 ? t_prev : t_cur;
      for (int i = 0; i < kNodes; ++i) mono[i] += cheb[k] * t[i];
      if (k >= 1 && k + 1 < kNodes) {
        std::array<long double, kNodes> next{};
        for (int i = 0; i + 1 < kNodes; ++i) next[i + 1] = 2.0L * t_cur[i];
        for (int i = 0; i < kNodes; ++i) next[i] -= t_prev[i];
        t_prev = t_cur;
        t_cur = next;
      }
    }
    for (int k = 0; k < kNodes; ++k) c_[cell][k] = static_cast<double>(std::ldexp(mono[k], -k * std::ilogb(b.half)));
  }
  // the table against f across each cell, its ends included
  for (int cell = 0; cell < kCells; ++cell) {
    const Cell b = cell_bounds(cell);
    for (int i = 0; i <= 8; ++i) {
      const double s = b.centre + b.half * (i / 4.0 - 1.0);
      if (s >= kMax) continue;
      const long double exact = f(s);
      worst = std::max(worst, static_cast<double>(std::abs((at(s) - exact) / exact)));
    }
  }
  return worst;
}

double EvenTable::at(double s) const { return (*this)(simd::splat(s))[0]; }

TyreTables::TyreTables(double c, double e) {
  const long double cl = c, el = e;
  const double curve_error = curve_ratio.build([cl, el](long double s) {
    if (s <= 0.0L) return cl;  // g(X) ~ C X
    const long double x = std::sqrt(s);
    return std::sin(cl * std::atan(x - el * (x - std::atan(x)))) / x;
  });
  const double atan_error = atan_ratio.build([](long double s) {
    if (s <= 0.0L) return 1.0L;
    const long double t = std::sqrt(s);
    return std::atan(t) / t;
  });
  error = std::max(curve_error, atan_error);
}

}  // namespace paddock::vehicle
