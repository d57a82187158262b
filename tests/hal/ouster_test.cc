// the Ouster LEGACY codec (autonomy/hal/ouster.h) against independent figures:
// the shipped metadata's layout against the layout defaults' own expressions,
// every bad metadata's file:line, packet bytes written at the manual's byte
// offsets by hand and points from the manual's "Lidar Range to XYZ" formula
// in Ouster's frame turned 180 deg, a full rotation bit for bit against
// beam_point of the layout, and the assembly under lost, duplicated,
// reordered, late, partial, malformed and random packets.
#include "autonomy/hal/ouster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace paddock::hal::ouster {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

const std::string kShipped = std::string(PADDOCK_SOURCE_DIR) + "/scenarios/sensors/os2_32.json";

// an OS1-64-like calibration on 4 pixels, altitudes out of order: rings
// (ascending) are pixels 1, 3, 0, 2
SensorInfo tiny(int columns = 64) {
  SensorInfo s;
  s.prod_line = "OS-1-64-U02";
  s.prod_sn = "122201000998";
  s.build_rev = "v2.3.0";
  s.columns_per_frame = columns;
  s.frequency = 10.0;
  s.pixels_per_column = 4;
  s.columns_per_packet = 16;
  s.column_window = {0, columns - 1};
  s.beam_altitude_angles = {2.0, -16.084, 16.611, -5.468};
  s.beam_azimuth_angles = {3.164, 1.055, -1.055, -3.164};
  s.lidar_origin_to_beam_origin_mm = 12.163;
  s.pixel_shift_by_row = {6, 2, -2, -6};
  return s;
}

// the same points, bit for bit
void expect_same(const LidarScan& a, const LidarScan& b) {
  EXPECT_EQ(a.stamp, b.stamp);
  EXPECT_EQ(a.end, b.end);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const LidarPoint &p = a.points[i], &q = b.points[i];
    ASSERT_TRUE(std::memcmp(&p.x, &q.x, 3 * sizeof(float)) == 0 && p.intensity == q.intensity && p.ring == q.ring &&
                p.t == q.t)
        << "point " << i;
  }
}

// a rotation of random returns (~60 % of pixels), intensities and encoder
// jitter on a tenth of the columns
RangeImage random_image(const SensorInfo& info, std::uint16_t frame, std::mt19937& rng, TimeNs t0 = 0) {
  RangeImage im = make_range_image(info, frame, t0);
  std::uniform_int_distribution<std::uint32_t> range(1, 200000), u16(0, 65535), pct(0, 99), jitter(1, 40);
  for (auto& px : im.pixels) {
    const std::uint32_t roll = pct(rng);
    px.range_mm = roll < 60 ? range(rng) : roll < 61 ? 0x1FFFFFu : 0;
    px.signal = static_cast<std::uint16_t>(u16(rng));
    px.reflectivity = static_cast<std::uint16_t>(u16(rng));
    px.near_ir = static_cast<std::uint16_t>(u16(rng));
  }
  for (auto& col : im.columns) {
    if (pct(rng) < 10) col.encoder += jitter(rng);
  }
  return im;
}

// what the wire carries of an image: ranges clamped to 20 bits
RangeImage wire(RangeImage im) {
  for (auto& px : im.pixels) px.range_mm = std::min(px.range_mm, 0xFFFFFu);
  return im;
}

// the image's packets
std::vector<Bytes> packets_of(const SensorInfo& info, const RangeImage& im) {
  Bytes all;
  encode(info, im, all);
  const std::size_t size = packet_size(info);
  std::vector<Bytes> out;
  for (std::size_t at = 0; at < all.size(); at += size)
    out.emplace_back(all.begin() + static_cast<std::ptrdiff_t>(at),
                     all.begin() + static_cast<std::ptrdiff_t>(at + size));
  return out;
}

std::vector<LidarScan> drain(Decoder& d) {
  std::vector<LidarScan> out;
  while (auto s = d.pop()) out.push_back(std::move(*s));
  return out;
}

void push_all(Decoder& d, const std::vector<Bytes>& packets) {
  for (const Bytes& p : packets) d.push(p.data(), p.size());
}

// writes v's `bytes` low bytes at `at`, little-endian, byte by byte
void le(Bytes& b, std::size_t at, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint64_t read_le(const Bytes& b, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(b[at + static_cast<std::size_t>(i)]) << (8 * i);
  return v;
}

// ------------------------------------------------------------------ metadata

TEST(OusterMetadata, ShippedFileGivesTheDefaultFan) {
  const SensorInfo info = parse_sensor_info(read_text(kShipped), kShipped);
  EXPECT_EQ(info.prod_line, "OS-2-32-U0");
  EXPECT_EQ(info.columns_per_frame, 1024);
  EXPECT_EQ(info.frequency, 10.0);
  EXPECT_EQ(info.pixels_per_column, 32);
  EXPECT_EQ(packet_size(info), 6464u);  // 16 x (16 + 12 x 32 + 4)
  LidarLayout mounting;
  mounting.mount_x = 1.25;
  mounting.mount_z = 0.4;
  mounting.clockwise = false;
  mounting.beam_origin = 0.5;
  const LidarLayout l = layout_of(info, mounting);
  EXPECT_EQ(l.mount_x, 1.25);
  EXPECT_EQ(l.mount_z, 0.4);
  EXPECT_EQ(l.channels, 32);
  EXPECT_EQ(l.columns, 1024);
  EXPECT_EQ(l.elevation_min, -8.0 * kPi / 180.0);
  EXPECT_EQ(l.elevation_max, 7.5 * kPi / 180.0);
  ASSERT_EQ(l.beam_elevation.size(), 32u);
  EXPECT_EQ(l.beam_elevation[16], 0.0);
  const LidarLayout fan;  // the even fan the file carries
  for (int j = 0; j < 32; ++j) EXPECT_NEAR(ring_elevation(l, j), ring_elevation(fan, j), 1e-15) << j;
  EXPECT_TRUE(l.beam_azimuth.empty());
  EXPECT_EQ(l.beam_origin, 0.0);
  EXPECT_TRUE(l.clockwise);
  EXPECT_EQ(l.range_resolution, 0.001);
  EXPECT_EQ(l.intensity_full_scale, 65535.0);
  EXPECT_EQ(l.check(), "");
  // the top beam first: pixel 0 is ring 31
  const std::vector<int> ring = ring_of_pixel(info);
  EXPECT_EQ(ring.front(), 31);
  EXPECT_EQ(ring.back(), 0);
  EXPECT_EQ(azimuth_offset(info), 0.0);
}

TEST(OusterMetadata, RoundTripsThroughJson) {
  const SensorInfo shipped = parse_sensor_info(read_text(kShipped), kShipped);
  EXPECT_EQ(parse_sensor_info(to_json(shipped), "x.json"), shipped);
  // odd numbers and a turned lidar frame survive too
  SensorInfo s = tiny(512);
  s.frequency = 20.0;
  s.beam_altitude_angles[0] = 0.1 + 0.2;
  s.lidar_to_sensor_transform = {0, -1, 0, 1.5, 1, 0, 0, -2.25, 0, 0, 1, 36.18, 0, 0, 0, 1};
  s.column_window = {500, 20};
  const SensorInfo back = parse_sensor_info(to_json(s), "x.json");
  EXPECT_EQ(back, s);
  EXPECT_EQ(back.beam_altitude_angles[0], 0.1 + 0.2);
  SensorInfo other = s;
  other.pixel_shift_by_row[3] = 0;
  EXPECT_NE(other, s);
}

TEST(OusterMetadata, NestedFormReadsAsTheFlat) {
  const SensorInfo s = tiny(512);
  const std::string text = R"({
  "sensor_info": {"prod_line": "OS-1-64-U02", "prod_sn": "122201000998", "build_rev": "v2.3.0", "status": "RUNNING"},
  "beam_intrinsics": {"beam_altitude_angles": [2.0, -16.084, 16.611, -5.468],
                      "beam_azimuth_angles": [3.164, 1.055, -1.055, -3.164],
                      "lidar_origin_to_beam_origin_mm": 12.163},
  "lidar_intrinsics": {"lidar_to_sensor_transform": [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]},
  "imu_intrinsics": {"imu_to_sensor_transform": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]},
  "lidar_data_format": {"pixels_per_column": 4, "columns_per_packet": 16, "columns_per_frame": 512,
                        "column_window": [0, 511], "pixel_shift_by_row": [6, 2, -2, -6]},
  "config_params": {"lidar_mode": "512x10", "udp_profile_lidar": "LEGACY"}
})";
  EXPECT_EQ(parse_sensor_info(text, "n.json"), s);
  // its profile and missing sections are checked as the flat form's
  std::string rng = text;
  rng.replace(rng.find("\"LEGACY\""), 8, "\"RNG19_RFL8_SIG16_NIR16\"");
  EXPECT_THROW(parse_sensor_info(rng, "n.json"), std::invalid_argument);
}

// the base file for the error cases, one key a line (line i + 1 is base[i])
const std::vector<std::string> kBase = {
    "{",
    R"(  "prod_line": "OS-1-64-U02",)",
    R"(  "prod_sn": "122201000998",)",
    R"(  "build_rev": "v2.3.0",)",
    R"(  "lidar_mode": "512x10",)",
    R"(  "beam_altitude_angles": [2.0, -16.084, 16.611, -5.468],)",
    R"(  "beam_azimuth_angles": [3.164, 1.055, -1.055, -3.164],)",
    R"(  "lidar_origin_to_beam_origin_mm": 12.163,)",
    R"(  "lidar_to_sensor_transform": [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],)",
    R"(  "imu_to_sensor_transform": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],)",
    R"(  "data_format": {)",
    R"(    "pixels_per_column": 4,)",
    R"(    "columns_per_packet": 16,)",
    R"(    "columns_per_frame": 512,)",
    R"(    "column_window": [0, 511],)",
    R"(    "pixel_shift_by_row": [6, 2, -2, -6],)",
    R"(    "udp_profile_lidar": "LEGACY")",
    "  }",
    "}",
};

std::string join(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

// what parsing the base with line `line` replaced (or removed: "-") throws
std::string error_of(int line, const std::string& text) {
  std::vector<std::string> lines = kBase;
  if (text == "-") {
    lines.erase(lines.begin() + (line - 1));
  } else {
    lines[static_cast<std::size_t>(line - 1)] = text;
  }
  try {
    parse_sensor_info(join(lines), "m.json");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(OusterMetadata, BaseFileParses) { EXPECT_EQ(parse_sensor_info(join(kBase), "m.json"), tiny(512)); }

TEST(OusterMetadata, BadFilesNameTheLine) {
  struct Case {
    int line;
    std::string text;
    std::string where;  // the message's start
    std::string what;   // and a part of it
  };
  const std::vector<Case> cases = {
      // syntax: a bad literal, a newline inside a string, the file cut short
      {13, R"(    "columns_per_packet": 16x,)", "m.json:13: ", "not valid JSON"},
      {3, R"(  "prod_sn": "1222,)", "m.json:3: ", "not valid JSON"},
      {19, "-", "m.json:18: ", "not valid JSON"},
      // missing keys: at the enclosing object's line
      {7, "-", "m.json:1: ", "missing key \"beam_azimuth_angles\""},
      {12, "-", "m.json:11: ", "missing key \"pixels_per_column\" in data_format"},
      // wrong counts and types
      {6, R"(  "beam_altitude_angles": [2.0, -16.084, 16.611],)",
       "m.json:6: ", "beam_altitude_angles: expected 4 numbers (pixels_per_column), got 3"},
      {16, R"(    "pixel_shift_by_row": [6, 2, -2, -6, 0],)",
       "m.json:16: ", "pixel_shift_by_row: expected 4 integers (pixels_per_column), got 5"},
      {12, R"(    "pixels_per_column": "4",)", "m.json:12: ", "pixels_per_column: expected"},
      {7, R"(  "beam_azimuth_angles": [3.164, 1.055, "x", -3.164],)", "m.json:7: ", "beam_azimuth_angles: "},
      {8, R"(  "lidar_origin_to_beam_origin_mm": 1e400,)", "m.json:8: ", "number overflow parsing '1e400'"},
      {4, R"(  "build_rev": 2,)", "m.json:4: ", "build_rev: expected a string, got number"},
      // the mode and the format agreeing with it
      {5, R"(  "lidar_mode": "1024x30",)", "m.json:5: ",
       "lidar_mode: \"1024x30\" is not a lidar mode, expected one of 512x10, 512x20, 1024x10, 1024x20, 2048x10, "
       "4096x5"},
      {14, R"(    "columns_per_frame": 1024,)",
       "m.json:14: ", "columns_per_frame: 1024 disagrees with lidar_mode 512x10, expected 512"},
      {13, R"(    "columns_per_packet": 7,)", "m.json:13: ", "columns_per_packet: 7 does not divide"},
      {15, R"(    "column_window": [0, 512],)", "m.json:15: ", "column_window: "},
      // the profile
      {17, R"(    "udp_profile_lidar": "RNG19_RFL8_SIG16_NIR16")", "m.json:17: ",
       "udp_profile_lidar: \"RNG19_RFL8_SIG16_NIR16\" is not supported: only the LEGACY profile is supported"},
      // the altitudes distinct
      {6, R"(  "beam_altitude_angles": [2.0, -16.084, 2.0, -5.468],)",
       "m.json:6: ", "pixels 0 and 2 have the same altitude 2.0 deg"},
      // the transform: a turn about x, a scaled one
      {9, R"(  "lidar_to_sensor_transform": [1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1],)",
       "m.json:9: ", "lidar_to_sensor_transform: not a rotation about z"},
      {9, R"(  "lidar_to_sensor_transform": [-2, 0, 0, 0, 0, -2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],)",
       "m.json:9: ", "lidar_to_sensor_transform: not a rotation about z"},
      {10, R"(  "imu_to_sensor_transform": [1, 0, 0, 0],)",
       "m.json:10: ", "imu_to_sensor_transform: expected 16 numbers"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.line, c.text);
    EXPECT_EQ(e.rfind(c.where, 0), 0u) << c.text << "\n -> " << e;
    EXPECT_NE(e.find(c.what), std::string::npos) << c.text << "\n -> " << e;
  }
  // a key's name as a value earlier does not move the line
  std::vector<std::string> lines = kBase;
  lines[1] = R"(  "prod_line": "lidar_mode",)";
  lines[4] = R"(  "lidar_mode": "1024x30",)";
  try {
    parse_sensor_info(join(lines), "m.json");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("m.json:5: ", 0), 0u) << e.what();
  }
  // the root not an object
  try {
    parse_sensor_info("\n\n[1, 2]\n", "m.json");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("m.json:3: expected a JSON object", 0), 0u) << e.what();
  }
}

TEST(OusterMetadata, LayoutOfACalibration) {
  const SensorInfo s = tiny();
  // pixels by ascending altitude: 1 (-16.084), 3 (-5.468), 0 (2.0), 2 (16.611)
  EXPECT_EQ(pixel_of_ring(s), (std::vector<int>{1, 3, 0, 2}));
  EXPECT_EQ(ring_of_pixel(s), (std::vector<int>{2, 0, 3, 1}));
  const LidarLayout l = layout_of(s, LidarLayout{});
  ASSERT_EQ(l.beam_elevation.size(), 4u);
  EXPECT_EQ(l.beam_elevation[0], -16.084 * kPi / 180.0);
  EXPECT_EQ(l.beam_elevation[3], 16.611 * kPi / 180.0);
  EXPECT_EQ(l.elevation_min, l.beam_elevation[0]);
  ASSERT_EQ(l.beam_azimuth.size(), 4u);
  // theta_azimuth = -2 pi beam_azimuth_angle / 360: ring 0 is pixel 1 (1.055 deg)
  EXPECT_NEAR(l.beam_azimuth[0], -1.055 * 2.0 * kPi / 360.0, 1e-16);
  EXPECT_NEAR(l.beam_azimuth[3], 1.055 * 2.0 * kPi / 360.0, 1e-16);
  EXPECT_NEAR(l.beam_origin, 0.012163, 1e-18);
  EXPECT_EQ(l.check(), "");
  // a layout that does not fit the metadata is refused
  const LidarLayout shipped = layout_of(parse_sensor_info(read_text(kShipped), kShipped), LidarLayout{});
  EXPECT_THROW(Decoder(s, shipped), std::invalid_argument);
  SensorInfo odd = s;
  odd.columns_per_packet = 24;
  EXPECT_THROW(Decoder(odd, l), std::invalid_argument);
  EXPECT_THROW(layout_of(odd, LidarLayout{}), std::invalid_argument);
}

// ------------------------------------------------------------------ packets

TEST(OusterPackets, EncoderWritesTheManualsOffsets) {
  const SensorInfo s = tiny();
  RangeImage im = make_range_image(s, 0xBEEF, 5'000'000'000);
  // nominal encoder counts: 90112 / 64 = 1408 ticks a column; 10 Hz x 64
  // columns: 1.5625 ms a column
  EXPECT_EQ(im.columns[3].encoder, 3u * 1408u);
  EXPECT_EQ(im.columns[3].time, 5'000'000'000 + 4'687'500);
  // range beyond 20 bits (clamped), reflectivity, signal, near_ir
  im.pixels[17 * 4 + 2] = {0x123456, 0xC3D4, 0xA1B2, 0xE5F6};
  im.pixels[17 * 4 + 1] = {54321, 7, 8, 9};
  im.columns[18].valid = false;
  Bytes b;
  b.push_back(0xAA);  // appended after what is there
  encode(s, im, b);
  ASSERT_EQ(b.size(), 1u + 4u * 1088u);  // 4 packets of 16 x (16 + 12 x 4 + 4) bytes
  // column 17: packet 1, block 1
  const std::size_t at = 1 + 1088 + 68;
  EXPECT_EQ(read_le(b, at + 0, 8), static_cast<std::uint64_t>(im.columns[17].time));
  EXPECT_EQ(read_le(b, at + 8, 2), 17u);
  EXPECT_EQ(read_le(b, at + 10, 2), 0xBEEFu);
  EXPECT_EQ(read_le(b, at + 12, 4), 17u * 1408u);
  EXPECT_EQ(read_le(b, at + 16 + 12 * 1 + 0, 4), 54321u);
  EXPECT_EQ(read_le(b, at + 16 + 12 * 2 + 0, 4), 0xFFFFFu);
  EXPECT_EQ(read_le(b, at + 16 + 12 * 2 + 4, 2), 0xC3D4u);  // reflectivity
  EXPECT_EQ(read_le(b, at + 16 + 12 * 2 + 6, 2), 0xA1B2u);  // signal
  EXPECT_EQ(read_le(b, at + 16 + 12 * 2 + 8, 2), 0xE5F6u);  // near_ir
  EXPECT_EQ(read_le(b, at + 16 + 12 * 2 + 10, 2), 0u);
  EXPECT_EQ(read_le(b, at + 64, 4), 0xFFFFFFFFu);
  EXPECT_EQ(read_le(b, at + 68 + 64, 4), 0u);  // column 18: invalid
  // an image of another size is refused
  im.pixels.pop_back();
  EXPECT_THROW(encode(s, im, b), std::invalid_argument);
}

TEST(OusterPackets, HandBuiltPacketsGiveTheManualsPoints) {
  const SensorInfo s = tiny();
  const LidarLayout layout = layout_of(s, LidarLayout{});
  // one rotation, 4 packets of 16 columns of 4 pixels, written field by field
  // at the manual's offsets: column 9 invalid, every fifth column off its
  // nominal encoder count, garbage above the range's 20 bits
  const auto range_of = [](int c, int p) {
    return c % 7 == 0 && p == 1 ? 0u : static_cast<std::uint32_t>(1000 + 3701 * c + 911 * p);
  };
  const auto signal_of = [](int c, int p) { return static_cast<std::uint32_t>((1000 * c + 7 * p) % 65536); };
  const auto encoder_of = [](int c) { return static_cast<std::uint32_t>(c * 1408 + (c % 5 == 3 ? 100 : 0)); };
  const auto time_of = [](int c) { return static_cast<std::uint64_t>(1'000'000'000 + 1'562'500 * c); };
  const std::size_t block = 16 + 12 * 4 + 4;
  std::vector<Bytes> packets(4, Bytes(16 * block, 0));
  for (int c = 0; c < 64; ++c) {
    Bytes& b = packets[static_cast<std::size_t>(c / 16)];
    const std::size_t at = static_cast<std::size_t>(c % 16) * block;
    le(b, at, time_of(c), 8);
    le(b, at + 8, static_cast<std::uint64_t>(c), 2);
    le(b, at + 10, 77, 2);
    le(b, at + 12, encoder_of(c), 4);
    for (int p = 0; p < 4; ++p) {
      const std::size_t d = at + 16 + 12 * static_cast<std::size_t>(p);
      le(b, d, range_of(c, p) | 0xA5u << 20, 4);
      le(b, d + 4, 100 + static_cast<std::uint64_t>(p), 2);
      le(b, d + 6, signal_of(c, p), 2);
      le(b, d + 8, 4242, 2);
    }
    le(b, at + 16 + 48, c == 9 ? 0u : 0xFFFFFFFFu, 4);
  }
  Decoder d(s, layout);
  push_all(d, packets);
  EXPECT_FALSE(d.pop().has_value());  // column 9 never came
  d.flush();
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(d.counters().bad_columns, 1u);
  EXPECT_EQ(d.counters().lost_columns, 1u);
  EXPECT_EQ(d.counters().columns, 63u);
  const LidarScan& scan = scans[0];
  EXPECT_EQ(scan.stamp, 1'000'000'000);
  EXPECT_EQ(scan.end, static_cast<TimeNs>(time_of(63)));

  // "Lidar Range to XYZ" in Ouster's lidar frame (mm), turned 180 deg about
  // z into the sensor frame; rings by ascending altitude: pixels 1, 3, 0, 2
  const int pixel_of[4] = {1, 3, 0, 2};
  const double n = 12.163;
  std::size_t i = 0;
  for (int c = 0; c < 64; ++c) {
    if (c == 9) continue;
    const double theta_encoder = 2.0 * kPi * (1.0 - encoder_of(c) / 90112.0);
    for (int ring = 0; ring < 4; ++ring) {
      const int p = pixel_of[ring];
      const std::uint32_t r_mm = range_of(c, p);
      if (r_mm == 0) continue;
      const double r = r_mm;
      const double theta_azimuth = -2.0 * kPi * s.beam_azimuth_angles[static_cast<std::size_t>(p)] / 360.0;
      const double phi = 2.0 * kPi * s.beam_altitude_angles[static_cast<std::size_t>(p)] / 360.0;
      const double x = (r - n) * std::cos(theta_encoder + theta_azimuth) * std::cos(phi) + n * std::cos(theta_encoder);
      const double y = (r - n) * std::sin(theta_encoder + theta_azimuth) * std::cos(phi) + n * std::sin(theta_encoder);
      const double z = (r - n) * std::sin(phi);
      ASSERT_LT(i, scan.points.size());
      const LidarPoint& q = scan.points[i++];
      EXPECT_NEAR(q.x, -x / 1000.0, 1e-5) << c << " " << ring;
      EXPECT_NEAR(q.y, -y / 1000.0, 1e-5) << c << " " << ring;
      EXPECT_NEAR(q.z, z / 1000.0, 1e-5) << c << " " << ring;
      EXPECT_EQ(q.ring, ring);
      EXPECT_EQ(q.t, static_cast<TimeNs>(time_of(c)));
      EXPECT_FLOAT_EQ(q.intensity, static_cast<float>(signal_of(c, p) / 65535.0));
    }
  }
  EXPECT_EQ(i, scan.points.size());
  EXPECT_EQ(i, 63u * 4u - 10u);  // columns 0, 7, ..., 63 have no return on pixel 1
}

TEST(OusterPackets, FullRotationRoundTripsBitForBit) {
  const SensorInfo shipped = parse_sensor_info(read_text(kShipped), kShipped);
  // the shipped calibration, and one with beam azimuths, a beam origin and
  // altitudes out of order
  SensorInfo os1 = shipped;
  std::mt19937 rng(11);
  std::shuffle(os1.beam_altitude_angles.begin(), os1.beam_altitude_angles.end(), rng);
  for (std::size_t p = 0; p < 32; ++p)
    os1.beam_azimuth_angles[p] = p % 4 == 0 ? 4.23 : p % 4 == 1 ? 1.41 : p % 4 == 2 ? -1.41 : -4.23;
  os1.lidar_origin_to_beam_origin_mm = 15.806;
  for (const SensorInfo& info : {shipped, os1}) {
    const LidarLayout l = layout_of(info, LidarLayout{});
    const RangeImage im = random_image(info, 4321, rng, 77'000'000'000);
    Bytes bytes;
    encode(info, im, bytes);
    ASSERT_EQ(bytes.size(), 64u * 6464u);
    Decoder d(info, l);
    for (std::size_t at = 0; at < bytes.size(); at += 6464) d.push(bytes.data() + at, 6464);
    const std::vector<LidarScan> scans = drain(d);  // done at its last column
    ASSERT_EQ(scans.size(), 1u);
    EXPECT_EQ(d.counters().packets, 64u);
    EXPECT_EQ(d.counters().rotations, 1u);
    EXPECT_EQ(d.counters().lost_columns + d.counters().bad_columns + d.counters().partial_first, 0u);
    const LidarScan& scan = scans[0];
    EXPECT_EQ(scan.stamp, im.columns.front().time);
    EXPECT_EQ(scan.end, im.columns.back().time);
    // each point as beam_point of the layout makes it, in column and ring order
    const std::vector<int> pixel = pixel_of_ring(info);
    std::size_t i = 0, clamped = 0;
    for (int c = 0; c < 1024; ++c) {
      const RangeImage::Column& col = im.columns[static_cast<std::size_t>(c)];
      const double az0 = turn_azimuth(l, col.encoder / 90112.0);
      for (int j = 0; j < 32; ++j) {
        const RangeImage::Pixel& px = im.pixels[static_cast<std::size_t>(c * 32 + pixel[static_cast<std::size_t>(j)])];
        if (px.range_mm == 0) continue;
        clamped += px.range_mm > 0xFFFFF ? 1 : 0;
        const double r = std::min(px.range_mm, 0xFFFFFu) * 0.001;
        const double az = l.beam_azimuth.empty() ? az0 : az0 + l.beam_azimuth[static_cast<std::size_t>(j)];
        const double el = ring_elevation(l, j);
        float p[3];
        beam_point(r, l.beam_origin, std::cos(el), std::sin(el), std::cos(az), std::sin(az), std::cos(az0),
                   std::sin(az0), p);
        ASSERT_LT(i, scan.points.size());
        const LidarPoint& q = scan.points[i++];
        ASSERT_TRUE(std::memcmp(&q.x, p, sizeof p) == 0) << c << " " << j;
        ASSERT_EQ(q.ring, j);
        ASSERT_EQ(q.t, col.time);
        ASSERT_EQ(q.intensity, static_cast<float>(px.signal / 65535.0));
        // what the layout says the sensor reports
        ASSERT_EQ(r, reported_range(l, r));
        ASSERT_EQ(static_cast<double>(px.signal) / 65535.0, reported_intensity(l, px.signal / 65535.0));
      }
    }
    EXPECT_EQ(i, scan.points.size());
    EXPECT_GT(clamped, 0u);
    EXPECT_NEAR(static_cast<double>(i) / (1024 * 32), 0.61, 0.02);
    // the decoder's scan of the image is the same
    expect_same(d.scan(wire(im)), scan);
  }
}

TEST(OusterPackets, NominalEncoderCountsAreTheSimulatorsColumns) {
  // the simulator casts column c at column_azimuth; a column at its nominal
  // count decodes at turn_azimuth(count / 90112): the same double, every mode
  for (const int columns : {512, 1024, 2048, 4096}) {
    const SensorInfo s = tiny(columns);
    const LidarLayout l = layout_of(s, LidarLayout{});
    const RangeImage im = make_range_image(s);
    for (int c = 0; c < columns; ++c) {
      const std::uint32_t count = im.columns[static_cast<std::size_t>(c)].encoder;
      ASSERT_EQ(count, static_cast<std::uint32_t>(c * (90112 / columns)));
      ASSERT_EQ(turn_azimuth(l, count / 90112.0), column_azimuth(l, c)) << columns << " " << c;
    }
    // column 0 looks backward, a quarter turn later left, half a turn forward
    EXPECT_EQ(column_azimuth(l, 0), kPi);
    EXPECT_EQ(column_azimuth(l, columns / 4), kPi / 2);
    EXPECT_EQ(column_azimuth(l, columns / 2), 0.0);
  }
}

TEST(OusterPackets, LidarFrameTurnedOtherwiseTurnsThePoints) {
  SensorInfo s = tiny();
  std::mt19937 rng(3);
  const RangeImage im = random_image(s, 1, rng);
  const LidarScan standard = Decoder(s, layout_of(s, LidarLayout{})).scan(im);
  // the identity: Ouster's lidar frame is the sensor frame, 180 deg from the standard
  s.lidar_to_sensor_transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_EQ(azimuth_offset(s), kPi);
  const LidarScan turned = Decoder(s, layout_of(s, LidarLayout{})).scan(im);
  ASSERT_EQ(turned.points.size(), standard.points.size());
  for (std::size_t i = 0; i < turned.points.size(); ++i) {
    EXPECT_NEAR(turned.points[i].x, -standard.points[i].x, 1e-4);
    EXPECT_NEAR(turned.points[i].y, -standard.points[i].y, 1e-4);
    EXPECT_EQ(turned.points[i].z, standard.points[i].z);
  }
}

// ------------------------------------------------------------------ assembly

// 4 pixels x 128 columns: 8 packets a rotation
struct Stream {
  SensorInfo info = tiny(128);
  LidarLayout layout = layout_of(info, LidarLayout{});
  std::mt19937 rng{5};
  RangeImage image(std::uint16_t frame) {
    return random_image(info, frame, rng, static_cast<TimeNs>(frame) * 100'000'000);
  }
  LidarScan scan(const RangeImage& im) const { return Decoder(info, layout).scan(wire(im)); }
};

TEST(OusterAssembly, LostPacketEmittedWhenTheNextFrameBegins) {
  Stream st;
  const RangeImage a = st.image(5), b = st.image(6);
  std::vector<Bytes> pa = packets_of(st.info, a);
  const std::vector<Bytes> pb = packets_of(st.info, b);
  pa.erase(pa.begin() + 3);
  Decoder d(st.info, st.layout);
  push_all(d, pa);
  EXPECT_FALSE(d.pop().has_value());
  d.push(pb[0].data(), pb[0].size());
  std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(d.counters().lost_columns, 16u);
  RangeImage without = a;
  for (int c = 48; c < 64; ++c) without.columns[static_cast<std::size_t>(c)].valid = false;
  expect_same(scans[0], st.scan(without));
  for (std::size_t k = 1; k < pb.size(); ++k) d.push(pb[k].data(), pb[k].size());
  scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  expect_same(scans[0], st.scan(b));
  EXPECT_EQ(d.counters().rotations, 2u);
  EXPECT_EQ(d.counters().lost_columns, 16u);
}

TEST(OusterAssembly, LostLastPacketEmittedAtFlush) {
  Stream st;
  const RangeImage a = st.image(9);
  std::vector<Bytes> pa = packets_of(st.info, a);
  pa.pop_back();
  Decoder d(st.info, st.layout);
  push_all(d, pa);
  EXPECT_FALSE(d.pop().has_value());
  d.flush();
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(d.counters().lost_columns, 16u);
  RangeImage without = a;
  for (int c = 112; c < 128; ++c) without.columns[static_cast<std::size_t>(c)].valid = false;
  expect_same(scans[0], st.scan(without));
  d.flush();  // nothing open: nothing more
  EXPECT_FALSE(d.pop().has_value());
}

TEST(OusterAssembly, DuplicatesAndLateCopiesDropped) {
  Stream st;
  const RangeImage a = st.image(1);
  Decoder d(st.info, st.layout);
  for (const Bytes& p : packets_of(st.info, a)) {
    d.push(p.data(), p.size());
    d.push(p.data(), p.size());
  }
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  expect_same(scans[0], st.scan(a));
  // the last packet's copy came after the rotation was done: late
  EXPECT_EQ(d.counters().duplicate_columns, 7u * 16u);
  EXPECT_EQ(d.counters().late_columns, 16u);
  EXPECT_EQ(d.counters().lost_columns, 0u);
}

TEST(OusterAssembly, OutOfOrderWithinARotationIsTheSameScan) {
  Stream st;
  const RangeImage a = st.image(20), b = st.image(21);
  std::vector<Bytes> pa = packets_of(st.info, a), pb = packets_of(st.info, b);
  std::mt19937 rng(9);
  std::shuffle(pa.begin(), pa.end(), rng);
  std::shuffle(pb.begin(), pb.end(), rng);
  ASSERT_NE(pa.front(), packets_of(st.info, a).front());  // the first column is not first
  Decoder d(st.info, st.layout);
  push_all(d, pa);
  push_all(d, pb);
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 2u);
  expect_same(scans[0], st.scan(a));
  expect_same(scans[1], st.scan(b));
  EXPECT_EQ(d.counters().lost_columns + d.counters().duplicate_columns + d.counters().late_columns +
                d.counters().partial_first,
            0u);
}

TEST(OusterAssembly, LatePacketsOfAnEmittedRotationDropped) {
  Stream st;
  const RangeImage a = st.image(5), b = st.image(6);
  const std::vector<Bytes> pa = packets_of(st.info, a), pb = packets_of(st.info, b);
  const std::vector<Bytes> old = packets_of(st.info, st.image(3));
  Decoder d(st.info, st.layout);
  push_all(d, pa);
  for (std::size_t k = 0; k < 4; ++k) d.push(pb[k].data(), pb[k].size());
  d.push(pa[2].data(), pa[2].size());    // of the rotation emitted
  d.push(old[5].data(), old[5].size());  // of one older still
  for (std::size_t k = 4; k < pb.size(); ++k) d.push(pb[k].data(), pb[k].size());
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 2u);
  expect_same(scans[0], st.scan(a));
  expect_same(scans[1], st.scan(b));
  EXPECT_EQ(d.counters().late_columns, 32u);
  EXPECT_EQ(d.counters().lost_columns, 0u);
}

// one packet with a frame_id far ahead (a corrupt one that passed every
// check) runs the decoder on: the real stream's columns are then late, and
// after a whole window of them in a row the decoder starts over with them
TEST(OusterAssembly, AFrameFarAheadCostsOneRotationNotTheStream) {
  Stream st;
  // (20005 is "ahead" of 5, and 6 "behind" it, modulo 2^16)
  const RangeImage a = st.image(5), bogus = st.image(20005);
  const std::vector<Bytes> pa = packets_of(st.info, a), pz = packets_of(st.info, bogus);
  Decoder d(st.info, st.layout);
  push_all(d, pa);
  d.push(pz[0].data(), pz[0].size());
  std::vector<RangeImage> next;
  for (std::uint16_t f = 6; f < 10; ++f) {
    next.push_back(st.image(f));
    push_all(d, packets_of(st.info, next.back()));
  }
  const std::vector<LidarScan> scans = drain(d);
  // frame 5; frame 6 is spent on the late run (its last column restarts
  // the decoder: a partial first rotation); frames 7 to 9 come through whole
  ASSERT_EQ(scans.size(), 4u);
  expect_same(scans[0], st.scan(a));
  expect_same(scans[1], st.scan(next[1]));
  expect_same(scans[3], st.scan(next[3]));
  EXPECT_EQ(d.counters().resyncs, 1u);
  EXPECT_EQ(d.counters().late_columns, 127u);
  EXPECT_EQ(d.counters().partial_first, 1u);
  EXPECT_EQ(d.counters().lost_columns, 16u);
}

TEST(OusterAssembly, PartialFirstRotationDropped) {
  Stream st;
  const RangeImage a = st.image(5), b = st.image(6);
  const std::vector<Bytes> pa = packets_of(st.info, a), pb = packets_of(st.info, b);
  Decoder d(st.info, st.layout);
  // the stream starts mid-way through frame 5
  for (std::size_t k = 3; k < pa.size(); ++k) d.push(pa[k].data(), pa[k].size());
  push_all(d, pb);
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  expect_same(scans[0], st.scan(b));
  EXPECT_EQ(d.counters().partial_first, 1u);
  EXPECT_EQ(d.counters().lost_columns, 0u);
  EXPECT_EQ(d.counters().rotations, 1u);
  // a late packet of the dropped one is late
  d.push(pa[6].data(), pa[6].size());
  EXPECT_EQ(d.counters().late_columns, 16u);
}

TEST(OusterAssembly, BadSizesDroppedWhole) {
  Stream st;
  const RangeImage a = st.image(2);
  const std::vector<Bytes> pa = packets_of(st.info, a);
  Decoder d(st.info, st.layout);
  Bytes longer = pa[0];
  longer.push_back(0);
  d.push(pa[0].data(), pa[0].size() - 1);  // truncated
  d.push(longer.data(), longer.size());    // oversized
  d.push(pa[0].data(), 0);
  d.push(nullptr, pa[0].size());
  EXPECT_EQ(d.counters().bad_size, 4u);
  EXPECT_EQ(d.counters().columns, 0u);
  push_all(d, pa);
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);
  expect_same(scans[0], st.scan(a));
  EXPECT_EQ(d.counters().packets, 4u + 8u);
}

TEST(OusterAssembly, InvalidColumnsDropped) {
  Stream st;
  const RangeImage a = st.image(2), b = st.image(3);
  std::vector<Bytes> pa = packets_of(st.info, a);
  const std::vector<Bytes> pb = packets_of(st.info, b);
  const std::size_t block = 16 + 12 * 4 + 4;
  // column 3: status 0; 20: a status neither valid nor 0; 40: measurement_id
  // beyond the frame; 50: an encoder count of a whole turn
  le(pa[0], 3 * block + 64, 0, 4);
  le(pa[1], 4 * block + 64, 0x12345678, 4);
  le(pa[2], 8 * block + 8, 128, 2);
  le(pa[3], 2 * block + 12, 90112, 4);
  Decoder d(st.info, st.layout);
  push_all(d, pa);
  EXPECT_FALSE(d.pop().has_value());
  push_all(d, pb);
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(d.counters().bad_columns, 4u);
  EXPECT_EQ(d.counters().lost_columns, 4u);
  RangeImage without = a;
  for (const int c : {3, 20, 40, 50}) without.columns[static_cast<std::size_t>(c)].valid = false;
  expect_same(scans[0], st.scan(without));
  expect_same(scans[1], st.scan(b));
}

TEST(OusterAssembly, ColumnWindowCompletesTheRotation) {
  Stream st;
  st.info.column_window = {16, 111};
  const RangeImage a = st.image(2);
  Decoder d(st.info, st.layout);
  const std::vector<Bytes> pa = packets_of(st.info, a);
  for (std::size_t k = 0; k < 7; ++k) d.push(pa[k].data(), pa[k].size());  // through column 111
  std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 1u);  // done without the last packet
  RangeImage window = a;
  for (int c = 0; c < 128; ++c) window.columns[static_cast<std::size_t>(c)].valid = c >= 16 && c <= 111;
  expect_same(scans[0], st.scan(window));
  EXPECT_EQ(d.counters().bad_columns, 16u);  // columns 0..15, outside the window
  EXPECT_EQ(d.counters().lost_columns, 0u);
  EXPECT_EQ(d.counters().partial_first, 0u);
}

// a decoder reset in the middle of a rotation (and after a late run and a
// partial first) decodes the next stream as a new one does, counters and all
TEST(OusterAssembly, ResetIsANewDecoder) {
  Stream st;
  const RangeImage a = st.image(40), b = st.image(41), c = st.image(7), e = st.image(8);
  const std::vector<Bytes> pa = packets_of(st.info, a), pb = packets_of(st.info, b);
  Decoder used(st.info, st.layout);
  for (std::size_t k = 3; k < pa.size(); ++k) used.push(pa[k].data(), pa[k].size());  // a partial first
  push_all(used, pb);
  for (std::size_t k = 0; k < 4; ++k) used.push(pa[k].data(), pa[k].size());  // late
  ASSERT_GT(used.counters().partial_first + used.counters().late_columns, 0u);
  used.reset();
  EXPECT_FALSE(used.pop().has_value());  // b's rotation, decoded before the reset, is gone
  Decoder fresh(st.info, st.layout);
  for (Decoder* d : {&used, &fresh}) {
    push_all(*d, packets_of(st.info, c));  // frame 7 after 41: old for the used one unless reset
    push_all(*d, packets_of(st.info, e));
    d->flush();
  }
  const std::vector<LidarScan> got = drain(used), want = drain(fresh);
  ASSERT_EQ(got.size(), 2u);
  ASSERT_EQ(want.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) expect_same(got[k], want[k]);
  expect_same(got[0], st.scan(c));
  EXPECT_EQ(std::memcmp(&used.counters(), &fresh.counters(), sizeof(Decoder::Counters)), 0);
}

// a scan every third rotation: the first, the fourth, the seventh, as a
// decoder of every rotation gives them; every rotation counted
TEST(OusterAssembly, AScanEveryNthRotationIsThatRotationsScan) {
  Stream st;
  Decoder every(st.info, st.layout), third(st.info, st.layout);
  third.set_scan_every(3);
  for (std::uint16_t f = 10; f < 17; ++f) {
    const std::vector<Bytes> p = packets_of(st.info, st.image(f));
    push_all(every, p);
    push_all(third, p);
  }
  every.flush();
  third.flush();
  const std::vector<LidarScan> all = drain(every), some = drain(third);
  ASSERT_EQ(all.size(), 7u);
  ASSERT_EQ(some.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) expect_same(some[k], all[3 * k]);
  EXPECT_EQ(third.counters().rotations, 7u);
  EXPECT_THROW(third.set_scan_every(0), std::invalid_argument);
}

TEST(OusterAssembly, FrameIdWrapsAround) {
  Stream st;
  const std::uint16_t frames[] = {65534, 65535, 0, 1};
  std::vector<RangeImage> images;
  Decoder d(st.info, st.layout);
  for (const std::uint16_t f : frames) {
    images.push_back(st.image(f));
    std::vector<Bytes> p = packets_of(st.info, images.back());
    p.pop_back();  // each emitted by the next frame's first column, or flush
    push_all(d, p);
  }
  d.flush();
  const std::vector<LidarScan> scans = drain(d);
  ASSERT_EQ(scans.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(scans[k].stamp, images[k].columns[0].time);
  EXPECT_EQ(d.counters().lost_columns, 4u * 16u);
  EXPECT_EQ(d.counters().late_columns, 0u);
  // 65535 is older than 1
  const std::vector<Bytes> old = packets_of(st.info, images[1]);
  d.push(old[0].data(), old[0].size());
  EXPECT_EQ(d.counters().late_columns, 16u);
}

TEST(OusterAssembly, FuzzNeverThrowsAndCountersAddUp) {
  Stream st;
  const std::size_t size = packet_size(st.info);
  std::vector<Bytes> valid;
  for (std::uint16_t f = 0; f < 4; ++f) {
    for (Bytes& p : packets_of(st.info, st.image(f))) valid.push_back(std::move(p));
  }
  std::mt19937 rng(1234);
  std::uniform_int_distribution<int> byte(0, 255);
  Decoder d(st.info, st.layout);
  std::size_t scans = 0, points = 0;
  const auto check_scans = [&] {
    while (auto s = d.pop()) {
      ++scans;
      points += s->points.size();
      for (const LidarPoint& p : s->points) {
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        ASSERT_TRUE(p.intensity >= 0.0f && p.intensity <= 1.0f && p.ring < 4);
      }
    }
  };
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    Bytes b;
    switch (i % 4) {
      case 0: {  // random bytes of a random size
        b.resize(std::uniform_int_distribution<std::size_t>(0, 2 * size)(rng));
        for (auto& x : b) x = static_cast<std::uint8_t>(byte(rng));
        break;
      }
      case 1: {  // random bytes of the right size, columns made to look valid
        b.resize(size);
        for (auto& x : b) x = static_cast<std::uint8_t>(byte(rng));
        for (std::size_t c = 0; c < 16; ++c) {
          const std::size_t at = c * (size / 16);
          le(b, at + 8, std::uniform_int_distribution<std::uint32_t>(0, 140)(rng), 2);
          le(b, at + 10, std::uniform_int_distribution<std::uint32_t>(0, 6)(rng), 2);
          le(b, at + 12, std::uniform_int_distribution<std::uint32_t>(0, 91000)(rng), 4);
          le(b, at + size / 16 - 4, c % 3 == 0 ? 0u : 0xFFFFFFFFu, 4);
        }
        break;
      }
      default: {  // a valid packet, a few bytes changed (or none)
        b = valid[std::uniform_int_distribution<std::size_t>(0, valid.size() - 1)(rng)];
        const int k = std::uniform_int_distribution<int>(0, 8)(rng);
        for (int m = 0; m < k; ++m)
          b[std::uniform_int_distribution<std::size_t>(0, size - 1)(rng)] = static_cast<std::uint8_t>(byte(rng));
        if (i % 40 == 2) b.resize(std::uniform_int_distribution<std::size_t>(0, size)(rng));
        break;
      }
    }
    ASSERT_NO_THROW(d.push(b.data(), b.size()));
    check_scans();
  }
  d.flush();
  check_scans();
  const Decoder::Counters& k = d.counters();
  EXPECT_EQ(k.packets, static_cast<std::uint64_t>(n));
  EXPECT_EQ((k.packets - k.bad_size) * 16, k.bad_columns + k.columns + k.duplicate_columns + k.late_columns);
  EXPECT_EQ(k.rotations, scans);
  EXPECT_LE(points, k.columns * 4);
  EXPECT_GT(k.columns, 0u);
  EXPECT_GT(k.rotations, 0u);
  EXPECT_GT(k.bad_size, 0u);
}

}  // namespace
}  // namespace paddock::hal::ouster
