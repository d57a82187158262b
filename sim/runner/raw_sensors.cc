#include "sim/runner/raw_sensors.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>

namespace paddock::runner {

namespace {

// the raw points read as the HAL's (a forward iterator: a vector built from
// a range of them is sized once and each point constructed in place)
struct AsHalPoint {
  using iterator_category = std::forward_iterator_tag;
  using value_type = hal::LidarPoint;
  using difference_type = std::ptrdiff_t;
  using pointer = const hal::LidarPoint*;
  using reference = hal::LidarPoint;
  const sensors::LidarPoint* p;
  hal::LidarPoint operator*() const { return {p->x, p->y, p->z, p->intensity, p->ring, p->t}; }
  AsHalPoint& operator++() {
    ++p;
    return *this;
  }
  AsHalPoint operator++(int) {
    AsHalPoint o = *this;
    ++p;
    return o;
  }
  bool operator==(const AsHalPoint& o) const { return p == o.p; }
  bool operator!=(const AsHalPoint& o) const { return p != o.p; }
};

}  // namespace

void PoseHistory::record(TimeNs now, const Pose2& base) {
  poses_.emplace_back(now, base);
  while (poses_.size() > 2 && poses_.front().first < now - span_) poses_.pop_front();
}

std::vector<bool> cones_hit(const std::vector<std::int32_t>& truth, std::size_t cone_count) {
  std::vector<bool> hit(cone_count, false);
  for (const std::int32_t c : truth)
    if (c >= 0 && static_cast<std::size_t>(c) < cone_count) hit[static_cast<std::size_t>(c)] = true;
  return hit;
}

RawSensors::RawSensors(const sensors::LidarParams& lidar, const sensors::GroundParams& ground,
                       const std::vector<world::Block>& blocks, const std::optional<sensors::CameraParams>& camera,
                       const sensors::DetectorParams& detector, std::uint64_t lidar_seed, std::uint64_t camera_seed,
                       std::uint64_t detector_seed, int threads)
    : workers_(camera && threads > 1 ? 2 : 1), lidar_(lidar, lidar_seed), ground_(ground), blocks_(blocks) {
  if (!camera) return;
  camera_ = std::make_unique<sensors::Camera>(*camera, camera_seed);
  detector_ = std::make_unique<sensors::AnnotationDetector>(detector, detector_seed);
}

TimeNs RawSensors::scan_end(TimeNs now) const {
  return lidar_.column_time(now - lidar_.period_ns(), lidar_.params().columns - 1);
}

bool RawSensors::rotation_ends(TimeNs now) const {
  const TimeNs period = lidar_.period_ns();
  return now >= period && now % period == 0;
}

Pose2 PoseHistory::at(TimeNs t) const {
  if (poses_.empty()) return {};
  if (t <= poses_.front().first) return poses_.front().second;
  if (t >= poses_.back().first) return poses_.back().second;
  // the first pose at or after t (lower_bound's). The poses come a physics
  // step apart, so the one where t falls at a steady spacing is nearly
  // always it: that guess is checked, and the search runs only when it misses
  const std::size_t n = poses_.size();
  // (t - 1: a t on a pose is that pose's)
  const TimeNs first = poses_.front().first, span = poses_.back().first - first;
  const double steps = static_cast<double>(t - 1 - first) / static_cast<double>(span) * static_cast<double>(n - 1);
  const std::size_t g = std::min(n - 1, 1 + static_cast<std::size_t>(steps));
  auto it = poses_.begin() + static_cast<std::ptrdiff_t>(g);
  if (!(it->first >= t && (it - 1)->first < t)) {
    it = std::lower_bound(poses_.begin(), poses_.end(), t,
                          [](const std::pair<TimeNs, Pose2>& p, TimeNs v) { return p.first < v; });
  }
  const auto& [t1, p1] = *it;
  const auto& [t0, p0] = *(it - 1);
  const double u = static_cast<double>(t - t0) / static_cast<double>(t1 - t0);
  Pose2 p;
  p.x = p0.x + u * (p1.x - p0.x);
  p.y = p0.y + u * (p1.y - p0.y);
  p.yaw = p0.yaw + u * wrap_angle(p1.yaw - p0.yaw);
  return p;
}

void RawSensors::update_scene(const world::ConeWorld& cones, const FaultInjector& faults, double t) {
  const auto n = static_cast<std::size_t>(cones.cone_count());
  const std::vector<world::Block>& objects = faults.objects(t);
  bool changed = world_ == nullptr || scene_cones_.size() != n || objects.size() != scene_objects_;
  if (!changed) {
    for (std::size_t i = 0; i < n && !changed; ++i) {
      const int ii = static_cast<int>(i);
      changed = cones.cone_knocked(ii) != scene_knocked_[i] ||
                distance(cones.cone_position(ii), scene_cones_[i].position) > 0.01 ||
                faults.colour(ii, cones.cone(ii).color, t) != scene_cones_[i].color;
    }
  }
  if (!changed) return;
  scene_cones_.resize(n);
  scene_knocked_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int ii = static_cast<int>(i);
    scene_cones_[i] = {cones.cone_position(ii), faults.colour(ii, cones.cone(ii).color, t)};
    scene_knocked_[i] = cones.cone_knocked(ii);
  }
  std::vector<world::Block> blocks = blocks_;
  blocks.insert(blocks.end(), objects.begin(), objects.end());
  scene_objects_ = objects.size();
  world_.reset();  // one Embree device at a time
  world_ = std::make_unique<sensors::LidarWorld>(scene_cones_, scene_knocked_, ground_, blocks);
}

const std::vector<std::int32_t>& RawSensors::emit(TimeNs now, const world::ConeWorld& cones, const PoseHistory& poses,
                                                  SimHal& hal, FaultInjector& faults, double t) {
  {
    const StageScope scope(profile_, Stage::Lidar);
    update_scene(cones, faults, t);
  }
  const TimeNs start = now - lidar_.period_ns();
  const bool camera_on = camera_ && !faults.camera_dead(t);
  // a frozen camera posts the same image again; a live one renders
  const bool frozen = camera_on && frozen_ && faults.camera_frozen(t);
  const bool render = camera_on && !frozen;
  const bool lidar_on = faults.lidar_sends(t);
  const TimeNs exposure =
      camera_on ? sensors::trigger_time(lidar_.params(), camera_->params().trigger_azimuth, start) : TimeNs{0};
  // the detector node's boxes on the frame (a frame it cannot read gives
  // none, as a node that fails posts nothing)
  std::optional<sensors::AnnotationDetection> detection;
  const auto shoot = [&] {
    // (a frame the log still encodes is left to it)
    hal::CameraFrame& frame = hal::writable(frame_).frame;
    camera_->render(*world_, poses.at(exposure), exposure, frame, annotation_, pixels_);
    frame_painted_ = pixels_;
    detection = detector_->detect(frame, annotation_);
  };
  // (into the buffer of the rotations before: no allocation)
  std::vector<sensors::LidarPoint>& raw = raw_;
  const auto cast = [&] { lidar_.scan(*world_, [&poses](TimeNs at) { return poses.at(at); }, start, raw); };
  bool cast_done = false;
  if (render && lidar_on && workers_.threads() > 1) {
    const StageScope scope(profile_, Stage::Camera);  // what the camera takes beyond the cast
    workers_.run([&](int part) {
      if (part == 0) {
        const StageScope lidar(profile_, Stage::Lidar);
        cast();
      } else {
        shoot();
      }
    });
    cast_done = true;
  } else if (render) {
    const StageScope scope(profile_, Stage::Camera);
    shoot();
  }
  if (frozen) {
    hal::CameraDetections again = *frozen_;
    again.stamp = exposure;
    hal.post(std::move(again));
  } else if (detection && detection->ok) {
    frozen_ = detection->detections;
    hal.post(std::move(detection->detections));
  }
  if (!lidar_on) {
    truth_.clear();
    return truth_;
  }
  const StageScope scope(profile_, Stage::Lidar);
  if (!cast_done) cast();
  faults.filter_lidar(t, raw);
  truth_.resize(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) truth_[i] = raw[i].cone;
  if (const WireLink* wire = hal.wire(); wire != nullptr && wire->has_lidar()) {
    // the sensor's packets, in the order it sends them (the car's decoder
    // gives the points back in the scan's order: column by column, rings up)
    column_time_.resize(static_cast<std::size_t>(lidar_.params().columns));
    for (std::size_t c = 0; c < column_time_.size(); ++c) column_time_[c] = lidar_.column_time(start, static_cast<int>(c));
    packets_.clear();
    wire->encode_lidar(raw, column_time_, frame_id_++, packets_);
    hal.post_lidar(packets_);
    return truth_;
  }
  hal::LidarScan scan;
  scan.stamp = start;
  scan.end = scan_end(now);
  // built from the raw points in one pass (a resize would first write every
  // point as zeros)
  scan.points.assign(AsHalPoint{raw.data()}, AsHalPoint{raw.data() + raw.size()});
  hal.post(std::move(scan));
  return truth_;
}

}  // namespace paddock::runner
