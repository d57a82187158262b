#pragma once
// CAN over UDP: paddock's framing of the car's CAN frames in UDP datagrams,
// for a computer with no CAN interface (CI; a simulator on another machine),
// and the channel that carries the simulated time when the simulator and the
// car binary run in lock-step. One datagram, all fields little-endian:
//
//   offset size
//    0     4   magic "PDKC"
//    4     1   version, 1
//    5     1   kind (CanDatagram::Kind)
//    6     2   n, the frames that follow, at most kMaxFrames
//    8     8   time: the sender's clock, ns (lock-step: the simulated time)
//   16     4   sequence: the datagram's number on its channel and direction, from 0
//   20     4   lidar_before: the LiDAR packets the sender sent before this datagram
//   24     4   objects_before: the object messages it sent before it
//   28     4   reserved, 0
//   32   24n   n frames: u64 stamp (ns: when the frame was received, or in
//              the simulator measured), then the 16 bytes of Linux's struct
//              can_frame (car_can.h)
//
// Lock-step (the simulator drives the time): data datagrams carry the
// sensors' frames; a sync asks the receiver to take the LiDAR packets and
// object messages counted (the sender waits for its ack before it sends
// more: the receiver's socket buffer never overflows); a tick asks it to run
// its control cycle at `time`, and the reply carries the cycle's frames (the
// actuator command); end says the run is over. The counts put the three
// channels (LiDAR packets, CAN, objects) back into the order they were sent
// in. Outside lock-step only data datagrams travel, with counts 0.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/hal/car_can.h"

namespace paddock::hal {

struct CanDatagram {
  enum class Kind : std::uint8_t { Data = 0, Tick = 1, Reply = 2, Sync = 3, Ack = 4, End = 5 };
  static constexpr std::size_t kHeaderSize = 32;
  static constexpr std::size_t kFrameSize = 24;
  // within one Ethernet frame's UDP payload (1472 bytes)
  static constexpr std::size_t kMaxFrames = 56;

  Kind kind = Kind::Data;
  TimeNs time = 0;
  std::uint32_t sequence = 0;
  std::uint32_t lidar_before = 0;
  std::uint32_t objects_before = 0;
  std::vector<CanFrame> frames;  // their stamps travel with them
};

const char* to_string(CanDatagram::Kind k);

// the datagram's bytes; throws std::invalid_argument for more than
// kMaxFrames frames
std::vector<std::uint8_t> encode(const CanDatagram& d);

// the datagram from n received bytes; nothing (and the reason in `why`) for
// bytes that are not one: a wrong magic, version or kind, a length that is
// not the header's frame count, a remote or error frame, a dlc over 8, a
// time or stamp past INT64_MAX
std::optional<CanDatagram> decode_datagram(const std::uint8_t* p, std::size_t n, std::string* why = nullptr);

}  // namespace paddock::hal
