#pragma once
// the car binary's loop (`paddock car SCENARIO.ini`): the stack alone behind
// the car's sockets. The LiDAR's UDP packets come to lidar_port, the CAN bus
// through a SocketCAN interface (can_interface) or as CAN over UDP
// (hal/can_udp.h) on can_port, the object messages (hal/json.h: a detector
// node's boxes) as UDP datagrams on objects_port, the camera's frames from
// its V4L2 device (camera.h); the actuator command goes back on the bus. Two clocks:
//   lockstep  the simulator drives the time (paddock run with [hal]
//             transport = udp): the CAN channel's datagrams carry the
//             simulated time, and the car runs a control cycle when a tick
//             asks for one, after the LiDAR packets and object messages sent
//             before it (their counts travel in the datagram). The same
//             messages reach the stack in the same order at the same
//             instants as in the simulator's own process.
//   wall      the car: the computer's clock (CLOCK_REALTIME, ns; the LiDAR
//             synchronised to it by PTP), a control cycle every period, frames
//             stamped when received; commands go to the bus (CAN over UDP:
//             to whoever sent the last datagram).
// The watchdogs (car_node.h) turn a silent sensor into AS Emergency.
#include <csignal>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/car/car_log.h"
#include "autonomy/car/car_node.h"
#include "autonomy/common/params.h"

namespace paddock::car {

enum class Clock { Lockstep, Wall };

// [car]: the car binary's sockets and clock (the simulator's side of
// transport = udp sends to the same ports)
struct CarParams {
  std::string host = "127.0.0.1";
  // 0: any free port (the binary prints the ones it got)
  int lidar_port = 7502;  // the Ouster's default UDP destination
  int can_port = 7600;
  int objects_port = 7601;
  std::string can_interface;  // a SocketCAN interface (can0); empty: CAN over UDP
  std::string camera_device;  // a V4L2 camera (/dev/video0); empty: none
  Clock clock = Clock::Lockstep;
  // lock-step: how long either side waits for the other (wall time)
  double peer_timeout = 30.0;
  WatchdogParams watchdog;

  static constexpr params::Choice<Clock> kClocks[] = {{"lockstep", Clock::Lockstep}, {"wall", Clock::Wall}};
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(host), "the address the car binary listens on (and the simulator sends to, transport = udp)");
    v(PADDOCK_PARAM(lidar_port), {"", params::in(0, 65535), "UDP port of the LiDAR's packets (0: any free port)"});
    v(PADDOCK_PARAM(can_port), {"", params::in(0, 65535), "UDP port of CAN over UDP (0: any free port)"});
    v(PADDOCK_PARAM(objects_port), {"", params::in(0, 65535), "UDP port of the object messages: the detector node's boxes (0: any free port)"});
    v(PADDOCK_PARAM(can_interface), "the SocketCAN interface of the car's bus (e.g. can0); empty: CAN over UDP on can_port");
    v(PADDOCK_PARAM(camera_device), "the camera's V4L2 device (e.g. /dev/video0), streamed at [camera] width x height; empty: no camera (clock = wall only)");
    v(PADDOCK_PARAM(clock), kClocks, "lockstep: the simulator's time, carried in the CAN datagrams; wall: the computer's clock");
    v(PADDOCK_PARAM(peer_timeout), {"s", params::in(0.1, 3600.0), "lock-step: wall time either side waits for the other before it gives up"});
    v.section(PADDOCK_PARAM(watchdog), "the sensors' watchdogs: AS Emergency when one goes silent");
  }
  std::string check() const {
    if (clock == Clock::Lockstep && !can_interface.empty())
      return "clock = lockstep carries the time in CAN over UDP: can_interface must be empty";
    if (clock == Clock::Lockstep && !camera_device.empty())
      return "clock = lockstep takes the simulator's detector boxes, not a camera: camera_device must be empty";
    return "";
  }
};

struct CarSetup {
  stack::StackParams stack;
  stack::MissionSpec mission;
  std::optional<hal::ouster::SensorInfo> lidar;  // none: the stack reads no LiDAR
  hal::LidarLayout layout;
  const hal::Dbc* dbc = nullptr;
  std::string dbc_source;
  CarParams car;
  TimeNs control_period = 10'000'000;  // clock = wall
  int camera_width = 0, camera_height = 0;  // car.camera_device's image size
  // the car's log (car_log.h): none when empty; the files a reader needs,
  // the file's metadata, the estimate's poses at most this often
  std::string log_path;
  std::vector<CarLog::File> log_files;
  log::KeyValues log_metadata;
  TimeNs log_pose_period = 10'000'000;
};

// the ports the sockets got (a port asked as 0 gets a free one)
struct CarPorts {
  int lidar = 0, can = 0, objects = 0;  // can: 0 on SocketCAN
};

// runs the car until the simulator's end datagram (lock-step) or *stop turns
// non-zero (a signal handler sets it); prints a line once the sockets are
// open ("paddock car: listening ...", with the ports) and a summary at the
// end to `out`; the log (if asked) is closed and in place at the end, and
// when an error stops the car. Throws std::runtime_error when a socket cannot be opened (a
// busy port, no such CAN interface) or the lock-step peer breaks the protocol
// or goes silent for peer_timeout
void run_car(const CarSetup& setup, std::ostream& out, const volatile std::sig_atomic_t* stop);

}  // namespace paddock::car
