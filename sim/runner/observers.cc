#include "sim/runner/observers.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "sim/runner/model.h"
#include "sim/runner/simulation.h"

namespace paddock::runner {
namespace {

// frame: the camera frame of the rotation whose scan perception delivered
// last, or null
PerceptionSnapshot take_snapshot(const stack::PerceptionStage& p, const hal::CameraFrame* frame, const Pose2& pose,
                                 const world::ConeWorld& cones) {
  const perception::PerceptionFrame& f = p.last();
  PerceptionSnapshot s;
  s.t = to_seconds(f.output.stamp);
  for (const perception::LabelledPoint& q : f.lidar.points) {
    const std::uint8_t label = q.label == perception::PointLabel::Ground ? 0 : q.label == perception::PointLabel::Cone ? 2 : 1;
    s.points.push_back({q.x, q.y, q.z, label});
  }
  for (const hal::DetectedCone& c : f.output.cones) s.detected.push_back({c.position, c.color});
  for (int i = 0; i < cones.cone_count(); ++i) {
    const Vec2 local = pose.inverse_transform(cones.cone_position(i));
    if (norm(local) <= 40.0) s.truth.push_back({local, cones.cone(i).color});
  }
  if (f.camera_used && frame != nullptr && frame->stamp == f.camera_stamp) {
    s.camera = true;
    s.width = frame->width;
    s.height = frame->height;
    s.rgb = frame->rgb;
    for (const perception::BoundingBox& b : f.detections.boxes) s.boxes.push_back({b.x_min, b.y_min, b.x_max, b.y_max, b.color});
    for (const perception::FusedCone& c : f.fusion.cones) {
      if (!c.projected) continue;
      (c.source == perception::FusionSource::Dropped ? s.dropped : s.projected).push_back({c.pixel.x(), c.pixel.y()});
    }
  }
  return s;
}

}  // namespace

void LogRecorder::observe(const SimModel& model, SimState& s) {
  if (!s.sampled) return;
  if (rows_.empty()) rows_.reserve(model.log_samples);
  const Pose2 base = vehicle::base_pose(model.scenario.vehicle, s.car);
  const Vec2 v = vehicle::base_velocity(model.scenario.vehicle, s.car);
  const control::Diagnostics& c = s.stack.telemetry().control;
  LogRow row;
  row.t = s.t;
  row.x = base.x;
  row.y = base.y;
  row.yaw = base.yaw;
  row.vx = v.x;
  row.vy = v.y;
  row.yaw_rate = s.car.r;
  row.steer_cmd = s.input.steering_angle;
  row.steer = s.car.steering;
  row.throttle = s.input.throttle;
  row.brake = s.input.brake;
  row.v_ref = c.v_ref;
  row.lateral_error = c.lateral_error;
  row.heading_error = c.heading_error;
  row.s = c.s;
  row.lap = s.event.current_lap();
  row.as_state = static_cast<int>(s.as_state);
  rows_.push_back(row);
}

void PerceptionScorer::observe(const SimModel& model, SimState& s) {
  if (s.stack.detection_frames() <= scored_frames_) return;
  scored_frames_ = s.stack.detection_frames();
  const hal::ConeDetections& d = s.stack.last_detections();
  truth_.resize(static_cast<std::size_t>(s.cones.cone_count()));
  for (std::size_t i = 0; i < truth_.size(); ++i)
    truth_[i] = {s.cones.cone_position(static_cast<int>(i)), s.cones.cone(static_cast<int>(i)).color};
  // the cones the sensor could see in the frame of that stamp
  const std::vector<bool>* visible = nullptr;
  for (const auto& [stamp, hit] : s.visible)
    if (std::llabs(stamp - d.stamp) < model.dt_ns) visible = &hit;
  if (visible && !visible->empty()) metrics_.add(d, s.true_poses.at(d.stamp), model.perception_mount, truth_, *visible);
}

void SnapshotRecorder::observe(const SimModel& model, SimState& s) {
  stack::PerceptionStage* p = s.stack.perception();
  if (!p || snapshot_) return;
  const long frames = s.stack.detection_frames();
  const bool new_frame = frames > frames_seen_;
  frames_seen_ = frames;
  const double snapshot_time = model.scenario.sim.snapshot_time;
  // the frame of the scan delivered last: the camera's newest, or with a
  // latency one of the frames kept since arming
  if (armed_ && s.raw && s.raw->camera_frame() != nullptr &&
      (frames_.empty() || frames_.back().stamp != s.raw->camera_frame()->stamp)) {
    frames_.push_back(*s.raw->camera_frame());
    while (frames_.size() > p->in_flight() + 2) frames_.pop_front();
  }
  if (armed_ && new_frame && s.t >= snapshot_time) {
    const hal::CameraFrame* frame = nullptr;
    for (const hal::CameraFrame& f : frames_)
      if (f.stamp == p->last().camera_stamp) frame = &f;
    snapshot_ = take_snapshot(*p, frame, s.true_poses.at(s.stack.last_detections().stamp), s.cones);
    p->set_keep_points(false);
    if (s.raw) s.raw->set_pixels(pixels_before_);
    frames_.clear();
  } else if (!armed_ && static_cast<double>(s.k + 1) * model.dt >= snapshot_time - p->params().latency) {
    // perception keeps the points, and the camera paints its frames, from
    // the next step's scan on (delivered from the snapshot's time on)
    p->set_keep_points(true);
    if (s.raw) {
      pixels_before_ = s.raw->pixels();
      s.raw->set_pixels(true);
    }
    armed_ = true;
  }
}

void SlamScorer::observe(const SimModel& model, SimState& s) {
  if (!s.sampled || !s.stack.estimate()) return;
  if (series_.empty()) series_.reserve(model.log_samples);
  const hal::StateEstimate& e = *s.stack.estimate();
  const Pose2 truth = s.true_poses.at(e.stamp);
  const double d = distance(e.pose.position(), truth.position());
  const double h = wrap_angle(e.pose.yaw - truth.yaw);
  sum2_ += d * d;
  heading2_ += h * h;
  max_ = std::max(max_, d);
  ++n_;
  const stack::Localisation* loc = s.stack.localisation();
  series_.push_back(
      {to_seconds(e.stamp), e.pose, truth, d, h, loc ? std::sqrt(std::max(0.0, loc->position_variance())) : 0.0});
  if (path_.empty() || distance(path_.back(), truth.position()) >= 1.0) path_.push_back(truth.position());
}

namespace {
double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}
}  // namespace

SlamMetrics SlamScorer::metrics(const SimModel& model, const SimState& state, const std::vector<events::Lap>& laps) {
  SlamMetrics m;
  m.samples = n_;
  m.series = std::move(series_);
  const std::vector<SlamSample>& series = m.series;
  m.map = map_metrics(state.stack.cone_map().cones(), model.cones, path_);
  for (const events::Lap& lap : laps) {
    SlamLap l;
    double sum2 = 0.0;
    long n = 0;
    for (const SlamSample& x : series) {
      if (x.t < lap.start || x.t >= lap.start + lap.time) continue;
      sum2 += x.error * x.error;
      l.ate_max = std::max(l.ate_max, x.error);
      ++n;
    }
    l.ate_rms = n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
    m.laps.push_back(l);
  }
  if (const stack::Localisation* loc = state.stack.localisation()) {
    const stack::LocalisationStats& st = loc->stats();
    m.frames = st.frames;
    m.fallbacks = st.empty_frames + st.dropped_frames;
    m.loop_closures = st.loop_closures;
    m.lost_frames = st.lost_frames;
    m.relocalisations = st.relocalisations;
    m.rejected_messages = st.rejected_messages;
    m.slide_samples = st.slide_samples;
    const std::vector<double>& ms = loc->lio() ? st.lio_ms : st.update_ms;
    double sum = 0.0;
    for (double x : ms) sum += x;
    m.update_ms_mean = ms.empty() ? 0.0 : sum / static_cast<double>(ms.size());
    m.update_ms_p99 = percentile(ms, 0.99);
    if (const slam::Lio* lio = loc->lio()) {
      m.lio_slices = lio->stats().slices;
      m.lio_degenerate_slices = st.lio_degenerate_slices;
      m.lio_too_few_points = st.lio_too_few_points;
    }
  }
  if (n_ == 0) return m;
  m.ate_rms = std::sqrt(sum2_ / static_cast<double>(n_));
  m.heading_rms = std::sqrt(heading2_ / static_cast<double>(n_));
  m.ate_max = max_;
  m.drift = relative_drift(
      series.size(), [&series](std::size_t i) -> const Pose2& { return series[i].truth; },
      [&series](std::size_t i) -> const Pose2& { return series[i].estimate; }, 100.0, 10.0);
  return m;
}

void tracking_from_log(const std::vector<events::Lap>& laps, const std::vector<LogRow>& log, double log_dt,
                       std::vector<LapTracking>& per_lap, Tracking& all) {
  per_lap.assign(laps.size(), LapTracking{});
  all = Tracking{};
  std::vector<double> sum2(laps.size(), 0.0);
  std::vector<int> count(laps.size(), 0);
  for (const LogRow& row : log) {
    if (row.lap < 1 || row.lap > static_cast<int>(laps.size())) continue;
    const auto i = static_cast<std::size_t>(row.lap - 1);
    const double e = std::abs(row.lateral_error);
    sum2[i] += e * e;
    ++count[i];
    per_lap[i].max = std::max(per_lap[i].max, e);
    per_lap[i].itae += (row.t - laps[i].start) * e * log_dt;
  }
  double all2 = 0.0;
  int all_n = 0;
  for (std::size_t i = 0; i < laps.size(); ++i) {
    per_lap[i].rms = count[i] > 0 ? std::sqrt(sum2[i] / count[i]) : 0.0;
    all2 += sum2[i];
    all_n += count[i];
    all.max = std::max(all.max, per_lap[i].max);
    all.itae += per_lap[i].itae / static_cast<double>(laps.size());
  }
  all.rms = all_n > 0 ? std::sqrt(all2 / all_n) : 0.0;
}

}  // namespace paddock::runner
