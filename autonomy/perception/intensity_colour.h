#pragma once
// a cone's colour from its LiDAR intensity profile (paper section "Lidar
// Perception"; ORACLES.md "Cones and LiDAR"). A blue cone carries a white
// middle stripe, so its returns' intensity peaks mid-height; a yellow cone a
// black one, so its intensity dips there. The returns (less those below
// min_height: ground) are cut into layers
// of layer_height by their height above the ground, each layer gives its
// median intensity, and a least-squares parabola I(z) = a z^2 + b z + c
// through the layers' (mean height, median intensity) decides:
//   a < -min_curvature: Blue;  a > +min_curvature: Yellow;  else Unknown.
// The intensities are divided by the largest layer median first: the range
// fall-off (1/r^2) and the incidence scale a cone's returns alike, so the
// sign of a is unchanged and min_curvature is a relative threshold.
// Unknown too when fewer than min_points returns, fewer than min_layers
// layers, or the layers span less than min_span of height (a stripe can only
// show between layers above and below it). A cone whose top return reaches
// big_cone_height is BigOrange (only big orange cones are that tall).
//
// The layers need rings: the default 32-channel sensor (0.5 deg over -8 ..
// +7.5 deg) 0.15 m above the ground puts three rings on a small cone out to
// ~11 m, one of them (0 deg) always at 0.15 m, inside the stripe (a 1 deg
// layout puts only two there beyond ~8 m: Unknown).
//
// No I/O, no clock, no global state; the classifier keeps scratch buffers.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/params.h"
#include "autonomy/perception/motion_correction.h"

namespace paddock::perception {

struct IntensityColourParams {
  // thinner than the small cone's 65 mm stripe, so the stripe owns a layer
  // of its own when the rings are dense enough
  double layer_height = 0.03;
  // 3: a parabola
  int min_layers = 3;
  // the ground return just in front of a cone joins the cone's vertical run
  // in the ground segmentation (its gap to the cone's lowest return is
  // within the expected gap + gap_noise), and its near-zero intensity at the
  // bottom of a yellow cone would read as a blue cone's dark base. Its
  // height is ~0 (the ground plane's error, ~1 cm); a cone's lowest ring may
  // hit only 1 - 2 cm up (a 1 deg layout's -1 deg ring at 7 - 8 m), which
  // 0.02 would lose
  double min_height = 0.01;
  int min_points = 4;
  double min_span = 0.1;
  // a stripe of contrast 0.3 over the cone's 0.3 m bends the parabola by
  // ~10-30
  double min_curvature = 2.0;
  // taller than any small cone (0.325 m), reached by a big one's (0.505 m)
  // returns when a ring hits its upper part
  double big_cone_height = 0.42;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(layer_height), {"m", params::above(0.0), "the returns are cut into layers this thick by their height"});
    v(PADDOCK_PARAM(min_layers), {"", params::at_least(3), "fewer layers: Unknown"});
    v(PADDOCK_PARAM(min_height), {"m", params::any(), "returns lower than this above the ground are left out"});
    v(PADDOCK_PARAM(min_points), {"", params::at_least(1), "fewer returns: Unknown"});
    v(PADDOCK_PARAM(min_span), {"m", params::at_least(0.0), "layers spanning less height than this (lowest to highest): Unknown"});
    v(PADDOCK_PARAM(min_curvature), {"1/m^2", params::at_least(0.0),
                                     "|a| of the normalised intensity parabola below this is no curvature: Unknown"});
    v(PADDOCK_PARAM(big_cone_height), {"m", params::above(0.0), "a cone whose top return reaches this is BigOrange"});
  }
};

// the fit behind a decision, for diagnostics
struct IntensityProfile {
  int layers = 0;
  double curvature = 0.0;  // a of the normalised fit (1/m^2); 0 when not fitted
};

class IntensityColourClassifier {
 public:
  // throws std::invalid_argument when params::validate(params) fails
  explicit IntensityColourClassifier(const IntensityColourParams& params = {});

  // the colour of the cone made of cloud.points[members[0 .. n)]; their
  // `height` is above the cone's ground; top: its highest return's height
  ConeColor classify(const Cloud& cloud, const std::uint32_t* members, std::size_t n, double top,
                     IntensityProfile* profile = nullptr);

  const IntensityColourParams& params() const { return params_; }

 private:
  IntensityColourParams params_;
  std::vector<std::pair<int, float>> samples_;  // scratch: (layer, intensity)
  std::vector<double> layer_z_, layer_i_;       // scratch: per layer
};

}  // namespace paddock::perception
