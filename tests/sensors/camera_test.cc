// the ray-cast camera, checked against independent numbers: K by hand from
// the field of view, a hand-written projection of the mounting geometry, the
// apparent size f h / r, the horizon row tan(pitch) f above the centre, the
// occluded cone's pixel count against the same cone rendered alone, and the
// trigger column of the LiDAR.
#include "sim/sensors/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <stdexcept>
#include <vector>

#include "sim/world/track.h"
#include "sim/world/venue.h"

namespace paddock::sensors {
namespace {

// the labelled pixels of one id: their count and tight box (pixel indices)
struct Blob {
  int count = 0;
  int i0 = 1 << 30, i1 = -1, j0 = 1 << 30, j1 = -1;
  long r = 0, g = 0, b = 0;  // summed colour
};

Blob blob(const AnnotatedFrame& f, std::int32_t id) {
  Blob bl;
  for (int j = 0; j < f.frame.height; ++j) {
    for (int i = 0; i < f.frame.width; ++i) {
      const std::size_t p = static_cast<std::size_t>(j) * f.frame.width + i;
      if (f.annotation.labels[p] != id) continue;
      ++bl.count;
      bl.i0 = std::min(bl.i0, i);
      bl.i1 = std::max(bl.i1, i);
      bl.j0 = std::min(bl.j0, j);
      bl.j1 = std::max(bl.j1, j);
      bl.r += f.frame.rgb[3 * p];
      bl.g += f.frame.rgb[3 * p + 1];
      bl.b += f.frame.rgb[3 * p + 2];
    }
  }
  return bl;
}

// the mounting geometry written out by hand (no Eigen, no calibration()):
// camera at (mx, my, mz) of the base frame, axis pitched down by th; for a
// base point d = P - C: z_opt = dx cos th - dz sin th, x_opt = -dy,
// y_opt = -dx sin th - dz cos th; u = f x / z + W / 2, v = f y / z + H / 2
struct Pix {
  double u, v, depth;
};
Pix hand_project(const CameraParams& p, double X, double Y, double Z) {
  const double f = 0.5 * p.width / std::tan(0.5 * p.hfov);
  const double dx = X - p.mount_x, dy = Y - p.mount_y, dz = Z - p.mount_z;
  const double c = std::cos(p.mount_pitch), s = std::sin(p.mount_pitch);
  const double z = dx * c - dz * s, x = -dy, y = -dx * s - dz * c;
  return {f * x / z + 0.5 * p.width, f * y / z + 0.5 * p.height, z};
}

TEST(Camera, CalibrationMatchesHandComputedIntrinsicsAndMount) {
  const CameraParams p;
  const perception::CameraCalibration k = Camera(p, 1).calibration();
  // 800 px over 90 deg: f = 400 / tan(45 deg) = 400 px; centre (400, 250)
  EXPECT_EQ(k.width, 800);
  EXPECT_EQ(k.height, 500);
  EXPECT_NEAR(k.fx, 400.0, 1e-9);
  EXPECT_NEAR(k.fy, 400.0, 1e-9);
  EXPECT_NEAR(k.cx, 400.0, 1e-12);
  EXPECT_NEAR(k.cy, 250.0, 1e-12);
  // a point 10 m down the optical axis is at optical (0, 0, 10)
  const double th = p.mount_pitch;
  const Eigen::Vector3d on_axis(p.mount_x + 10.0 * std::cos(th), p.mount_y, p.mount_z - 10.0 * std::sin(th));
  const Eigen::Vector3d pc = k.T_camera_base * on_axis;
  EXPECT_NEAR(pc.x(), 0.0, 1e-9);
  EXPECT_NEAR(pc.y(), 0.0, 1e-9);
  EXPECT_NEAR(pc.z(), 10.0, 1e-9);
  // base +y (left) is optical -x; the optical centre is the mount point
  const Eigen::Vector3d left = k.T_camera_base.linear() * Eigen::Vector3d(0, 1, 0);
  EXPECT_NEAR(left.x(), -1.0, 1e-12);
  const Eigen::Vector3d c = k.T_camera_base.inverse().translation();
  EXPECT_NEAR(c.x(), 0.95, 1e-12);
  EXPECT_NEAR(c.z(), 1.20, 1e-12);
  // and a general point as the hand formula has it
  const Pix h = hand_project(p, 7.0, 1.3, 0.2);
  const Eigen::Vector3d q = k.T_camera_base * Eigen::Vector3d(7.0, 1.3, 0.2);
  EXPECT_NEAR(k.fx * q.x() / q.z() + k.cx, h.u, 1e-9);
  EXPECT_NEAR(k.fy * q.y() / q.z() + k.cy, h.v, 1e-9);
}

TEST(Camera, RejectsBadParams) {
  CameraParams p;
  p.width = 4;
  EXPECT_EQ(params::validate(p), "width must be in [16, 8192] px (got 4)");
  p = CameraParams{};
  p.hfov = 3.2;
  EXPECT_EQ(params::validate(p).rfind("hfov must be in [", 0), 0u) << params::validate(p);
  p = CameraParams{};
  p.blue.b = 1.5;
  EXPECT_EQ(params::validate(p), "blue.b must be in [0, 1] (got 1.5)");
  p = CameraParams{};
  p.mount_z = 0.0;
  EXPECT_EQ(params::validate(p), "mount_z must be in [0.01, 5] m (got 0)");
  EXPECT_THROW(Camera(p, 1), std::invalid_argument);
  EXPECT_EQ(params::validate(CameraParams{}), "");
}

TEST(Camera, SingleConeSitsWhereItsCentreProjects) {
  const CameraParams p;
  for (const auto& [color, y] : {std::pair{ConeColor::Blue, 0.8}, std::pair{ConeColor::Yellow, -1.1}}) {
    const double X = 7.0;
    LidarWorld world({Cone{{X, y}, color}});
    Camera cam(p, 1);
    const AnnotatedFrame f = cam.render(world, Pose2{}, 123);
    ASSERT_EQ(f.frame.width * f.frame.height, 800 * 500);
    ASSERT_EQ(f.frame.rgb.size(), 3u * 800 * 500);
    ASSERT_EQ(f.annotation.labels.size(), 800u * 500);
    EXPECT_EQ(f.frame.stamp, 123);
    ASSERT_EQ(f.annotation.instances.size(), 1u);
    EXPECT_EQ(f.annotation.instances[0].id, 0);
    EXPECT_EQ(f.annotation.instances[0].color, color);
    EXPECT_NEAR(f.annotation.instances[0].visible_fraction, 1.0, 1e-12);
    // range to the middle of the axis, h / 2 = 0.1625 m up
    EXPECT_NEAR(f.annotation.instances[0].range,
                std::sqrt((X - 0.95) * (X - 0.95) + y * y + (1.2 - 0.1625) * (1.2 - 0.1625)), 1e-4);

    const Blob b = blob(f, 0);
    ASSERT_GT(b.count, 50);
    // the projected mid-height point lies inside the labelled pixels' box,
    // and the calibration puts it at the same pixel as the hand formula
    const Pix c = hand_project(p, X, y, 0.1625);
    const perception::CameraCalibration k = cam.calibration();
    const Eigen::Vector3d q = k.T_camera_base * Eigen::Vector3d(X, y, 0.1625);
    EXPECT_NEAR(k.fx * q.x() / q.z() + k.cx, c.u, 1e-9);
    EXPECT_NEAR(k.fy * q.y() / q.z() + k.cy, c.v, 1e-9);
    EXPECT_GE(c.u, b.i0);
    EXPECT_LE(c.u, b.i1 + 1);
    EXPECT_GE(c.v, b.j0);
    EXPECT_LE(c.v, b.j1 + 1);
    // the pixel under it is the cone's
    const auto pi = static_cast<std::size_t>(c.u), pj = static_cast<std::size_t>(c.v);
    EXPECT_EQ(f.annotation.labels[pj * 800 + pi], 0);
    // its box: f h / r tall and f w / r wide, within a few px (the pitch and
    // the base's depth make the true figures differ a little)
    const double depth = c.depth;
    EXPECT_NEAR(b.j1 + 1 - b.j0, 400.0 * 0.325 / depth, 3.0);
    EXPECT_NEAR(b.i1 + 1 - b.i0, 400.0 * 0.228 / depth, 3.0);
    // its colour: blue-ish or yellow-ish on average (stripes included)
    if (color == ConeColor::Blue) {
      EXPECT_GT(b.b, 2 * b.r);
      EXPECT_GT(b.b, b.g);
    } else {
      EXPECT_GT(b.r, 2 * b.b);
      EXPECT_GT(b.g, 2 * b.b);
    }
    // nothing else is labelled
    EXPECT_EQ(std::count(f.annotation.labels.begin(), f.annotation.labels.end(), -1), 800 * 500 - b.count);
  }
}

TEST(Camera, HiddenConeHasTheVisibleFractionOfItsUnoccludedPixels) {
  const CameraParams p;
  // front cone at 5 m, the other 0.6 m behind and 0.1 m aside: the camera
  // 1.2 m up sees the back cone's top above the front one
  const Cone front{{0.95 + 5.0, 0.0}, ConeColor::Yellow};
  const Cone back{{0.95 + 5.6, 0.1}, ConeColor::Blue};
  LidarWorld both({front, back});
  LidarWorld alone({back});
  Camera cam(p, 1);
  const AnnotatedFrame f = cam.render(both, Pose2{}, 0);
  EXPECT_GT(cam.last_continued_rays(), 0u);  // the rays through the front cone
  const AnnotatedFrame g = cam.render(alone, Pose2{}, 0);
  ASSERT_EQ(f.annotation.instances.size(), 2u);
  ASSERT_EQ(g.annotation.instances.size(), 1u);
  EXPECT_EQ(f.annotation.instances[0].id, 0);
  EXPECT_EQ(f.annotation.instances[1].id, 1);
  EXPECT_NEAR(f.annotation.instances[0].visible_fraction, 1.0, 1e-12);
  const int seen = blob(f, 1).count, whole = blob(g, 0).count;
  ASSERT_GT(whole, 100);
  EXPECT_GT(seen, 0);
  EXPECT_LT(seen, whole);
  EXPECT_NEAR(f.annotation.instances[1].visible_fraction, static_cast<double>(seen) / whole, 1e-9);
  EXPECT_LT(f.annotation.instances[1].visible_fraction, 0.9);
  std::printf("hidden cone: %d of %d pixels visible (%.3f)\n", seen, whole, f.annotation.instances[1].visible_fraction);
}

TEST(Camera, NoConesGivesSkyAboveTheHorizonAndGroundBelow) {
  const CameraParams p;
  LidarWorld world({});
  Camera cam(p, 1);
  const AnnotatedFrame f = cam.render(world, Pose2{3.0, -2.0, 0.7}, 0);
  EXPECT_TRUE(f.annotation.instances.empty());
  EXPECT_EQ(std::count(f.annotation.labels.begin(), f.annotation.labels.end(), -1), 800 * 500);
  // horizon: v = cy - f tan(pitch) = 250 - 400 tan(5 deg) = 215.0; rows whose
  // centres (j + 0.5) lie above it are sky, below ground
  const double vh = 250.0 - 400.0 * std::tan(5.0 * kPi / 180.0);
  ASSERT_NEAR(vh, 215.0, 0.1);
  const auto px = [&](int i, int j) {
    const std::size_t q = 3 * (static_cast<std::size_t>(j) * 800 + i);
    return std::array<int, 3>{f.frame.rgb[q], f.frame.rgb[q + 1], f.frame.rgb[q + 2]};
  };
  // sky: the configured colour (0.55, 0.72, 0.92) * 255
  const std::array<int, 3> sky{140, 184, 235};
  for (int j : {0, 100, 213}) {
    for (int i : {0, 400, 799}) EXPECT_EQ(px(i, j), sky) << i << " " << j;
  }
  // ground: asphalt 0.32 * (0.35 + 0.65 sin 50 deg) = 0.2714 -> 69, blue 0.34 -> 0.2884 -> 74
  const std::array<int, 3> ground{69, 69, 74};
  for (int j : {216, 300, 499}) {
    for (int i : {0, 400, 799}) EXPECT_EQ(px(i, j), ground) << i << " " << j;
  }
}

TEST(Camera, ColourClassesOfEveryConeKindStandingOrKnocked) {
  const std::vector<Cone> cones = {{{6.0, 2.0}, ConeColor::Blue},
                                   {{6.0, 1.0}, ConeColor::Yellow},
                                   {{6.0, 0.0}, ConeColor::SmallOrange},
                                   {{6.0, -1.0}, ConeColor::BigOrange},
                                   {{6.0, -2.0}, ConeColor::Unknown},
                                   {{8.0, 1.0}, ConeColor::BigOrange},
                                   {{8.0, -1.0}, ConeColor::Blue}};
  const std::vector<bool> knocked = {false, false, false, false, false, true, true};
  LidarWorld world(cones, knocked);
  Camera cam(CameraParams{}, 1);
  const AnnotatedFrame f = cam.render(world, Pose2{}, 0);
  ASSERT_EQ(f.annotation.instances.size(), cones.size());
  for (std::size_t k = 0; k < cones.size(); ++k) {
    EXPECT_EQ(f.annotation.instances[k].id, static_cast<int>(k));
    EXPECT_EQ(f.annotation.instances[k].color, cones[k].color) << k;
  }
  // a knocked big cone lies along x: wider than tall on the image? It lies
  // along the line of sight here, so only its height (its base width 0.285 m)
  // counts: shorter than the standing big cone (0.505 m) at 6 m
  EXPECT_LT(blob(f, 5).j1 - blob(f, 5).j0, blob(f, 3).j1 - blob(f, 3).j0);
}

TEST(Camera, DeterministicWithNoiseAndNoiseHasTheConfiguredSpread) {
  CameraParams p;
  p.pixel_noise = 4.0;
  std::vector<Cone> cones;
  for (int i = 0; i < 20; ++i) cones.push_back({{3.0 + i, (i % 2) ? 1.5 : -1.5}, (i % 2) ? ConeColor::Blue : ConeColor::Yellow});
  LidarWorld world(cones);
  Camera a(p, 42), b(p, 42);
  const AnnotatedFrame fa = a.render(world, Pose2{0.5, 0.2, 0.1}, 7);
  const AnnotatedFrame fb = b.render(world, Pose2{0.5, 0.2, 0.1}, 7);
  EXPECT_EQ(fa.frame.rgb, fb.frame.rgb);
  EXPECT_EQ(fa.annotation.labels, fb.annotation.labels);
  ASSERT_EQ(fa.annotation.instances.size(), fb.annotation.instances.size());
  for (std::size_t k = 0; k < fa.annotation.instances.size(); ++k) {
    EXPECT_EQ(fa.annotation.instances[k].id, fb.annotation.instances[k].id);
    EXPECT_EQ(fa.annotation.instances[k].visible_fraction, fb.annotation.instances[k].visible_fraction);
  }
  // the sky's red channel (140) with noise: mean 140, std 4 (the table's rounding
  // to whole levels adds about 1/12 to the variance, its 3.4 sigma cut takes 1 %)
  double s = 0.0, s2 = 0.0;
  int n = 0;
  for (int j = 0; j < 150; ++j) {
    for (int i = 0; i < 800; ++i) {
      const double v = fa.frame.rgb[3 * (static_cast<std::size_t>(j) * 800 + i)];
      s += v;
      s2 += v * v;
      ++n;
    }
  }
  const double mean = s / n, sd = std::sqrt(s2 / n - mean * mean);
  EXPECT_NEAR(mean, 140.0, 0.1);
  EXPECT_NEAR(sd, std::sqrt(16.0 + 1.0 / 12.0), 0.1);
  // the next frame's noise differs
  const AnnotatedFrame fc = a.render(world, Pose2{0.5, 0.2, 0.1}, 7);
  EXPECT_NE(fa.frame.rgb, fc.frame.rgb);
  EXPECT_EQ(fa.annotation.labels, fc.annotation.labels);
}

TEST(Camera, ConeOnSlopedGroundIsSeenWhereItStands) {
  GroundParams g;
  g.slope_x = 0.05;
  LidarWorld world({Cone{{8.0, 0.5}, ConeColor::Yellow}}, {}, g);
  CameraParams p;
  Camera cam(p, 1);
  const AnnotatedFrame f = cam.render(world, Pose2{}, 0);
  ASSERT_EQ(f.annotation.instances.size(), 1u);
  EXPECT_NEAR(f.annotation.instances[0].visible_fraction, 1.0, 1e-12);
  // the camera stands mount_z above the ground under its mount (z = 0.0475):
  // the cone's mid-height, at z = 0.4 + 0.1625, relative to it
  const double zc = 0.05 * 0.95;
  const Pix c = hand_project(p, 8.0, 0.5, 0.05 * 8.0 + 0.1625 - zc);
  const Blob b = blob(f, 0);
  EXPECT_GE(c.u, b.i0);
  EXPECT_LE(c.u, b.i1 + 1);
  EXPECT_GE(c.v, b.j0);
  EXPECT_LE(c.v, b.j1 + 1);
  // the box's pixels and one ray a 4 x 4 tile (200 x 125 tiles) were cast;
  // the ground rises ahead, so the horizon row shows it
  EXPECT_GT(cam.last_primary_rays(), 200u * 125u + static_cast<unsigned>(b.count));
  EXPECT_LT(cam.last_primary_rays(), 200u * 125u + 4000u);
  const std::size_t q = 3 * (static_cast<std::size_t>(216) * 800 + 10);
  EXPECT_NE(f.frame.rgb[q + 2], 235);  // not sky
}

TEST(Camera, NonFinitePoseGivesABlackUnlabelledFrame) {
  LidarWorld world({Cone{{5.0, 0.0}, ConeColor::Blue}});
  Camera cam(CameraParams{}, 1);
  const AnnotatedFrame f = cam.render(world, Pose2{std::nan(""), 0.0, 0.0}, 5);
  EXPECT_EQ(f.frame.rgb.size(), 3u * 800 * 500);
  EXPECT_EQ(std::count(f.frame.rgb.begin(), f.frame.rgb.end(), 0), 3 * 800 * 500);
  EXPECT_EQ(std::count(f.annotation.labels.begin(), f.annotation.labels.end(), -1), 800 * 500);
  EXPECT_TRUE(f.annotation.instances.empty());
}

// every pixel cast on its own (rtcIntersect1, the ray built from the
// calibration's K and T_camera_base, from mount_z above the ground under the
// lens): the labels the box culling gives must be the same, up to a few
// pixels on silhouette edges where the two float rays could differ in the
// last bit. Six poses on FSG 2023: four along the centreline, two moved so
// that a cone stands right beside the lens (base frame (0.95, +-0.5): its box
// straddles the lens's plane), turned 20 deg towards it.
void expect_labels_match_brute_force(const GroundParams& ground) {
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  std::stringstream text;
  text << in.rdbuf();
  const world::TrackModel track = world::build_track(world::parse_track(text.str(), "fsg_2023"));
  LidarWorld world(track.cones, {}, ground);
  CameraParams p;
  p.width = 400;
  p.height = 250;
  Camera cam(p, 1);
  const perception::CameraCalibration k = cam.calibration();
  const Eigen::Isometry3d T_base_camera = k.T_camera_base.inverse();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  const std::size_t m = track.centreline.size();
  for (int s = 0; s < 6; ++s) {
    const std::size_t i = m * static_cast<std::size_t>(s) / 6;
    const Vec2 a = track.centreline[i], b = track.centreline[(i + 4) % m];
    double yaw = angle_of(b - a);
    Vec2 pos = a;
    if (s >= 4) {
      const double side = s == 4 ? 1.0 : -1.0;
      const Cone& c = track.cones[s == 4 ? 20 : 61];
      yaw += side * 20.0 * kPi / 180.0;
      pos = c.position - rotate({0.95, side * 0.5}, yaw);
    }
    const AnnotatedFrame f = cam.render(world, Pose2{pos.x, pos.y, yaw}, 0);
    const Eigen::Vector3d o_base = T_base_camera.translation();
    const Vec2 o = pos + rotate({o_base.x(), o_base.y()}, yaw);
    const double oz = world.ground_z(o.x, o.y) + o_base.z();
    int labelled = 0, differ = 0;
    for (int j = 0; j < p.height; ++j) {
      for (int ii = 0; ii < p.width; ++ii) {
        const Eigen::Vector3d d_cam((ii + 0.5 - k.cx) / k.fx, (j + 0.5 - k.cy) / k.fy, 1.0);
        const Eigen::Vector3d d_base = (T_base_camera.linear() * d_cam).normalized();
        const Vec2 d_xy = rotate({d_base.x(), d_base.y()}, yaw);
        RTCRayHit rh{};
        rh.ray.org_x = static_cast<float>(o.x);
        rh.ray.org_y = static_cast<float>(o.y);
        rh.ray.org_z = static_cast<float>(oz);
        rh.ray.dir_x = static_cast<float>(d_xy.x);
        rh.ray.dir_y = static_cast<float>(d_xy.y);
        rh.ray.dir_z = static_cast<float>(d_base.z());
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = std::numeric_limits<float>::infinity();
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(world.scene(), &ctx, &rh);
        std::int32_t want = -1;
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) want = std::max(-1, world.cone_of(rh.hit.geomID, rh.hit.primID));
        const std::int32_t got = f.annotation.labels[static_cast<std::size_t>(j) * p.width + ii];
        labelled += want >= 0;
        differ += want != got;
      }
    }
    std::printf("%s ground, pose %d: %zu instances, %d labelled pixels, %d differ\n",
                flat(ground) ? "flat" : "bumpy", s, f.annotation.instances.size(), labelled, differ);
    EXPECT_GT(labelled, 100) << s;
    EXPECT_LE(differ, 2 + labelled / 1000) << s;
  }
}

TEST(Camera, LabelsMatchABruteForceCastOfEveryPixelOnFsg2023) { expect_labels_match_brute_force({}); }

TEST(Camera, LabelsMatchABruteForceCastOnBumpyGround) {
  GroundParams g;
  g.bump_height = 0.3;
  g.bump_wavelength = 8.0;
  expect_labels_match_brute_force(g);
}

// the runner renders every frame into the same buffers: what was drawn and
// labelled the frame before must leave no trace. A camera rendering into
// reused buffers against one rendering each frame into fresh ones, along FSG
// 2023 on flat and bumpy ground and once through a non-finite pose.
// the camera reads a world's cones once; a world rebuilt in the same place
// (as the runner rebuilds the scene when a cone is knocked or moved) is read
// again: the frame is a fresh camera's
TEST(Camera, AWorldRebuiltInPlaceIsReadAgain) {
  std::vector<Cone> cones;
  for (int i = 0; i < 6; ++i) {
    cones.push_back({{6.0 + 2.0 * i, -1.5}, ConeColor::Blue});
    cones.push_back({{6.0 + 2.0 * i, 1.5}, ConeColor::Yellow});
  }
  CameraParams p;
  p.width = 320;
  p.height = 200;
  Camera reused(p, 1);
  hal::CameraFrame frame;
  CameraAnnotation annotation;
  std::optional<LidarWorld> world;
  for (int k = 0; k < 3; ++k) {
    // the nearest blue cone knocked, then moved by 1 m, then standing again
    std::vector<Cone> now = cones;
    std::vector<bool> knocked(cones.size(), false);
    if (k == 0) knocked[0] = true;
    if (k == 1) now[0].position.x -= 1.0;
    world.reset();
    world.emplace(now, knocked);
    reused.render(*world, Pose2{}, k, frame, annotation);
    const AnnotatedFrame want = Camera(p, 1).render(*world, Pose2{}, k);
    EXPECT_TRUE(frame.rgb == want.frame.rgb) << k;
    EXPECT_TRUE(annotation.labels == want.annotation.labels) << k;
    ASSERT_EQ(annotation.instances.size(), want.annotation.instances.size()) << k;
    for (std::size_t i = 0; i < want.annotation.instances.size(); ++i) {
      EXPECT_EQ(annotation.instances[i].range, want.annotation.instances[i].range) << k;
    }
  }
}

TEST(Camera, ReusedBuffersGiveTheFramesFreshOnesGive) {
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  std::stringstream text;
  text << in.rdbuf();
  const world::TrackModel track = world::build_track(world::parse_track(text.str(), "fsg_2023"));
  // one camera and one pair of buffers through frames of a flat world, a
  // bumpy one and a flat one with barrier blocks (their pixels drawn too),
  // in turn, with a non-finite pose among them; with and without pixel
  // noise: each frame as fresh buffers give it (a twin camera, the same
  // calls, its own random stream alike). A third camera renders every third
  // frame without pixels (pixels = false) into buffers of its own: those
  // frames' annotations are the fresh ones', and its next image with pixels
  // is the fresh one (painted whole, its random stream kept in step)
  GroundParams bumpy;
  bumpy.bump_height = 0.3;
  bumpy.bump_wavelength = 8.0;
  std::vector<world::Block> blocks;
  for (std::size_t i = 0; i < track.cones.size(); i += 9) {
    world::Block b;
    b.centre = track.cones[i].position + Vec2{1.5, 0.0};
    b.length = 1.0;
    b.width = 0.5;
    b.height = 0.8;
    blocks.push_back(b);
  }
  const LidarWorld flat_world(track.cones), bumpy_world(track.cones, {}, bumpy), walled(track.cones, {}, {}, blocks);
  const LidarWorld* worlds[] = {&flat_world, &flat_world, &bumpy_world, &flat_world, &walled, &flat_world};
  for (double noise : {0.0, 2.0}) {
    CameraParams p;
    p.width = 320;
    p.height = 200;
    p.pixel_noise = noise;
    Camera reused(p, 1), fresh(p, 1), sparse(p, 1);
    hal::CameraFrame frame, sparse_frame;
    CameraAnnotation annotation, sparse_annotation;
    int without_pixels = 0;
    const std::size_t m = track.centreline.size();
    int labelled_frames = 0, barrier_frames = 0;
    for (int s = 0; s < 24; ++s) {
      const LidarWorld& world = *worlds[s % 6];
      const std::size_t i = m * static_cast<std::size_t>(s) / 24;
      const Vec2 a = track.centreline[i], b = track.centreline[(i + 4) % m];
      Pose2 pose{a.x, a.y, angle_of(b - a)};
      if (s == 7) pose.yaw = std::nan("");
      reused.render(world, pose, s, frame, annotation);
      const bool pixels = s % 3 != 1;
      sparse.render(world, pose, s, sparse_frame, sparse_annotation, pixels);
      const AnnotatedFrame want = fresh.render(world, pose, s);
      EXPECT_TRUE(frame.rgb == want.frame.rgb) << "noise " << noise << ", frame " << s;
      EXPECT_TRUE(annotation.labels == want.annotation.labels) << "noise " << noise << ", frame " << s;
      EXPECT_TRUE(sparse_annotation.labels == want.annotation.labels) << "noise " << noise << ", frame " << s;
      EXPECT_EQ(sparse_frame.stamp, want.frame.stamp);
      EXPECT_EQ(sparse_frame.rgb.size(), want.frame.rgb.size());
      if (pixels) {
        EXPECT_TRUE(sparse_frame.rgb == want.frame.rgb) << "noise " << noise << ", frame " << s;
      } else {
        ++without_pixels;
      }
      ASSERT_EQ(annotation.instances.size(), want.annotation.instances.size()) << s;
      ASSERT_EQ(sparse_annotation.instances.size(), want.annotation.instances.size()) << s;
      for (std::size_t k = 0; k < want.annotation.instances.size(); ++k) {
        EXPECT_EQ(annotation.instances[k].id, want.annotation.instances[k].id);
        EXPECT_EQ(annotation.instances[k].visible_fraction, want.annotation.instances[k].visible_fraction);
        EXPECT_EQ(sparse_annotation.instances[k].id, want.annotation.instances[k].id);
        EXPECT_EQ(sparse_annotation.instances[k].color, want.annotation.instances[k].color);
        EXPECT_EQ(sparse_annotation.instances[k].range, want.annotation.instances[k].range);
        EXPECT_EQ(sparse_annotation.instances[k].visible_fraction, want.annotation.instances[k].visible_fraction);
      }
      labelled_frames += std::any_of(want.annotation.labels.begin(), want.annotation.labels.end(),
                                     [](std::int32_t l) { return l >= 0; });
      // a block drawn: a pixel of neither the sky's nor the flat ground's colour, and no cone's
      if (&world == &walled && noise == 0.0) {
        const hal::CameraFrame empty = Camera(p, 1).render(flat_world, pose, s).frame;
        bool drawn = false;
        for (std::size_t q = 0; q < want.annotation.labels.size() && !drawn; ++q) {
          drawn = want.annotation.labels[q] < 0 && (want.frame.rgb[3 * q] != empty.rgb[3 * q] ||
                                                     want.frame.rgb[3 * q + 2] != empty.rgb[3 * q + 2]);
        }
        barrier_frames += drawn;
      }
    }
    EXPECT_GE(labelled_frames, 20) << "noise " << noise;  // cones in (nearly) every frame
    EXPECT_EQ(without_pixels, 8);
    if (noise == 0.0) {
      EXPECT_GE(barrier_frames, 2);  // and the blocks drawn where they were
    }
  }
}

// how far x lies outside f, in the units of bounding_frustum's margin: <= 0
// inside, <= delta within f grown by delta (its ends moved out by delta, its
// radius grown by delta (1 + |slope|)), which holds every point within delta
// of f (a point delta from one of f is at most delta further along the axis
// or from it, and the radius changes by at most |slope| delta between them)
double outside(const ConeFrustum& f, const double x[3]) {
  const int ax = f.axis, p = (ax + 1) % 3, q = (ax + 2) % 3;
  const double a = x[ax] - f.centre[ax];
  const double slope = (f.r1 - f.r0) / f.length;
  const double r = f.r0 + slope * std::clamp(a, 0.0, f.length);
  const double radial = std::hypot(x[p] - f.centre[p], x[q] - f.centre[q]);
  return std::max({-a, a - f.length, (radial - r) / (1.0 + std::abs(slope))});
}

// ray_meets_frustum against dense sampling: random frustums (both axes,
// narrowing, widening, cylinders, to a point) and rays from inside, near and
// far, aimed anywhere, at the frustum, across its axis or along it. Each ray
// is sampled every 0.1 mm where it lies within the frustum's bounding ball.
// A ray reported as missing has no sample inside; one reported as meeting
// has a sample within half a step of it.
TEST(Camera, RayFrustumTestAgreesWithDenseSamplingAlongTheRay) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto unit = [&](double d[3]) {
    double n = 0.0;
    do {
      for (int e = 0; e < 3; ++e) d[e] = 2.0 * u(rng) - 1.0;
      n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    } while (n > 1.0 || n < 1e-3);
    for (int e = 0; e < 3; ++e) d[e] /= n;
  };
  const double h = 1e-4;  // m, the sampling step along the ray
  int met = 0, missed = 0, near_misses = 0, inside = 0, from_inside = 0;
  for (int n = 0; n < 10000; ++n) {
    ConeFrustum f;
    f.axis = n % 2 == 0 ? 2 : 0;
    for (double& c : f.centre) c = 200.0 * u(rng) - 100.0;
    f.length = 0.05 + 0.6 * u(rng);
    f.r0 = 0.3 * u(rng);
    switch (n % 8) {
      case 0: f.r1 = f.r0; break;  // a cylinder
      case 1: f.r1 = 0.0; break;   // to a point
      default: f.r1 = 0.3 * u(rng);
    }
    const int ax = f.axis, p = (ax + 1) % 3, q = (ax + 2) % 3;
    // a point inside: along the axis, then across within the radius there
    const auto point_inside = [&](double x[3]) {
      const double a = f.length * u(rng), r = (f.r0 + (f.r1 - f.r0) * a / f.length) * std::sqrt(u(rng));
      const double phi = 2.0 * kPi * u(rng);
      x[ax] = f.centre[ax] + a;
      x[p] = f.centre[p] + r * std::cos(phi);
      x[q] = f.centre[q] + r * std::sin(phi);
    };
    double o[3], d[3];
    if (n % 5 == 0) {
      ++inside;
      point_inside(o);
    } else {
      double w[3];
      unit(w);
      const double dist = n % 5 == 1 ? 10.0 + 30.0 * u(rng) : 0.01 + 2.0 * u(rng);
      for (int e = 0; e < 3; ++e) o[e] = f.centre[e] + 0.5 * f.length * (e == ax) + dist * w[e];
    }
    switch (n % 6) {
      case 0:
      case 1: unit(d); break;
      case 2:
      case 3: {  // grazing: along the surface, up to 2 mm off it, tilted a little
        double x[3], nrm[3] = {0.0, 0.0, 0.0}, w[3];
        if (u(rng) < 0.3) {  // an end
          point_inside(x);
          const bool top = u(rng) < 0.5;
          x[ax] = f.centre[ax] + (top ? f.length : 0.0);
          nrm[ax] = top ? 1.0 : -1.0;
        } else {  // the side
          const double k = (f.r1 - f.r0) / f.length, c = 1.0 / std::sqrt(1.0 + k * k);
          const double a = f.length * u(rng), r = f.r0 + k * a, phi = 2.0 * kPi * u(rng);
          x[ax] = f.centre[ax] + a;
          x[p] = f.centre[p] + r * std::cos(phi);
          x[q] = f.centre[q] + r * std::sin(phi);
          nrm[ax] = -k * c;
          nrm[p] = std::cos(phi) * c;
          nrm[q] = std::sin(phi) * c;
        }
        unit(w);
        const double wn = w[0] * nrm[0] + w[1] * nrm[1] + w[2] * nrm[2];
        const double off = 0.004 * u(rng) - 0.002, tilt = 0.02 * u(rng) - 0.01, back = 0.01 + 20.0 * u(rng);
        for (int k = 0; k < 3; ++k) {
          d[k] = w[k] - wn * nrm[k] + tilt * nrm[k];
          if (n % 5 != 0) o[k] = x[k] + off * nrm[k] - back * d[k];
        }
        break;
      }
      case 4: unit(d); d[ax] = 0.0; break;  // across the axis
      default:                            // along it
        d[0] = d[1] = d[2] = 0.0;
        d[ax] = u(rng) < 0.5 ? 1.0 : -1.0;
    }
    const double scale = 0.5 + 1.5 * u(rng);  // not a unit vector
    for (double& e : d) e *= scale;
    const bool meets = ray_meets_frustum(f, o, d);
    // the t where the ray lies in the ball about the axis's middle that holds f
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    double e[3];
    for (int k = 0; k < 3; ++k) e[k] = o[k] - (f.centre[k] + 0.5 * f.length * (k == ax));
    const double R = 0.5 * f.length + std::max(f.r0, f.r1) + 1e-6;
    const double b = e[0] * d[0] + e[1] * d[1] + e[2] * d[2];
    const double disc = b * b - dd * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] - R * R);
    double least = std::numeric_limits<double>::infinity();  // of outside()
    if (disc >= 0.0) {
      const double ta = std::max(0.0, (-b - std::sqrt(disc)) / dd), tb = (-b + std::sqrt(disc)) / dd;
      const double step = h / std::sqrt(dd);
      for (double t = ta; t <= tb + step; t += step) {
        const double tt = std::min(t, tb);
        if (tt < 0.0) continue;
        const double x[3] = {o[0] + tt * d[0], o[1] + tt * d[1], o[2] + tt * d[2]};
        least = std::min(least, outside(f, x));
      }
    }
    if (meets) {
      ++met;
      from_inside += n % 5 == 0;
      EXPECT_LE(least, 0.5 * h + 1e-9) << "ray " << n << " reported as meeting the frustum";
    } else {
      ++missed;
      near_misses += least < 0.01;
      EXPECT_GT(least, 0.0) << "ray " << n << " reported as missing the frustum";
    }
  }
  std::printf("frustum test: %d rays meet (%d from inside), %d miss (%d within 1 cm)\n", met, from_inside, missed,
              near_misses);
  EXPECT_EQ(from_inside, inside);
  EXPECT_GT(met, 3000);
  EXPECT_GT(missed, 3000);
  EXPECT_GT(near_misses, 500);
}

// bounding_frustum on the cone meshes LidarWorld builds (standing and
// knocked, small and big): the frustum of the true shape (base radius, top
// radius kConeApexRadius, height along the axis), holding every vertex and,
// grown by a margin, every point within it of the triangles; and the
// cylinder where the radii at the ends do not hold the middle
TEST(Camera, BoundingFrustumOfTheConeMeshes) {
  const std::vector<Cone> cones = {{{6.0, 2.0}, ConeColor::Blue},
                                   {{-3.5, 41.0}, ConeColor::BigOrange},
                                   {{60.0, -7.25}, ConeColor::Yellow},
                                   {{12.0, 1.0}, ConeColor::BigOrange}};
  const std::vector<bool> knocked = {false, false, true, true};
  LidarWorld world(cones, knocked);
  unsigned g = 0;
  while (g < 4 && world.cone_of(g, 0) < 0) ++g;
  ASSERT_LT(g, 4u);
  RTCGeometry geom = rtcGetGeometry(world.scene(), g);
  const auto* v = static_cast<const float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
  const auto* idx = static_cast<const unsigned*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  unsigned prim = 0;
  for (std::size_t i = 0; i < cones.size(); ++i) {
    const unsigned prim0 = prim;
    while (world.cone_of(g, prim) == static_cast<std::int32_t>(i)) ++prim;
    ASSERT_EQ(prim - prim0, 3u * kConeSegments) << i;
    const bool big = cones[i].color == ConeColor::BigOrange;
    const double r_base = 0.5 * (big ? kBigConeBaseWidth : kSmallConeBaseWidth);
    const double height = big ? kBigConeHeight : kSmallConeHeight;
    const int axis = knocked[i] ? 0 : 2;
    ConeFrustum f;
    ASSERT_TRUE(bounding_frustum(v, idx, prim0, prim, axis, 0.0, f));
    EXPECT_EQ(f.axis, axis);
    EXPECT_NEAR(f.length, height, 1e-5) << i;
    EXPECT_NEAR(f.r0, r_base, 1e-5) << i;
    EXPECT_NEAR(f.r1, kConeApexRadius, 1e-5) << i;
    // the base centre: on the ground (standing), h / 2 behind the position at
    // the base radius's height (knocked)
    const double base[3] = {cones[i].position.x - (knocked[i] ? 0.5 * height : 0.0), cones[i].position.y,
                            knocked[i] ? r_base : 0.0};
    for (int e = 0; e < 3; ++e) EXPECT_NEAR(f.centre[e], base[e], 1e-5) << i << " " << e;
    for (unsigned t = prim0; t < prim; ++t) {
      for (int k = 0; k < 3; ++k) {
        const float* x = v + 3 * idx[3 * t + static_cast<unsigned>(k)];
        const double xd[3] = {x[0], x[1], x[2]};
        EXPECT_LE(outside(f, xd), 1e-9) << i;
      }
    }
    // grown by 1 mm: points up to 0.999 mm from points of the triangles
    const double margin = 1e-3;
    ConeFrustum grown;
    ASSERT_TRUE(bounding_frustum(v, idx, prim0, prim, axis, margin, grown));
    for (int n = 0; n < 20000; ++n) {
      const unsigned t = prim0 + static_cast<unsigned>(n) % (prim - prim0);
      double a = u(rng), b = u(rng);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      const float* x0 = v + 3 * idx[3 * t];
      const float* x1 = v + 3 * idx[3 * t + 1];
      const float* x2 = v + 3 * idx[3 * t + 2];
      double w[3];
      double wn = 0.0;
      for (int e = 0; e < 3; ++e) {
        w[e] = 2.0 * u(rng) - 1.0;
        wn += w[e] * w[e];
      }
      const double s = 0.999 * margin * u(rng) / std::sqrt(wn);
      double x[3];
      for (int e = 0; e < 3; ++e) x[e] = x0[e] + a * (x1[e] - x0[e]) + b * (x2[e] - x0[e]) + s * w[e];
      EXPECT_LE(outside(grown, x), 0.0) << i << " " << n;
    }
  }

  // hand-made meshes about z: rings of 8 vertices joined by triangles
  const auto rings = [](const std::vector<std::pair<double, double>>& za_r, std::vector<float>& vs,
                        std::vector<unsigned>& is) {
    vs.clear();
    is.clear();
    for (const auto& [z, r] : za_r) {
      for (int s = 0; s < 8; ++s) {
        vs.push_back(static_cast<float>(5.0 + r * std::cos(kPi * s / 4)));
        vs.push_back(static_cast<float>(-2.0 + r * std::sin(kPi * s / 4)));
        vs.push_back(static_cast<float>(z));
      }
    }
    for (unsigned ring = 0; ring + 1 < za_r.size(); ++ring) {
      for (unsigned s = 0; s < 8; ++s) {
        const unsigned a = 8 * ring + s, b = 8 * ring + (s + 1) % 8;
        for (unsigned k : {a, b, b + 8, a, b + 8, a + 8}) is.push_back(k);
      }
    }
  };
  std::vector<float> vs;
  std::vector<unsigned> is;
  // widening: kept as it is
  rings({{0.0, 0.05}, {1.0, 0.2}}, vs, is);
  ConeFrustum f;
  ASSERT_TRUE(bounding_frustum(vs.data(), is.data(), 0, static_cast<unsigned>(is.size() / 3), 2, 0.0, f));
  EXPECT_NEAR(f.r0, 0.05, 1e-6);
  EXPECT_NEAR(f.r1, 0.2, 1e-6);
  EXPECT_NEAR(f.centre[0], 5.0, 1e-6);
  EXPECT_NEAR(f.centre[1], -2.0, 1e-6);
  // a barrel: the middle ring sticks out of the ends' frustum, so the
  // cylinder of the widest ring
  rings({{0.0, 0.05}, {0.5, 0.2}, {1.0, 0.05}}, vs, is);
  ASSERT_TRUE(bounding_frustum(vs.data(), is.data(), 0, static_cast<unsigned>(is.size() / 3), 2, 0.0, f));
  EXPECT_NEAR(f.r0, 0.2, 1e-6);
  EXPECT_NEAR(f.r1, 0.2, 1e-6);
  EXPECT_NEAR(f.length, 1.0, 1e-6);
  for (std::size_t k = 0; k < vs.size(); k += 3) {
    const double x[3] = {vs[k], vs[k + 1], vs[k + 2]};
    EXPECT_LE(outside(f, x), 1e-9);
  }
  // no triangle, or a vertex not finite: none
  EXPECT_FALSE(bounding_frustum(vs.data(), is.data(), 3, 3, 2, 0.0, f));
  vs[4] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(bounding_frustum(vs.data(), is.data(), 0, static_cast<unsigned>(is.size() / 3), 2, 0.0, f));
}

// a camera culling its rays and one casting every pixel of the boxes render
// the same poses (the culling one into reused buffers, as the runner does):
// the same rgb, labels and instances to the bit, and no more rays. Returns
// the primary rays each cast, summed over the poses.
std::pair<std::size_t, std::size_t> expect_culling_changes_nothing(const LidarWorld& world, const CameraParams& p,
                                                                   const std::vector<Pose2>& poses,
                                                                   const std::string& what) {
  Camera culled(p, 5), whole(p, 5);
  EXPECT_TRUE(culled.culling());
  whole.set_culling(false);
  hal::CameraFrame frame;
  CameraAnnotation annotation;
  std::size_t rays_culled = 0, rays_whole = 0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    culled.render(world, poses[k], static_cast<TimeNs>(k), frame, annotation);
    const AnnotatedFrame want = whole.render(world, poses[k], static_cast<TimeNs>(k));
    EXPECT_TRUE(frame.rgb == want.frame.rgb) << what << ", pose " << k;
    EXPECT_TRUE(annotation.labels == want.annotation.labels) << what << ", pose " << k;
    EXPECT_EQ(annotation.instances.size(), want.annotation.instances.size()) << what << ", pose " << k;
    for (std::size_t i = 0; i < std::min(annotation.instances.size(), want.annotation.instances.size()); ++i) {
      const CameraInstance &a = annotation.instances[i], &b = want.annotation.instances[i];
      EXPECT_EQ(a.id, b.id) << what << ", pose " << k;
      EXPECT_EQ(a.color, b.color) << what << ", pose " << k;
      EXPECT_EQ(a.range, b.range) << what << ", pose " << k;
      EXPECT_EQ(a.visible_fraction, b.visible_fraction) << what << ", pose " << k << ", cone " << a.id;
    }
    EXPECT_LE(culled.last_primary_rays(), whole.last_primary_rays()) << what << ", pose " << k;
    EXPECT_LE(culled.last_continued_rays(), whole.last_continued_rays()) << what << ", pose " << k;
    rays_culled += culled.last_primary_rays();
    rays_whole += whole.last_primary_rays();
  }
  std::printf("%s: %zu poses, %.0f rays a frame culled, %.0f not\n", what.c_str(), poses.size(),
              static_cast<double>(rays_culled) / static_cast<double>(poses.size()),
              static_cast<double>(rays_whole) / static_cast<double>(poses.size()));
  return {rays_culled, rays_whole};
}

// along FSG 2023 at the default resolution: 240 poses on the centreline
// looking along it (as bench/camera_bench.cc's), 240 more moved 1.5 m aside
// and turned 35 deg in or out, so cones pass the image's edges and stand
// close to the lens
TEST(Camera, CullingGivesTheSameFramesAlongFsg2023) {
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  std::stringstream text;
  text << in.rdbuf();
  const world::TrackModel track = world::build_track(world::parse_track(text.str(), "fsg_2023"));
  LidarWorld world(track.cones);
  std::vector<Pose2> poses;
  const std::size_t m = track.centreline.size();
  for (int k = 0; k < 240; ++k) {
    const std::size_t i = m * static_cast<std::size_t>(k) / 240;
    const Vec2 a = track.centreline[i], b = track.centreline[(i + 4) % m];
    const double yaw = angle_of(b - a);
    poses.push_back({a.x, a.y, yaw});
    const double side = k % 2 == 0 ? 1.0 : -1.0, turn = k % 4 < 2 ? 1.0 : -1.0;
    const Vec2 c = a + rotate({0.0, 1.5 * side}, yaw);
    poses.push_back({c.x, c.y, yaw + turn * 35.0 * kPi / 180.0});
  }
  const auto [culled, whole] = expect_culling_changes_nothing(world, CameraParams{}, poses, "FSG 2023");
  EXPECT_LT(culled, whole);
}

// a made-up scene: big orange cones a metre from the lens (cut by the
// image's bottom edge), a cone beside the lens (its box straddles the lens's
// plane), cones behind the camera, on the image's left and right edges,
// knocked cones small and big (near, far, on an edge, in front of a standing
// one), a row of cones hiding each other; seen from several places and
// headings, with the default camera, a wide low one and with pixel noise
TEST(Camera, CullingGivesTheSameFramesNearKnockedAndBigCones) {
  std::vector<Cone> cones;
  std::vector<bool> knocked;
  const auto add = [&](double x, double y, ConeColor c, bool down = false) {
    cones.push_back({{x, y}, c});
    knocked.push_back(down);
  };
  // the lens at base (0.95, 0): big orange cones 1 m ahead and beside
  add(1.95, 0.0, ConeColor::BigOrange);
  add(2.1, 0.45, ConeColor::BigOrange);
  add(2.3, -0.6, ConeColor::BigOrange, true);
  add(0.95, 0.5, ConeColor::Blue);       // beside the lens
  add(0.6, -0.4, ConeColor::Yellow);     // just behind it
  add(-2.0, 0.0, ConeColor::BigOrange);  // behind the car
  add(-6.0, 3.0, ConeColor::Blue, true);
  // on the left and right edges (45 deg off the axis)
  add(5.0, 4.05, ConeColor::Yellow);
  add(5.0, -4.05, ConeColor::Blue);
  add(9.0, 8.05, ConeColor::SmallOrange, true);
  add(3.0, -2.0, ConeColor::BigOrange, true);
  // a row along the axis, hiding each other, a knocked cone before the first
  add(6.0, 0.2, ConeColor::Yellow, true);
  add(7.0, 0.2, ConeColor::Blue);
  add(7.6, 0.25, ConeColor::Yellow);
  add(8.2, 0.15, ConeColor::BigOrange);
  add(16.0, -1.5, ConeColor::Unknown, true);
  add(30.0, 2.0, ConeColor::Blue);
  LidarWorld world(cones, knocked);
  std::vector<Pose2> poses;
  for (double yaw : {0.0, 0.35, -0.35, 0.8, -0.8, 1.6, -2.4, kPi}) {
    for (const Vec2 at : {Vec2{0.0, 0.0}, Vec2{0.6, -0.3}, Vec2{-1.0, 0.8}}) poses.push_back({at.x, at.y, yaw});
  }
  const auto [culled, whole] = expect_culling_changes_nothing(world, CameraParams{}, poses, "near cones");
  EXPECT_LT(culled, whole);
  CameraParams wide;
  wide.width = 320;
  wide.height = 240;
  wide.hfov = 120.0 * kPi / 180.0;
  wide.mount_z = 0.6;
  wide.mount_pitch = 0.2;
  expect_culling_changes_nothing(world, wide, poses, "near cones, wide low lens");
  CameraParams noisy;
  noisy.pixel_noise = 3.0;
  expect_culling_changes_nothing(world, noisy, poses, "near cones, noisy");
}

// where the culling could change the frame it is off: on a height field
// (the boxes' pixels take the ground's shading) and with barrier blocks
// (drawn only where rays are cast): the same rays as without it
TEST(Camera, NoCullingOnBumpyGroundOrWithBarrierBlocks) {
  const std::vector<Cone> cones = {{{5.0, 1.0}, ConeColor::Blue},
                                   {{5.0, -1.0}, ConeColor::Yellow},
                                   {{9.0, 0.5}, ConeColor::BigOrange}};
  GroundParams bumpy;
  bumpy.bump_height = 0.2;
  bumpy.bump_wavelength = 8.0;
  world::Block block;
  block.centre = {12.0, 0.0};
  block.length = 2.0;
  block.width = 0.5;
  block.height = 0.8;
  LidarWorld hills(cones, {}, bumpy);
  LidarWorld walled(cones, {}, {}, {block});
  ASSERT_EQ(walled.block_count(), 1u);
  const std::vector<Pose2> poses = {{0.0, 0.0, 0.0}, {1.0, 0.5, -0.2}};
  for (const LidarWorld* world : {&hills, &walled}) {
    const auto [culled, whole] =
        expect_culling_changes_nothing(*world, CameraParams{}, poses, world == &hills ? "bumpy" : "blocks");
    EXPECT_EQ(culled, whole);
  }
}

TEST(Camera, TriggerIsTheLidarColumnAtTheAzimuth) {
  LidarParams lp;  // 1024 columns, 10 Hz
  Lidar lidar(lp, 1);
  // straight ahead: column 512 (-pi + 2 pi 512 / 1024 = 0), half a rotation in
  EXPECT_EQ(trigger_column(lp, 0.0), 512);
  EXPECT_EQ(trigger_time(lp, 0.0, 1'000'000), 1'000'000 + 50'000'000);
  EXPECT_EQ(trigger_time(lp, 0.0, 1'000'000), lidar.column_time(1'000'000, 512));
  // 90 deg left: column 768; -pi and +pi: column 0
  EXPECT_EQ(trigger_column(lp, 0.5 * kPi), 768);
  EXPECT_EQ(trigger_time(lp, 0.5 * kPi, 0), lidar.column_time(0, 768));
  EXPECT_EQ(trigger_column(lp, -kPi), 0);
  EXPECT_EQ(trigger_column(lp, kPi), 0);
  lp.columns = 2048;
  lp.rate = 20.0;
  Lidar l2(lp, 1);
  EXPECT_EQ(trigger_time(lp, 0.3, 0), l2.column_time(0, trigger_column(lp, 0.3)));
  EXPECT_EQ(trigger_column(lp, 0.3), static_cast<int>(std::lround((0.3 + kPi) * 2048 / (2 * kPi))));
}

}  // namespace
}  // namespace paddock::sensors
