#pragma once
// transport = wire: the car's wires between the simulator and the stack.
// The simulator's side encodes what the car's hardware would send (the
// LiDAR's UDP packets, the VCU's CAN frames as Linux's struct can_frame);
// the car's own decoders (hal::ouster::Decoder, hal::CarCan) turn the bytes
// back into HAL messages, exactly as on the car. The stack's command goes
// back as the ACU's CAN frame, decoded by the simulated VCU.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/messages.h"
#include "autonomy/hal/ouster.h"
#include "sim/runner/car_link.h"
#include "sim/sensors/lidar.h"

namespace paddock::runner {

// what crossed the wires, and what the decoders dropped
struct WireCounters {
  std::uint64_t lidar_packets = 0;
  std::uint64_t lidar_bytes = 0;
  std::uint64_t can_frames = 0;     // both ways
  std::uint64_t can_bytes = 0;
  hal::ouster::Decoder::Counters lidar;  // the car's LiDAR decoder
  hal::CarCanCounters acu;               // the stack's side of the CAN bus (sensors in)
  hal::CarCanCounters vcu;               // the car's VCU (commands in)
};

// what watches the HAL's traffic (a run's log): the bytes on the wires, and
// the messages that cross in memory, each at the instant it crossed
class WireTap {
 public:
  virtual ~WireTap() = default;
  // one UDP payload of the LiDAR
  virtual void lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) = 0;
  // one CAN frame as struct can_frame: to the stack (the sensors) or from it (the command)
  virtual void can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) = 0;
  // a message that crosses the HAL as a struct (no wire carries it: the
  // detector node's boxes, an object-level sensor's cones, the true state)
  virtual void message(TimeNs at, const hal::SensorMessage& m) = 0;
};

class WireLink {
 public:
  // lidar: the LiDAR's metadata (none: no LiDAR on the wire) and layout, the
  // layout_of it (mounted); dbc: the car's CAN database, named `dbc_source`
  WireLink(const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout, const hal::Dbc& dbc,
           const std::string& dbc_source);

  // whether m travels on the CAN bus (IMU, wheel speeds, steering, RES)
  static bool on_can(const hal::SensorMessage& m);
  // m (on_can) through the bus: the VCU's frames as bytes, decoded by the
  // stack's side; what came out appended to `out`
  void carry(const hal::SensorMessage& m, std::deque<hal::SensorMessage>& out, TimeNs now);
  // one rotation's packets, as the sensor sends them, into the car's decoder;
  // the scans it completed appended to `out`
  void carry_lidar(const std::vector<std::uint8_t>& packets, std::deque<hal::SensorMessage>& out, TimeNs now);
  // the stack's command through the bus to the VCU (nothing if it dropped it)
  std::optional<hal::ActuatorCommand> carry(const hal::ActuatorCommand& c, TimeNs now);
  // who sees the bytes (none: nobody)
  void set_tap(WireTap* tap) { tap_ = tap; }

  // transport = udp: the stack's end of the wires is a car binary's, over
  // `link`; what carry() and carry_lidar() take goes to it (their `out` stays
  // empty), and its control cycles run through remote_cycle()
  void set_remote(std::unique_ptr<CarLink> link) { remote_ = std::move(link); }
  bool remote() const { return remote_ != nullptr; }
  // the car binary's control cycle at `now`: its command as the VCU decodes
  // it (nothing if it dropped the frame)
  std::optional<hal::ActuatorCommand> remote_cycle(TimeNs now);
  // a message no wire of the car carries (the detector node's boxes) to the
  // car binary, as its JSON
  void send_object(TimeNs now, const hal::SensorMessage& m);

  // the rotation's packets from the simulated LiDAR's points (each with its
  // column and ring): frame `frame_id`, column c fired at column_time(c)
  // (the sensor's timestamps); every column valid, the pixels without a
  // return 0 mm
  void encode_lidar(const std::vector<sensors::LidarPoint>& points, const std::vector<TimeNs>& column_time,
                    std::uint16_t frame_id, std::vector<std::uint8_t>& out) const;
  bool has_lidar() const { return info_.has_value(); }

  WireCounters counters() const;

 private:
  void carry_frame(const hal::CanFrame& f, hal::CarCan* to, bool to_stack, TimeNs now);

  std::optional<hal::ouster::SensorInfo> info_;
  std::unique_ptr<hal::ouster::Decoder> decoder_;
  std::vector<int> pixel_of_ring_;
  std::size_t packet_size_ = 0;
  hal::CarCan vcu_;  // the car: sends the sensors' frames, takes the command
  hal::CarCan acu_;  // the stack's computer: takes the sensors' frames, sends the command
  WireCounters counters_;
  WireTap* tap_ = nullptr;
  std::unique_ptr<CarLink> remote_;
};

}  // namespace paddock::runner
