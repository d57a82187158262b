// a replay's second thread (car/read_ahead.h) against the reader and the
// pipeline run in place: it gives the reader's messages, in its order, with
// their bytes; the LiDAR pipeline's result it computed ahead for a scan is
// the one the pipeline gives on that scan with that odometry, bit for bit,
// and is refused for a scan or an odometry that differs in a bit; the
// reader's error comes after the messages before it; it stops at `until`,
// and when dropped half-way
#include "autonomy/car/read_ahead.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/car/car_log.h"
#include "autonomy/common/same_bits.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/ouster.h"
#include "tests/car/shipped_files.h"

namespace paddock::car {
namespace {

namespace fs = std::filesystem;

using testing::read;
using testing::shipped;

struct Owned {
  std::uint16_t channel = 0;
  std::uint64_t log_time = 0;
  std::vector<std::uint8_t> data;
};

// two pipeline results alike in every field
void expect_same(const perception::LidarResult& a, const perception::LidarResult& b) {
  EXPECT_EQ(a.ok, b.ok);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.stamp, b.stamp);
  EXPECT_EQ(a.corrected, b.corrected);
  ASSERT_EQ(a.cones.size(), b.cones.size());
  for (std::size_t i = 0; i < a.cones.size(); ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(same_bits(a.cones[i].centre[k], b.cones[i].centre[k])) << i;
    EXPECT_EQ(a.cones[i].color, b.cones[i].color) << i;
    EXPECT_EQ(a.cones[i].points, b.cones[i].points) << i;
  }
  ASSERT_EQ(a.free_range.size(), b.free_range.size());
  EXPECT_EQ(std::memcmp(a.free_range.data(), b.free_range.data(), a.free_range.size() * sizeof(float)), 0);
  EXPECT_EQ(a.counts.ground, b.counts.ground);
  EXPECT_EQ(a.counts.non_ground, b.counts.non_ground);
  EXPECT_EQ(a.counts.clusters, b.counts.clusters);
}

class ReadAheadTest : public ::testing::Test {
 protected:
  static constexpr int kRotations = 12;
  static constexpr TimeNs kRotation = 100'000'000;

  void SetUp() override {
    info_ = hal::ouster::parse_sensor_info(shipped("os2_32.json"), "os2_32.json");
    layout_ = hal::ouster::layout_of(info_, hal::LidarLayout{});
    dbc_ = hal::parse_dbc(shipped("paddock.dbc"), "paddock.dbc");
    perception_.use_camera = false;
    perception_.lidar.calibration = layout_;
    dir_ = fs::temp_directory_path() / ("paddock_read_ahead_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                        "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    path_ = (dir_ / "run.mcap").string();
    write_log();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // a drive's wires: the LiDAR's rotations (a ground ring and a few posts
  // in each, moving with the car) and the IMU's and wheels' CAN frames
  // of a car turning at 8 m/s
  void write_log() {
    CarLog log(path_, {}, {}, info_, layout_, 50'000'000, false);
    hal::CarCan can(dbc_, "paddock.dbc");
    const auto frame = [&log](const hal::CanFrame& f) {
      std::uint8_t bytes[hal::kSocketCanFrameSize];
      hal::to_socketcan(f, bytes);
      log.can_frame(f.stamp, true, bytes);
    };
    for (int r = 0; r < kRotations; ++r) {
      hal::ouster::RangeImage image = hal::ouster::make_range_image(info_, static_cast<std::uint16_t>(r), r * kRotation);
      const std::size_t beams = static_cast<std::size_t>(image.pixels_per_column);
      for (std::size_t c = 0; c < image.columns.size(); ++c) {
        for (std::size_t b = 0; b < beams; ++b) {
          hal::ouster::RangeImage::Pixel& px = image.pixels[c * beams + b];
          const double alt = info_.beam_altitude_angles[b] * M_PI / 180.0;
          // the ground 0.4 m below, to 30 m; a cone (0.3 m tall, 5 columns
          // wide) every 64 columns, 5-8 m away
          double range = alt < -0.01 ? std::min(0.4 / std::sin(-alt), 30.0) : 0.0;
          const double d = 5.0 + 0.2 * static_cast<double>((c / 64 + static_cast<std::size_t>(r)) % 16);
          const double z = 0.4 + d * std::tan(alt);
          if (c % 64 < 5 && z > 0.0 && z < 0.3) range = d / std::cos(alt);
          px.range_mm = static_cast<std::uint32_t>(range * 1000.0);
          px.signal = static_cast<std::uint16_t>(range > 0 ? 200 + (b * 97 + c) % 3000 : 0);
          px.reflectivity = static_cast<std::uint16_t>(b * 7 % 255);
        }
      }
      std::vector<std::uint8_t> packets;
      hal::ouster::encode(info_, image, packets);
      const std::size_t size = hal::ouster::packet_size(info_);
      const std::size_t n = packets.size() / size;
      std::size_t k = 0;
      for (TimeNs t = r * kRotation; t < (r + 1) * kRotation; t += 5'000'000) {
        // the packets of the columns fired by now, then the IMU (200 Hz) and wheels (100 Hz)
        for (; k < n && image.columns[k * info_.columns_per_packet].time <= t; ++k)
          log.lidar_packet(image.columns[k * info_.columns_per_packet].time, packets.data() + k * size, size);
        for (const hal::CanFrame& f : can.encode(hal::Imu{t, 0.1, 3.2, 0.4})) frame(f);
        if (t % 10'000'000 == 0) frame(can.encode(hal::WheelSpeeds{t, {34.6, 34.6, 34.6, 34.7}}));
      }
      for (; k < n; ++k)
        log.lidar_packet(image.columns[k * info_.columns_per_packet].time, packets.data() + k * size, size);
    }
    log.close();
  }

  std::vector<Owned> read_directly() {
    log::McapReader reader(std::make_unique<log::FileSource>(path_));
    reader.open();
    std::vector<Owned> out;
    log::McapReader::Messages messages = reader.messages();
    log::Message m;
    while (messages.next(m)) out.push_back({m.channel_id, m.log_time, {m.data, m.data + m.size}});
    return out;
  }

  AheadSetup setup(const log::McapReader& reader) const {
    AheadSetup s;
    for (const auto& [id, ch] : reader.channels()) {
      if (ch.topic == "/lidar/packets") s.packet_channels.insert(id);
      if (ch.topic == "/can/rx") s.can_channels.insert(id);
    }
    s.lidar = info_;
    s.layout = layout_;
    s.dbc = &dbc_;
    s.dbc_source = "paddock.dbc";
    s.perception = perception_;
    return s;
  }

  hal::ouster::SensorInfo info_;
  hal::LidarLayout layout_;
  hal::Dbc dbc_;
  perception::PerceptionParams perception_;
  fs::path dir_;
  std::string path_;
};

TEST_F(ReadAheadTest, GivesTheReadersMessagesAndThePipelinesResultsOnTheSameInputsOnly) {
  const std::vector<Owned> direct = read_directly();
  ASSERT_GT(direct.size(), 1000u);
  log::McapReader reader(std::make_unique<log::FileSource>(path_));
  reader.open();
  const AheadSetup s = setup(reader);
  ASSERT_EQ(s.packet_channels.size(), 1u);
  ASSERT_EQ(s.can_channels.size(), 1u);
  AheadLimits limits;
  limits.batch_bytes = 64 * 1024;  // many batches
  limits.max_batches = 1000;
  limits.max_computed = 1000;
  limits.leave_to_stack = 0;  // every scan ahead
  ReadAhead ahead(reader.messages(), std::numeric_limits<std::uint64_t>::max(), s, limits);

  // the stack's side: the car's decoders, the perception's odometry and pipeline
  hal::ouster::Decoder lidar(info_, layout_);
  hal::CarCan can(dbc_, "paddock.dbc");
  perception::Odometry odometry(perception_.odometry);
  perception::LidarPipeline pipeline(perception_.lidar);
  std::size_t i = 0;
  int scans = 0, with_cones = 0;
  log::Message m;
  while (ahead.next(m)) {
    ASSERT_LT(i, direct.size());
    const Owned& d = direct[i++];
    ASSERT_EQ(m.channel_id, d.channel);
    ASSERT_EQ(m.log_time, d.log_time);
    ASSERT_EQ(std::vector<std::uint8_t>(m.data, m.data + m.size), d.data) << "message " << i;
    if (s.can_channels.count(m.channel_id)) {
      can.push(*hal::from_socketcan(m.data, m.size, static_cast<TimeNs>(m.log_time)));
      while (std::optional<hal::SensorMessage> sm = can.pop_sensor()) {
        if (const auto* imu = std::get_if<hal::Imu>(&*sm)) odometry.add(*imu);
        if (const auto* w = std::get_if<hal::WheelSpeeds>(&*sm)) odometry.add(*w);
      }
      continue;
    }
    lidar.push(m.data, m.size);
    while (std::optional<hal::LidarScan> scan = lidar.pop()) {
      ++scans;
      const perception::LidarResult own = pipeline.process(*scan, &odometry);
      if (scans == 3) {
        // a point's x one bit off: not this scan's result
        hal::LidarScan other = *scan;
        float& x = other.points[other.points.size() / 2].x;
        x = std::nextafter(x, 1e9f);
        EXPECT_FALSE(ahead.take(other, odometry).has_value());
      } else if (scans == 5) {
        // an odometry one message on: not this scan's either
        perception::Odometry later = odometry;
        later.add(hal::Imu{scan->end + 1'000'000, 0.0, 0.0, 0.4});
        EXPECT_FALSE(ahead.take(*scan, later).has_value());
      } else {
        const std::optional<perception::LidarResult> r = ahead.take(*scan, odometry);
        ASSERT_TRUE(r.has_value()) << "scan " << scans;
        expect_same(*r, own);
        with_cones += r->cones.empty() ? 0 : 1;
      }
      // asked again, the same scan has no result left
      EXPECT_FALSE(ahead.take(*scan, odometry).has_value());
    }
  }
  EXPECT_EQ(i, direct.size());
  ASSERT_GE(scans, kRotations - 2);  // (the first rotation may be partial)
  EXPECT_GT(with_cones, 0);          // the posts were found: a pipeline that did its work
  const ReadAhead::Counters c = ahead.counters();
  EXPECT_EQ(c.computed, static_cast<std::uint64_t>(scans));
  EXPECT_EQ(c.taken, static_cast<std::uint64_t>(scans - 2));
  EXPECT_EQ(c.mismatched, 2u);
  EXPECT_EQ(c.not_ahead, static_cast<std::uint64_t>(scans));  // the second asks
  EXPECT_EQ(c.left, 0u);
  EXPECT_GT(c.batches, 10u);
}

TEST_F(ReadAheadTest, StopsAtTheFirstMessageAfterUntil) {
  const std::vector<Owned> direct = read_directly();
  const std::uint64_t until = direct[direct.size() / 2].log_time;
  std::size_t expected = 0;
  while (expected < direct.size() && direct[expected].log_time <= until) ++expected;
  ++expected;  // and the first after it
  log::McapReader reader(std::make_unique<log::FileSource>(path_));
  reader.open();
  ReadAhead ahead(reader.messages(), until, std::nullopt);
  std::size_t n = 0;
  log::Message m;
  while (ahead.next(m)) ++n;
  EXPECT_EQ(n, expected);
  EXPECT_FALSE(ahead.next(m));  // and stays at the end
}

TEST_F(ReadAheadTest, ThrowsTheReadersErrorAfterTheMessagesBeforeIt) {
  // a byte of the last chunk's data flipped: its CRC fails
  log::McapReader index(std::make_unique<log::FileSource>(path_));
  index.open();
  ASSERT_GE(index.chunk_indexes().size(), 2u);
  const log::ChunkIndex last = index.chunk_indexes().back();
  std::string bytes = read(path_);
  const std::size_t at = static_cast<std::size_t>(last.chunk_start_offset + last.chunk_length - 10);
  bytes[at] = static_cast<char>(bytes[at] ^ 0x40);
  const std::string bad = (dir_ / "bad.mcap").string();
  std::ofstream(bad, std::ios::binary) << bytes;

  std::size_t before = 0;
  std::string error;
  {
    log::McapReader reader(std::make_unique<log::FileSource>(bad));
    reader.open();
    log::McapReader::Messages messages = reader.messages();
    log::Message m;
    try {
      while (messages.next(m)) ++before;
    } catch (const log::McapError& e) {
      error = e.what();
    }
  }
  ASSERT_FALSE(error.empty()) << "the damaged chunk was read without an error";
  ASSERT_GT(before, 0u);
  log::McapReader reader(std::make_unique<log::FileSource>(bad));
  reader.open();
  AheadLimits small;
  small.batch_bytes = 16 * 1024;
  ReadAhead ahead(reader.messages(), std::numeric_limits<std::uint64_t>::max(), setup(reader), small);
  std::size_t n = 0;
  log::Message m;
  try {
    while (ahead.next(m)) ++n;
    ADD_FAILURE() << "no error after " << n << " messages";
  } catch (const log::McapError& e) {
    EXPECT_EQ(std::string(e.what()), error);
  }
  EXPECT_EQ(n, before);
}

TEST_F(ReadAheadTest, DroppedHalfWayItsThreadStops) {
  log::McapReader reader(std::make_unique<log::FileSource>(path_));
  reader.open();
  AheadLimits tight;
  tight.batch_messages = 8;
  tight.max_batches = 1;  // the thread waits for room at once
  {
    ReadAhead ahead(reader.messages(), std::numeric_limits<std::uint64_t>::max(), setup(reader), tight);
    log::Message m;
    for (int i = 0; i < 20; ++i) ASSERT_TRUE(ahead.next(m));
  }  // (a hang here is the failure)
  SUCCEED();
}

}  // namespace
}  // namespace paddock::car
