// the Ouster LEGACY codec (autonomy/hal/ouster.h) on one rotation of the
// shipped OS2-32 (scenarios/sensors/os2_32.json: 32 pixels x 1024 columns, 64
// packets of 6464 bytes), 60 % of pixels with a return, a tenth of the
// columns off their nominal encoder count. Target: <= 0.3 ms each on one
// core (a rotation lasts 100 ms at 10 Hz).
//
// BM_OusterEncode: the image into its packets (the simulator's side).
// BM_OusterDecode: the packets into a LidarScan (the car's side): each
//   iteration rewrites the 64 x 16 frame_ids to the next frame (the decoder
//   drops a frame it has emitted) and pushes the 64 packets; the rotation is
//   emitted at its last column and popped.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/hal/ouster.h"

namespace {

using namespace paddock::hal;

ouster::SensorInfo shipped() {
  const std::string path = std::string(PADDOCK_SOURCE_DIR) + "/scenarios/sensors/os2_32.json";
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ouster::parse_sensor_info(ss.str(), path);
}

// a rotation: 60 % returns up to 100 m, random signal
ouster::RangeImage rotation(const ouster::SensorInfo& info) {
  ouster::RangeImage im = ouster::make_range_image(info, 0, 0);
  std::mt19937 rng(42);
  std::uniform_int_distribution<std::uint32_t> range(500, 100000), u16(0, 65535), pct(0, 99);
  for (auto& px : im.pixels) {
    px.range_mm = pct(rng) < 60 ? range(rng) : 0;
    px.signal = static_cast<std::uint16_t>(u16(rng));
    px.reflectivity = static_cast<std::uint16_t>(u16(rng));
    px.near_ir = static_cast<std::uint16_t>(u16(rng));
  }
  for (auto& col : im.columns) {
    if (pct(rng) < 10) col.encoder += 7;
  }
  return im;
}

void BM_OusterEncode(benchmark::State& state) {
  const ouster::SensorInfo info = shipped();
  const ouster::RangeImage im = rotation(info);
  std::vector<std::uint8_t> out;
  for (auto _ : state) {
    out.clear();
    ouster::encode(info, im, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["bytes"] = static_cast<double>(out.size());
}
BENCHMARK(BM_OusterEncode)->Unit(benchmark::kMicrosecond);

void BM_OusterDecode(benchmark::State& state) {
  const ouster::SensorInfo info = shipped();
  const LidarLayout layout = ouster::layout_of(info, LidarLayout{});
  std::vector<std::uint8_t> bytes;
  ouster::encode(info, rotation(info), bytes);
  const std::size_t size = ouster::packet_size(info);
  const std::size_t block = size / static_cast<std::size_t>(info.columns_per_packet);
  ouster::Decoder decoder(info, layout);
  std::uint16_t frame = 0;
  std::size_t points = 0;
  for (auto _ : state) {
    // the next frame's packets (frame_id at byte 10 of each azimuth block)
    ++frame;
    for (std::size_t at = 10; at < bytes.size(); at += block) std::memcpy(&bytes[at], &frame, sizeof frame);
    for (std::size_t at = 0; at < bytes.size(); at += size) decoder.push(bytes.data() + at, size);
    auto scan = decoder.pop();
    points = scan ? scan->points.size() : 0;
    benchmark::DoNotOptimize(scan);
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["rotations"] = static_cast<double>(decoder.counters().rotations);
}
BENCHMARK(BM_OusterDecode)->Unit(benchmark::kMicrosecond);

}  // namespace
