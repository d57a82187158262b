#pragma once
// the car's CAN bus (scenarios/sensors/paddock.dbc): the VCU sends the stack
// the IMU, wheel speeds, steering angle, RES and VCU status frames, the stack (ACU) sends
// the VCU its actuator command. CarCan turns HAL messages into those frames and
// frames back into HAL messages, with the layout the parsed DBC gives; the
// SocketCAN functions put a frame into and out of Linux's struct can_frame.
// An IMU sample is two frames, IMU_Accel and IMU_Rate, which carry the same
// 4-bit rolling counter (the "alive counter", +1 mod 16 per sample): the
// receiver pairs the halves by it, since on the car each frame is stamped at its
// own arrival and the two stamps differ.
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/time.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/messages.h"

namespace paddock::hal {

// one classical CAN frame
struct CanFrame {
  // when it was received (SocketCAN's receive time on the car) or measured
  // (the simulator's measurement time); not part of the bytes on the bus
  TimeNs stamp = 0;
  std::uint32_t id = 0;  // 11-bit (standard) or 29-bit (extended)
  bool extended = false;
  std::uint8_t dlc = 0;                // data bytes, 0..8
  std::array<std::uint8_t, 8> data{};  // bytes past dlc are 0
};

// Linux's struct can_frame: can_id (u32, little-endian, with the EFF/RTR/ERR
// flags in its top bits), can_dlc (u8), 3 pad bytes, data[8]
inline constexpr std::size_t kSocketCanFrameSize = 16;
void to_socketcan(const CanFrame& frame, std::uint8_t out[kSocketCanFrameSize]);
// a data frame from n bytes of struct can_frame, stamped `stamp` (the caller's
// receive time); nothing for n != 16, a remote or error frame, or a dlc over 8
std::optional<CanFrame> from_socketcan(const std::uint8_t* p, std::size_t n, TimeNs stamp = 0);

struct CarCanCounters {
  // frames pushed, and the ones dropped
  std::uint64_t frames = 0;
  std::uint64_t unknown_id = 0;            // an id (or frame format) the car does not send
  std::uint64_t bad_dlc = 0;               // a dlc other than the DBC's
  std::uint64_t bad_value = 0;             // an AsState or Mission outside its enum
  // an IMU frame whose other half never came (the next IMU frame has another
  // counter, or is a repeat of its own half, which replaces it)
  std::uint64_t unmatched_imu_halves = 0;
  // messages decoded
  std::uint64_t res = 0;
  std::uint64_t vcu_status = 0;
  std::uint64_t imu = 0;
  std::uint64_t wheel_speeds = 0;
  std::uint64_t steering = 0;
  std::uint64_t commands = 0;
  // encoding: frames made, values that did not fit
  std::uint64_t encoded = 0;
  std::uint64_t nonfinite = 0;  // NaN (sent as raw 0) or +-inf (saturated)
  std::uint64_t saturated = 0;  // finite but out of the signal's range: sent as its nearest end
};

class CarCan {
 public:
  // takes the car's messages from a parsed DBC (source names it in errors);
  // throws std::invalid_argument("source: message IMU_Accel: no signal Az")
  // when one is missing (IMU_Accel and IMU_Rate each need their Counter: 4
  // bits, factor 1, offset 0, unit ""), or "source:line: ..." when a signal's
  // unit or length differs or its range or step cannot carry a racing car's
  // values
  explicit CarCan(const Dbc& dbc, const std::string& source);

  // frames stamped with the message's stamp; a value out of a signal's range
  // is sent as the range's nearest end, a NaN as raw 0 (both counted). An
  // Imu's two frames carry this CarCan's IMU counter, which then goes up by
  // one (mod 16): the first Imu encoded has counter 0
  std::vector<CanFrame> encode(const Imu& m);  // IMU_Accel, IMU_Rate
  CanFrame encode(const WheelSpeeds& m);
  CanFrame encode(const SteeringAngle& m);
  CanFrame encode(const ResSignal& m);
  CanFrame encode(const VcuStatus& m);
  CanFrame encode(const ActuatorCommand& m);

  // decodes a received frame; a frame that is not the car's, or malformed, is
  // dropped and counted. An Imu comes out once an IMU_Accel and an IMU_Rate
  // with the same counter are in, in either order, stamped with the first one
  // received (on the car its receive time; in the simulator both halves carry
  // the measurement time). A waiting half meets one new IMU frame: with its
  // partner it pairs; otherwise (a different counter, or a repeat of its own
  // half) the waiting half is dropped and counted, and the new one waits
  void push(const CanFrame& frame);
  // the decoded messages, in arrival order
  std::optional<SensorMessage> pop_sensor();
  std::optional<ActuatorCommand> pop_command();

  const CarCanCounters& counters() const { return counters_; }

 private:
  // the car's messages
  enum Kind : std::size_t { kRes, kCommand, kImuAccel, kImuRate, kWheels, kSteering, kVcuStatus, kKinds };
  struct Message {
    std::uint32_t id = 0;
    bool extended = false;
    std::uint8_t dlc = 0;
    std::vector<DbcSignal> signals;  // the car's, in the order of its table
  };
  // the IMU frame waiting for its other half, if any
  struct ImuHalf {
    bool waiting = false;
    std::size_t half = 0;  // 0 IMU_Accel, 1 IMU_Rate
    std::uint8_t counter = 0;
    TimeNs stamp = 0;
    std::array<double, 3> v{};  // ax, ay, az or roll, pitch, yaw rate
  };

  CanFrame frame(Kind k, TimeNs stamp, std::initializer_list<double> values);
  void imu_half(std::size_t half, std::uint8_t counter, TimeNs stamp, const std::array<double, 3>& v);

  std::array<Message, kKinds> msg_;
  std::uint8_t imu_counter_ = 0;  // the next encoded Imu's, 0..15
  ImuHalf imu_;                   // at most one half waits
  std::deque<SensorMessage> sensors_;
  std::deque<ActuatorCommand> commands_;
  CarCanCounters counters_;
};

}  // namespace paddock::hal
