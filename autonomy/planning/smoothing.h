#pragma once
// centreline smoothing (paper section "Planning", Table II): a centred moving
// average, Opheim polyline simplification with psimpl's semantics, and their
// combination (moving average, then Opheim).
//
// Bad input never throws: an unusable window, tolerance or a non-finite
// value gives the input back unchanged (all indices, for Opheim), as each
// function documents; params::validate() names the reason for a parameter
// set.
#include <cstddef>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::planning {

// ---- moving average --------------------------------------------------------

// centred moving average: out[i] = mean of v[i-h .. i+h], h = window / 2.
//   window  odd and >= 1 (1 = identity). An even window, a window < 1, or a
//           window longer than the input is rejected: the input comes back
//           unchanged.
//   closed  the sequence is a loop: the window wraps around the ends.
//           open: the first and last h values lack a full window and are
//           left unfiltered (copied).
// A non-finite value anywhere gives the input back unchanged (a NaN would
// otherwise spread over a whole window).
std::vector<double> moving_average(const std::vector<double>& v, int window, bool closed);

// the same on each coordinate of a polyline
std::vector<Vec2> moving_average(const std::vector<Vec2>& pts, int window, bool closed);

// ---- Opheim simplification ---------------------------------------------------

// Opheim simplification with the semantics of psimpl's
// PolylineSimplification::Opheim (Elmar de Koning, 2010-2011), written anew:
// walk from the current key k. Points closer than min_tol to k are
// skipped; the point just before the first one that is not defines, with k,
// a ray. Following points are skipped while they are closer than max_tol to
// k AND closer than min_tol to the ray (perpendicular distance; the distance
// to k itself when they lie behind it). The point before the first that
// fails becomes the next key. First and last points are always kept.
// Distances are compared strictly (a point exactly max_tol from the key
// ends the run). Unlike psimpl, a zero, negative or NaN tolerance is
// rejected (psimpl squares a negative one) and all arithmetic is double.
//
// What this guarantees (and what not): each removed point lies within
// min_tol of its preceding key, or within max_tol of that key and within
// min_tol of the ray; except the point right after a key, which is not
// tested against that key: it is the ray's point, or it is dropped
// unchecked when the point after it is within min_tol of the key (psimpl's
// behaviour; a lone spike at index 1 can vanish). It does NOT guarantee
// that a removed point lies within min_tol of the kept segment that spans
// it: when the path stays inside the strip around the ray it can be up to
// 2 min_tol away (the point and the next key on opposite edges of the
// strip), and more when the path folds back along the strip.
//
//   min_tol  radial and perpendicular tolerance (m), finite and > 0
//   max_tol  search radius around the key (m), > 0, may be +infinity
//   closed   the polyline is a loop (first point not repeated at the end):
//            it is cut open at pts[0], simplified as the open polyline
//            pts[0], ..., pts[n-1], pts[0], and the repeated end is
//            dropped; pts[0] is therefore always kept. A loop that would
//            shrink to fewer than 3 points keeps all of them.
// Returns the kept indices, increasing. Fewer than 3 points (4 closed),
// a bad tolerance, or a non-finite coordinate keep every index.
std::vector<std::size_t> opheim_indices(const std::vector<Vec2>& pts, double min_tol,
                                        double max_tol, bool closed = false);

// the kept points themselves
std::vector<Vec2> opheim(const std::vector<Vec2>& pts, double min_tol, double max_tol,
                         bool closed = false);

// ---- the paper's combination -------------------------------------------------

struct SmoothingParams {
  enum Method { Raw, MovingAverage, Opheim, Combined };
  static constexpr params::Choice<Method> kMethodNames[] = {
      {"combined", Combined}, {"moving_average", MovingAverage}, {"opheim", Opheim}, {"raw", Raw}};
  // Combined = moving average, then Opheim on the averaged points (the
  // paper's best row in Table II)
  Method method = Combined;
  // The defaults were chosen on the real FS circuits in tracks/ (FSG 2019,
  // 2021, 2023, FSE 2023, FSS 2019) with a Delaunay-like centreline (the
  // midpoints of the rungs of a strip triangulation between the blue and
  // yellow cones, ~1.3-2 m apart), each run through build_reference with
  // its default 3 m knots, with and without 0.1 m cone noise. On FSG 2023:
  //                      max ay@5m/s  mean|dk/ds|  max|dk/ds|  min dist to boundary
  //   raw                 15.9 m/s^2   0.026 1/m^2  0.45        1.39 m
  //   moving average 3     8.8         0.019        0.15        1.35
  //   moving average 5    13.9         0.015        0.34        1.10
  //   Opheim 0.15/5       15.0         0.027        0.37        1.37
  //   Combined 3,0.15/5    8.4         0.018        0.14        1.36  (131 of 194 points)
  //
  // window: 3 removes most of the zig-zag of the midpoints. 5 and wider cut
  // the hairpins: averaging points on an arc pulls them towards its centre
  // by about R (1 - mean cos), which at a ~2.5 m hairpin with 1.6 m spacing
  // shrinks the radius (peak curvature up, not down) and moves the line
  // 0.4-0.8 m towards the inner cones.
  int window = 3;
  // 0.1-0.3 m behave alike on these tracks (a third to a half of the
  // averaged points dropped, the curvature variation a little lower still);
  // 0.15 m is the best on FSG 2023 and below the ~0.2 m by which the
  // midpoints already scatter about the true centreline.
  double opheim_min_tol = 0.15;
  // consecutive kept points are at most about this far apart (unless the
  // input's own points are farther), so straights keep knots for the
  // spline; 8 m let the line drift up to 0.3 m off the centreline on FSE
  // 2023 (0.14 m at 5 m).
  double opheim_max_tol = 5.0;

  // a parameter the method does not use is not checked: the rules that need
  // the method are in check()
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(method), kMethodNames, "centreline smoothing");
    v(PADDOCK_PARAM(window), {"", params::any(), "moving-average window (points, odd, >= 1)"});
    v(PADDOCK_PARAM(opheim_min_tol), {"m", params::any(), "Opheim radial and perpendicular tolerance (> 0)"});
    v(PADDOCK_PARAM(opheim_max_tol), {"m", params::any(), "Opheim largest step: the search radius around the key (> 0)"});
  }
  std::string check() const;
};

// the centreline smoothed by the chosen method.
//   pts     centreline points in driving order (m); closed: a lap, the
//           first point not repeated at the end
// Raw returns pts. Bad parameters (see params::validate), fewer than 3 points or a
// non-finite coordinate return pts unchanged.
std::vector<Vec2> smooth_centreline(const std::vector<Vec2>& pts, bool closed,
                                    const SmoothingParams& params = {});

}  // namespace paddock::planning
