#pragma once
// a rotating LiDAR's layout and mounting: what its metadata/calibration file
// tells (beam elevations, columns per rotation) and where it sits on the car.
// One struct for both sides of the HAL: the simulated sensor is built with it
// (sensors::LidarParams embeds it) and the stack is told it as its
// calibration (perception::LidarCalibration is this struct).
#include <string>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::hal {

struct LidarLayout {
  // mounting in the base frame: on the nose cone, low, as in the paper (about
  // 0.7 m ahead of the front axle of a 1.53 m wheelbase). The sensor frame's
  // yaw is the base's; its pitch turns about its y axis.
  double mount_x = 2.2;
  double mount_y = 0.0;
  double mount_z = 0.15;
  double mount_pitch = 0.0;
  // channels evenly spaced in elevation from elevation_min to elevation_max
  // (both included). 32 channels over -8 .. +7.5 deg: a 0.5 deg vertical
  // resolution, with a channel level with the optical centre (channel 16,
  // 0 deg). The beams go where the cones are: seen from 0.15 m above the
  // ground a small cone (0.325 m) 1 m ahead spans -8.5 .. +9.9 deg, one 5 m
  // ahead -1.7 .. +2.0 deg, 10 m ahead -0.9 .. +1.0 deg; a 1 deg fan over
  // -16 .. +15 deg puts only two rings on it beyond ~8 m, too few for the
  // intensity profile's parabola (autonomy/perception/intensity_colour.h),
  // this one three out to ~11 m (four out to ~7 m). The lowest ring meets
  // the ground 1.07 m ahead; a cone closer than ~1.3 m loses its top. What
  // the layout resembles: the 0.33 - 0.5 deg band around the horizon of a
  // Velodyne VLP-32C or Hesai Pandar40P (-6 .. +2 deg at 0.33 deg, coarser
  // outside) spread evenly over a narrow field, like a narrow-FoV 32-beam
  // unit (an Ouster OS2-32: 22.5 deg, 0.7 deg uniform), not the 40 deg
  // fans that waste half their beams on the sky and the car's own nose.
  int channels = 32;
  double elevation_min = -8.0 * kPi / 180.0;
  double elevation_max = 7.5 * kPi / 180.0;
  // 1024 columns give a 6.1 mrad horizontal resolution
  int columns = 1024;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(mount_x), {"m", params::in(-10.0, 10.0), "the optical centre ahead of the rear axle"});
    v(PADDOCK_PARAM(mount_y), {"m", params::in(-5.0, 5.0), "the optical centre left of the centre"});
    v(PADDOCK_PARAM(mount_z), {"m", params::in(0.01, 5.0), "the optical centre above the ground"});
    v(PADDOCK_PARAM(mount_pitch), {"rad", params::in(-0.5, 0.5), "tilt about the sensor's y axis, > 0 nose down"});
    v(PADDOCK_PARAM(channels), {"", params::in(1, 65535), "channels, evenly spaced in elevation"});
    v(PADDOCK_PARAM(elevation_min), {"rad", params::Bounds{-kPi / 2, kPi / 2, true, true}, "the lowest channel's elevation"});
    v(PADDOCK_PARAM(elevation_max), {"rad", params::Bounds{-kPi / 2, kPi / 2, true, true}, "the highest channel's elevation"});
    v(PADDOCK_PARAM(columns), {"", params::in(1, 100000), "columns (firings) per rotation"});
  }
  std::string check() const {
    const bool ordered = channels > 1 ? elevation_max > elevation_min : elevation_max >= elevation_min;
    return ordered ? "" : "elevation_max must be > elevation_min (>= with one channel)";
  }
};

}  // namespace paddock::hal
