#include "sim/runner/wire.h"

#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "autonomy/hal/json.h"

namespace paddock::runner {

WireLink::WireLink(const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout,
                   const hal::Dbc& dbc, const std::string& dbc_source)
    : info_(lidar), vcu_(dbc, dbc_source), acu_(dbc, dbc_source) {
  if (!info_) return;
  decoder_ = std::make_unique<hal::ouster::Decoder>(*info_, layout);
  pixel_of_ring_ = hal::ouster::pixel_of_ring(*info_);
  packet_size_ = hal::ouster::packet_size(*info_);
}

bool WireLink::on_can(const hal::SensorMessage& m) {
  return std::holds_alternative<hal::Imu>(m) || std::holds_alternative<hal::WheelSpeeds>(m) ||
         std::holds_alternative<hal::SteeringAngle>(m) || std::holds_alternative<hal::ResSignal>(m) ||
         std::holds_alternative<hal::VcuStatus>(m);
}

// one frame onto the bus and off it: the 16 bytes of struct can_frame, read
// back with the frame's time as the receive stamp (to: none when another
// process reads the bus)
void WireLink::carry_frame(const hal::CanFrame& f, hal::CarCan* to, bool to_stack, TimeNs now) {
  std::uint8_t bytes[hal::kSocketCanFrameSize];
  hal::to_socketcan(f, bytes);
  if (tap_) tap_->can_frame(now, to_stack, bytes);
  ++counters_.can_frames;
  counters_.can_bytes += hal::kSocketCanFrameSize;
  if (!to) return;
  if (const std::optional<hal::CanFrame> r = hal::from_socketcan(bytes, sizeof bytes, f.stamp)) to->push(*r);
}

void WireLink::carry(const hal::SensorMessage& m, std::deque<hal::SensorMessage>& out, TimeNs now) {
  const std::vector<hal::CanFrame> frames = std::visit(
      [this](const auto& msg) -> std::vector<hal::CanFrame> {
        using T = std::decay_t<decltype(msg)>;
        if constexpr (std::is_same_v<T, hal::Imu>) {
          return vcu_.encode(msg);
        } else if constexpr (std::is_same_v<T, hal::WheelSpeeds> || std::is_same_v<T, hal::SteeringAngle> ||
                             std::is_same_v<T, hal::ResSignal> || std::is_same_v<T, hal::VcuStatus>) {
          return {vcu_.encode(msg)};
        } else {
          throw std::logic_error("WireLink::carry: not a message of the CAN bus");
        }
      },
      m);
  // to the car binary's bus, or to the stack's side of ours
  for (const hal::CanFrame& f : frames) carry_frame(f, remote_ ? nullptr : &acu_, true, now);
  if (remote_) return remote_->can_frames(now, frames);
  while (std::optional<hal::SensorMessage> d = acu_.pop_sensor()) out.push_back(std::move(*d));
}

void WireLink::carry_lidar(const std::vector<std::uint8_t>& packets, std::deque<hal::SensorMessage>& out,
                           TimeNs now) {
  if (!decoder_) throw std::logic_error("WireLink::carry_lidar: no LiDAR metadata");
  for (std::size_t at = 0; at + packet_size_ <= packets.size(); at += packet_size_) {
    if (tap_) tap_->lidar_packet(now, packets.data() + at, packet_size_);
    if (remote_) {
      remote_->lidar_packet(now, packets.data() + at, packet_size_);
    } else {
      decoder_->push(packets.data() + at, packet_size_);
    }
    ++counters_.lidar_packets;
    counters_.lidar_bytes += packet_size_;
  }
  while (std::optional<hal::LidarScan> s = decoder_->pop()) out.push_back(std::move(*s));
}

std::optional<hal::ActuatorCommand> WireLink::carry(const hal::ActuatorCommand& c, TimeNs now) {
  carry_frame(acu_.encode(c), &vcu_, false, now);
  std::optional<hal::ActuatorCommand> last;
  while (std::optional<hal::ActuatorCommand> d = vcu_.pop_command()) last = *d;
  return last;
}

void WireLink::encode_lidar(const std::vector<sensors::LidarPoint>& points, const std::vector<TimeNs>& column_time,
                            std::uint16_t frame_id, std::vector<std::uint8_t>& out) const {
  if (!info_) throw std::logic_error("WireLink::encode_lidar: no LiDAR metadata");
  hal::ouster::RangeImage image = hal::ouster::make_range_image(*info_, frame_id);
  const std::size_t columns = image.columns.size();
  if (column_time.size() != columns) throw std::logic_error("WireLink::encode_lidar: one time per column");
  for (std::size_t c = 0; c < columns; ++c) image.columns[c].time = column_time[c];
  const auto pixels = static_cast<std::size_t>(image.pixels_per_column);
  for (const sensors::LidarPoint& p : points) {
    // the range the sensor measured, in its mm (the simulated LiDAR reports
    // whole mm: the float coordinates give it back to a few um)
    const double r = std::sqrt(static_cast<double>(p.x) * p.x + static_cast<double>(p.y) * p.y +
                               static_cast<double>(p.z) * p.z);
    hal::ouster::RangeImage::Pixel& px =
        image.pixels[p.column * pixels + static_cast<std::size_t>(pixel_of_ring_[p.ring])];
    px.range_mm = static_cast<std::uint32_t>(std::lround(r * 1000.0));
    px.signal = static_cast<std::uint16_t>(std::lround(static_cast<double>(p.intensity) * hal::ouster::kSignalFullScale));
  }
  hal::ouster::encode(*info_, image, out);
}

std::optional<hal::ActuatorCommand> WireLink::remote_cycle(TimeNs now) {
  for (const hal::CanFrame& f : remote_->tick(now)) carry_frame(f, &vcu_, false, now);
  std::optional<hal::ActuatorCommand> last;
  while (std::optional<hal::ActuatorCommand> d = vcu_.pop_command()) last = *d;
  return last;
}

void WireLink::send_object(TimeNs now, const hal::SensorMessage& m) {
  const std::optional<std::string> json = hal::to_json(m);
  if (!json) throw std::logic_error("WireLink::send_object: a message that travels on a wire");
  remote_->object(now, *json);
}

WireCounters WireLink::counters() const {
  WireCounters c = counters_;
  if (decoder_) c.lidar = decoder_->counters();
  c.acu = acu_.counters();
  c.vcu = vcu_.counters();
  return c;
}

}  // namespace paddock::runner
