// CAN on the wire with the shipped DBC (scenarios/sensors/paddock.dbc): the
// input is read as CAN-over-UDP datagrams (autonomy/hal/can_udp.h) and as
// SocketCAN frames; every frame that decodes goes into the car's codec, and
// whatever it makes of them is drained
#include <fstream>
#include <sstream>
#include <string>

#include "autonomy/hal/can_udp.h"
#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "fuzz/fuzz_target.h"

namespace {

const paddock::hal::Dbc& shipped() {
  static const paddock::hal::Dbc dbc = [] {
    const std::string path = paddock::fuzz::source_dir() + "/scenarios/sensors/paddock.dbc";
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return paddock::hal::parse_dbc(text.str(), path);
  }();
  return dbc;
}

void drain(paddock::hal::CarCan& can) {
  while (can.pop_sensor()) {
  }
  while (can.pop_command()) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  paddock::hal::CarCan can(shipped(), "paddock.dbc");
  // the whole input as one datagram
  std::string why;
  if (const auto d = paddock::hal::decode_datagram(data, size, &why)) {
    for (const paddock::hal::CanFrame& f : d->frames) can.push(f);
    drain(can);
    // what decodes must encode back to the same bytes' meaning
    const std::vector<std::uint8_t> again = paddock::hal::encode(*d);
    const auto d2 = paddock::hal::decode_datagram(again.data(), again.size());
    if (!d2 || d2->frames.size() != d->frames.size() || d2->kind != d->kind || d2->time != d->time) __builtin_trap();
  } else if (why.empty()) {
    __builtin_trap();  // a datagram refused says why
  }
  // and as 16-byte SocketCAN frames
  for (std::size_t at = 0; at + paddock::hal::kSocketCanFrameSize <= size; at += paddock::hal::kSocketCanFrameSize) {
    if (const auto f = paddock::hal::from_socketcan(data + at, paddock::hal::kSocketCanFrameSize, 0)) can.push(*f);
    drain(can);
  }
  return 0;
}
