#pragma once
// relocalisation against the map: where the car must be for one frame of
// cone observations to land on mapped cones, when the SLAM front end has
// lost track (a kidnapped car: lifted, pushed, or an odometry that jumped).
//
// An exhaustive search over a box of poses around the guess (translation on
// a grid of step_xy, heading on a grid of step_yaw), each scored by how many
// observations land within match_radius of a mapped cone (a lookup in a
// grid of cells marked near a cone, so a pose costs one lookup per
// observation), then the best pose refined by point-to-point least squares
// on its inliers (the closed-form 2-D rigid fit, a few rounds). Accepted
// when the inliers are at least min_inlier_ratio of the observations (and
// min_inliers): not all of a frame's cones are mapped (the far ones ahead
// are new), hence well under 1. A frame of a few cones on a regular row of
// cones can fit in several places, a row's spacing apart: the box must stay
// under the spacing of the cones along a row (~5 m), which a 2 m kidnap does.
#include <optional>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::slam {

struct RelocaliseParams {
  // lost: in lost_frames frames in a row, the front end's best particle
  // associated under lost_ratio of a frame's observations (at least
  // lost_min_observations of them) with cones it had mapped. Driving into
  // unexplored track a frame's new cones are the far few (a cone is seen
  // ~20 times on the way), so a healthy frame associates most of its cones
  double lost_ratio = 0.25;
  int lost_frames = 3;
  int lost_min_observations = 5;
  // the search box around the guess: +-search_xy, +-search_yaw
  double search_xy = 3.0;
  double search_yaw = 0.3;
  // grid steps: under the match radius (a pose within step/2 of the truth
  // puts every observation within ~match_radius of its cone)
  double step_xy = 0.2;
  double step_yaw = 0.01;
  double match_radius = 0.4;
  int min_inliers = 5;
  double min_inlier_ratio = 0.4;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(lost_ratio), {"", params::fraction(), "lost when a frame associates under this share of its observations ..."});
    v(PADDOCK_PARAM(lost_frames), {"", params::in(1, 1000), "... in this many frames in a row ..."});
    v(PADDOCK_PARAM(lost_min_observations), {"", params::in(1, 1000), "... each with at least this many observations"});
    v(PADDOCK_PARAM(search_xy), {"m", params::above_up_to(0.0, 50.0), "relocalisation searches +-this around the lost pose"});
    v(PADDOCK_PARAM(search_yaw), {"rad", params::in(0.0, kPi), "and +-this in heading"});
    v(PADDOCK_PARAM(step_xy), {"m", params::above_up_to(0.0, 10.0), "the search grid's step in x and y"});
    v(PADDOCK_PARAM(step_yaw), {"rad", params::above_up_to(0.0, 1.0), "the search grid's step in heading"});
    v(PADDOCK_PARAM(match_radius), {"m", params::above_up_to(0.0, 10.0), "an observation this close to a mapped cone is an inlier"});
    v(PADDOCK_PARAM(min_inliers), {"", params::in(1, 1000), "a relocalisation needs this many inliers ..."});
    v(PADDOCK_PARAM(min_inlier_ratio), {"", params::fraction(), "... and this share of the frame's observations"});
  }
};

struct Relocalisation {
  Pose2 pose;
  int inliers = 0;
};

// map: the mapped cones (map frame); observations: one frame's (base frame);
// guess: the pose the filter believed. None when no pose in the box fits
std::optional<Relocalisation> relocalise(const std::vector<Vec2>& map, const std::vector<Vec2>& observations,
                                         const Pose2& guess, const RelocaliseParams& p);

}  // namespace paddock::slam
