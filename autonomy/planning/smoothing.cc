#include "autonomy/planning/smoothing.h"

#include <cmath>

namespace paddock::planning {
namespace {

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

bool all_finite(const std::vector<Vec2>& pts) {
  for (const Vec2& p : pts)
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
  return true;
}

bool usable_window(int window, std::size_t n) {
  return window >= 1 && window % 2 == 1 && static_cast<std::size_t>(window) <= n;
}

bool usable_tolerances(double min_tol, double max_tol) {
  // max_tol may be +infinity (no search limit); NaN fails both comparisons
  return std::isfinite(min_tol) && min_tol > 0.0 && max_tol > 0.0;
}

// the centred moving average of any value type with + and / double
template <typename T>
std::vector<T> centred_average(const std::vector<T>& v, int window, bool closed) {
  const std::size_t n = v.size();
  const std::size_t h = static_cast<std::size_t>(window) / 2;
  const double w = static_cast<double>(window);
  std::vector<T> out = v;
  if (closed) {
    // sum each wrapped window [i-h, i+h] directly: windows are a few points,
    // and no running sum means no drift and no dependence on the start index
    for (std::size_t i = 0; i < n; ++i) {
      T sum{};
      for (std::size_t k = 0; k < static_cast<std::size_t>(window); ++k)
        sum = sum + v[(i + n - h + k) % n];
      out[i] = sum / w;
    }
    return out;
  }
  // open: only the points with a full window, [h, n-1-h], are filtered
  for (std::size_t i = h; i + h < n; ++i) {
    T sum{};
    for (std::size_t k = i - h; k <= i + h; ++k) sum = sum + v[k];
    out[i] = sum / w;
  }
  return out;
}

// squared distance from p to the ray that starts at r0 and passes through
// r1: perpendicular when p projects onto the ray, the distance to r0 when it
// lies behind r0 (or when r0 == r1)
double ray_distance2(Vec2 r0, Vec2 r1, Vec2 p) {
  const Vec2 v = r1 - r0;
  const Vec2 w = p - r0;
  const double cw = dot(w, v);
  const double cv = dot(v, v);
  if (cw <= 0.0 || cv == 0.0) return squared_norm(w);
  return squared_norm(w - v * (cw / cv));
}

// psimpl's Opheim on an open polyline of n >= 2 points given by an accessor
template <typename At>
std::vector<std::size_t> opheim_open(std::size_t n, At at, double min_tol, double max_tol) {
  const double min2 = min_tol * min_tol;
  const double max2 = max_tol * max_tol;  // +inf stays +inf: every point is "inside"
  std::vector<std::size_t> keys{0};
  std::size_t key = 0;    // the current key, start of the ray
  std::size_t ray = 0;    // the point that gives the ray its direction
  bool has_ray = false;
  // the test point j and the one before it, i = j - 1; j starts at 2 as in
  // psimpl, so the point right after a key is only ever the ray's point or
  // the next key
  for (std::size_t j = 2; j < n; ++j) {
    const std::size_t i = j - 1;
    const double d2 = squared_norm(at(j) - at(key));
    if (!has_ray) {
      // skip points within the radial tolerance of the key
      if (d2 < min2) continue;
      // the last point within it defines the ray
      ray = i;
      has_ray = true;
    }
    // inside the search radius and the strip around the ray: skip
    if (d2 < max2 && ray_distance2(at(key), at(ray), at(j)) < min2) continue;
    // j left the region: the point before it is the next key
    keys.push_back(i);
    key = i;
    has_ray = false;
  }
  keys.push_back(n - 1);
  return keys;
}

std::vector<std::size_t> all_indices(std::size_t n) {
  std::vector<std::size_t> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = i;
  return idx;
}

}  // namespace

std::vector<double> moving_average(const std::vector<double>& v, int window, bool closed) {
  if (!usable_window(window, v.size()) || !all_finite(v)) return v;
  return centred_average(v, window, closed);
}

std::vector<Vec2> moving_average(const std::vector<Vec2>& pts, int window, bool closed) {
  if (!usable_window(window, pts.size()) || !all_finite(pts)) return pts;
  return centred_average(pts, window, closed);
}

std::vector<std::size_t> opheim_indices(const std::vector<Vec2>& pts, double min_tol,
                                        double max_tol, bool closed) {
  const std::size_t n = pts.size();
  if (n < (closed ? 4u : 3u) || !usable_tolerances(min_tol, max_tol) || !all_finite(pts))
    return all_indices(n);
  if (!closed) return opheim_open(n, [&](std::size_t k) { return pts[k]; }, min_tol, max_tol);
  // a lap: cut open at pts[0], append it again as the end, drop that repeat
  std::vector<std::size_t> keys =
      opheim_open(n + 1, [&](std::size_t k) { return pts[k % n]; }, min_tol, max_tol);
  keys.pop_back();
  // a lap needs three corners; a loop smaller than the tolerances stays as it is
  if (keys.size() < 3) return all_indices(n);
  return keys;
}

std::vector<Vec2> opheim(const std::vector<Vec2>& pts, double min_tol, double max_tol,
                         bool closed) {
  std::vector<Vec2> out;
  for (std::size_t k : opheim_indices(pts, min_tol, max_tol, closed)) out.push_back(pts[k]);
  return out;
}

std::string SmoothingParams::check() const {
  const bool uses_average = method == MovingAverage || method == Combined;
  const bool uses_opheim = method == Opheim || method == Combined;
  if (uses_average && (window < 1 || window % 2 == 0))
    return "window must be odd and >= 1 when the method averages (got " + std::to_string(window) + ")";
  if (uses_opheim && !(opheim_min_tol > 0.0))
    return "opheim_min_tol must be > 0 m when the method uses Opheim (got " + params::number(opheim_min_tol) + ")";
  if (uses_opheim && !(opheim_max_tol > 0.0))
    return "opheim_max_tol must be > 0 m when the method uses Opheim (got " + params::number(opheim_max_tol) + ")";
  return "";
}

std::vector<Vec2> smooth_centreline(const std::vector<Vec2>& pts, bool closed,
                                    const SmoothingParams& params) {
  if (!params::validate(params).empty() || pts.size() < 3 || !all_finite(pts)) return pts;
  switch (params.method) {
    case SmoothingParams::MovingAverage:
      return moving_average(pts, params.window, closed);
    case SmoothingParams::Opheim:
      return opheim(pts, params.opheim_min_tol, params.opheim_max_tol, closed);
    case SmoothingParams::Combined:
      return opheim(moving_average(pts, params.window, closed), params.opheim_min_tol,
                    params.opheim_max_tol, closed);
    case SmoothingParams::Raw:
    default:
      return pts;
  }
}

}  // namespace paddock::planning
