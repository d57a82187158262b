#pragma once
// a rotating LiDAR's layout and mounting: what its metadata/calibration file
// tells (beam elevations, columns per rotation) and where it sits on the car.
// One struct for both sides of the HAL: the simulated sensor is built with it
// (sensors::LidarParams embeds it) and the stack is told it as its
// calibration (perception::LidarCalibration is this struct).
#include <cmath>
#include <string>
#include <vector>

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

  // what a sensor's metadata file adds (hal/ouster.h: layout_of); none of it
  // is an INI key, and all of it empty or zero is the even fan above.
  // the beams' elevations, one per channel, ascending (ring 0 the lowest);
  // empty: evenly spaced from elevation_min to elevation_max
  std::vector<double> beam_elevation;  // rad
  // per channel, added to the column's azimuth (> 0 counter-clockwise);
  // empty: none
  std::vector<double> beam_azimuth;  // rad
  // the beams leave the head beam_origin from the rotation axis, along the
  // column's azimuth (Ouster's lidar_origin_to_beam_origin_mm)
  double beam_origin = 0.0;  // m
  // the head spins clockwise seen from above (an Ouster, a Velodyne): column c
  // looks at pi - 2 pi c / columns; else counter-clockwise, at -pi + 2 pi c /
  // columns. Both put column 0 behind the car (the seam where the car's body
  // hides the view) and column columns / 2 straight ahead.
  bool clockwise = false;
  // the unit the sensor reports ranges in (an Ouster: 1 mm); 0: continuous
  double range_resolution = 0.0;  // m
  // the sensor reports intensity in [0, 1] in steps of 1 / intensity_full_scale
  // (an Ouster's 16-bit signal field: 65535); 0: continuous
  double intensity_full_scale = 0.0;

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
    if (!ordered) return "elevation_max must be > elevation_min (>= with one channel)";
    const auto n = static_cast<std::size_t>(channels);
    if (!beam_elevation.empty()) {
      if (beam_elevation.size() != n) return "beam_elevation must have one entry per channel";
      for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(beam_elevation[i]) || (i > 0 && !(beam_elevation[i] > beam_elevation[i - 1])))
          return "beam_elevation must be finite and strictly ascending";
      }
      if (beam_elevation.front() != elevation_min || beam_elevation.back() != elevation_max)
        return "beam_elevation must run from elevation_min to elevation_max";
    }
    if (!beam_azimuth.empty() && beam_azimuth.size() != n) return "beam_azimuth must have one entry per channel";
    for (const double a : beam_azimuth) {
      if (!std::isfinite(a)) return "beam_azimuth must be finite";
    }
    if (!std::isfinite(beam_origin) || std::abs(beam_origin) > 1.0) return "beam_origin must be in [-1, 1] m";
    if (!std::isfinite(range_resolution) || range_resolution < 0.0 || range_resolution > 1.0)
      return "range_resolution must be in [0, 1] m";
    if (!std::isfinite(intensity_full_scale) || intensity_full_scale < 0.0 || intensity_full_scale > 4294967295.0)
      return "intensity_full_scale must be in [0, 2^32 - 1]";
    return "";
  }
};

// the elevation of ring j (rad): beam_elevation[j], or the even fan's
inline double ring_elevation(const LidarLayout& l, int j) {
  if (!l.beam_elevation.empty()) return l.beam_elevation[static_cast<std::size_t>(j)];
  const double res = l.channels > 1 ? (l.elevation_max - l.elevation_min) / (l.channels - 1) : 0.0;
  return l.elevation_min + static_cast<double>(j) * res;
}

// the azimuth (rad, sensor frame, before beam_azimuth) of the head when it
// has turned `turn` of a rotation (0 <= turn < 1) since the seam: the one
// formula the simulated LiDAR casts along and the packet decoders use, so
// that a column's angle agrees to the bit on both sides of the wire
inline double turn_azimuth(const LidarLayout& l, double turn) {
  return l.clockwise ? kPi - 2.0 * kPi * turn : -kPi + 2.0 * kPi * turn;
}

// the azimuth of column c: turn_azimuth at c / columns (counter-clockwise
// written -pi + c (2 pi / columns), the simulator's formula before there was
// a clockwise head; the same number when columns is a power of two)
inline double column_azimuth(const LidarLayout& l, int c) {
  if (!l.clockwise) return -kPi + static_cast<double>(c) * (2.0 * kPi / l.columns);
  return turn_azimuth(l, static_cast<double>(c) / static_cast<double>(l.columns));
}

// the range a sensor reports for a measured range r (m): r rounded to
// range_resolution (the nearest unit, halves away from zero), or r itself
inline double reported_range(const LidarLayout& l, double r) {
  return l.range_resolution > 0.0 ? std::round(r / l.range_resolution) * l.range_resolution : r;
}

// the intensity a sensor reports for i in [0, 1]: the nearest step of
// 1 / intensity_full_scale (as the decoder's count / full scale), or i itself
inline double reported_intensity(const LidarLayout& l, double i) {
  return l.intensity_full_scale > 0.0 ? std::round(i * l.intensity_full_scale) / l.intensity_full_scale : i;
}

// the point (sensor frame) of a return at range r (m) on a beam of elevation
// (cos ce, sin se) and azimuth (cos ca, sin sa), the head's column azimuth
// (cos ca0, sin sa0): the beam leaves beam_origin n out along the column's
// azimuth (Ouster, "Lidar Range to XYZ"). n = 0 is r * (ce ca, ce sa, se).
inline void beam_point(double r, double n, double ce, double se, double ca, double sa, double ca0, double sa0,
                       float p[3]) {
  if (n == 0.0) {
    p[0] = static_cast<float>(r * (ce * ca));
    p[1] = static_cast<float>(r * (ce * sa));
    p[2] = static_cast<float>(r * se);
    return;
  }
  const double q = r - n;
  p[0] = static_cast<float>(q * (ce * ca) + n * ca0);
  p[1] = static_cast<float>(q * (ce * sa) + n * sa0);
  p[2] = static_cast<float>(q * se);
}

}  // namespace paddock::hal
