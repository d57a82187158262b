// [hal] transport = wire: what the car sends on its wires goes through their
// bytes (the LiDAR's UDP packets, the CAN frames as struct can_frame) and
// the car's own decoders. The stack then gets the LiDAR's scans bit for bit
// as with transport = memory (the simulated LiDAR reports what the packets
// carry: whole mm, 16-bit signal), the CAN sensors' values within half their
// DBC step, and the car the stack's command within half its step; a closed
// loop on either transport drives the same event to within the quantisation's
// butterfly effect.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <optional>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "autonomy/hal/can_udp.h"
#include "autonomy/hal/udp.h"
#include "sim/runner/files.h"
#include "sim/runner/model.h"
#include "sim/runner/raw_sensors.h"
#include "sim/runner/sim_hal.h"
#include "sim/runner/simulation.h"
#include "sim/world/cone_world.h"
#include "tests/runner/background.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

const std::string kRoot = PADDOCK_SOURCE_DIR;

struct OnTrack {
  Scenario scenario;
  world::TrackModel track;
};
// scenarios/fsg_2023_autocross_wire.ini on the memory transport: the car's
// sensors described by their hardware files (sensors/ouster.ini)
const OnTrack& autocross() {
  static const OnTrack s = [] {
    OnTrack out;
    out.scenario = load_scenario(kRoot + "/scenarios/fsg_2023_autocross_wire.ini", {"hal.transport=memory"});
    out.track = world::build_track(load_track_file(out.scenario.track_path));
    return out;
  }();
  return s;
}

std::unique_ptr<WireLink> wire_of(const Scenario& s) {
  return std::make_unique<WireLink>(s.lidar_info, s.lidar, *s.dbc, s.hal.dbc);
}

// sensors/ouster.ini describes the car's sensors by their hardware files,
// and the simulated LiDAR takes its layout from the metadata
TEST(Transport, TheOusterIncludeNamesItsLidarMetadataAndDbc) {
  const Scenario& s = autocross().scenario;
  ASSERT_TRUE(s.lidar_info.has_value());
  ASSERT_NE(s.dbc, nullptr);
  EXPECT_EQ(s.lidar.channels, 32);
  EXPECT_EQ(s.lidar.columns, 1024);
  EXPECT_TRUE(s.lidar.clockwise);
  EXPECT_EQ(s.lidar.range_resolution, 0.001);
  EXPECT_EQ(s.lidar.rate, 10.0);
  EXPECT_EQ(s.lidar.intensity_full_scale, 65535.0);
  // without it, the simulator's own fan (counter-clockwise, continuous ranges)
  const Scenario plain = load_scenario(kRoot + "/scenarios/fsg_2023_autocross.ini");
  EXPECT_FALSE(plain.lidar_info.has_value());
  EXPECT_FALSE(plain.lidar.clockwise);
  EXPECT_EQ(plain.lidar.range_resolution, 0.0);
}

// three rotations of a car driving a curve through the track's cones: the
// wire's scans are the memory's, every field of every point, to the bit
TEST(Transport, TheWireGivesTheStackTheLidarScansBitForBit) {
  const OnTrack& a = autocross();
  const SimModel model = compile_model(a.scenario, a.track);
  world::ConeWorld cones(model.cones, model.scenario.cones,
                         world::Footprint{-model.footprint.x_min, model.footprint.x_max, model.footprint.y_max});
  const Scenario& sc = model.scenario;
  RawSensors mem_raw(sc.lidar, sc.ground, model.blocks, std::nullopt, sc.detector, 11, 12, 13);
  RawSensors wire_raw(sc.lidar, sc.ground, model.blocks, std::nullopt, sc.detector, 11, 12, 13);
  SimHal mem(false);
  SimHal wire(false, wire_of(sc));
  PoseHistory poses(from_seconds(1.0));
  std::size_t points = 0, scans = 0;
  for (TimeNs now = 0; now <= from_seconds(0.3); now += 1000000) {
    // 12 m/s on a 25 m radius, from the start
    const double t = to_seconds(now), yaw = model.start.yaw + 12.0 * t / 25.0;
    poses.record(now, Pose2{model.start.x + 25.0 * (std::sin(yaw) - std::sin(model.start.yaw)),
                            model.start.y - 25.0 * (std::cos(yaw) - std::cos(model.start.yaw)), yaw});
    if (!mem_raw.rotation_ends(now)) continue;
    FaultInjector none(FaultsSection{}, 0);
    const std::vector<std::int32_t> truth_mem = mem_raw.emit(now, cones, poses, mem, none, to_seconds(now));
    const std::vector<std::int32_t> truth_wire = wire_raw.emit(now, cones, poses, wire, none, to_seconds(now));
    EXPECT_EQ(truth_mem, truth_wire);
    const std::optional<hal::SensorMessage> m = mem.receive(), w = wire.receive();
    ASSERT_TRUE(m && w);
    const auto* ms = std::get_if<hal::LidarScan>(&*m);
    const auto* ws = std::get_if<hal::LidarScan>(&*w);
    ASSERT_TRUE(ms && ws);
    EXPECT_EQ(ms->stamp, ws->stamp);
    EXPECT_EQ(ms->end, ws->end);
    ASSERT_EQ(ms->points.size(), ws->points.size());
    for (std::size_t i = 0; i < ms->points.size(); ++i) {
      const hal::LidarPoint& p = ms->points[i];
      const hal::LidarPoint& q = ws->points[i];
      ASSERT_TRUE(std::memcmp(&p.x, &q.x, sizeof p.x) == 0 && std::memcmp(&p.y, &q.y, sizeof p.y) == 0 &&
                  std::memcmp(&p.z, &q.z, sizeof p.z) == 0 &&
                  std::memcmp(&p.intensity, &q.intensity, sizeof p.intensity) == 0 && p.ring == q.ring && p.t == q.t)
          << "point " << i << ": (" << p.x << ", " << p.y << ", " << p.z << ", " << p.intensity << ") against ("
          << q.x << ", " << q.y << ", " << q.z << ", " << q.intensity << ")";
    }
    points += ms->points.size();
    ++scans;
  }
  EXPECT_EQ(scans, 3u);
  EXPECT_GT(points, 3u * 10000u);
  const WireCounters c = wire.wire()->counters();
  // 64 packets of 6464 bytes a rotation, none dropped
  EXPECT_EQ(c.lidar_packets, 3u * 64u);
  EXPECT_EQ(c.lidar_bytes, 3u * 64u * 6464u);
  EXPECT_EQ(c.lidar.rotations, 3u);
  EXPECT_EQ(c.lidar.bad_size + c.lidar.bad_columns + c.lidar.lost_columns + c.lidar.duplicate_columns, 0u);
}

// the CAN sensors within half their DBC step (the steps read from the DBC
// itself), the RES exactly, the command back within half its step; a NaN
// brake request reaches the car as a full brake
TEST(Transport, TheWireCarriesTheCanSensorsAndTheCommandWithinHalfAStep) {
  const Scenario& sc = autocross().scenario;
  const hal::Dbc& dbc = *sc.dbc;
  const auto step = [&dbc](const char* message, const char* signal) {
    const hal::DbcMessage* m = dbc.find(std::string(message));
    EXPECT_NE(m, nullptr) << message;
    const hal::DbcSignal* s = m ? m->find(signal) : nullptr;
    EXPECT_NE(s, nullptr) << signal;
    return s ? std::abs(s->factor) : 0.0;
  };
  SimHal wire(false, wire_of(sc));
  const hal::Imu imu{from_seconds(1.0), 3.21987, -17.0101, 0.412345, 9.80665, -0.0123456, 0.00098765};
  wire.post(imu);
  const hal::WheelSpeeds wheels{from_seconds(1.01), {101.2345, 99.87654, -3.1415, 0.0}};
  wire.post(wheels);
  const hal::SteeringAngle steer{from_seconds(1.02), -0.2345678};
  wire.post(steer);
  wire.post(hal::ResSignal{from_seconds(1.03), true, false});
  std::optional<hal::SensorMessage> m = wire.receive();
  ASSERT_TRUE(m && std::holds_alternative<hal::Imu>(*m));
  const hal::Imu& i = std::get<hal::Imu>(*m);
  EXPECT_EQ(i.stamp, imu.stamp);
  const double sa = step("IMU_Accel", "Ax"), sr = step("IMU_Rate", "YawRate");
  EXPECT_NEAR(i.ax, imu.ax, sa / 2 + 1e-12);
  EXPECT_NEAR(i.ay, imu.ay, sa / 2 + 1e-12);
  EXPECT_NEAR(i.az, imu.az, sa / 2 + 1e-12);
  EXPECT_NEAR(i.yaw_rate, imu.yaw_rate, sr / 2 + 1e-12);
  EXPECT_NEAR(i.roll_rate, imu.roll_rate, sr / 2 + 1e-12);
  EXPECT_NEAR(i.pitch_rate, imu.pitch_rate, sr / 2 + 1e-12);
  m = wire.receive();
  ASSERT_TRUE(m && std::holds_alternative<hal::WheelSpeeds>(*m));
  for (std::size_t k = 0; k < 4; ++k)
    EXPECT_NEAR(std::get<hal::WheelSpeeds>(*m).omega[k], wheels.omega[k], step("WheelSpeeds", "FL") / 2 + 1e-12);
  m = wire.receive();
  ASSERT_TRUE(m && std::holds_alternative<hal::SteeringAngle>(*m));
  EXPECT_NEAR(std::get<hal::SteeringAngle>(*m).angle, steer.angle, step("SteeringAngle", "Angle") / 2 + 1e-12);
  m = wire.receive();
  ASSERT_TRUE(m && std::holds_alternative<hal::ResSignal>(*m));
  EXPECT_TRUE(std::get<hal::ResSignal>(*m).go);
  EXPECT_FALSE(std::get<hal::ResSignal>(*m).emergency);
  EXPECT_FALSE(wire.receive().has_value());
  // the command, through the ACU's frame to the car's VCU
  const hal::ActuatorCommand c{from_seconds(1.04), 0.123456, 0.654321, 0.0, -234.56, hal::AsState::Driving};
  wire.send(c);
  ASSERT_TRUE(wire.command().has_value());
  const hal::ActuatorCommand& got = *wire.command();
  EXPECT_NEAR(got.steering_angle, c.steering_angle, step("ACU_Command", "SteeringAngleRequest") / 2 + 1e-12);
  EXPECT_NEAR(got.throttle, c.throttle, step("ACU_Command", "DriveTorqueRequest") / 2 + 1e-12);
  EXPECT_EQ(got.brake, 0.0);
  EXPECT_NEAR(got.yaw_moment, c.yaw_moment, step("ACU_Command", "YawMomentRequest") / 2 + 1e-12);
  EXPECT_EQ(got.as_state, hal::AsState::Driving);
  hal::ActuatorCommand bad = c;
  bad.brake = std::numeric_limits<double>::quiet_NaN();
  wire.send(bad);
  EXPECT_EQ(wire.command()->brake, 1.0);
  EXPECT_EQ(wire.command()->throttle, c.throttle > 0 ? wire.command()->throttle : 0.0);
  // and the truth still may not cross
  EXPECT_THROW(wire.post(hal::StateEstimate{}), std::logic_error);
}

// the same autocross on both transports: raw LiDAR and camera, FastSLAM and
// the graph. The runs part where the wire quantises (the CAN sensors, the
// command), so the lap differs by what that changes, not by a cone
// the car binary's first line: the ports it listens on
struct CarPorts {
  int lidar = 0, can = 0, objects = 0;
};
std::optional<CarPorts> ports_of(const std::optional<std::string>& line) {
  CarPorts p;
  if (!line || std::sscanf(line->c_str(), "paddock car: listening on %*[^:]: lidar udp %d, can udp %d, objects udp %d",
                           &p.lidar, &p.can, &p.objects) != 3)
    return std::nullopt;
  return p;
}

std::vector<std::string> car_ports(const CarPorts& p) {
  return {"car.lidar_port=" + std::to_string(p.lidar), "car.can_port=" + std::to_string(p.can),
          "car.objects_port=" + std::to_string(p.objects)};
}

// the closed loop on the three transports: memory and wire drive the same
// autocross to within the CAN quantisation's butterfly effect; udp, the
// stack in the car binary as a second process in lock-step (software in the
// loop), drives the wire's run to the bit: the same lap, energy, cones
TEST(Transport, TheThreeTransportsDriveTheSameAutocross) {
  const OnTrack& a = autocross();
  const std::string ac = kRoot + "/scenarios/fsg_2023_autocross_wire.ini";
  testing::Background car("car " + ac + " --set car.lidar_port=0 --set car.can_port=0 --set car.objects_port=0");
  const std::optional<CarPorts> ports = ports_of(car.line(120.0));
  ASSERT_TRUE(ports) << car.output();
  std::vector<std::string> sets = car_ports(*ports);
  sets.push_back("hal.transport=udp");
  const Scenario udp = load_scenario(ac, sets);
  std::future<RunResult> memory = std::async(std::launch::async, [&a] { return run(a.scenario, a.track); });
  std::future<RunResult> wired = std::async(std::launch::async, [&a] {
    Scenario wire = a.scenario;
    wire.hal.transport = Transport::Wire;
    return run(wire, a.track);
  });
  const RunResult u = run(udp, a.track);
  const int car_exit = car.wait(120.0);
  const RunResult m = memory.get(), w = wired.get();
  ASSERT_EQ(m.event.laps.size(), 1u);
  ASSERT_EQ(w.event.laps.size(), 1u);
  ASSERT_EQ(u.event.laps.size(), 1u) << car.output();
  const double tm = m.event.laps[0].time, tw = w.event.laps[0].time, tu = u.event.laps[0].time;
  std::printf("autocross: memory %.3f s, wire %.3f s (%+.2f %%), udp %.3f s; ATE rms %.3f / %.3f m; DOO %d / %d\n", tm,
              tw, 100.0 * (tw - tm) / tm, tu, m.slam.ate_rms, w.slam.ate_rms, m.event.doo, w.event.doo);
  EXPECT_TRUE(m.event.finished);
  EXPECT_TRUE(w.event.finished);
  EXPECT_EQ(w.event.doo, 0);
  EXPECT_EQ(w.event.oc, 0);
  EXPECT_NEAR(tw, tm, 0.02 * tm);
  EXPECT_LT(w.slam.ate_rms, 0.15);
  // the car binary's run is the in-process wire run
  EXPECT_TRUE(u.stack_remote);
  EXPECT_TRUE(u.event.finished) << u.event.dnf_reason;
  EXPECT_EQ(tu, tw);
  EXPECT_EQ(u.energy, w.energy);
  EXPECT_EQ(u.event.doo, w.event.doo);
  EXPECT_EQ(u.sim_time, w.sim_time);
  EXPECT_EQ(car_exit, 0) << car.output();
  const std::string out = car.output();
  EXPECT_NE(out.find("paddock car: done after " + std::to_string(u.cycles) + " control cycles, AS finished"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("fault    -"), std::string::npos) << out;
  EXPECT_NE(out.find("0 unknown id, 0 bad dlc, 0 unmatched IMU halves"), std::string::npos) << out;
}

// the car binary on its own clock (as on the car): a control cycle's command
// for every CAN datagram's sender; when the CAN bus goes silent for 0.1 s the
// watchdog puts it in AS Emergency with the brakes on, and SIGTERM stops it
// with its summary. Its log: read whole by the official MCAP reader, and
// replayed (at the cycles' own instants, off any grid) to the bit
TEST(Transport, TheCarBinarysWatchdogStopsACarWhoseBusWentSilent) {
  const std::string ac = kRoot + "/scenarios/fsg_2023_autocross_wire.ini";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("paddock_car_wall_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  testing::Background car("car " + ac +
                          " --set car.clock=wall --set car.lidar_port=0 --set car.can_port=0 --set car.objects_port=0"
                          " --log --out " + dir.string());
  const std::optional<CarPorts> ports = ports_of(car.line(120.0));
  ASSERT_TRUE(ports) << car.output();
  const Scenario sc = autocross().scenario;
  hal::CarCan vcu(*sc.dbc, sc.hal.dbc);
  hal::UdpSocket vcu_socket("127.0.0.1", 0);
  const sockaddr_in to = hal::UdpSocket::address("127.0.0.1", ports->can);
  // the commands that came back: their AS states, in order
  std::vector<hal::AsState> states;
  std::vector<std::uint8_t> buf;
  const auto take_commands = [&] {
    while (vcu_socket.receive(buf, 0)) {
      const std::optional<hal::CanDatagram> d = hal::decode_datagram(buf.data(), buf.size());
      ASSERT_TRUE(d);
      for (const hal::CanFrame& f : d->frames) vcu.push(f);
      while (const std::optional<hal::ActuatorCommand> c = vcu.pop_command()) states.push_back(c->as_state);
    }
  };
  // 0.5 s of wheel speeds at 100 Hz
  for (std::uint32_t k = 0; k < 50; ++k) {
    hal::CanDatagram d;
    d.sequence = k;
    d.frames.push_back(vcu.encode(hal::WheelSpeeds{0, {5.0, 5.0, 5.0, 5.0}}));
    const std::vector<std::uint8_t> bytes = hal::encode(d);
    vcu_socket.send_to(to, bytes.data(), bytes.size());
    take_commands();
    ::usleep(10'000);
  }
  // garbage on the CAN port and the LiDAR's: dropped and counted, the car drives on
  const std::uint8_t garbage[40] = {'P', 'D', 'K', 'C', 9};
  vcu_socket.send_to(to, garbage, sizeof garbage);
  vcu_socket.send_to(hal::UdpSocket::address("127.0.0.1", ports->lidar), garbage, sizeof garbage);
  const std::size_t while_alive = states.size();
  // then silence: the watchdog's fault. The car never showed AS Ready (no
  // VCU status, no plan): by the rules' state diagram it stays in AS Off,
  // brakes on, and the fault keeps it from ever getting Ready (a car that
  // was Ready goes to AS Emergency: tests/car/car_node_test.cc)
  for (int i = 0; i < 30; ++i) {
    ::usleep(10'000);
    take_commands();
  }
  car.signal(SIGTERM);
  EXPECT_EQ(car.wait(30.0), 0) << car.output();
  ASSERT_GT(while_alive, 10u) << "the car answered " << while_alive << " cycles while the bus was alive";
  for (const hal::AsState s : states) EXPECT_EQ(s, hal::AsState::Off);
  EXPECT_NE(car.output().find("fault    watchdog: no sensor frame on the CAN bus"), std::string::npos) << car.output();
  EXPECT_NE(car.output().find("AS off"), std::string::npos) << car.output();
  EXPECT_NE(car.output().find("can/udp  1 datagrams that were no CAN over UDP"), std::string::npos) << car.output();
  EXPECT_NE(car.output().find("1 packets of a wrong size"), std::string::npos) << car.output();

  const std::string log = (dir / "run.mcap").string();
  ASSERT_TRUE(std::filesystem::exists(log)) << car.output();
  const std::string modules = (std::filesystem::current_path() / "mcap-validator" / "node_modules").string();
  ASSERT_TRUE(std::filesystem::exists(std::filesystem::path(modules) / "@mcap" / "core"))
      << "the official MCAP reader is needed: run ./paddock test, which installs it into <build>/mcap-validator";
  const testing::Outcome read = testing::run_paddock_command("NODE_PATH='" + modules + "' node '" + kRoot +
                                                             "/tests/log/validate_mcap.mjs' '" + log + "' 2>&1");
  ASSERT_EQ(read.code, 0) << read.output;
  const nlohmann::json topics = nlohmann::json::parse(read.output).at("topics");
  EXPECT_EQ(topics.at("/can/rx").get<long>(), 50);
  const long cycles = topics.at("/stack/command").get<long>();
  EXPECT_EQ(topics.at("/can/tx").get<long>(), cycles);
  EXPECT_GE(static_cast<std::size_t>(cycles), states.size());
  const testing::Outcome replayed = testing::run_paddock("replay " + log);
  EXPECT_EQ(replayed.code, 0) << replayed.output;
  EXPECT_NE(replayed.output.find(std::to_string(cycles) + " compared with the log: all identical, bit for bit"),
            std::string::npos)
      << replayed.output;
  EXPECT_NE(replayed.output.find("watchdog    watchdog: no sensor frame on the CAN bus"), std::string::npos)
      << replayed.output;
  std::filesystem::remove_all(dir);
}

// what cannot work says so: no CAN interface of that name; a simulator whose
// car binary is not there; a port already taken
TEST(Transport, TheCarBinaryAndItsLinkSayWhatIsMissing) {
  const std::string ac = kRoot + "/scenarios/fsg_2023_autocross_wire.ini";
  const testing::Outcome no_bus =
      testing::run_paddock("car " + ac + " --set car.clock=wall --set car.can_interface=paddock_nocan0 --set car.lidar_port=0 --set car.objects_port=0");
  EXPECT_EQ(no_bus.code, 2);
  EXPECT_NE(no_bus.output.find("no CAN interface 'paddock_nocan0'"), std::string::npos) << no_bus.output;
  const testing::Outcome lockstep_bus = testing::run_paddock("car " + ac + " --set car.can_interface=can0");
  EXPECT_EQ(lockstep_bus.code, 2);
  EXPECT_NE(lockstep_bus.output.find("can_interface must be empty"), std::string::npos) << lockstep_bus.output;
  // a port nobody listens on (taken here, so nothing else has it)
  hal::UdpSocket taken("127.0.0.1", 0);
  const std::string port = std::to_string(taken.port());
  const testing::Outcome alone = testing::run_paddock("run " + ac + " --set hal.transport=udp --set car.can_port=" + port +
                                                      " --set car.peer_timeout=0.5 --out /tmp/paddock_sil_alone");
  EXPECT_EQ(alone.code, 2);
  EXPECT_NE(alone.output.find("gave no reply at t = 0.000 s within 0.5"), std::string::npos) << alone.output;
  const testing::Outcome busy = testing::run_paddock("car " + ac + " --set car.can_port=" + port);
  EXPECT_EQ(busy.code, 2);
  EXPECT_NE(busy.output.find("cannot listen on UDP 127.0.0.1:" + port), std::string::npos) << busy.output;
  // one car binary takes one simulation: a sweep on udp is refused before it runs
  const std::string sweep = (std::filesystem::temp_directory_path() / ("paddock_udp_sweep_" + port + ".ini")).string();
  std::ofstream(sweep) << "[sweep]\nscenarios = " << ac << "\n[vary]\ncontrol.stanley.k = 1, 2\n[hal]\ntransport = udp\n";
  const testing::Outcome swept = testing::run_paddock("sweep " + sweep + " --out /tmp/paddock_udp_sweep_" + port);
  EXPECT_EQ(swept.code, 2);
  EXPECT_NE(swept.output.find("a sweep runs many side by side"), std::string::npos) << swept.output;
}

// a wire run needs both files; a [lidar] key the metadata sets must agree with it
TEST(Transport, TheWireNeedsItsFilesAndTheMetadataOwnsTheLayout) {
  const std::string ac = kRoot + "/scenarios/fsg_2023_autocross_wire.ini";
  EXPECT_NO_THROW(load_scenario(ac, {"hal.transport=wire"}));
  try {
    load_scenario(ac, {"hal.dbc="});
    ADD_FAILURE() << "no DBC accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("[hal] dbc must name"), std::string::npos) << e.what();
  }
  try {
    load_scenario(ac, {"hal.lidar_metadata="});
    ADD_FAILURE() << "no LiDAR metadata accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("[hal] lidar_metadata must name"), std::string::npos) << e.what();
  }
  // the object-level cone sensor sends nothing on a wire: no metadata needed
  EXPECT_NO_THROW(load_scenario(ac, {"hal.lidar_metadata=", "autonomy.perception=ground_truth"}));
  try {
    load_scenario(ac, {"lidar.channels=64"});
    ADD_FAILURE() << "a contradicting [lidar] key accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("--set:1: [lidar] channels = 64 contradicts the metadata file"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(load_scenario(ac, {"lidar.channels=32", "lidar.rate=10"}));
  // a file that is no DBC or no metadata: its own line named, nothing run
  const testing::Outcome bad = testing::run_paddock("run " + ac + " --set hal.dbc=" + kRoot + "/README.md --out /tmp/paddock_bad_dbc");
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.output.find("README.md:1:"), std::string::npos) << bad.output;
  const testing::Outcome bad_json =
      testing::run_paddock("run " + ac + " --set hal.lidar_metadata=" + kRoot + "/scenarios/sensors/paddock.dbc --out /tmp/paddock_bad_json");
  EXPECT_NE(bad_json.code, 0);
  EXPECT_NE(bad_json.output.find("paddock.dbc:1:"), std::string::npos) << bad_json.output;
}

}  // namespace
}  // namespace paddock::runner
