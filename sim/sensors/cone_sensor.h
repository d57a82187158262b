#pragma once
// an object-level cone sensor: the `perception = ground_truth` source. It
// stands in for the output of a good LiDAR + camera pipeline (the paper's
// section "Perception": clusters from a nose-mounted LiDAR, coloured by the
// camera inside its field of view and by the LiDAR intensity profile outside
// it): the cones within range and field of view that no nearer cone hides, in
// the vehicle base frame, with range/bearing noise, missed cones, colours
// reported `unknown` or flipped, false positives, and a delivery latency.
//
// Model (ConeSensorParams) + a small class holding only its random stream
// (ConeSensor). No I/O, no clock, no global state: measure() is a pure
// function of the cones, the pose, the stamp and the stream's state.
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "sim/sensors/gaussian.h"

namespace paddock::sensors {

// every field is the INI key `[cone_sensor] <field>`. The defaults describe a
// good FS pipeline (a 64-channel 1024-column LiDAR on the nose cone, a camera
// on the main hoop, as on the paper's FRED-003C); each says why.
struct ConeSensorParams {
  // mounting of the sensor origin in the base frame (rear axle centre, x
  // forward, y left); the sensor looks along +x of the base frame.
  // 2.2 m: the paper's LiDAR sits on the nose cone, about 0.7 m ahead of the
  // front axle of a 1.53 m wheelbase.
  double mount_x = 2.2;
  double mount_y = 0.0;

  // range limits, from the sensor origin to the cone centre.
  // range_min 0.5 m: the blind zone of common FS LiDARs (0.3-0.5 m) and of the
  // nose's own body; a cone that close is about to be hit anyway.
  double range_min = 0.5;
  // range_max 20 m: a 64 x 1024 LiDAR puts E(15) = 2.7 and E(20) = 1.5 points
  // on a cone (ORACLES.md, AMZ's formula); past 20 m clustering stops working,
  // and between 15 and 20 m the miss probability below grows.
  double range_max = 20.0;

  // centred on +x of the sensor. 180 deg: the nose LiDAR sees the front
  // half-plane (the car's body hides the rear), and the fusion keeps
  // LiDAR-only cones outside the camera's narrower field of view (paper,
  // "Sensor fusion"), so the pipeline's output covers the LiDAR's.
  double fov = kPi;

  // occlusion: a cone whose bearing interval (from its base radius and range)
  // is covered by nearer cones' intervals by at least occlusion_fraction is
  // not seen. 0.5: a half-hidden cone keeps half its LiDAR points, about the
  // least a cluster filter tuned on whole cones accepts at mid range.
  bool occlusion = true;
  double occlusion_fraction = 0.5;
  // the base radii used for the bearing intervals: half the FS rule base
  // widths (228 mm small, 285 mm big orange), as the cone world's collision
  // circles. Blue, yellow, small orange and unknown cones are small. Not set
  // by the user, so not visited: the runner fills them from the cones' sizes
  // (half of world::ConeWorldParams' small_cone and big_cone base_width,
  // sim/runner/model.cc); check() checks them.
  double small_cone_radius = 0.114;  // m
  double big_cone_radius = 0.1425;   // m

  // range noise std sigma_r = range_noise + range_noise_per_m * r.
  // 0.02 m: the paper quotes a 2-3 cm LiDAR uncertainty; + 2 mm per m: the
  // cluster centre comes from fewer points farther out (6 cm at 20 m).
  double range_noise = 0.02;
  double range_noise_per_m = 0.002;
  // 2 mrad: a 1024-column LiDAR quantises the azimuth in steps of
  // 2 pi / 1024 = 6.1 mrad; a uniform error over one step has a std of
  // 6.1 / sqrt(12) = 1.8 mrad (4 cm across at 20 m).
  double bearing_noise = 0.002;

  // a cone in view is missed with p = miss_probability + miss_probability_growth
  // * (r / range_max)^2. 2 % near, 14 % at 20 m, 8.75 % at 15 m: the > 90 %
  // recall to 15 m of a good FS pipeline, falling as E(d) ~ 1/d^2 thins the
  // clusters.
  double miss_probability = 0.02;
  double miss_probability_growth = 0.12;

  // colour: a detected cone's colour is reported `unknown` with p_u =
  // unknown_color_probability + unknown_color_growth * (r / range_max)^2;
  // otherwise it flips to the wrong colour (blue <-> yellow, small orange <->
  // big orange) with p_f = color_flip_probability + color_flip_growth *
  // (r / range_max)^2; a cone of unknown true colour stays unknown.
  // 1 % + 1 % at the car (98 % correct; 96.6 % at 5 m: the > 95 % a good
  // camera classifier reaches on near cones); at 15 m 11.7 % unknown and 3.25 % flipped of the rest
  // (85 % correct): the camera boxes shrink to a few pixels and the LiDAR
  // intensity profile rests on two or three rings.
  double unknown_color_probability = 0.01;
  double unknown_color_growth = 0.19;
  double color_flip_probability = 0.01;
  double color_flip_growth = 0.04;

  // false positives per frame, a Poisson mean, placed uniformly over the area
  // of the field of view between range_min and range_max; each is `unknown`
  // with false_positive_unknown_probability, else blue, yellow, small or big
  // orange with equal odds. 0.2: the rule-based cluster filter and the camera
  // check leave about one spurious cone every half second; half of them come
  // from the LiDAR alone (outside the camera boxes) with no colour.
  double false_positives_per_frame = 0.2;
  double false_positive_unknown_probability = 0.5;

  // between the measurement (the stamp) and the delivery of the message.
  // 0.1 s: a point of a 10 Hz rotation is on average 50 ms old when the scan
  // closes, plus ~50 ms for motion correction, ground removal, clustering,
  // YOLO and fusion.
  double latency = 0.1;
  // one per LiDAR rotation, 10 Hz (DESIGN.md default rates)
  double rate = 10.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(mount_x), {"m", params::in(-10.0, 10.0), "sensor position ahead of the rear axle"});
    v(PADDOCK_PARAM(mount_y), {"m", params::in(-5.0, 5.0), "sensor position left of the centre"});
    v(PADDOCK_PARAM(range_min), {"m", params::in(0.0, 1000.0), "nearest cone seen"});
    v(PADDOCK_PARAM(range_max), {"m", params::in(0.1, 1000.0), "farthest cone seen"});
    v(PADDOCK_PARAM(fov), {"rad", params::in(0.01, 2.0 * kPi), "horizontal field of view, centred forward"});
    v(PADDOCK_PARAM(occlusion), "cones hide cones behind them");
    v(PADDOCK_PARAM(occlusion_fraction), {"", params::above_up_to(0.0, 1.0), "share of a cone's bearing that must be covered to hide it"});
    v(PADDOCK_PARAM(range_noise), {"m", params::in(0.0, 10.0), "range noise std at 0 m"});
    v(PADDOCK_PARAM(range_noise_per_m), {"m/m", params::in(0.0, 1.0), "growth of the range noise std with range"});
    v(PADDOCK_PARAM(bearing_noise), {"rad", params::in(0.0, 1.0), "bearing noise std"});
    v(PADDOCK_PARAM(miss_probability), {"", params::fraction(), "chance a cone in view is missed, near"});
    v(PADDOCK_PARAM(miss_probability_growth), {"", params::fraction(), "added at range_max (quadratic in range)"});
    v(PADDOCK_PARAM(unknown_color_probability), {"", params::fraction(), "chance of no colour, near"});
    v(PADDOCK_PARAM(unknown_color_growth), {"", params::fraction(), "added at range_max (quadratic in range)"});
    v(PADDOCK_PARAM(color_flip_probability), {"", params::fraction(), "chance of the look-alike colour, near"});
    v(PADDOCK_PARAM(color_flip_growth), {"", params::fraction(), "added at range_max (quadratic in range)"});
    // the upper bound keeps the Poisson draw and the frame size sane
    v(PADDOCK_PARAM(false_positives_per_frame), {"", params::in(0.0, 100.0), "mean ghost cones per frame (Poisson)"});
    v(PADDOCK_PARAM(false_positive_unknown_probability), {"", params::fraction(), "share of ghosts without colour"});
    v(PADDOCK_PARAM(latency), {"s", params::in(0.0, 10.0), "measurement to delivery"});
    v(PADDOCK_PARAM(rate), {"Hz", params::in(0.1, 1000.0), "frames per second"});
  }
  // the cone radii, range_max > range_min, and each probability with its
  // growth at most 1
  std::string check() const;
};

// what one measure() call did, for reports and tests
struct ConeSensorFrameStats {
  int in_view = 0;          // standing cones within range and field of view
  int occluded = 0;         // of which hidden behind nearer cones
  int missed = 0;           // of the rest, dropped by the miss probability
  int knocked = 0;          // knocked cones within range (never reported)
  int false_positives = 0;  // spurious detections added
};

class ConeSensor {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // this sensor's own random stream (std::mt19937_64): the same seed and the
  // same inputs give the same frames.
  ConeSensor(const ConeSensorParams& params, std::uint64_t seed);

  // one frame. cones: current map-frame positions and true colours; knocked:
  // same size as cones (true = lying down: neither reported nor hiding the
  // cones behind it), or empty for none;
  // base_pose: the true pose of the base frame in the map at the measurement
  // time; stamp: that time. Returns the detections in the BASE frame, stamped
  // with `stamp`, sorted by measured range. A non-finite pose gives an empty
  // frame (and draws nothing); cones with a non-finite position are skipped.
  hal::ConeDetections measure(const std::vector<Cone>& cones, const std::vector<bool>& knocked,
                              const Pose2& base_pose, TimeNs stamp);

  const ConeSensorParams& params() const { return params_; }
  const ConeSensorFrameStats& last_stats() const { return stats_; }
  // per cone of the last measure() call: in range and field of view, standing
  // and not hidden (whether or not then missed): the cones it could see
  const std::vector<bool>& last_visible() const { return visible_; }
  // the latency and frame period in integer nanoseconds
  TimeNs latency_ns() const { return from_seconds(params_.latency); }
  TimeNs period_ns() const { return from_seconds(1.0 / params_.rate); }

 private:
  // a cone within range_max, for the occlusion sweep
  struct Candidate {
    double range2;   // squared range from the sensor (m^2)
    double bearing;  // rad, in the sensor frame, [-pi, pi]
    double radius;   // m, base radius
    ConeColor color;
    std::size_t index;  // in the input list
  };
  // a bearing interval [lo, hi] within [-pi, pi]
  struct Interval {
    double lo;
    double hi;
  };

  double covered_length(double lo, double hi) const;
  void cover(double lo, double hi);
  double uniform();   // [0, 1)
  double gaussian();  // N(0, 1)

  ConeSensorParams params_;
  std::mt19937_64 rng_;
  Gaussian normal_{0.0, 1.0};
  ConeSensorFrameStats stats_;
  std::vector<bool> visible_;
  // scratch, kept to avoid allocating every frame
  std::vector<Candidate> candidates_;
  std::vector<Interval> covered_;  // disjoint, sorted by lo
};

}  // namespace paddock::sensors
