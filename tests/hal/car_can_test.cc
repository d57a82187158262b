// the car's CAN: the shipped DBC parses and carries every HAL message to within
// half a step (exactly on the grid), saturates at its limits, pairs the IMU's
// two frames by their rolling counter (not their stamps, which differ on the
// car), counts what it drops, and refuses DBC files it cannot use, each error
// naming the file and line.
#include "autonomy/hal/car_can.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>

namespace paddock::hal {
namespace {

const std::string kSource = "paddock.dbc";

std::string shipped() {
  std::ifstream f(std::string(PADDOCK_SOURCE_DIR) + "/scenarios/sensors/paddock.dbc");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

CarCan car() { return CarCan(parse_dbc(shipped(), kSource), kSource); }

// the step of a signal of the shipped DBC
double step(const char* message, const char* signal) {
  static const Dbc dbc = parse_dbc(shipped(), kSource);
  return dbc.find(message)->find(signal)->factor;
}

// the one sensor message `can` has decoded, as T
template <class T>
T only_sensor(CarCan& can) {
  auto m = can.pop_sensor();
  EXPECT_TRUE(m.has_value());
  EXPECT_FALSE(can.pop_sensor().has_value());
  EXPECT_TRUE(m && std::holds_alternative<T>(*m));
  return m && std::holds_alternative<T>(*m) ? std::get<T>(*m) : T{};
}

// frames through the decoder
void push_all(CarCan& can, const std::vector<CanFrame>& frames) {
  for (const CanFrame& f : frames) can.push(f);
}

// the IMU counter an IMU_Accel or IMU_Rate frame carries, read with the
// shipped DBC's Counter signal
int counter(const CanFrame& f) {
  static const Dbc dbc = parse_dbc(shipped(), kSource);
  const DbcMessage* m = dbc.find(f.id, f.extended);
  EXPECT_TRUE(m && m->find("Counter")) << f.id;
  return m && m->find("Counter") ? static_cast<int>(m->find("Counter")->raw(f.data.data())) : -1;
}

// a frame as received at `stamp`
CanFrame received(CanFrame f, TimeNs stamp) {
  f.stamp = stamp;
  return f;
}

// ------------------------------------------------------------ the shipped DBC

TEST(CarCan, ShippedDbcParsesAndIsTheCars) {
  const Dbc dbc = parse_dbc(shipped(), kSource);
  EXPECT_EQ(dbc.nodes, (std::vector<std::string>{"VCU", "ACU"}));
  ASSERT_EQ(dbc.messages.size(), 7u);
  EXPECT_NE(dbc.comment.find("paddock's own car bus"), std::string::npos);
  // priorities: the RES first, the safety chain's status, then the command, then the sensors
  EXPECT_EQ(dbc.find("RES_Status")->id, 0x010u);
  EXPECT_EQ(dbc.find("VCU_Status")->id, 0x020u);
  EXPECT_EQ(dbc.find("ACU_Command")->id, 0x100u);
  EXPECT_EQ(dbc.find("IMU_Accel")->id, 0x180u);
  EXPECT_EQ(dbc.find("IMU_Rate")->id, 0x181u);
  EXPECT_EQ(dbc.find("WheelSpeeds")->id, 0x190u);
  EXPECT_EQ(dbc.find("SteeringAngle")->id, 0x1A0u);
  // both byte orders on the real bus; every message and signal commented
  EXPECT_EQ(dbc.find("SteeringAngle")->find("Angle")->order, ByteOrder::Motorola);
  EXPECT_EQ(dbc.find("IMU_Accel")->find("Az")->order, ByteOrder::Intel);
  // the IMU's two frames share a 4-bit rolling counter in their top bits
  for (const char* imu : {"IMU_Accel", "IMU_Rate"}) {
    const DbcSignal* c = dbc.find(imu)->find("Counter");
    ASSERT_NE(c, nullptr) << imu;
    EXPECT_EQ(c->start, 60) << imu;
    EXPECT_EQ(c->length, 4) << imu;
    EXPECT_EQ(c->order, ByteOrder::Intel) << imu;
    EXPECT_FALSE(c->is_signed) << imu;
    EXPECT_EQ(c->factor, 1.0) << imu;
    EXPECT_EQ(c->offset, 0.0) << imu;
    EXPECT_EQ(c->highest(), 15.0) << imu;
    EXPECT_NE(c->comment.find("mod 16"), std::string::npos) << imu;
  }
  for (const DbcMessage& m : dbc.messages) {
    EXPECT_FALSE(m.extended);
    EXPECT_FALSE(m.comment.empty()) << m.name;
    for (const DbcSignal& s : m.signals) EXPECT_FALSE(s.comment.empty()) << m.name << " " << s.name;
  }
  EXPECT_NO_THROW(CarCan(dbc, kSource));
}

// ------------------------------------------------------------ round trips

TEST(CarCan, EveryMessageRoundTripsWithinHalfAStep) {
  CarCan can = car();
  std::mt19937_64 rng(7);
  const auto u = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const double acc = step("IMU_Accel", "Ax"), rate = step("IMU_Rate", "YawRate"), wheel = step("WheelSpeeds", "FL"),
               steer = step("SteeringAngle", "Angle"), frac = step("ACU_Command", "BrakeRequest"),
               yaw = step("ACU_Command", "YawMomentRequest");
  for (int i = 0; i < 2000; ++i) {
    const TimeNs t = 1'000'000 * i + 17;
    // the racing car's range: 5 g, 5 rad/s, 300 rad/s, past the 0.52 rad lock
    const Imu imu{t, u(-49, 49), u(-49, 49), u(-5, 5), u(-49, 49), u(-5, 5), u(-5, 5)};
    push_all(can, can.encode(imu));
    const Imu im = only_sensor<Imu>(can);
    EXPECT_EQ(im.stamp, t);
    EXPECT_NEAR(im.ax, imu.ax, acc / 2 * (1 + 1e-9));
    EXPECT_NEAR(im.ay, imu.ay, acc / 2 * (1 + 1e-9));
    EXPECT_NEAR(im.az, imu.az, acc / 2 * (1 + 1e-9));
    EXPECT_NEAR(im.roll_rate, imu.roll_rate, rate / 2 * (1 + 1e-9));
    EXPECT_NEAR(im.pitch_rate, imu.pitch_rate, rate / 2 * (1 + 1e-9));
    EXPECT_NEAR(im.yaw_rate, imu.yaw_rate, rate / 2 * (1 + 1e-9));

    const WheelSpeeds ws{t, {u(-300, 300), u(-300, 300), u(-300, 300), u(-300, 300)}};
    can.push(can.encode(ws));
    const WheelSpeeds w = only_sensor<WheelSpeeds>(can);
    EXPECT_EQ(w.stamp, t);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(w.omega[k], ws.omega[k], wheel / 2 * (1 + 1e-9));

    const SteeringAngle sa{t, u(-0.6, 0.6)};
    can.push(can.encode(sa));
    EXPECT_NEAR(only_sensor<SteeringAngle>(can).angle, sa.angle, steer / 2 * (1 + 1e-9));

    const ResSignal res{t, i % 2 == 0, i % 3 == 0};
    can.push(can.encode(res));
    const ResSignal r = only_sensor<ResSignal>(can);
    EXPECT_EQ(r.stamp, t);
    EXPECT_EQ(r.go, res.go);
    EXPECT_EQ(r.emergency, res.emergency);

    // the EBS tank's 0..20 bar, the brake lines' 0..200 bar, every mission
    const double bar = step("VCU_Status", "EbsPressure");
    const VcuStatus vs{t, i % 2 == 1, static_cast<MissionCode>(i % 8), u(0, 20), u(0, 200), u(0, 200)};
    can.push(can.encode(vs));
    const VcuStatus st = only_sensor<VcuStatus>(can);
    EXPECT_EQ(st.stamp, t);
    EXPECT_EQ(st.asms_on, vs.asms_on);
    EXPECT_EQ(st.mission, vs.mission);
    EXPECT_NEAR(st.ebs_pressure, vs.ebs_pressure, bar / 2 * (1 + 1e-9));
    EXPECT_NEAR(st.brake_pressure_front, vs.brake_pressure_front, step("VCU_Status", "BrakePressureFront") / 2 * (1 + 1e-9));
    EXPECT_NEAR(st.brake_pressure_rear, vs.brake_pressure_rear, step("VCU_Status", "BrakePressureRear") / 2 * (1 + 1e-9));

    const ActuatorCommand cmd{t, u(-0.6, 0.6), u(0, 1), u(0, 1), u(-3000, 3000), static_cast<AsState>(i % 5)};
    can.push(can.encode(cmd));
    const auto c = can.pop_command();
    ASSERT_TRUE(c.has_value());
    EXPECT_FALSE(can.pop_command().has_value());
    EXPECT_EQ(c->stamp, t);
    EXPECT_NEAR(c->steering_angle, cmd.steering_angle, steer / 2 * (1 + 1e-9));
    EXPECT_NEAR(c->throttle, cmd.throttle, frac / 2 * (1 + 1e-9));
    EXPECT_NEAR(c->brake, cmd.brake, frac / 2 * (1 + 1e-9));
    EXPECT_NEAR(c->yaw_moment, cmd.yaw_moment, yaw / 2 * (1 + 1e-9));
    EXPECT_EQ(c->as_state, cmd.as_state);
  }
  const CarCanCounters& n = can.counters();
  EXPECT_EQ(n.imu, 2000u);
  EXPECT_EQ(n.commands, 2000u);
  EXPECT_EQ(n.vcu_status, 2000u);
  EXPECT_EQ(n.frames, 7u * 2000u);
  EXPECT_EQ(n.encoded, 7u * 2000u);
  EXPECT_EQ(n.saturated + n.nonfinite + n.unknown_id + n.bad_dlc + n.bad_value + n.unmatched_imu_halves, 0u);
}

TEST(CarCan, ValuesOnTheGridRoundTripExactly) {
  CarCan can = car();
  std::mt19937_64 rng(8);
  const auto k = [&](int n) { return static_cast<double>(static_cast<int>(rng() % (2 * n + 1)) - n); };
  const double acc = step("IMU_Accel", "Ax"), rate = step("IMU_Rate", "YawRate"), wheel = step("WheelSpeeds", "FL"),
               steer = step("SteeringAngle", "Angle"), frac = step("ACU_Command", "BrakeRequest"),
               yaw = step("ACU_Command", "YawMomentRequest");
  for (int i = 0; i < 500; ++i) {
    const Imu imu{
        i, k(490000) * acc, k(490000) * acc, k(500000) * rate, k(490000) * acc, k(500000) * rate, k(500000) * rate};
    push_all(can, can.encode(imu));
    const Imu im = only_sensor<Imu>(can);
    EXPECT_EQ(im.ax, imu.ax);
    EXPECT_EQ(im.ay, imu.ay);
    EXPECT_EQ(im.az, imu.az);
    EXPECT_EQ(im.roll_rate, imu.roll_rate);
    EXPECT_EQ(im.pitch_rate, imu.pitch_rate);
    EXPECT_EQ(im.yaw_rate, imu.yaw_rate);
    const WheelSpeeds ws{i, {k(30000) * wheel, k(30000) * wheel, k(30000) * wheel, k(30000) * wheel}};
    can.push(can.encode(ws));
    EXPECT_EQ(only_sensor<WheelSpeeds>(can).omega, ws.omega);
    const SteeringAngle sa{i, k(6000) * steer};
    can.push(can.encode(sa));
    EXPECT_EQ(only_sensor<SteeringAngle>(can).angle, sa.angle);
    const ActuatorCommand cmd{
        i, k(6000) * steer, std::abs(k(5000)) * frac, std::abs(k(5000)) * frac, k(30000) * yaw, AsState::Driving};
    can.push(can.encode(cmd));
    const auto c = can.pop_command();
    ASSERT_TRUE(c.has_value());
    EXPECT_EQ(c->steering_angle, cmd.steering_angle);
    EXPECT_EQ(c->throttle, cmd.throttle);
    EXPECT_EQ(c->brake, cmd.brake);
    EXPECT_EQ(c->yaw_moment, cmd.yaw_moment);
  }
  EXPECT_EQ(can.counters().saturated, 0u);
}

TEST(CarCan, OutOfRangeSaturatesAndNonFiniteIsCounted) {
  CarCan can = car();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  // the IMU: past the 20-bit range, +-inf
  push_all(can, can.encode(Imu{1, 100.0, -100.0, inf, 9.81, -inf, nan}));
  const Imu im = only_sensor<Imu>(can);
  EXPECT_DOUBLE_EQ(im.ax, 52.4287);
  EXPECT_DOUBLE_EQ(im.ay, -52.4288);
  EXPECT_DOUBLE_EQ(im.az, 9.81);
  EXPECT_DOUBLE_EQ(im.yaw_rate, 5.24287);
  EXPECT_DOUBLE_EQ(im.roll_rate, -5.24288);
  EXPECT_EQ(im.pitch_rate, 0.0);  // NaN: raw 0
  EXPECT_EQ(can.counters().saturated, 2u);
  EXPECT_EQ(can.counters().nonfinite, 3u);
  // the command: fractions to the DBC's [0|1], the rest to the raw range
  can.push(can.encode(ActuatorCommand{2, 10.0, 1.5, -0.5, -1e6, AsState::Emergency}));
  auto c = can.pop_command();
  ASSERT_TRUE(c.has_value());
  EXPECT_DOUBLE_EQ(c->steering_angle, 3.2767);
  EXPECT_EQ(c->throttle, 1.0);
  EXPECT_EQ(c->brake, 0.0);
  EXPECT_DOUBLE_EQ(c->yaw_moment, -3276.8);
  EXPECT_EQ(c->as_state, AsState::Emergency);
  EXPECT_EQ(can.counters().saturated, 6u);
  // a NaN command fails safe: no drive, full brake; raw 0 for the rest
  can.push(can.encode(ActuatorCommand{3, nan, nan, nan, nan, AsState::Driving}));
  c = can.pop_command();
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->steering_angle, 0.0);
  EXPECT_EQ(c->throttle, 0.0);
  EXPECT_EQ(c->brake, 1.0);
  EXPECT_EQ(c->yaw_moment, 0.0);
  EXPECT_EQ(can.counters().nonfinite, 7u);
  // wheels and steering at and past their ends
  can.push(can.encode(WheelSpeeds{4, {327.67, -327.68, 400.0, -400.0}}));
  const WheelSpeeds w = only_sensor<WheelSpeeds>(can);
  const double ends[4] = {327.67, -327.68, 327.67, -327.68};
  for (int k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(w.omega[k], ends[k]);
  can.push(can.encode(SteeringAngle{5, -4.0}));
  EXPECT_DOUBLE_EQ(only_sensor<SteeringAngle>(can).angle, -3.2768);
  EXPECT_EQ(can.counters().saturated, 9u);
}

// ------------------------------------------------------------ decoding

TEST(CarCan, ImuHalvesPairByCounter) {
  CarCan can = car();
  const std::vector<CanFrame> a = can.encode(Imu{100, 1, 2, 3, 4, 5, 6}),
                              b = can.encode(Imu{200, 7, 8, 0.9, 10, 1.1, 1.2});
  EXPECT_EQ(counter(a[0]), 0);
  EXPECT_EQ(counter(b[0]), 1);
  // in order, and the rate frame first
  push_all(can, {a[0], a[1]});
  EXPECT_EQ(only_sensor<Imu>(can).stamp, 100);
  push_all(can, {b[1], b[0]});
  const Imu im = only_sensor<Imu>(can);
  EXPECT_EQ(im.stamp, 200);
  EXPECT_DOUBLE_EQ(im.ax, 7.0);
  EXPECT_DOUBLE_EQ(im.ay, 8.0);
  EXPECT_DOUBLE_EQ(im.yaw_rate, 0.9);
  EXPECT_DOUBLE_EQ(im.az, 10.0);
  EXPECT_DOUBLE_EQ(im.roll_rate, 1.1);
  EXPECT_DOUBLE_EQ(im.pitch_rate, 1.2);
  EXPECT_EQ(can.counters().unmatched_imu_halves, 0u);
  // the counter pairs, not the stamp: halves of one stamp but two samples do not
  push_all(can, {a[0], received(b[1], 100)});
  EXPECT_FALSE(can.pop_sensor().has_value());
  EXPECT_EQ(can.counters().unmatched_imu_halves, 1u);
  can.push(b[0]);
  EXPECT_EQ(only_sensor<Imu>(can).stamp, 100);  // the waiting rate's stamp, the first half's
  EXPECT_EQ(can.counters().imu, 3u);
  // other messages keep their arrival order around the pair
  push_all(can, {a[0], can.encode(WheelSpeeds{100, {}}), a[1]});
  auto first = can.pop_sensor(), second = can.pop_sensor();
  ASSERT_TRUE(first && second);
  EXPECT_TRUE(std::holds_alternative<WheelSpeeds>(*first));
  EXPECT_TRUE(std::holds_alternative<Imu>(*second));
}

// the car's case: SocketCAN stamps each frame at its arrival, so the two
// halves of a sample differ by a fraction of a millisecond; the sender and the
// receiver are two CarCans (the VCU's and the stack's)
TEST(CarCan, ImuHalvesWithTheirOwnReceiveTimesPair) {
  CarCan vcu = car(), acu = car();
  const double acc = step("IMU_Accel", "Ax"), rate = step("IMU_Rate", "YawRate");
  constexpr TimeNs kPeriod = 5'000'000, kLatency = 100'000, kGap = 300'000;  // 200 Hz; the halves 0.3 ms apart
  for (int i = 0; i < 40; ++i) {  // past the counter's wrap, twice
    const TimeNs t = kPeriod * i;
    const Imu imu{t, 0.5 * i, -0.25 * i, 0.01 * i, 9.81, -0.02 * i, 0.03 * i};
    const std::vector<CanFrame> f = vcu.encode(imu);
    // the accel frame first, and every third sample the rate frame first
    const std::size_t one = i % 3 == 2 ? 1 : 0;
    acu.push(received(f[one], t + kLatency));
    EXPECT_FALSE(acu.pop_sensor().has_value()) << i;
    acu.push(received(f[1 - one], t + kLatency + kGap));
    const Imu im = only_sensor<Imu>(acu);
    EXPECT_EQ(im.stamp, t + kLatency) << i;  // the first half's receive time
    EXPECT_NEAR(im.ax, imu.ax, acc / 2 * (1 + 1e-9)) << i;
    EXPECT_NEAR(im.ay, imu.ay, acc / 2 * (1 + 1e-9)) << i;
    EXPECT_NEAR(im.az, imu.az, acc / 2 * (1 + 1e-9)) << i;
    EXPECT_NEAR(im.roll_rate, imu.roll_rate, rate / 2 * (1 + 1e-9)) << i;
    EXPECT_NEAR(im.pitch_rate, imu.pitch_rate, rate / 2 * (1 + 1e-9)) << i;
    EXPECT_NEAR(im.yaw_rate, imu.yaw_rate, rate / 2 * (1 + 1e-9)) << i;
  }
  EXPECT_EQ(acu.counters().imu, 40u);
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 0u);
  EXPECT_EQ(vcu.counters().encoded, 80u);
}

TEST(CarCan, StaleAndRepeatedImuHalvesAreDropped) {
  CarCan vcu = car(), acu = car();
  std::vector<std::vector<CanFrame>> s;  // sample i, counter i, measured at i ms
  for (int i = 0; i < 8; ++i) s.push_back(vcu.encode(Imu{1'000'000 * i, 1.0 * i, 0, 0, 0, 0, 0}));
  const auto at = [](const CanFrame& f, TimeNs extra) { return received(f, f.stamp + extra); };
  // a lost rate: accel 0 waits; accel 1, another counter, drops it and pairs with rate 1
  push_all(acu, {s[0][0], s[1][0], at(s[1][1], 300'000)});
  Imu im = only_sensor<Imu>(acu);
  EXPECT_EQ(im.stamp, 1'000'000);
  EXPECT_DOUBLE_EQ(im.ax, 1.0);
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 1u);
  // a lost accel, the rate waiting: rate 3 drops rate 2
  push_all(acu, {s[2][1], s[3][1], at(s[3][0], 300'000)});
  im = only_sensor<Imu>(acu);
  EXPECT_EQ(im.stamp, 3'000'000);
  EXPECT_DOUBLE_EQ(im.ax, 3.0);
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 2u);
  // a stale half, rate 3 again after accel 4: neither pairs; the stale one
  // waits until the next frame, rate 4, drops it (and rate 4 lost its accel)
  push_all(acu, {s[4][0], at(s[3][1], 100'000), at(s[4][1], 300'000)});
  EXPECT_FALSE(acu.pop_sensor().has_value());
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 4u);
  push_all(acu, {s[5][0], at(s[5][1], 300'000)});
  EXPECT_EQ(only_sensor<Imu>(acu).stamp, 5'000'000);
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 5u);
  // a repeat of the waiting half (the same counter, other values) replaces
  // it: the pair has the repeat's values and stamp
  CanFrame repeat = at(s[6][0], 200'000);
  const Dbc dbc = parse_dbc(shipped(), kSource);
  EXPECT_TRUE(dbc.find("IMU_Accel")->find("Ax")->encode(40.0, repeat.data.data()));
  EXPECT_EQ(counter(repeat), 6);
  push_all(acu, {s[6][0], repeat});
  EXPECT_FALSE(acu.pop_sensor().has_value());
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 6u);
  acu.push(at(s[6][1], 300'000));
  im = only_sensor<Imu>(acu);
  EXPECT_EQ(im.stamp, 6'200'000);
  EXPECT_DOUBLE_EQ(im.ax, 40.0);
  // a half repeated after its pair was made waits for a partner, and the next
  // sample's first half drops it
  push_all(acu, {s[7][0], s[7][1]});
  EXPECT_EQ(only_sensor<Imu>(acu).stamp, 7'000'000);
  acu.push(s[7][1]);
  EXPECT_FALSE(acu.pop_sensor().has_value());
  acu.push(vcu.encode(Imu{8'000'000, 0, 0, 0, 0, 0, 0})[0]);
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 7u);
  EXPECT_EQ(acu.counters().imu, 5u);
}

TEST(CarCan, ImuCounterCountsSamplesModSixteen) {
  CarCan vcu = car();
  std::vector<std::vector<CanFrame>> s;
  for (int i = 0; i < 35; ++i) {
    s.push_back(vcu.encode(Imu{i, 0, 0, 0, 0, 0, 0}));
    // one counter for both halves, one more per Imu, 15 -> 0
    EXPECT_EQ(counter(s.back()[0]), i % 16) << i;
    EXPECT_EQ(counter(s.back()[1]), i % 16) << i;
  }
  // other messages do not count; another CarCan counts its own, from 0
  vcu.encode(WheelSpeeds{35, {}});
  vcu.encode(SteeringAngle{35, 0.1});
  EXPECT_EQ(counter(vcu.encode(Imu{35, 0, 0, 0, 0, 0, 0})[0]), 35 % 16);
  CarCan other = car();
  EXPECT_EQ(counter(other.encode(Imu{36, 0, 0, 0, 0, 0, 0})[1]), 0);
  EXPECT_EQ(counter(vcu.encode(Imu{36, 0, 0, 0, 0, 0, 0})[1]), 36 % 16);
  // decoding across the wrap: 15 and then 0 are two samples
  CarCan acu = car();
  ASSERT_EQ(counter(s[15][0]), 15);
  ASSERT_EQ(counter(s[16][0]), 0);
  push_all(acu, {s[15][1], s[15][0], s[16][0], s[16][1]});
  EXPECT_EQ(std::get<Imu>(*acu.pop_sensor()).stamp, 15);
  EXPECT_EQ(only_sensor<Imu>(acu).stamp, 16);
  // a half of 15 does not pair with the other half of 0 (nor of 31, 16 later)
  push_all(acu, {s[15][0], s[16][1]});
  EXPECT_FALSE(acu.pop_sensor().has_value());
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 1u);
  push_all(acu, {s[31][0], s[16][1]});
  EXPECT_FALSE(acu.pop_sensor().has_value());
  EXPECT_EQ(acu.counters().unmatched_imu_halves, 3u);
}

TEST(CarCan, ForeignAndMalformedFramesAreCountedDrops) {
  CarCan can = car();
  CanFrame f = can.encode(WheelSpeeds{1, {1, 2, 3, 4}});
  CanFrame unknown = f, extended = f, short_frame = f;
  unknown.id = 0x7FF;
  extended.extended = true;  // 0x190 as a 29-bit id is another frame
  short_frame.dlc = 7;
  push_all(can, {unknown, extended, short_frame});
  CanFrame bad_state = can.encode(ActuatorCommand{});
  bad_state.data[7] = static_cast<std::uint8_t>(bad_state.data[7] | 0x70);  // AsState bits 60..62: raw 7
  can.push(bad_state);
  EXPECT_FALSE(can.pop_sensor().has_value());
  EXPECT_FALSE(can.pop_command().has_value());
  const CarCanCounters& n = can.counters();
  EXPECT_EQ(n.frames, 4u);
  EXPECT_EQ(n.unknown_id, 2u);
  EXPECT_EQ(n.bad_dlc, 1u);
  EXPECT_EQ(n.bad_value, 1u);
  can.push(f);
  EXPECT_EQ(only_sensor<WheelSpeeds>(can).omega, (std::array<double, 4>{1, 2, 3, 4}));
}

// ------------------------------------------------------------ SocketCAN

TEST(CarCan, SocketCanLayout) {
  CanFrame f{5, 0x1A0, false, 2, {0x12, 0x34}};
  std::uint8_t b[kSocketCanFrameSize];
  to_socketcan(f, b);
  const std::uint8_t want[16] = {0xA0, 0x01, 0, 0, 2, 0, 0, 0, 0x12, 0x34, 0, 0, 0, 0, 0, 0};
  for (int i = 0; i < 16; ++i) EXPECT_EQ(b[i], want[i]) << i;
  auto g = from_socketcan(b, sizeof b, 42);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->stamp, 42);
  EXPECT_EQ(g->id, 0x1A0u);
  EXPECT_FALSE(g->extended);
  EXPECT_EQ(g->dlc, 2);
  EXPECT_EQ(g->data, f.data);
  // an extended id: CAN_EFF_FLAG in bit 31
  f = CanFrame{0, 0x18FEF100, true, 8, {1, 2, 3, 4, 5, 6, 7, 8}};
  to_socketcan(f, b);
  EXPECT_EQ(b[3], 0x98);
  g = from_socketcan(b, sizeof b);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->id, 0x18FEF100u);
  EXPECT_TRUE(g->extended);
  EXPECT_EQ(g->data, f.data);
}

TEST(CarCan, SocketCanRefusesWhatIsNoDataFrame) {
  std::uint8_t b[17] = {};
  to_socketcan(CanFrame{0, 0x100, false, 8, {}}, b);
  EXPECT_TRUE(from_socketcan(b, 16).has_value());
  EXPECT_FALSE(from_socketcan(b, 15).has_value());  // truncated
  EXPECT_FALSE(from_socketcan(b, 17).has_value());  // oversized (a CAN FD frame is 72)
  EXPECT_FALSE(from_socketcan(b, 0).has_value());
  std::uint8_t flagged[16];
  for (const int flag : {0x40, 0x20}) {  // CAN_RTR_FLAG, CAN_ERR_FLAG (bits 30, 29)
    std::copy(b, b + 16, flagged);
    flagged[3] = static_cast<std::uint8_t>(flagged[3] | flag);
    EXPECT_FALSE(from_socketcan(flagged, 16).has_value()) << flag;
  }
  std::copy(b, b + 16, flagged);
  flagged[4] = 9;  // dlc
  EXPECT_FALSE(from_socketcan(flagged, 16).has_value());
  std::copy(b, b + 16, flagged);
  flagged[1] = 0x08;  // a standard id past 11 bits
  EXPECT_FALSE(from_socketcan(flagged, 16).has_value());
}

// ------------------------------------------------------------ refused DBC files

// the 1-based line of the shipped DBC that contains `pattern`
int line_of(const std::string& text, const std::string& pattern) {
  const std::size_t at = text.find(pattern);
  EXPECT_NE(at, std::string::npos) << pattern;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

// the shipped DBC with `from` replaced by `to`
std::string edited(const std::string& from, const std::string& to) {
  std::string t = shipped();
  const std::size_t at = t.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? t : t.replace(at, from.size(), to);
}

std::string error(const std::string& text) {
  try {
    CarCan(parse_dbc(text, kSource), kSource);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// each broken file is refused at the line that is wrong
TEST(CarCan, BadDbcFilesNameTheirLine) {
  const std::string t = shipped();
  const auto at = [&](const std::string& pattern) {
    return kSource + ":" + std::to_string(line_of(t, pattern)) + ": ";
  };
  // bad syntax
  EXPECT_EQ(error(edited("SG_ Ay : 20|20@1-", "SG_ Ay : 20|20@1*")).rfind(at("SG_ Ay :"), 0), 0u);
  EXPECT_EQ(error(edited("BO_ 400 WheelSpeeds:", "BO_ 400 WheelSpeeds")).rfind(at("BO_ 400 "), 0), 0u);
  // dlc 9
  EXPECT_EQ(error(edited("BO_ 384 IMU_Accel: 8", "BO_ 384 IMU_Accel: 9")),
            at("BO_ 384 ") + "message IMU_Accel: dlc 9, expected 0..8 (classic CAN)");
  // overlapping signals
  EXPECT_EQ(error(edited("SG_ Ay : 20|20", "SG_ Ay : 19|20")),
            at("SG_ Ay :") + "message IMU_Accel: signal Ay: overlaps signal Ax (line " +
                std::to_string(line_of(t, "SG_ Ax :")) + "), expected disjoint bits");
  // a signal past the frame: Motorola in a shortened message, Intel off the end
  EXPECT_EQ(error(edited("SteeringAngle: 2", "SteeringAngle: 1")),
            at("SG_ Angle :") +
                "message SteeringAngle: signal Angle: bits 7|16@0 run past the message's 1 bytes, expected them within "
                "the dlc");
  EXPECT_EQ(error(edited("SG_ RR : 48|16", "SG_ RR : 50|16"))
                .rfind(at("SG_ RR :") + "message WheelSpeeds: signal RR: bits 50|16@1 run past", 0),
            0u);
  // a duplicate id
  EXPECT_EQ(error(edited("BO_ 385 IMU_Rate", "BO_ 384 IMU_Rate")),
            at("BO_ 385 ") + "message IMU_Rate: id 0x180 already used by message IMU_Accel (line " +
                std::to_string(line_of(t, "BO_ 384 ")) + "), expected unique ids");
  // an unterminated string
  EXPECT_EQ(error(edited("0 \"Off\" ;", "0 \"Off ;")),
            at("VAL_ 256 ") + "unterminated string: expected a closing '\"' for a string in VAL_");
  EXPECT_EQ(
      error(edited("CM_ SG_ 400 FL \"Front left wheel speed, rad/s.\";", "CM_ SG_ 400 FL \"Front left wheel speed;")),
      at("CM_ SG_ 400 FR ") + "expected ';' to end CM_, found 'Front'");
}

// a DBC the parser takes but the car cannot use
TEST(CarCan, DbcWithoutTheCarsSignalsIsRefused) {
  const std::string t = shipped();
  const auto at = [&](const std::string& pattern) {
    return kSource + ":" + std::to_string(line_of(t, pattern)) + ": ";
  };
  // a missing signal (and its comment) or message
  std::string no_az = edited(" SG_ Az : 40|20@1- (0.0001,0) [-52.4288|52.4287] \"m/s^2\" ACU\n", "");
  no_az.replace(no_az.find("CM_ SG_ 384 Az"),
                no_az.find('\n', no_az.find("CM_ SG_ 384 Az")) - no_az.find("CM_ SG_ 384 Az"), "");
  EXPECT_EQ(error(no_az), "paddock.dbc: message IMU_Accel: no signal Az");
  // the IMU's counter, in either frame
  for (const std::string id : {"384", "385"}) {
    std::string no_counter = t;
    for (const std::string& pattern : {std::string(" SG_ Counter :"), "CM_ SG_ " + id + " Counter "}) {
      const std::size_t from = no_counter.find(pattern, id == "384" ? 0 : no_counter.find("BO_ 385 "));
      ASSERT_NE(from, std::string::npos) << pattern;
      no_counter.erase(from, no_counter.find('\n', from) + 1 - from);
    }
    EXPECT_EQ(error(no_counter),
              std::string("paddock.dbc: message ") + (id == "384" ? "IMU_Accel" : "IMU_Rate") + ": no signal Counter");
  }
  EXPECT_EQ(error(edited("BO_ 416 SteeringAngle:", "BO_ 416 SteerAngle:")),
            "paddock.dbc: no message SteeringAngle, expected the car's messages");
  // a unit, a range, a step it cannot carry the car's values in
  EXPECT_EQ(error(edited("[-52.4288|52.4287] \"m/s^2\" ACU\n SG_ Ay", "[-52.4288|52.4287] \"g\" ACU\n SG_ Ay")),
            at("SG_ Ax :") + "message IMU_Accel: signal Ax: unit \"g\", expected \"m/s^2\"");
  EXPECT_EQ(error(edited("SG_ FL : 0|16@1- (0.01,0) [-327.68|327.67]", "SG_ FL : 0|16@1- (0.01,0) [-200|200]")),
            at("SG_ FL :") + "message WheelSpeeds: signal FL: carries [-200, 200], expected at least [-300, 300]");
  EXPECT_EQ(error(edited("SG_ YawRate : 40|20@1- (1E-005,0)", "SG_ YawRate : 40|20@1- (0.01,0)")),
            at("SG_ YawRate :") +
                "message IMU_Rate: signal YawRate: factor 0.01 offset 0, expected a step of 0.001 or finer");
  EXPECT_EQ(error(edited("SG_ AsState : 60|3@1+ (1,0)", "SG_ AsState : 60|3@1+ (2,0)")),
            at("SG_ AsState :") +
                "message ACU_Command: signal AsState: factor 2 offset 0, expected factor 1 offset 0 (integer values)");
  // a counter of another length, unit or step (IMU_Accel's, the first)
  EXPECT_EQ(error(edited("SG_ Counter : 60|4@1+ (1,0) [0|15]", "SG_ Counter : 60|3@1+ (1,0) [0|7]")),
            at("SG_ Counter :") + "message IMU_Accel: signal Counter: length 3 bits, expected 4 (a counter mod 16)");
  EXPECT_EQ(error(edited("SG_ Counter : 60|4@1+ (1,0) [0|15] \"\"", "SG_ Counter : 60|4@1+ (1,0) [0|15] \"n\"")),
            at("SG_ Counter :") + "message IMU_Accel: signal Counter: unit \"n\", expected \"\"");
  EXPECT_EQ(error(edited("SG_ Counter : 60|4@1+ (1,0) [0|15]", "SG_ Counter : 60|4@1+ (2,0) [0|30]")),
            at("SG_ Counter :") +
                "message IMU_Accel: signal Counter: factor 2 offset 0, expected factor 1 offset 0 (integer values)");
}

}  // namespace
}  // namespace paddock::hal
