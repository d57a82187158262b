// the LiDAR's UDP packets (autonomy/hal/ouster.h Decoder) with the shipped
// metadata (scenarios/sensors/os2_32.json): the input is a stream of
// payloads, each a 2-byte little-endian length and that many bytes (most
// lengths a mutation makes are wrong: the decoder must count them, and a
// payload of the right length is read as columns). The rotations that come
// out must keep to the layout: rings in range, finite points.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "autonomy/hal/ouster.h"
#include "fuzz/fuzz_target.h"

namespace {

namespace ouster = paddock::hal::ouster;

const ouster::SensorInfo& shipped() {
  static const ouster::SensorInfo info = [] {
    const std::string path = paddock::fuzz::source_dir() + "/scenarios/sensors/os2_32.json";
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return ouster::parse_sensor_info(text.str(), path);
  }();
  return info;
}

void drain(ouster::Decoder& d, int rings) {
  while (const auto scan = d.pop()) {
    for (const paddock::hal::LidarPoint& p : scan->points) {
      if (static_cast<int>(p.ring) >= rings) __builtin_trap();
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) __builtin_trap();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const ouster::SensorInfo& info = shipped();
  // one decoder, reset for each input (its tables of the beams' angles, and
  // even a copy of them, cost more than most inputs)
  static const paddock::hal::LidarLayout layout = ouster::layout_of(info, paddock::hal::LidarLayout{});
  static ouster::Decoder d(info, layout);
  d.reset();
  const int rings = layout.channels;
  std::size_t at = 0;
  while (at + 2 <= size) {
    const std::size_t n = std::min<std::size_t>(data[at] | (data[at + 1] << 8), size - at - 2);
    at += 2;
    // a length of 0xffff stands for "one whole packet" (so that the fuzzer
    // reaches the column decoding without guessing the size)
    const std::size_t take = (data[at - 2] == 0xff && data[at - 1] == 0xff)
                                 ? std::min(ouster::packet_size(info), size - at)
                                 : n;
    d.push(data + at, take);
    at += take;
    drain(d, rings);
  }
  d.flush();
  drain(d, rings);
  return 0;
}
