// an honest HAL: every field of every message that crosses it is one a part of
// the car fills (sensor messages) or takes (the actuator command), so the
// simulator cannot hand the stack anything the hardware could not.
//
// The table below names, per message type, each field and the hardware behind
// it. Each entry is checked against the struct's actual number of fields (a
// C++17 aggregate-arity count: the most initialisers the type accepts in
// braces), so a field added without a row here fails; and the alternatives of
// hal::SensorMessage must be exactly the tabled sensor messages, so a new
// message type fails until it is tabled too. A field the car cannot fill
// (a simulator's annotation, a ground-truth id) has no honest row to add: it
// belongs on the simulator's side of the seam (sim/sensors).
#include "autonomy/hal/messages.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <variant>
#include <vector>

#include "autonomy/hal/hal.h"

namespace paddock::hal {
namespace {

// ------------------------------------------------------------- field counting

// converts to any field's type (only in unevaluated braces)
struct AnyField {
  template <class T>
  operator T() const;  // NOLINT: implicit on purpose
};

template <std::size_t>
using AnyFieldAt = AnyField;

// T{a_0, ..., a_(n-1)} is well-formed
template <class T, class Seq, class = void>
struct BracesTake : std::false_type {};
template <class T, std::size_t... I>
struct BracesTake<T, std::index_sequence<I...>, std::void_t<decltype(T{AnyFieldAt<I>{}...})>> : std::true_type {};

// the number of fields of an aggregate: the most initialisers its braces take
// (a std::array or an aggregate field takes one: AnyField converts to it
// whole, so no brace elision spreads it over several; a C array would take
// its length, and HAL messages have none)
template <class T, std::size_t N = 0>
constexpr std::size_t field_count() {
  static_assert(std::is_aggregate_v<T>, "a HAL message is a plain aggregate");
  static_assert(N <= 64, "no HAL message has this many fields");
  if constexpr (BracesTake<T, std::make_index_sequence<N + 1>>::value) {
    return field_count<T, N + 1>();
  } else {
    return N;
  }
}

// the counter itself, on structs of known size
struct Three {
  int a = 0;
  std::vector<double> b;
  std::array<float, 4> c{};
};
struct Nested {
  Three t;
  std::array<double, 2> d{};
  bool e = false;
};
struct Empty {};
static_assert(field_count<Three>() == 3);
static_assert(field_count<Nested>() == 3);
static_assert(field_count<Empty>() == 0);

// ------------------------------------------------------------- the table

// a field and the part of the car that fills it (or, for a command, takes it)
struct Field {
  const char* name;
  const char* hardware;
};

struct Message {
  std::type_index type;
  const char* name;
  std::size_t fields;         // counted
  std::vector<Field> table;   // named
};

template <class T>
Message message(const char* name, std::vector<Field> table) {
  return {std::type_index(typeid(T)), name, field_count<T>(), std::move(table)};
}

// what a sensor message carries, on the car
std::vector<Message> sensor_messages() {
  return {
      message<StateEstimate>("StateEstimate",
                             {{"stamp", "INS (GNSS + IMU): GNSS-disciplined time of the solution"},
                              {"pose", "INS: GNSS position, heading from the dual antenna / IMU fusion"},
                              {"vx", "INS: velocity, rotated into the base frame"},
                              {"vy", "INS: velocity, rotated into the base frame"},
                              {"yaw_rate", "INS: gyro"}}),
      message<ResSignal>("ResSignal", {{"stamp", "RES receiver frame on CAN: reception time"},
                                       {"go", "RES receiver: the go button"},
                                       {"emergency", "RES receiver: the emergency stop"}}),
      message<VcuStatus>("VcuStatus", {{"stamp", "VCU frame on CAN: sample time"},
                                       {"asms_on", "the autonomous system master switch, read by the VCU"},
                                       {"mission", "the mission selector (the AMI's switch), read by the VCU"},
                                       {"ebs_pressure", "the EBS tank's pressure sensor, via the VCU"},
                                       {"brake_pressure_front", "the front brake line's pressure sensor, via the VCU"},
                                       {"brake_pressure_rear", "the rear brake line's pressure sensor, via the VCU"}}),
      message<ConeDetections>("ConeDetections",
                              {{"stamp", "object-level perception node: its measurement time"},
                               {"cones", "object-level perception node: its cone list"},
                               {"free_range", "object-level perception node: its free-space boundary (the nearest non-cone obstacle per bearing)"}}),
      message<Imu>("Imu", {{"stamp", "IMU frame on CAN: the sensor's sample time"},
                           {"ax", "IMU accelerometer"},
                           {"ay", "IMU accelerometer"},
                           {"yaw_rate", "IMU gyro"},
                           {"az", "IMU accelerometer"},
                           {"roll_rate", "IMU gyro"},
                           {"pitch_rate", "IMU gyro"}}),
      message<WheelSpeeds>("WheelSpeeds", {{"stamp", "VCU frame on CAN: sample time"},
                                           {"omega", "four hall-effect wheel speed sensors, via the VCU"}}),
      message<SteeringAngle>("SteeringAngle", {{"stamp", "steering sensor frame on CAN: sample time"},
                                               {"angle", "steering angle sensor on the column, via the rack ratio"}}),
      message<LidarScan>("LidarScan", {{"stamp", "LiDAR packets: the first column's timestamp"},
                                       {"end", "LiDAR packets: the last column's timestamp"},
                                       {"points", "LiDAR packets: the returns"}}),
      message<CameraFrame>("CameraFrame", {{"stamp", "camera driver: the exposure's (trigger) time"},
                                           {"width", "camera driver: the image size"},
                                           {"height", "camera driver: the image size"},
                                           {"rgb", "camera driver: the debayered, undistorted pixels"}}),
      message<CameraDetections>("CameraDetections",
                                {{"stamp", "detector node: the stamp of the frame it ran on"},
                                 {"width", "detector node: the size of the frame it ran on"},
                                 {"height", "detector node: the size of the frame it ran on"},
                                 {"boxes", "detector node: the network's boxes"}}),
  };
}

// the parts of messages (element types of their vectors)
std::vector<Message> message_parts() {
  return {
      message<DetectedCone>("DetectedCone", {{"position", "object-level perception node: cone position"},
                                             {"color", "object-level perception node: cone class"},
                                             {"colour_from_camera", "perception node: which sensor decided the class"}}),
      message<LidarPoint>("LidarPoint", {{"x", "LiDAR packet: range along the beam's azimuth and elevation"},
                                         {"y", "LiDAR packet: range along the beam's azimuth and elevation"},
                                         {"z", "LiDAR packet: range along the beam's azimuth and elevation"},
                                         {"intensity", "LiDAR packet: calibrated reflectivity"},
                                         {"ring", "LiDAR packet: the channel (laser) id"},
                                         {"t", "LiDAR packet: the column's (firing) timestamp"}}),
      message<CameraBox>("CameraBox", {{"x_min", "detector node: the network's box"},
                                       {"y_min", "detector node: the network's box"},
                                       {"x_max", "detector node: the network's box"},
                                       {"y_max", "detector node: the network's box"},
                                       {"color", "detector node: the network's class"},
                                       {"confidence", "detector node: the network's score"}}),
  };
}

// what the actuator command asks of the car, and which part takes it
Message actuator_command() {
  return message<ActuatorCommand>("ActuatorCommand",
                                  {{"stamp", "VCU: the command's age, for its watchdog"},
                                   {"steering_angle", "steering actuator controller on CAN"},
                                   {"throttle", "inverters via the VCU: drive torque request"},
                                   {"brake", "brake actuator (service brake) controller on CAN"},
                                   {"yaw_moment", "inverters via the VCU: the left/right torque difference (torque vectoring)"},
                                   {"as_state", "VCU: the AS state machine, ASSIs and EBS"}});
}

// the types of the variant's alternatives, in order
template <class V, std::size_t... I>
std::vector<std::type_index> alternatives(std::index_sequence<I...>) {
  return {std::type_index(typeid(std::variant_alternative_t<I, V>))...};
}

void expect_tabled(const Message& m) {
  EXPECT_EQ(m.fields, m.table.size())
      << "hal::" << m.name << " has " << m.fields << " fields, the table names " << m.table.size()
      << ": a field crosses the HAL only when a part of the car fills it; table it with that part, or "
         "keep it on the simulator's side (sim/sensors)";
  std::set<std::string> names;
  for (const Field& f : m.table) {
    EXPECT_TRUE(names.insert(f.name).second) << "hal::" << m.name << "::" << f.name << " is tabled twice";
    EXPECT_FALSE(std::string(f.hardware).empty()) << "hal::" << m.name << "::" << f.name << " has no hardware";
  }
}

// ------------------------------------------------------------- the tests

TEST(Messages, EveryFieldOfASensorMessageHasAHardwareSource) {
  for (const Message& m : sensor_messages()) expect_tabled(m);
  for (const Message& m : message_parts()) expect_tabled(m);
}

TEST(Messages, EveryFieldOfTheActuatorCommandHasAHardwareTaker) { expect_tabled(actuator_command()); }

TEST(Messages, TheSensorMessagesAreExactlyTheTabledOnes) {
  const std::vector<std::type_index> alts =
      alternatives<SensorMessage>(std::make_index_sequence<std::variant_size_v<SensorMessage>>{});
  const std::vector<Message> tabled = sensor_messages();
  std::set<std::type_index> in_table;
  for (const Message& m : tabled) in_table.insert(m.type);
  for (std::size_t i = 0; i < alts.size(); ++i) {
    EXPECT_EQ(in_table.count(alts[i]), 1u)
        << "hal::SensorMessage's alternative " << i << " (" << alts[i].name() << ") is not in the table";
  }
  const std::set<std::type_index> in_variant(alts.begin(), alts.end());
  for (const Message& m : tabled) {
    EXPECT_EQ(in_variant.count(m.type), 1u) << "hal::" << m.name << " is tabled but not a SensorMessage";
  }
  EXPECT_EQ(alts.size(), tabled.size());
}

TEST(Messages, TheHalTakesSensorMessagesAndSendsActuatorCommands) {
  // the door's two sides are these types and no others
  static_assert(std::is_same_v<decltype(std::declval<Hal&>().receive()), std::optional<SensorMessage>>);
  static_assert(std::is_same_v<decltype(&Hal::send), void (Hal::*)(const ActuatorCommand&)>);
  SUCCEED();
}

// free_range_bin against its definition, bearing by bearing: bin i holds
// [-pi + i w, -pi + (i + 1) w), w = 2 pi / n, and a bearing k turns off the
// circle lands in the same bin as the bearing itself
TEST(Messages, FreeRangeBinsCoverTheCircleOnce) {
  for (std::size_t n : {1u, 4u, 360u, 1000u}) {
    const double w = 2.0 * kPi / static_cast<double>(n);
    for (int j = 0; j < 3600; ++j) {
      const double b = -kPi + (j + 0.5) * 2.0 * kPi / 3600.0;
      const std::size_t i = free_range_bin(b, n);
      ASSERT_LT(i, n);
      EXPECT_LE(-kPi + static_cast<double>(i) * w, b + 1e-12) << n << " " << b;
      EXPECT_GT(-kPi + static_cast<double>(i + 1) * w, b - 1e-12) << n << " " << b;
      EXPECT_EQ(free_range_bin(b + 2.0 * kPi, n), i);
      EXPECT_EQ(free_range_bin(b - 4.0 * kPi, n), i);
    }
    EXPECT_EQ(free_range_bin(kPi, n), 0u) << "pi is -pi";
    EXPECT_EQ(free_range_bin(std::nan(""), n), 0u);
  }
  EXPECT_EQ(free_range_bin(1.0, 0), 0u);
}

}  // namespace
}  // namespace paddock::hal
