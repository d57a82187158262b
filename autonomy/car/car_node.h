#pragma once
// the car's computer without its sockets: the car's decoders in front of the
// stack, and the watchdogs. What arrives on the car's wires goes in as bytes
// (the LiDAR's UDP payloads, CAN frames, the object messages' JSON), each
// with its receive time; tick() runs the control cycle and gives the command
// to put on the bus. The car binary (car.h) feeds it from its sockets, the
// replay from a log. No I/O, no clock: the caller says what time it is.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/common/profile.h"
#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/hal.h"
#include "autonomy/hal/ouster.h"
#include "autonomy/stack/stack.h"

namespace paddock::car {

// AS Emergency when a sensor goes silent (the FS rules' "loss of a sensor":
// the car brakes to a stop). Each watchdog arms with its sensor's first
// message: before it the AS cannot be Ready anyway
struct WatchdogParams {
  double lidar_timeout = 0.5;  // s without a LiDAR packet
  double can_timeout = 0.1;    // s without a sensor frame of the CAN bus

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(lidar_timeout), {"s", params::in(0.01, 60.0), "no LiDAR packet for this long: AS Emergency"});
    v(PADDOCK_PARAM(can_timeout), {"s", params::in(0.001, 60.0), "no sensor frame on the CAN bus for this long: AS Emergency"});
  }
};

struct CarCounters {
  std::uint64_t lidar_packets = 0;
  std::uint64_t can_frames = 0;
  std::uint64_t camera_frames = 0;
  std::uint64_t objects = 0;      // object messages taken
  std::uint64_t bad_objects = 0;  // object messages dropped (no paddock JSON)
  std::uint64_t ticks = 0;
  hal::ouster::Decoder::Counters lidar;
  hal::CarCanCounters can;
};

class CarNode {
 public:
  // lidar: the LiDAR's metadata (none: the stack reads no LiDAR) and the
  // layout the scenario gives it (its mounting)
  CarNode(const stack::StackParams& params, const stack::MissionSpec& mission,
          const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout, const hal::Dbc& dbc,
          const std::string& dbc_source, const WatchdogParams& watchdogs);

  // one UDP payload of the LiDAR (a packet it cannot use is counted by the decoder)
  void lidar_packet(TimeNs received, const std::uint8_t* data, std::size_t size);
  // one frame off the CAN bus, stamped with its receive time
  void can_frame(const hal::CanFrame& frame);
  // one object message (hal/json.h): the message taken (valid until the
  // next call), or none when it was bad (dropped, counted, its reason kept:
  // last_bad_object)
  const hal::SensorMessage* object(TimeNs received, const char* data, std::size_t size);

  // one frame of the car's camera
  void camera_frame(hal::CameraFrame frame);

  // the control cycle at `now`: the watchdogs, then the stack; the command
  // it sent (AS Emergency with the brakes on once a watchdog fired)
  hal::ActuatorCommand tick(TimeNs now);
  // the command's CAN frame, as the ACU sends it
  hal::CanFrame command_frame(const hal::ActuatorCommand& c);

  const stack::Stack& stack() const { return stack_; }
  // the stack's perception (perception = lidar | lidar_camera), else null
  stack::PerceptionStage* perception() { return stack_.perception(); }
  // where the time goes, timed into `profile` from now on (null: not
  // timed): the stack's stages, and the LiDAR's decoding as Stage::Lidar
  void set_profile(Profile* profile) {
    profile_ = profile;
    stack_.set_profile(profile);
  }
  CarCounters counters() const;
  // why a watchdog fired, if one did
  const std::optional<std::string>& watchdog_fault() const { return watchdog_fault_; }
  const std::string& last_bad_object() const { return last_bad_object_; }

 private:
  // the HAL as the stack sees it on the car: the decoders' messages in arrival order
  class Inbox final : public hal::Hal {
   public:
    std::deque<hal::SensorMessage> messages;
    std::optional<hal::ActuatorCommand> sent;
    std::optional<hal::SensorMessage> receive() override;
    void send(const hal::ActuatorCommand& c) override { sent = c; }
  };
  void watch(TimeNs now);

  stack::Stack stack_;
  std::unique_ptr<hal::ouster::Decoder> lidar_;
  hal::CarCan can_;
  WatchdogParams watchdogs_;
  Inbox inbox_;
  std::optional<TimeNs> last_lidar_, last_can_;
  std::optional<std::string> watchdog_fault_;
  std::string last_bad_object_;
  CarCounters counters_;
  Profile* profile_ = nullptr;
};

}  // namespace paddock::car
