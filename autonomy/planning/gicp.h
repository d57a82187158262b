#pragma once
// a 2D Generalised ICP (Segal, Haehnel, Thrun 2009, "Generalized-ICP"): the
// skidpad planner aligns its precalculated cone template to the observed
// cones with it (paper section "Planning").
//
// Each point of both clouds carries a 2x2 covariance estimated from its k
// nearest neighbours in its own cloud (nanoflann KD-tree) and regularised
// "plane-to-plane" style: in 2D the surface is a curve, so the direction of
// the neighbourhood's largest spread (the local tangent) gets variance 1 and
// the direction of the smallest (the normal) gets covariance_epsilon. A pair
// (a in the source, b its nearest target point within a max distance) then
// costs d^T (C_b + R C_a R^T)^{-1} d with d = b - (R a + t): the normal
// component of d is weighted ~1/(2 eps), the tangential one ~1/2, so points
// on a ring of cones are pulled onto the ring but may slide along it, which
// is what lets a wrong neighbour on the same ring still pull the right way
// and what pins the fit where point-to-point ICP drifts.
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::planning {

// defaults measured on the skidpad template (73 cones) moved by random
// transforms, 10 % of the cones dropped, 5 % colour flips, 3 false cones,
// only cones within 20 m of the start seen (GicpBasin in
// tests/planning/gicp_test.cc is a small version of that sweep)
struct GicpParams {
  // Skidpad cones along a ring are 2.9-4.2 m apart and the rings 3.3 m
  // apart, so a neighbourhood mixes both rings whatever k; 4 (a cone, its two
  // ring neighbours, one more) had the widest convergence basin of 3, 4 and 5.
  int k_neighbours = 4;
  // wide enough to pull the template in from a rough start-pose guess
  // (offsets of 4-7 m at the far cones), and thanks to the plane-to-plane
  // weights a cone matched to its ring neighbour still pulls along the
  // ring's normal
  double max_correspondence_distance = 5.0;
  // a cone with no counterpart (missed, extra) is matched to a neighbour
  // metres away by the wide gate and drags the fit along the rings (without
  // this stage the error was 9 cm / 0.45 deg RMS instead of 0.6 cm / 0.02
  // deg); the narrow gate drops it. Between the cone position noise (cm) and
  // half the cone spacing (~1.5 m).
  double refine_correspondence_distance = 1.0;
  int max_iterations = 100;
  double translation_tolerance = 1e-4;
  double rotation_tolerance = 1e-5;
  // The GICP paper's 1e-3 suits dense scans of surfaces; cones are discrete
  // points whose position along the ring is information too, and normals
  // from 4 noisy cones are rough: 1e-2 kept the basin of 1e-3 (better: 291
  // vs 271 of 300 partial views) and cut the error at 10 cm cone noise from
  // 3.3 to 2.8 cm; 1 would be point-to-point ICP (99 of 300).
  double covariance_epsilon = 1e-2;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(k_neighbours), {"", params::at_least(3), "neighbours (the point itself included) whose spread gives a point's covariance"});
    v(PADDOCK_PARAM(max_correspondence_distance), {"m", params::above(0.0), "correspondences farther apart than this are ignored"});
    v(PADDOCK_PARAM(refine_correspondence_distance), {"m", params::at_least(0.0),
                                                      "once converged, a second stage with correspondences gated at this (0: none)"});
    v(PADDOCK_PARAM(max_iterations), {"", params::at_least(1),
                                      "outer iterations (correspondences, then one damped Gauss-Newton step) per stage"});
    v(PADDOCK_PARAM(translation_tolerance), {"m", params::above(0.0), "converged when a step of the last stage moves less than this ..."});
    v(PADDOCK_PARAM(rotation_tolerance), {"rad", params::above(0.0), "... and turns less than this"});
    v(PADDOCK_PARAM(covariance_epsilon), {"", params::Bounds{0.0, 1.0, true, true},
                                          "the variance along the normal relative to 1 along the tangent"});
  }
};

// a symmetric 2x2 covariance [xx xy; xy yy] (m^2)
struct Covariance2 {
  double xx = 1.0;
  double xy = 0.0;
  double yy = 1.0;
};

struct GicpResult {
  Pose2 transform;         // T_target_source: source points into the target frame
  bool converged = false;  // the last stage's step fell below the tolerances (or no step
                           // lowered the cost) on a well-posed problem
  int iterations = 0;      // outer iterations done
  double rmse = 0.0;       // Euclidean RMS distance of the final correspondences (m)
  int inliers = 0;         // final correspondences within the max distance
  std::string reason;      // why not converged (empty when converged)

  bool ok() const { return converged; }
};

// the regularised covariance of each point from its k nearest neighbours in
// `points` (k = params.k_neighbours, clamped to the cloud's size): the
// eigenvector of the smallest eigenvalue (the normal) gets
// covariance_epsilon, the other (the tangent) 1. A neighbourhood with no
// spread at all (coincident points) gets the identity. Empty when the input
// has a non-finite point or the parameters are invalid.
std::vector<Covariance2> estimate_covariances(const std::vector<Vec2>& points,
                                              const GicpParams& params);

// the GICP alignment of `source` onto `target`, starting from `initial`
// (T_target_source), with covariances estimated inside. Fewer than 3 points
// in either cloud, non-finite values, collinear clouds, too few
// correspondences, a degenerate system or no convergence within
// max_iterations give converged = false with a reason; nothing throws.
GicpResult align(const std::vector<Vec2>& source, const std::vector<Vec2>& target,
                 const Pose2& initial, const GicpParams& params);

// the same with covariances given per point (one per point of each cloud),
// e.g. estimated per cone colour; identity covariances everywhere make this
// point-to-point ICP
GicpResult align(const std::vector<Vec2>& source, const std::vector<Covariance2>& source_cov,
                 const std::vector<Vec2>& target, const std::vector<Covariance2>& target_cov,
                 const Pose2& initial, const GicpParams& params);

// the GICP objective at a transform, correspondences by nearest neighbour
// within the max distance: sum d^T (C_b + R C_a R^T)^{-1} d
struct GicpObjective {
  double value = 0.0;
  int inliers = 0;
  std::string reason;  // empty when the inputs could be evaluated
};
GicpObjective gicp_objective(const std::vector<Vec2>& source,
                             const std::vector<Covariance2>& source_cov,
                             const std::vector<Vec2>& target,
                             const std::vector<Covariance2>& target_cov, const Pose2& transform,
                             const GicpParams& params);

}  // namespace paddock::planning
