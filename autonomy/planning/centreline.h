#pragma once
// the reward-based centreline search (paper section "Planning"): greedy from
// the vehicle over the midpoints of the Delaunay edges, each step scoring the
// candidate midpoints ahead by weighted reward factors (the colour of the
// edge's cones, the track width, the change of angle, the step length, the
// distance to the position predicted from the previous points, and how
// squarely the step crosses the edge), with an event horizon that looks a
// few steps ahead before it commits to one.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/planning/delaunay.h"

namespace paddock::planning {

// The weights and shapes below were tuned on the 14 real circuits in tracks/
// (ground-truth cones; then 10 % missed cones, 5 % colour flips and 0.1 m
// noise; then no colour at all; then only the cones within 20 m of the start):
// see the comments of each group and tests/planning/centreline_test.cc.
// Every field is an INI key `[planning] <name>`.
struct CentrelineParams {
  // ---- candidates ------------------------------------------------------------
  // how far ahead a next midpoint is looked for (m): enough to bridge a
  // missed cone (rung midpoints are ~1-2.5 m apart, 5 m with a gap)
  double search_radius = 6.0;
  // candidates nearer than this are skipped (m): the zig-zag of the
  // midpoints of two rungs sharing a cone
  double min_step = 0.5;
  // half-angle of the forward cone of candidates around the current
  // direction (rad): a 2.5 m radius hairpin turns ~0.8 rad per 2 m step
  double max_turn = 1.4;

  // ---- reward factor weights (dimensionless) ----------------------------------
  // Each factor scores a step in [-1, 1] (track width in [-0.3, 1]); the
  // step's reward is the weighted mean sum(w_i s_i) / sum(w_i), so 1 is a
  // perfect step. The paper: track width >> prediction.
  double weight_colour = 2.0;      // blue left and yellow right
  double weight_width = 3.0;       // the edge's length: a plausible track width
  double weight_angle = 1.0;       // a small change of heading
  double weight_step = 0.5;        // a step near the typical spacing
  double weight_prediction = 1.0;  // near the predicted position
  double weight_crossing = 2.0;    // the step crosses its edge squarely

  // ---- factor shapes ---------------------------------------------------------
  // track width reward (the paper's figure): 1 in [width_min, width_max],
  // 1.3 exp(-((w - edge)/width_sigma)^2 / 2) - 0.3 outside (m)
  double width_min = 3.0;
  double width_max = 5.0;
  double width_sigma = 0.4;
  // change of heading: 2 exp(-(dtheta/angle_sigma)^2 / 2) - 1 (rad)
  double angle_sigma = 0.6;
  // step length: 2 exp(-((l - step_preferred)/step_sigma)^2 / 2) - 1 (m)
  double step_preferred = 2.0;
  double step_sigma = 1.5;
  // prediction: the last step's length and turn repeated; scored
  // 2 exp(-(e/prediction_sigma)^2 / 2) - 1 on the distance e to it (m)
  double prediction_sigma = 1.0;

  // ---- event horizon ------------------------------------------------------------
  // steps looked ahead before committing (count, >= 1; 1 = plain greedy)
  int horizon_depth = 3;
  // candidates followed from each node of the look-ahead, best first (count, >= 1)
  int beam_width = 3;

  // ---- stopping -------------------------------------------------------------------
  // a step must reward at least this much to be taken (dimensionless)
  double min_reward = 0.2;
  // the most points and the longest path the search produces (count, m)
  int max_points = 1000;
  double max_length = 2000.0;

  // ---- loop closure ----------------------------------------------------------------
  // the path closes when it steps onto one of its first closure_points points
  // (count) again, after at least closure_min_length (m) of path, arriving
  // within closure_max_angle (rad) of the heading it first had there
  int closure_points = 3;
  double closure_min_length = 30.0;
  double closure_max_angle = 0.8;
};

// a reason when the parameters cannot be used, or nothing when they can
std::optional<std::string> validate(const CentrelineParams& p);

// the scores of one step, each factor before weighting
struct RewardTerms {
  double colour = 0.0;
  double width = 0.0;
  double angle = 0.0;
  double step = 0.0;
  double prediction = 0.0;
  double crossing = 0.0;
};

// one point of the centreline and how it was chosen (for plots and tuning)
struct CentrelineStep {
  std::size_t edge = 0;         // the triangulation edge whose midpoint it is
  Vec2 point;                   // that midpoint (m)
  RewardTerms terms;            // the factor scores of the step onto it
  double reward = 0.0;          // their weighted mean
  double horizon_reward = 0.0;  // the best cumulative reward over the horizon
  int candidates = 0;           // candidates above min_reward at this step
};

enum class CentrelineStatus {
  Ok,               // at least two points
  BadParams,        // validate() failed
  BadPose,          // the start pose is not finite
  NoTriangulation,  // fewer than 3 distinct cones, or all on one line
  SingleColour,     // every cone has the same known colour: one boundary only
  NoPath,           // fewer than two points found
};

// why the search stopped
enum class CentrelineStop { None, NoCandidate, LoopClosed, MaxPoints, MaxLength };

struct CentrelineResult {
  std::vector<Vec2> points;           // in driving order; a closed lap does not repeat its first point
  std::vector<CentrelineStep> steps;  // one per point
  bool closed = false;                // the path is a full lap
  double length = 0.0;                // along the points (m), with the closing step when closed
  CentrelineStop stop = CentrelineStop::None;
  CentrelineStatus status = CentrelineStatus::NoPath;
  std::string reason;                 // empty when Ok

  bool ok() const { return status == CentrelineStatus::Ok; }
};

// the centreline from the vehicle's pose through the triangulation of
// `cones` (the same vector the triangulation was built from: the cones'
// colours are read by the edges' indices). Never throws; a degenerate map,
// a bad pose or bad parameters come back as a status and a reason.
CentrelineResult search_centreline(const Triangulation& triangulation,
                                   const std::vector<Cone>& cones, const Pose2& start,
                                   const CentrelineParams& params = {});

// the track-width reward of the paper's figure for an edge of length w (m)
double track_width_reward(double w, const CentrelineParams& params = {});

const char* to_string(CentrelineStatus s);
const char* to_string(CentrelineStop s);

}  // namespace paddock::planning
