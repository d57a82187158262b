#pragma once
// transport = udp: the simulator's end of the car's wires to a car binary
// (`paddock car`, autonomy/car/car.h) in lock-step. The LiDAR's packets go to
// its lidar_port as the sensor sends them, the VCU's CAN frames as CAN over
// UDP (hal/can_udp.h) to its can_port, the detector node's boxes as JSON
// (hal/json.h) to its objects_port; each control cycle is a tick datagram,
// answered by the car's command frame. The simulator waits for every answer:
// the car binary's stack sees what an in-process stack sees, at the same
// simulated instants, however long either side takes.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "autonomy/car/car.h"
#include "autonomy/hal/can_udp.h"
#include "autonomy/hal/udp.h"

namespace paddock::runner {

class CarLink {
 public:
  // a sync after this many LiDAR packets: the car takes them before more come
  static constexpr std::uint32_t kSyncEvery = 16;

  // a socket of its own (any interface, any free port); the car binary
  // listens on [car] host and its ports
  explicit CarLink(const car::CarParams& car);
  // tells the car binary the run is over (it prints its summary and exits)
  ~CarLink();
  CarLink(const CarLink&) = delete;
  CarLink& operator=(const CarLink&) = delete;

  void lidar_packet(TimeNs now, const std::uint8_t* data, std::size_t size);
  // one message's frames (an IMU sample is two) as one datagram
  void can_frames(TimeNs now, const std::vector<hal::CanFrame>& frames);
  void object(TimeNs now, const std::string& json);
  // the control cycle at `now` in the car binary: its command's frames.
  // Throws std::runtime_error when it does not answer within [car]
  // peer_timeout or answers out of turn
  std::vector<hal::CanFrame> tick(TimeNs now);

 private:
  void send(hal::CanDatagram& d);
  hal::CanDatagram await(hal::CanDatagram::Kind kind, TimeNs now);

  car::CarParams car_;
  hal::UdpSocket socket_;
  sockaddr_in lidar_{}, can_{}, objects_{};
  std::uint32_t sequence_ = 0, answers_ = 0, lidar_sent_ = 0, objects_sent_ = 0, lidar_unsynced_ = 0;
  std::vector<std::uint8_t> buf_;
};

}  // namespace paddock::runner
