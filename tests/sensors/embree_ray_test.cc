// the shared Embree ray set-up: rays set by set_ray meet a known triangle
// where plane geometry says, in a packet of 16 and alone, and respect
// [tnear, tfar].
#include "sim/sensors/embree_ray.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace paddock::sensors {
namespace {

// one big triangle in the plane x = 5, facing -x
class OneWall : public ::testing::Test {
 protected:
  void SetUp() override {
    device_ = rtcNewDevice("threads=1");
    ASSERT_NE(device_, nullptr);
    scene_ = rtcNewScene(device_);
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3));
    const float verts[9] = {5.0f, -100.0f, -100.0f, 5.0f, 100.0f, -100.0f, 5.0f, 0.0f, 100.0f};
    for (int i = 0; i < 9; ++i) v[i] = verts[i];
    auto* idx = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 1));
    idx[0] = 0, idx[1] = 1, idx[2] = 2;
    rtcCommitGeometry(g);
    geom_ = rtcAttachGeometry(scene_, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene_);
    ASSERT_EQ(rtcGetDeviceError(device_), RTC_ERROR_NONE);
  }
  void TearDown() override {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
  }
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  unsigned geom_ = 0;
};

TEST_F(OneWall, PacketLanesHitWherePlaneGeometrySays) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(64) int valid[16];
  alignas(64) RTCRayHit16 rh;
  const double org[3] = {1.0, 0.5, 0.25};
  const float inf = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 16; ++k) {
    // lanes 0..11 fan out towards the wall, 12..15 are masked off
    valid[k] = k < 12 ? -1 : 0;
    const double a = 0.1 * (k - 6);
    const double dir[3] = {std::cos(a), std::sin(a), 0.0};
    set_ray(rh, k, org, dir, 0.0f, inf);
  }
  // lane 3 may only look between 1 and 2 m: the wall (4 m away) is out of reach
  rh.ray.tfar[3] = 2.0f;
  rtcIntersect16(valid, scene_, &context, &rh);
  for (int k = 0; k < 16; ++k) {
    EXPECT_EQ(rh.ray.id[k], static_cast<unsigned>(k));
    // masked lanes: Embree's manual says their hit data is left alone, but
    // Debian's Embree 3 on an AVX2 machine (no AVX-512) writes it, so the
    // sensors read the valid lanes only and this checks nothing of them
    if (k >= 12) continue;
    if (k == 3) {
      EXPECT_EQ(rh.hit.geomID[k], RTC_INVALID_GEOMETRY_ID) << k;
      continue;
    }
    ASSERT_EQ(rh.hit.geomID[k], geom_) << k;
    // from x = 1 to the plane x = 5 along a unit direction at angle a: 4 / cos(a)
    const double a = 0.1 * (k - 6);
    EXPECT_NEAR(rh.ray.tfar[k], 4.0 / std::cos(a), 1e-5) << k;
  }
}

TEST_F(OneWall, ASingleRayRespectsTnearAndTfar) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const double org[3] = {0.0, 0.0, 0.0};
  const double dir[3] = {1.0, 0.0, 0.0};
  RTCRayHit rh;
  set_ray(rh, org, dir, 0.0f, 10.0f);
  rtcIntersect1(scene_, &context, &rh);
  ASSERT_EQ(rh.hit.geomID, geom_);
  EXPECT_NEAR(rh.ray.tfar, 5.0f, 1e-6f);
  // starting past the wall, or stopping short of it: no hit
  set_ray(rh, org, dir, 5.5f, 10.0f);
  rtcIntersect1(scene_, &context, &rh);
  EXPECT_EQ(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID);
  set_ray(rh, org, dir, 0.0f, 4.5f);
  rtcIntersect1(scene_, &context, &rh);
  EXPECT_EQ(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID);
}

}  // namespace
}  // namespace paddock::sensors
