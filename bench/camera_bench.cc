// the camera path of the perception pipeline on the FSG 2023 trackdrive
// (tracks/fsg_2023.csv, its cones on a flat ground, default parameters):
//   BM_CameraFrame   one rendered frame (Camera::render into a reused frame,
//                    800 x 500), from 50 poses spread along the centreline,
//                    looking along it, one pose per iteration in turn;
//                    target: well under 5 ms on one core (10 Hz camera, the
//                    whole closed loop >= 20x real time). Flat ground: the
//                    boxes' pixels whose rays meet a cone's bounding frustum
//                    are cast (camera.h)
//   BM_CameraFrameUnculled  the same casting every pixel of the boxes
//                    (Camera::set_culling(false)): the frames are the same,
//                    the difference is what the culling saves
//   BM_CameraFrameBumpy  the same on a bumpy ground (height field: every
//                    pixel of the boxes plus a ray per 4 x 4 tile)
//   BM_CameraFrameNoisy  the same with 2 levels of pixel noise
//   BM_CameraAnnotation, BM_CameraAnnotationBumpy  the frames of
//                    BM_CameraFrame and BM_CameraFrameBumpy annotated
//                    without their pixels (pixels = false: what a run that
//                    neither logs nor snapshots its frames renders)
//   BM_Detector      sensors::AnnotationDetector::detect on such a frame and
//                    its annotation (a pass over the labels, the error model)
//   BM_Fusion        fuse() of 60 candidates (the cones within 20 m ahead and
//                    a few fakes) with that frame's boxes
//   BM_JpegEncode    hal::encode_jpeg of that frame at the log's quality (85):
//                    a run's log keeps every camera frame so
//   BM_JpegDecode    hal::decode_jpeg of it (the car's MJPEG camera)
// Counters: mean and p99 (ms) of the timed calls, rays cast, instances.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "autonomy/hal/image.h"
#include "autonomy/perception/fusion.h"
#include "bench/bench_scenes.h"
#include "sim/sensors/annotation_detector.h"
#include "sim/sensors/camera.h"
#include "sim/world/track.h"

namespace {

using namespace paddock;

world::TrackModel fsg_2023() { return bench::real_track("fsg_2023"); }

// n base poses along the centreline, each looking at the point 2 m ahead
std::vector<Pose2> poses_along(const world::TrackModel& t, int n) {
  std::vector<Pose2> poses;
  const std::size_t m = t.centreline.size();
  for (int k = 0; k < n; ++k) {
    const std::size_t i = m * static_cast<std::size_t>(k) / static_cast<std::size_t>(n);
    const Vec2 a = t.centreline[i], b = t.centreline[(i + 4) % m];
    poses.push_back({a.x, a.y, angle_of(b - a)});
  }
  return poses;
}

void report(benchmark::State& state, std::vector<double>& ms) {
  std::sort(ms.begin(), ms.end());
  double sum = 0.0;
  for (double v : ms) sum += v;
  const std::size_t i99 = std::min(ms.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(ms.size())));
  state.counters["mean_ms"] = sum / static_cast<double>(ms.size());
  state.counters["p99_ms"] = ms[i99];
}

void camera_frames(benchmark::State& state, const sensors::GroundParams& ground,
                   const sensors::CameraParams& params = {}, bool culling = true, bool pixels = true) {
  const world::TrackModel track = fsg_2023();
  const sensors::LidarWorld world(track.cones, {}, ground);
  sensors::Camera camera(params, 1);
  camera.set_culling(culling);
  const std::vector<Pose2> poses = poses_along(track, 50);
  hal::CameraFrame frame;
  sensors::CameraAnnotation annotation;
  std::vector<double> ms;
  std::size_t k = 0, rays = 0, instances = 0;
  for (auto _ : state) {
    const Pose2& pose = poses[k++ % poses.size()];
    const auto t0 = std::chrono::steady_clock::now();
    camera.render(world, pose, 0, frame, annotation, pixels);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    rays += camera.last_primary_rays() + camera.last_continued_rays();
    instances += annotation.instances.size();
    benchmark::DoNotOptimize(frame.rgb.data());
  }
  report(state, ms);
  state.counters["cones"] = static_cast<double>(track.cones.size());
  state.counters["rays"] = static_cast<double>(rays) / static_cast<double>(ms.size());
  state.counters["instances"] = static_cast<double>(instances) / static_cast<double>(ms.size());
}

void BM_CameraFrame(benchmark::State& state) { camera_frames(state, {}); }
BENCHMARK(BM_CameraFrame)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_CameraFrameUnculled(benchmark::State& state) { camera_frames(state, {}, {}, false); }
BENCHMARK(BM_CameraFrameUnculled)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_CameraFrameBumpy(benchmark::State& state) {
  sensors::GroundParams g;
  g.bump_height = 0.1;
  g.bump_wavelength = 10.0;
  camera_frames(state, g);
}
BENCHMARK(BM_CameraFrameBumpy)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_CameraFrameNoisy(benchmark::State& state) {
  sensors::CameraParams p;
  p.pixel_noise = 2.0;
  camera_frames(state, {}, p);
}
BENCHMARK(BM_CameraFrameNoisy)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_CameraAnnotation(benchmark::State& state) { camera_frames(state, {}, {}, true, false); }
BENCHMARK(BM_CameraAnnotation)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_CameraAnnotationBumpy(benchmark::State& state) {
  sensors::GroundParams g;
  g.bump_height = 0.1;
  g.bump_wavelength = 10.0;
  camera_frames(state, g, {}, true, false);
}
BENCHMARK(BM_CameraAnnotationBumpy)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// a frame from the start pose of the track, for the detector and the fusion
struct Scene {
  world::TrackModel track = fsg_2023();
  sensors::AnnotatedFrame shot;
  perception::CameraCalibration calib;
  Pose2 pose;
};

Scene start_scene() {
  Scene s;
  const sensors::LidarWorld world(s.track.cones);
  sensors::Camera camera(sensors::CameraParams{}, 1);
  s.pose = poses_along(s.track, 50)[3];
  s.shot = camera.render(world, s.pose, 0);
  s.calib = camera.calibration();
  return s;
}

void BM_Detector(benchmark::State& state) {
  const Scene s = start_scene();
  sensors::AnnotationDetector detector(sensors::DetectorParams{}, 1);
  std::size_t boxes = 0;
  for (auto _ : state) {
    const sensors::AnnotationDetection r = detector.detect(s.shot.frame, s.shot.annotation);
    boxes = r.detections.boxes.size();
    benchmark::DoNotOptimize(r.detections.boxes.data());
  }
  state.counters["instances"] = static_cast<double>(s.shot.annotation.instances.size());
  state.counters["boxes"] = static_cast<double>(boxes);
}
BENCHMARK(BM_Detector)->Unit(benchmark::kMicrosecond);

void BM_Fusion(benchmark::State& state) {
  const Scene s = start_scene();
  sensors::AnnotationDetector detector(sensors::DetectorParams{}, 1);
  const std::vector<hal::CameraBox> boxes = detector.detect(s.shot.frame, s.shot.annotation).detections.boxes;
  // the cones within 20 m (base frame, mid-height), then fakes between them
  std::vector<perception::ConeCandidate> cands;
  for (const Cone& c : s.track.cones) {
    const Vec2 b = s.pose.inverse_transform(c.position);
    if (norm(b) < 20.0 && cands.size() < 50) cands.push_back({Eigen::Vector3d(b.x, b.y, 0.16), c.color, 20});
  }
  for (int k = 0; cands.size() < 60; ++k) cands.push_back({Eigen::Vector3d(3.0 + k, 0.0, 0.16), ConeColor::Unknown, 10});
  int kept = 0;
  for (auto _ : state) {
    const perception::FusionResult r = perception::fuse(cands, boxes, s.calib);
    kept = r.from_camera + r.from_lidar;
    benchmark::DoNotOptimize(r.cones.data());
  }
  state.counters["candidates"] = static_cast<double>(cands.size());
  state.counters["boxes"] = static_cast<double>(boxes.size());
  state.counters["kept"] = kept;
}
BENCHMARK(BM_Fusion)->Unit(benchmark::kMicrosecond);

}  // namespace

namespace {

void BM_JpegEncode(benchmark::State& state) {
  const Scene s = start_scene();
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::vector<std::uint8_t> jpeg = hal::encode_jpeg(s.shot.frame, 85);
    bytes = jpeg.size();
    benchmark::DoNotOptimize(jpeg.data());
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_JpegEncode)->Unit(benchmark::kMillisecond);

void BM_JpegDecode(benchmark::State& state) {
  const Scene s = start_scene();
  const std::vector<std::uint8_t> jpeg = hal::encode_jpeg(s.shot.frame, 85);
  for (auto _ : state) {
    const hal::CameraFrame f = hal::decode_jpeg(jpeg.data(), jpeg.size(), 0);
    benchmark::DoNotOptimize(f.rgb.data());
  }
}
BENCHMARK(BM_JpegDecode)->Unit(benchmark::kMillisecond);

}  // namespace
