// CAN over UDP: the header's bytes where the framing says, a round trip to
// the bit, and every malformed datagram refused with its reason, never a crash
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "autonomy/hal/can_udp.h"

namespace paddock::hal {
namespace {

CanDatagram sample() {
  CanDatagram d;
  d.kind = CanDatagram::Kind::Tick;
  d.time = 0x0102030405060708;
  d.sequence = 0xA0B0C0D0;
  d.lidar_before = 64;
  d.objects_before = 3;
  CanFrame a;
  a.stamp = 123'456'789;
  a.id = 0x101;
  a.dlc = 8;
  a.data = {1, 2, 3, 4, 5, 6, 7, 8};
  CanFrame b;
  b.stamp = 987'654'321'000;
  b.id = 0x1ABCDEF;
  b.extended = true;
  b.dlc = 3;
  b.data = {9, 8, 7};
  d.frames = {a, b};
  return d;
}

TEST(CanUdp, TheHeaderLiesWhereTheFramingSays) {
  const std::vector<std::uint8_t> b = encode(sample());
  ASSERT_EQ(b.size(), 32u + 2u * 24u);
  EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "PDKC");
  EXPECT_EQ(b[4], 1);                    // version
  EXPECT_EQ(b[5], 1);                    // tick
  EXPECT_EQ(b[6] | b[7] << 8, 2);        // frames
  EXPECT_EQ(b[8], 0x08);                 // time, little-endian
  EXPECT_EQ(b[15], 0x01);
  EXPECT_EQ(b[16], 0xD0);                // sequence
  EXPECT_EQ(b[20], 64);                  // lidar_before
  EXPECT_EQ(b[24], 3);                   // objects_before
  // the first frame: its stamp, then struct can_frame (id 0x101, dlc 8)
  EXPECT_EQ(b[32] | b[33] << 8 | b[34] << 16 | b[35] << 24, 123'456'789);
  EXPECT_EQ(b[40] | b[41] << 8, 0x101);
  EXPECT_EQ(b[44], 8);
  EXPECT_EQ(b[48], 1);
  // the second's id carries the extended-frame flag in its top bit
  EXPECT_EQ(b[56 + 8 + 3] & 0x80, 0x80);
}

TEST(CanUdp, ADatagramComesBackToTheBit) {
  const CanDatagram d = sample();
  const std::vector<std::uint8_t> b = encode(d);
  std::string why;
  const std::optional<CanDatagram> r = decode_datagram(b.data(), b.size(), &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->kind, d.kind);
  EXPECT_EQ(r->time, d.time);
  EXPECT_EQ(r->sequence, d.sequence);
  EXPECT_EQ(r->lidar_before, d.lidar_before);
  EXPECT_EQ(r->objects_before, d.objects_before);
  ASSERT_EQ(r->frames.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(r->frames[i].stamp, d.frames[i].stamp);
    EXPECT_EQ(r->frames[i].id, d.frames[i].id);
    EXPECT_EQ(r->frames[i].extended, d.frames[i].extended);
    EXPECT_EQ(r->frames[i].dlc, d.frames[i].dlc);
    EXPECT_EQ(r->frames[i].data, d.frames[i].data);
  }
  CanDatagram empty;
  empty.kind = CanDatagram::Kind::End;
  const std::vector<std::uint8_t> e = encode(empty);
  EXPECT_EQ(e.size(), 32u);
  ASSERT_TRUE(decode_datagram(e.data(), e.size()));
  EXPECT_EQ(decode_datagram(e.data(), e.size())->kind, CanDatagram::Kind::End);
}

std::string refused(std::vector<std::uint8_t> b) {
  std::string why;
  EXPECT_FALSE(decode_datagram(b.data(), b.size(), &why));
  return why;
}

TEST(CanUdp, AMalformedDatagramIsRefusedWithItsReason) {
  const std::vector<std::uint8_t> good = encode(sample());
  EXPECT_NE(refused({good.begin(), good.begin() + 20}).find("shorter than the header"), std::string::npos);
  std::vector<std::uint8_t> b = good;
  b[0] = 'X';
  EXPECT_NE(refused(b).find("magic"), std::string::npos);
  b = good;
  b[4] = 2;
  EXPECT_NE(refused(b).find("version 2"), std::string::npos);
  b = good;
  b[5] = 9;
  EXPECT_NE(refused(b).find("kind 9"), std::string::npos);
  b = good;
  b.pop_back();
  EXPECT_NE(refused(b).find("bytes for 2 frames"), std::string::npos);
  b = good;
  b[6] = 200;  // more frames than a datagram holds
  EXPECT_NE(refused(b).find("at most 56"), std::string::npos);
  b = good;
  b[15] = 0x80;  // a time past INT64_MAX
  EXPECT_NE(refused(b).find("clock's range"), std::string::npos);
  b = good;
  b[32 + 8 + 3] |= 0x40;  // the first frame a remote frame
  EXPECT_NE(refused(b).find("frame 0"), std::string::npos);
  b = good;
  b[32 + 8 + 4] = 9;  // dlc 9
  EXPECT_NE(refused(b).find("frame 0"), std::string::npos);
  CanDatagram too_many;
  too_many.frames.resize(CanDatagram::kMaxFrames + 1);
  EXPECT_THROW(encode(too_many), std::invalid_argument);
}

// random bytes and damaged datagrams: a refusal or a datagram, never a crash
TEST(CanUdp, GarbageNeverCrashes) {
  std::mt19937_64 rng(7);
  const std::vector<std::uint8_t> good = encode(sample());
  int decoded = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> b = good;
    if (i % 2 == 0) {
      b.resize(rng() % 200);
      for (auto& x : b) x = static_cast<std::uint8_t>(rng());
      if (b.size() >= 4) b[0] = 'P', b[1] = 'D', b[2] = 'K', b[3] = 'C';
    } else {
      b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
    }
    if (decode_datagram(b.data(), b.size())) ++decoded;
  }
  EXPECT_GT(decoded, 0);  // flips in the payload's data bytes leave a datagram
}

}  // namespace
}  // namespace paddock::hal
