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
#include "autonomy/common/params.h"
#include "autonomy/planning/delaunay.h"

namespace paddock::planning {

// How the defaults were chosen: on the 14 real circuits in tracks/ (FSG
// 2019-2024, FSE 2022-2024, FSS 2019/2022, the FSSIM, EUFS and FSDS tracks),
// from each start pose, by coordinate descent over the fields below on 30
// seeded perturbed maps per circuit (10 % of the cones missed, 5 % of blue
// and yellow swapped, 0.1 m noise; once with colours, once without),
// counting the laps that do not close inside the true boundaries, under the
// constraints that every ground-truth lap, with and without colours, closes
// with >= 0.9 m between trajectory and boundary lines, and that the cones
// within 20 m of each start give an open path inside the track. Checked on
// 30 other seeds (840 laps, seeds 101-130: path_planner_test.cc,
// PathPlannerTracks.PerturbedMapsOnEveryCircuit): 29 of 420 fail with
// colours, 48 without; 13 and 23 of them on fss_2022_v1, whose infield
// strip between two blue lines looks like a lane once a boundary cone is
// missing. Missed cones cause nearly all failures (colour swaps alone: 1 in
// 420, noise alone: 0), and with colours most are safe: the search stops,
// inside the track, at a gap of two or three missed cones in a row that it
// cannot bridge. The counts quoted below for each field are of those 840
// laps as they were before 2026-11-29 (89 with the defaults, 40 with
// colours), when an edge between two cones of one colour scored as a
// perfect rung for a step with its first cone on the right (near_cones);
// weight_colour again since: 0.5: 30, 1: 29, 2: 36, 3: 48 with colours.
// Every field is an INI key `[planning.search] <name>`.
struct CentrelineParams {
  // the event horizon's largest depth and beam width (the search keeps a
  // branch's edges in fixed arrays of these sizes)
  static constexpr int kMaxDepth = 8;
  static constexpr int kMaxBeam = 16;

  // ---- candidates ------------------------------------------------------------
  // neighbouring rung midpoints are 1-2.5 m apart; 8 m bridges a missed cone
  // (6 m: 166 failures; 10 m: 89, 20 % slower)
  double search_radius = 8.0;
  // the zig-zag of the midpoints of two rungs sharing a cone
  double min_step = 0.5;
  // a 2.5 m radius hairpin turns ~0.8 rad per 2 m step
  double max_turn = 1.2;
  // a step must not cut through a boundary. The steps of the ground-truth
  // laps keep >= 1.02 m (FSG 2023); a step across a gap of missed cones can
  // cut the corner of a hairpin, and at the end of a partial map one can
  // leave the track (off: 1 of the 14 partial maps does)
  double min_clearance = 0.7;

  // ---- reward factor weights --------------------------------------------------
  // Each factor scores a step in [-1, 1] (track width in [-0.3, 1]); the
  // step's reward is the weighted mean sum(w_i s_i) / sum(w_i), so 1 is a
  // perfect step. As in the paper, track width >> prediction. Failures
  // with one weight at 0 instead: width 329, crossing 144, prediction 139,
  // angle 127, step 97, colour 92. Colour 0.5: 83, 2: 115, 3: 157 (a
  // swapped cone then leads the search across a boundary more often than
  // the colours keep it on the track).
  double weight_colour = 1.0;
  // the edge's extent across the step: a plausible track width
  double weight_width = 4.0;
  double weight_angle = 1.0;
  double weight_step = 0.5;
  double weight_prediction = 1.0;
  // a rung, not a boundary
  double weight_crossing = 3.0;

  // ---- factor shapes ---------------------------------------------------------
  // colour: the coloured cones within colour_radius of a midpoint vote on
  // which side is blue, the edge's own two cones double, one colour on both
  // ends of the edge votes against
  double colour_radius = 5.0;
  // track width reward (the paper's figure): 1 in [width_min, width_max],
  // 1.3 exp(-((w - edge)/width_sigma)^2 / 2) - 0.3 outside, on the edge's
  // length across the direction of the step (a diagonal rung between
  // staggered cones is longer than the track is wide)
  double width_min = 3.0;
  double width_max = 5.0;
  double width_sigma = 0.4;
  // change of heading: 2 exp(-(dtheta/angle_sigma)^2 / 2) - 1
  double angle_sigma = 0.6;
  // step length: 2 exp(-((l - step_preferred)/step_sigma)^2 / 2) - 1
  double step_preferred = 2.0;
  double step_sigma = 1.5;
  // prediction: the heading turned on by the mean turn of the last two
  // steps, at the candidate's distance; 2 exp(-(e/prediction_sigma)^2 / 2) - 1
  // on the distance e from that point
  double prediction_sigma = 1.5;

  // ---- event horizon ------------------------------------------------------------
  // 1 = greedy; 1: 517 failures, 2: 129, 3: 89, 4: 88 at 1.3 times the time
  int horizon_depth = 3;
  // best first: 4 and all (8-10) choose alike on every map tried, 3 not
  int first_beam_width = 4;
  // best first
  int beam_width = 2;

  // ---- stopping -------------------------------------------------------------------
  double min_reward = 0.1;
  // a continuation cut short by the end of the candidates counts 0 for each
  // missing step. Where the seen map ends on a bend, the last rungs fan out
  // from the last cone of one side and their midpoints lead across the
  // boundary; their continuations reward 0.3-0.45 a step, a real track's
  // 0.6-1. 0.5 stops there, 1.5-2 m before the end of the seen track (off:
  // 84 failures instead of 89, and 2 of the 14 partial maps leave the track)
  double min_horizon_reward = 0.5;
  int max_points = 1000;
  double max_length = 2000.0;

  // ---- loop closure ----------------------------------------------------------------
  // the path closes when it steps onto one of its first closure_points points
  // again, after at least closure_min_length of path, arriving within
  // closure_max_angle of the heading it first had there
  int closure_points = 3;
  double closure_min_length = 30.0;
  double closure_max_angle = 0.8;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(search_radius), {"m", params::in(0.5, 100.0), "candidate midpoints within this of the last point"});
    v(PADDOCK_PARAM(min_step), {"m", params::in(0.0, 10.0), "shortest step (< search_radius)"});
    v(PADDOCK_PARAM(max_turn), {"rad", params::Bounds{0.0, kPi, true, true}, "largest heading change of a step"});
    v(PADDOCK_PARAM(min_clearance), {"m", params::in(0.0, 5.0), "a step passes at least this far from every cone"});
    v(PADDOCK_PARAM(weight_colour), {"", params::in(0.0, 100.0), "reward weight: blue left, yellow right"});
    v(PADDOCK_PARAM(weight_width), {"", params::in(0.0, 100.0), "reward weight: track width (3-5 m, Gaussian edges)"});
    v(PADDOCK_PARAM(weight_angle), {"", params::in(0.0, 100.0), "reward weight: small change of angle"});
    v(PADDOCK_PARAM(weight_step), {"", params::in(0.0, 100.0), "reward weight: distance between midpoints"});
    v(PADDOCK_PARAM(weight_prediction), {"", params::in(0.0, 100.0), "reward weight: near the predicted position"});
    v(PADDOCK_PARAM(weight_crossing), {"", params::in(0.0, 100.0), "reward weight: the step crosses its edge squarely"});
    v(PADDOCK_PARAM(colour_radius), {"m", params::in(0.0, 50.0), "cones within this vote on the colour factor"});
    v(PADDOCK_PARAM(width_min), {"m", params::in(0.0, 20.0), "full width reward from"});
    v(PADDOCK_PARAM(width_max), {"m", params::in(0.0, 20.0), "full width reward up to (>= width_min)"});
    v(PADDOCK_PARAM(width_sigma), {"m", params::in(0.01, 10.0), "Gaussian edges of the width reward"});
    v(PADDOCK_PARAM(angle_sigma), {"rad", params::in(0.01, 10.0), "scale of the angle factor"});
    v(PADDOCK_PARAM(step_preferred), {"m", params::in(0.0, 50.0), "the typical step"});
    v(PADDOCK_PARAM(step_sigma), {"m", params::in(0.01, 50.0), "scale of the step factor"});
    v(PADDOCK_PARAM(prediction_sigma), {"m", params::in(0.01, 50.0), "scale of the prediction factor"});
    v(PADDOCK_PARAM(horizon_depth), {"", params::in(1, kMaxDepth), "event horizon: steps evaluated before committing"});
    v(PADDOCK_PARAM(first_beam_width), {"", params::in(1, kMaxBeam), "event horizon: first steps kept"});
    v(PADDOCK_PARAM(beam_width), {"", params::in(1, kMaxBeam), "event horizon: continuations kept per step"});
    v(PADDOCK_PARAM(min_reward), {"", params::in(-10.0, 10.0), "a step below this reward is not taken"});
    v(PADDOCK_PARAM(min_horizon_reward), {"", params::in(-10.0, 10.0), "stop when the best continuation averages below this"});
    v(PADDOCK_PARAM(max_points), {"", params::at_least(2), "the most points the search produces"});
    v(PADDOCK_PARAM(max_length), {"m", params::above(0.0), "the longest path the search produces"});
    v(PADDOCK_PARAM(closure_points), {"", params::at_least(1), "a loop closes on one of the path's first this many points"});
    v(PADDOCK_PARAM(closure_min_length), {"m", params::in(0.0, 10000.0), "a loop closes only after this length"});
    v(PADDOCK_PARAM(closure_max_angle), {"rad", params::above_up_to(0.0, kPi), "largest heading difference at a loop closure"});
  }
  std::string check() const;
};

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
  BadParams,        // params::validate() failed
  BadPose,          // the start pose is not finite
  NoTriangulation,  // fewer than 3 distinct cones, or all on one line
  SingleColour,     // every cone has the same known colour: one boundary only
  NoPath,           // fewer than two points found
};

// why the search stopped
enum class CentrelineStop {
  None,              // it did not run
  NoCandidate,       // no candidate above min_reward (the end of the cones)
  PoorContinuation,  // no continuation above min_horizon_reward (the end of the seen track, a gap)
  LoopClosed,        // back at its start: a full lap
  MaxPoints,
  MaxLength,
};

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
