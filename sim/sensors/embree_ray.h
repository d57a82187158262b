#pragma once
// the Embree ray set-up shared by the LiDAR and the camera: a ray from an
// origin along a direction (both cast to Embree's floats) over [tnear, tfar],
// at time 0, that sees every geometry and has no hit yet.
#include <embree3/rtcore.h>

namespace paddock::sensors {

// lane k of a packet of 16 (ray id k)
inline void set_ray(RTCRayHit16& rh, int k, const double org[3], const double dir[3], float tnear, float tfar) {
  rh.ray.org_x[k] = static_cast<float>(org[0]);
  rh.ray.org_y[k] = static_cast<float>(org[1]);
  rh.ray.org_z[k] = static_cast<float>(org[2]);
  rh.ray.dir_x[k] = static_cast<float>(dir[0]);
  rh.ray.dir_y[k] = static_cast<float>(dir[1]);
  rh.ray.dir_z[k] = static_cast<float>(dir[2]);
  rh.ray.tnear[k] = tnear;
  rh.ray.tfar[k] = tfar;
  rh.ray.time[k] = 0.0f;
  rh.ray.mask[k] = 0xFFFFFFFFu;
  rh.ray.id[k] = static_cast<unsigned>(k);
  rh.ray.flags[k] = 0;
  rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
}

// a single ray (ray id 0)
inline void set_ray(RTCRayHit& rh, const double org[3], const double dir[3], float tnear, float tfar) {
  rh.ray.org_x = static_cast<float>(org[0]);
  rh.ray.org_y = static_cast<float>(org[1]);
  rh.ray.org_z = static_cast<float>(org[2]);
  rh.ray.dir_x = static_cast<float>(dir[0]);
  rh.ray.dir_y = static_cast<float>(dir[1]);
  rh.ray.dir_z = static_cast<float>(dir[2]);
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

}  // namespace paddock::sensors
