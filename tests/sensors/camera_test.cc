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
#include <sstream>
#include <string>
#include <stdexcept>
#include <vector>

#include "sim/world/track.h"

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
TEST(Camera, ReusedBuffersGiveTheFramesFreshOnesGive) {
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  std::stringstream text;
  text << in.rdbuf();
  const world::TrackModel track = world::build_track(world::parse_track(text.str(), "fsg_2023"));
  for (double bump : {0.0, 0.3}) {
    GroundParams g;
    g.bump_height = bump;
    g.bump_wavelength = 8.0;
    LidarWorld world(track.cones, {}, g);
    CameraParams p;
    p.width = 320;
    p.height = 200;
    Camera reused(p, 1), fresh(p, 1);
    hal::CameraFrame frame;
    CameraAnnotation annotation;
    const std::size_t m = track.centreline.size();
    int labelled_frames = 0;
    for (int s = 0; s < 12; ++s) {
      const std::size_t i = m * static_cast<std::size_t>(s) / 12;
      const Vec2 a = track.centreline[i], b = track.centreline[(i + 4) % m];
      Pose2 pose{a.x, a.y, angle_of(b - a)};
      if (s == 7) pose.yaw = std::nan("");
      reused.render(world, pose, s, frame, annotation);
      const AnnotatedFrame want = fresh.render(world, pose, s);
      EXPECT_TRUE(frame.rgb == want.frame.rgb) << "bump " << bump << ", pose " << s;
      EXPECT_TRUE(annotation.labels == want.annotation.labels) << "bump " << bump << ", pose " << s;
      ASSERT_EQ(annotation.instances.size(), want.annotation.instances.size()) << s;
      for (std::size_t k = 0; k < want.annotation.instances.size(); ++k) {
        EXPECT_EQ(annotation.instances[k].id, want.annotation.instances[k].id);
        EXPECT_EQ(annotation.instances[k].visible_fraction, want.annotation.instances[k].visible_fraction);
      }
      labelled_frames += std::any_of(want.annotation.labels.begin(), want.annotation.labels.end(),
                                     [](std::int32_t l) { return l >= 0; });
    }
    EXPECT_GE(labelled_frames, 10) << "bump " << bump;  // cones in (nearly) every frame
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
