#include "autonomy/hal/car_can.h"

#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "autonomy/common/params.h"

#if __has_include(<linux/can.h>)
#include <linux/can.h>
static_assert(sizeof(struct can_frame) == paddock::hal::kSocketCanFrameSize, "struct can_frame is 16 bytes");
static_assert(offsetof(struct can_frame, data) == 8, "struct can_frame's data at byte 8");
#else
// linux/can.h's flags of can_id
#define CAN_EFF_FLAG 0x80000000U
#define CAN_RTR_FLAG 0x40000000U
#define CAN_ERR_FLAG 0x20000000U
#define CAN_SFF_MASK 0x000007FFU
#define CAN_EFF_MASK 0x1FFFFFFFU
#endif

namespace paddock::hal {

namespace {

// what the car needs of a signal: its unit, the physical range it must carry
// without clipping, the coarsest step that will do; `integer` values (a flag,
// an enum, a counter) must come through exactly: factor 1, offset 0; a
// counter that wraps at 2^bits needs exactly that many `bits` (0: any length)
struct Need {
  const char* signal;
  const char* unit;
  double lo, hi, step;
  bool integer = false;
  int bits = 0;
};

// the IMU frames' rolling counter: 4 bits, +1 mod 16 per sample
constexpr int kImuCounterBits = 4;
constexpr std::uint8_t kImuCounterMask = (1U << kImuCounterBits) - 1;

struct MessageNeed {
  const char* name;
  std::array<Need, 5> signals;  // the first ones; the rest without a name
};

// the car's messages and signals, in CarCan::Kind's order; the ranges: a
// racing car's 5 g and 5 rad/s, wheels to 300 rad/s (60 m/s on a 0.2 m tyre),
// the road wheels past their 0.52 rad lock, 3 kN m of torque vectoring; the
// IMU's Counter is the fourth signal of both its frames
constexpr MessageNeed kCar[] = {
    {"RES_Status", {{{"Go", "", 0.0, 1.0, 1.0, true}, {"Emergency", "", 0.0, 1.0, 1.0, true}}}},
    {"ACU_Command",
     {{{"SteeringAngleRequest", "rad", -0.6, 0.6, 1e-3},
       {"DriveTorqueRequest", "", 0.0, 1.0, 1e-3},
       {"BrakeRequest", "", 0.0, 1.0, 1e-3},
       {"YawMomentRequest", "Nm", -3000.0, 3000.0, 1.0},
       {"AsState", "", 0.0, 4.0, 1.0, true}}}},
    {"IMU_Accel",
     {{{"Ax", "m/s^2", -49.0, 49.0, 1e-2},
       {"Ay", "m/s^2", -49.0, 49.0, 1e-2},
       {"Az", "m/s^2", -49.0, 49.0, 1e-2},
       {"Counter", "", 0.0, kImuCounterMask, 1.0, true, kImuCounterBits}}}},
    {"IMU_Rate",
     {{{"RollRate", "rad/s", -5.0, 5.0, 1e-3},
       {"PitchRate", "rad/s", -5.0, 5.0, 1e-3},
       {"YawRate", "rad/s", -5.0, 5.0, 1e-3},
       {"Counter", "", 0.0, kImuCounterMask, 1.0, true, kImuCounterBits}}}},
    {"WheelSpeeds",
     {{{"FL", "rad/s", -300.0, 300.0, 0.05},
       {"FR", "rad/s", -300.0, 300.0, 0.05},
       {"RL", "rad/s", -300.0, 300.0, 0.05},
       {"RR", "rad/s", -300.0, 300.0, 0.05}}}},
    {"SteeringAngle", {{{"Angle", "rad", -0.6, 0.6, 1e-3}}}},
    // the EBS's tank holds up to ~10 bar, a brake line over 100 bar
    {"VCU_Status",
     {{{"Asms", "", 0.0, 1.0, 1.0, true},
       {"Mission", "", 0.0, static_cast<double>(MissionCode::Manual), 1.0, true},
       {"EbsPressure", "bar", 0.0, 20.0, 0.1},
       {"BrakePressureFront", "bar", 0.0, 200.0, 0.1},
       {"BrakePressureRear", "bar", 0.0, 200.0, 0.1}}}},
};

// a little-endian u32
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

}  // namespace

void to_socketcan(const CanFrame& frame, std::uint8_t out[kSocketCanFrameSize]) {
  put_u32(out, frame.extended ? (frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG : frame.id & CAN_SFF_MASK);
  out[4] = frame.dlc;
  out[5] = out[6] = out[7] = 0;
  for (std::size_t i = 0; i < 8; ++i) out[8 + i] = i < frame.dlc ? frame.data[i] : 0;
}

std::optional<CanFrame> from_socketcan(const std::uint8_t* p, std::size_t n, TimeNs stamp) {
  if (n != kSocketCanFrameSize) return std::nullopt;
  const std::uint32_t can_id = get_u32(p);
  // remote and error frames carry no data; a standard id has 11 bits
  if ((can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0 || p[4] > 8) return std::nullopt;
  CanFrame f;
  f.stamp = stamp;
  f.extended = (can_id & CAN_EFF_FLAG) != 0;
  f.id = can_id & CAN_EFF_MASK;
  if (!f.extended && f.id > CAN_SFF_MASK) return std::nullopt;
  f.dlc = p[4];
  for (std::size_t i = 0; i < f.dlc; ++i) f.data[i] = p[8 + i];
  return f;
}

CarCan::CarCan(const Dbc& dbc, const std::string& source) {
  // each of the car's messages by name, and its signals
  for (std::size_t k = 0; k < kKinds; ++k) {
    const MessageNeed& need = kCar[k];
    const DbcMessage* m = dbc.find(need.name);
    if (!m) throw std::invalid_argument(source + ": no message " + need.name + ", expected the car's messages");
    msg_[k] = Message{m->id, m->extended, m->dlc, {}};
    for (const Need& n : need.signals) {
      if (!n.signal) break;
      const DbcSignal* s = m->find(n.signal);
      const std::string what = "message " + m->name + ": ";
      if (!s) throw std::invalid_argument(source + ": " + what + "no signal " + n.signal);
      // its unit, range and step
      const std::string at = source + ":" + std::to_string(s->line) + ": " + what + "signal " + s->name + ": ";
      if (s->unit != n.unit) throw std::invalid_argument(at + "unit \"" + s->unit + "\", expected \"" + n.unit + "\"");
      if (n.bits != 0 && s->length != n.bits) {
        throw std::invalid_argument(at + "length " + std::to_string(s->length) + " bits, expected " +
                                    std::to_string(n.bits) + " (a counter mod " + std::to_string(1 << n.bits) + ")");
      }
      if (s->lowest() > n.lo || s->highest() < n.hi) {
        throw std::invalid_argument(at + "carries [" + params::number(s->lowest()) + ", " +
                                    params::number(s->highest()) + "], expected at least [" + params::number(n.lo) +
                                    ", " + params::number(n.hi) + "]");
      }
      if (n.integer ? s->factor != 1.0 || s->offset != 0.0 : std::abs(s->factor) > n.step) {
        throw std::invalid_argument(at + "factor " + params::number(s->factor) + " offset " +
                                    params::number(s->offset) +
                                    (n.integer ? ", expected factor 1 offset 0 (integer values)"
                                               : ", expected a step of " + params::number(n.step) + " or finer"));
      }
      msg_[k].signals.push_back(*s);
    }
  }
}

// one message's frame: each value into its signal, the ones that do not fit counted
CanFrame CarCan::frame(Kind k, TimeNs stamp, std::initializer_list<double> values) {
  const Message& m = msg_[k];
  CanFrame f{stamp, m.id, m.extended, m.dlc, {}};
  const DbcSignal* s = m.signals.data();
  for (const double v : values) {
    if (!(s++)->encode(v, f.data.data())) ++(std::isfinite(v) ? counters_.saturated : counters_.nonfinite);
  }
  ++counters_.encoded;
  return f;
}

std::vector<CanFrame> CarCan::encode(const Imu& m) {
  // both halves of the sample carry the same counter, the next sample the next
  const double counter = imu_counter_;
  imu_counter_ = static_cast<std::uint8_t>((imu_counter_ + 1) & kImuCounterMask);
  return {frame(kImuAccel, m.stamp, {m.ax, m.ay, m.az, counter}),
          frame(kImuRate, m.stamp, {m.roll_rate, m.pitch_rate, m.yaw_rate, counter})};
}

CanFrame CarCan::encode(const WheelSpeeds& m) {
  return frame(kWheels, m.stamp, {m.omega[0], m.omega[1], m.omega[2], m.omega[3]});
}

CanFrame CarCan::encode(const SteeringAngle& m) { return frame(kSteering, m.stamp, {m.angle}); }

CanFrame CarCan::encode(const ResSignal& m) {
  return frame(kRes, m.stamp, {m.go ? 1.0 : 0.0, m.emergency ? 1.0 : 0.0});
}

CanFrame CarCan::encode(const VcuStatus& m) {
  return frame(kVcuStatus, m.stamp,
               {m.asms_on ? 1.0 : 0.0, static_cast<double>(static_cast<int>(m.mission)), m.ebs_pressure,
                m.brake_pressure_front, m.brake_pressure_rear});
}

CanFrame CarCan::encode(const ActuatorCommand& m) {
  // a command that is no number fails safe: no drive, full brake (a NaN
  // brake sent as raw 0 would release it); still counted as non-finite
  const double throttle = std::isnan(m.throttle) ? 0.0 : m.throttle;
  const double brake = std::isnan(m.brake) ? 1.0 : m.brake;
  if (std::isnan(m.throttle)) ++counters_.nonfinite;
  if (std::isnan(m.brake)) ++counters_.nonfinite;
  return frame(kCommand, m.stamp,
               {m.steering_angle, throttle, brake, m.yaw_moment, static_cast<double>(static_cast<int>(m.as_state))});
}

void CarCan::push(const CanFrame& f) {
  ++counters_.frames;
  // which of the car's messages, and whole
  std::size_t k = 0;
  while (k < kKinds && !(msg_[k].id == f.id && msg_[k].extended == f.extended)) ++k;
  if (k == kKinds) {
    ++counters_.unknown_id;
    return;
  }
  if (f.dlc != msg_[k].dlc) {
    ++counters_.bad_dlc;
    return;
  }
  const auto v = [&](std::size_t i) { return msg_[k].signals[i].decode(f.data.data()); };
  switch (k) {
    case kRes:
      sensors_.push_back(ResSignal{f.stamp, v(0) != 0.0, v(1) != 0.0});
      ++counters_.res;
      break;
    case kCommand: {
      // AsState's raw value is the enum's (factor 1, offset 0): 0..4
      const double as = v(4);
      if (as < 0.0 || as > static_cast<double>(AsState::Emergency)) {
        ++counters_.bad_value;
        return;
      }
      commands_.push_back(ActuatorCommand{f.stamp, v(0), v(1), v(2), v(3), static_cast<AsState>(static_cast<int>(as))});
      ++counters_.commands;
      break;
    }
    case kImuAccel:
    case kImuRate:
      // the Counter's raw value is the counter (4 bits, factor 1, offset 0)
      imu_half(k - kImuAccel, static_cast<std::uint8_t>(msg_[k].signals[3].raw(f.data.data()) & kImuCounterMask),
               f.stamp, {v(0), v(1), v(2)});
      break;
    case kWheels:
      sensors_.push_back(WheelSpeeds{f.stamp, {v(0), v(1), v(2), v(3)}});
      ++counters_.wheel_speeds;
      break;
    case kSteering:
      sensors_.push_back(SteeringAngle{f.stamp, v(0)});
      ++counters_.steering;
      break;
    case kVcuStatus: {
      // Mission's raw value is the enum's (factor 1, offset 0)
      const double mission = v(1);
      if (mission < 0.0 || mission > static_cast<double>(MissionCode::Manual)) {
        ++counters_.bad_value;
        return;
      }
      sensors_.push_back(VcuStatus{f.stamp, v(0) != 0.0, static_cast<MissionCode>(static_cast<int>(mission)), v(2),
                                   v(3), v(4)});
      ++counters_.vcu_status;
      break;
    }
  }
}

// pairs the IMU's two frames by their counter (their stamps differ on the
// car): the waiting half pairs with the other half of the same counter; any
// other IMU frame (a later sample's, or a repeat of the waiting half) means
// the waiting half's partner is lost, and it is dropped for the new one
void CarCan::imu_half(std::size_t half, std::uint8_t counter, TimeNs stamp, const std::array<double, 3>& v) {
  if (imu_.waiting && imu_.half != half && imu_.counter == counter) {
    // the pair, stamped with its first half: accel ax, ay, az; rate roll, pitch, yaw
    imu_.waiting = false;
    const std::array<double, 3>& a = half == 0 ? v : imu_.v;
    const std::array<double, 3>& r = half == 0 ? imu_.v : v;
    sensors_.push_back(Imu{imu_.stamp, a[0], a[1], r[2], a[2], r[0], r[1]});
    ++counters_.imu;
    return;
  }
  if (imu_.waiting) ++counters_.unmatched_imu_halves;
  imu_ = ImuHalf{true, half, counter, stamp, v};
}

std::optional<SensorMessage> CarCan::pop_sensor() {
  if (sensors_.empty()) return std::nullopt;
  SensorMessage m = std::move(sensors_.front());
  sensors_.pop_front();
  return m;
}

std::optional<ActuatorCommand> CarCan::pop_command() {
  if (commands_.empty()) return std::nullopt;
  const ActuatorCommand c = commands_.front();
  commands_.pop_front();
  return c;
}

}  // namespace paddock::hal
