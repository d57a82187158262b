// writes the generated seeds of fuzz/corpus/ (the inputs no repo file is:
// packets, datagrams, logs), made by the project's own encoders:
//   cmake --build build --target fuzz_make_seeds && build/fuzz_make_seeds fuzz/corpus
// ouster_packets: packets of the shipped OS2-32 (os2_32.json) with a few
// returns, in the target's framing (0xffff + a whole packet): three of one
// rotation and the first of the next, and four with one cut short; can: a CAN-over-UDP datagram of the car's
// frames (IMU, wheels, steering, RES, command) and those frames as SocketCAN;
// mcap: a small log (two channels, a schema, metadata, an attachment),
// uncompressed and zstd, chunked small.
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/hal/can_udp.h"
#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/ouster.h"
#include "autonomy/log/mcap.h"

namespace {

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "%s: cannot write\n", path.c_str());
    std::exit(1);
  }
  std::printf("%s: %zu bytes\n", path.c_str(), bytes.size());
}

}  // namespace

int main(int argc, char** argv) {
  namespace hal = paddock::hal;
  namespace ouster = paddock::hal::ouster;
  namespace log = paddock::log;
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds CORPUS_DIR (its ouster_packets/, can/, mcap/ must exist)\n");
    return 2;
  }
  const std::string dir = argv[1];
  const std::string root = PADDOCK_SOURCE_DIR;

  // ouster_packets
  const ouster::SensorInfo info = ouster::parse_sensor_info(read(root + "/scenarios/sensors/os2_32.json"), "os2_32.json");
  ouster::RangeImage image = ouster::make_range_image(info, 7, 1000000000);
  for (std::size_t i = 0; i < image.pixels.size(); i += 97) {
    image.pixels[i].range_mm = static_cast<std::uint32_t>(1000 + 13 * i % 30000);
    image.pixels[i].reflectivity = static_cast<std::uint16_t>(i % 255);
  }
  std::vector<std::uint8_t> packets, next;
  ouster::encode(info, image, packets);
  ouster::encode(info, ouster::make_range_image(info, 8, 1100000000), next);
  const std::size_t ps = ouster::packet_size(info);
  // a payload in the target's framing: its 2-byte length (0xffff: a whole packet) and its bytes
  const auto frame = [](std::vector<std::uint8_t>& out, const std::vector<std::uint8_t>& from, std::size_t at,
                        std::size_t n, bool whole) {
    out.push_back(whole ? 0xff : static_cast<std::uint8_t>(n & 0xff));
    out.push_back(whole ? 0xff : static_cast<std::uint8_t>(n >> 8));
    out.insert(out.end(), from.begin() + static_cast<std::ptrdiff_t>(at), from.begin() + static_cast<std::ptrdiff_t>(at + n));
  };
  // three packets of frame 7, then the first of frame 8, which closes 7
  std::vector<std::uint8_t> two_frames, cut;
  for (std::size_t k = 0; k < 3; ++k) frame(two_frames, packets, k * ps, ps, true);
  frame(two_frames, next, 0, ps, true);
  // four packets of frame 7, the third cut to 100 bytes
  for (std::size_t k = 0; k < 4; ++k) frame(cut, packets, k * ps, k == 2 ? 100 : ps, false);
  write(dir + "/ouster_packets/two_frames", two_frames);
  write(dir + "/ouster_packets/cut_packet", cut);

  // can
  const hal::Dbc dbc = hal::parse_dbc(read(root + "/scenarios/sensors/paddock.dbc"), "paddock.dbc");
  hal::CarCan can(dbc, "paddock.dbc");
  hal::CanDatagram d;
  d.time = 5000000;
  d.sequence = 3;
  hal::Imu imu;
  imu.stamp = 5000000;
  imu.ax = 1.5;
  imu.ay = -2.0;
  imu.az = 9.81;
  imu.yaw_rate = 0.3;
  for (const hal::CanFrame& f : can.encode(imu)) d.frames.push_back(f);
  hal::WheelSpeeds w;
  w.stamp = 5000000;
  w.omega = {40.0, 40.0, 39.5, 39.5};
  d.frames.push_back(can.encode(w));
  hal::SteeringAngle s;
  s.stamp = 5000000;
  s.angle = 0.1;
  d.frames.push_back(can.encode(s));
  hal::ResSignal res;
  res.stamp = 5000000;
  d.frames.push_back(can.encode(res));
  hal::ActuatorCommand cmd;
  cmd.stamp = 5000000;
  d.frames.push_back(can.encode(cmd));
  write(dir + "/can/datagram", hal::encode(d));
  std::vector<std::uint8_t> socketcan;
  for (const hal::CanFrame& f : d.frames) {
    std::uint8_t b[hal::kSocketCanFrameSize];
    hal::to_socketcan(f, b);
    socketcan.insert(socketcan.end(), b, b + hal::kSocketCanFrameSize);
  }
  write(dir + "/can/socketcan", socketcan);

  // mcap
  for (const log::Compression c : {log::Compression::None, log::Compression::Zstd}) {
    std::vector<std::uint8_t> bytes;
    log::McapWriterOptions o;
    o.compression = c;
    o.chunk_size = 256;
    log::McapWriter wr(std::make_unique<log::MemorySink>(bytes), o);
    const std::uint16_t schema = wr.add_schema("foxglove.Log", "jsonschema", std::string("{\"type\":\"object\"}"));
    const std::uint16_t json = wr.add_channel(schema, "/log", "json", {{"k", "v"}});
    const std::uint16_t raw = wr.add_channel(0, "/can", "paddock.can_udp");
    for (std::uint32_t i = 0; i < 12; ++i) {
      wr.write(json, i, 1000u * (12u - i), 1000u * i, "{\"message\":\"m" + std::to_string(i) + "\"}");
      const std::vector<std::uint8_t> dg = hal::encode(d);
      wr.write(raw, i, 1000u * i, 1000u * i, dg.data(), dg.size());
    }
    wr.write_metadata("scenario", {{"track", "fsg_2023"}});
    log::Attachment a;
    a.name = "scenario.ini";
    a.media_type = "text/plain";
    a.data = {'[', 'a', ']'};
    wr.write_attachment(a);
    wr.close();
    write(dir + (c == log::Compression::Zstd ? "/mcap/log_zstd.mcap" : "/mcap/log_uncompressed.mcap"), bytes);
  }
  return 0;
}
