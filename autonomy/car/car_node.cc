#include "autonomy/car/car_node.h"

#include <cstdio>
#include <stdexcept>

#include "autonomy/hal/json.h"

namespace paddock::car {

std::optional<hal::SensorMessage> CarNode::Inbox::receive() {
  if (messages.empty()) return std::nullopt;
  hal::SensorMessage m = std::move(messages.front());
  messages.pop_front();
  return m;
}

CarNode::CarNode(const stack::StackParams& params, const stack::MissionSpec& mission,
                 const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout,
                 const hal::Dbc& dbc, const std::string& dbc_source, const WatchdogParams& watchdogs)
    : stack_(params, mission), can_(dbc, dbc_source), watchdogs_(watchdogs) {
  if (lidar) lidar_ = std::make_unique<hal::ouster::Decoder>(*lidar, layout);
}

void CarNode::lidar_packet(TimeNs received, const std::uint8_t* data, std::size_t size) {
  ++counters_.lidar_packets;
  last_lidar_ = received;
  if (!lidar_) return;
  const StageScope scope(profile_, Stage::Lidar);
  lidar_->push(data, size);
  while (std::optional<hal::LidarScan> s = lidar_->pop()) inbox_.messages.push_back(std::move(*s));
}

void CarNode::can_frame(const hal::CanFrame& frame) {
  ++counters_.can_frames;
  const std::uint64_t before = can_.counters().frames - can_.counters().unknown_id - can_.counters().bad_dlc;
  can_.push(frame);
  // the watchdog counts the car's own frames only (another node's on the bus are no sign of life)
  if (can_.counters().frames - can_.counters().unknown_id - can_.counters().bad_dlc > before) last_can_ = frame.stamp;
  while (std::optional<hal::SensorMessage> m = can_.pop_sensor()) inbox_.messages.push_back(std::move(*m));
}

void CarNode::camera_frame(hal::CameraFrame frame) {
  ++counters_.camera_frames;
  inbox_.messages.push_back(std::move(frame));
}

const hal::SensorMessage* CarNode::object(TimeNs, const char* data, std::size_t size) {
  try {
    inbox_.messages.push_back(hal::message_from_json(data, size));
    ++counters_.objects;
    return &inbox_.messages.back();
  } catch (const std::invalid_argument& e) {
    ++counters_.bad_objects;
    last_bad_object_ = e.what();
    return nullptr;
  }
}

void CarNode::watch(TimeNs now) {
  if (watchdog_fault_) return;
  char why[160];
  if (lidar_ && last_lidar_ && now - *last_lidar_ > from_seconds(watchdogs_.lidar_timeout)) {
    std::snprintf(why, sizeof why, "watchdog: no LiDAR packet for %.3f s (limit %.3f s)",
                  to_seconds(now - *last_lidar_), watchdogs_.lidar_timeout);
    watchdog_fault_ = why;
  } else if (last_can_ && now - *last_can_ > from_seconds(watchdogs_.can_timeout)) {
    std::snprintf(why, sizeof why, "watchdog: no sensor frame on the CAN bus for %.3f s (limit %.3f s)",
                  to_seconds(now - *last_can_), watchdogs_.can_timeout);
    watchdog_fault_ = why;
  }
  if (watchdog_fault_) stack_.emergency(*watchdog_fault_);
}

hal::ActuatorCommand CarNode::tick(TimeNs now) {
  ++counters_.ticks;
  watch(now);
  inbox_.sent.reset();
  stack_.tick(now, inbox_);
  if (!inbox_.sent) throw std::logic_error("CarNode::tick: the stack sent no command");
  return *inbox_.sent;
}

hal::CanFrame CarNode::command_frame(const hal::ActuatorCommand& c) { return can_.encode(c); }

CarCounters CarNode::counters() const {
  CarCounters c = counters_;
  if (lidar_) c.lidar = lidar_->counters();
  c.can = can_.counters();
  return c;
}

}  // namespace paddock::car
