// the car's log is the same file, byte for byte, whether its own thread
// encodes, compresses and writes it or the caller does: the same packets
// (and the clouds decoded from them), CAN frames, object messages, camera
// frames (JPEG-encoded by the log) and control cycles, in the same order
#include "autonomy/car/car_log.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/car/car_node.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/ouster.h"
#include "tests/car/shipped_files.h"

namespace paddock::car {
namespace {

using testing::read;
using testing::shipped;

TEST(CarLog, ItsThreadWritesTheSameBytesAsTheCaller) {
  const hal::ouster::SensorInfo info = hal::ouster::parse_sensor_info(shipped("os2_32.json"), "os2_32.json");
  const hal::LidarLayout layout = hal::ouster::layout_of(info, hal::LidarLayout{});
  const hal::Dbc dbc = hal::parse_dbc(shipped("paddock.dbc"), "paddock.dbc");
  stack::StackParams params;
  params.autonomy.planner = stack::PlannerMode::Oracle;
  stack::MissionSpec mission;
  mission.mission = stack::Mission::Trackdrive;
  for (int i = 0; i <= 10; ++i) mission.oracle_path.push_back({5.0 * i, 0.0});
  const CarNode node{params, mission, info, layout, dbc, "paddock.dbc", WatchdogParams{}};

  const std::string dir = (std::filesystem::temp_directory_path() / "paddock_car_log_test").string();
  std::filesystem::create_directories(dir);
  std::vector<std::string> files;
  // on the caller's thread; on the log's; on the log's with the frames lent
  // (hal::FrameLease), each rewritten while the log may still encode it
  for (const int variant : {0, 1, 2}) {
    const bool threaded = variant > 0, lent = variant == 2;
    const std::string path = dir + "/variant" + std::to_string(variant) + ".mcap";
    auto shared = std::make_shared<hal::SharedFrame>();
    CarLog log(path, {{"note.txt", "text/plain", "hello"}}, {{"k", "v"}}, info, layout, 50'000'000, threaded);
    const std::uint16_t own = log.channel("/own", "", "text");
    const TimeNs rotation = 100'000'000;
    for (int r = 0; r < 11; ++r) {  // two clouds (every fifth rotation)
      hal::ouster::RangeImage image = hal::ouster::make_range_image(info, static_cast<std::uint16_t>(r), r * rotation);
      for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        image.pixels[i].range_mm = static_cast<std::uint32_t>(1000 + (i * 37 + static_cast<std::size_t>(r)) % 20000);
        image.pixels[i].reflectivity = static_cast<std::uint16_t>(i % 255);
      }
      std::vector<std::uint8_t> packets;
      hal::ouster::encode(info, image, packets);
      const std::size_t size = hal::ouster::packet_size(info);
      for (std::size_t at = 0; at + size <= packets.size(); at += size)
        log.lidar_packet(r * rotation + static_cast<TimeNs>(at), packets.data() + at, size);
      for (int c = 0; c < 10; ++c) {
        const TimeNs t = r * rotation + c * 10'000'000;
        std::uint8_t frame[hal::kSocketCanFrameSize] = {static_cast<std::uint8_t>(c), 0, 0, 0, 8};
        frame[8] = static_cast<std::uint8_t>(r);
        log.can_frame(t, c % 2 == 0, frame);
        hal::ActuatorCommand command;
        command.stamp = t;
        command.steering_angle = 0.01 * c;
        command.throttle = 0.1 * r;
        log.cycle(t, command, node.stack());
        log.write(own, t, "cycle " + std::to_string(c));
      }
      hal::CameraFrame& f = hal::writable(shared).frame;
      f.rgb.clear();
      f.stamp = r * rotation;
      f.width = 64;
      f.height = 48;
      for (int p = 0; p < f.width * f.height * 3; ++p) f.rgb.push_back(static_cast<std::uint8_t>((p * 7 + r) % 256));
      if (lent) log.image(r * rotation + 1, hal::FrameLease(shared), 85);
      else log.image(r * rotation + 1, f, 85);
      log.image(r * rotation + 2, f.stamp, std::vector<std::uint8_t>{0xFF, 0xD8, 0xFF, 0xD9});
      hal::CameraDetections d;
      d.stamp = r * rotation;
      d.width = 64;
      d.height = 48;
      d.boxes.push_back({1.0, 2.0, 3.0, 4.0, ConeColor::Blue, 0.5});
      log.message(r * rotation + 3, d);
    }
    log.close();
    files.push_back(read(path));
  }
  ASSERT_GT(files[0].size(), 100'000u);  // the packets, two clouds, the images are in
  EXPECT_TRUE(files[0] == files[1]) << "the threaded log differs from the caller's (" << files[0].size() << " and "
                                    << files[1].size() << " bytes)";
  EXPECT_TRUE(files[0] == files[2]) << "the log of lent frames differs from the caller's (" << files[0].size()
                                    << " and " << files[2].size() << " bytes)";
}

}  // namespace
}  // namespace paddock::car
