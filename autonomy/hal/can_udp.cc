#include "autonomy/hal/can_udp.h"

#include <cstring>
#include <limits>
#include <stdexcept>

namespace paddock::hal {
namespace {

constexpr std::uint8_t kMagic[4] = {'P', 'D', 'K', 'C'};
constexpr std::uint8_t kVersion = 1;

void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint16_t u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
std::uint32_t u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = v << 8 | p[i];
  return v;
}
std::uint64_t u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

std::optional<CanDatagram> fail(std::string* why, const std::string& reason) {
  if (why) *why = reason;
  return std::nullopt;
}

}  // namespace

const char* to_string(CanDatagram::Kind k) {
  switch (k) {
    case CanDatagram::Kind::Data: return "data";
    case CanDatagram::Kind::Tick: return "tick";
    case CanDatagram::Kind::Reply: return "reply";
    case CanDatagram::Kind::Sync: return "sync";
    case CanDatagram::Kind::Ack: return "ack";
    case CanDatagram::Kind::End: return "end";
  }
  return "?";
}

std::vector<std::uint8_t> encode(const CanDatagram& d) {
  if (d.frames.size() > CanDatagram::kMaxFrames)
    throw std::invalid_argument("CAN over UDP: " + std::to_string(d.frames.size()) + " frames in one datagram; at most " +
                                std::to_string(CanDatagram::kMaxFrames));
  std::vector<std::uint8_t> out(CanDatagram::kHeaderSize + CanDatagram::kFrameSize * d.frames.size(), 0);
  std::uint8_t* p = out.data();
  std::memcpy(p, kMagic, 4);
  p[4] = kVersion;
  p[5] = static_cast<std::uint8_t>(d.kind);
  put_u16(p + 6, static_cast<std::uint16_t>(d.frames.size()));
  put_u64(p + 8, static_cast<std::uint64_t>(d.time));
  put_u32(p + 16, d.sequence);
  put_u32(p + 20, d.lidar_before);
  put_u32(p + 24, d.objects_before);
  p += CanDatagram::kHeaderSize;
  for (const CanFrame& f : d.frames) {
    put_u64(p, static_cast<std::uint64_t>(f.stamp));
    to_socketcan(f, p + 8);
    p += CanDatagram::kFrameSize;
  }
  return out;
}

std::optional<CanDatagram> decode_datagram(const std::uint8_t* p, std::size_t n, std::string* why) {
  if (n < CanDatagram::kHeaderSize)
    return fail(why, std::to_string(n) + " bytes: shorter than the header (" +
                         std::to_string(CanDatagram::kHeaderSize) + ")");
  if (std::memcmp(p, kMagic, 4) != 0) return fail(why, "no PDKC magic: not a CAN-over-UDP datagram");
  if (p[4] != kVersion) return fail(why, "version " + std::to_string(p[4]) + "; expected 1");
  if (p[5] > static_cast<std::uint8_t>(CanDatagram::Kind::End))
    return fail(why, "kind " + std::to_string(p[5]) + " is none of data, tick, reply, sync, ack, end");
  const std::size_t frames = u16(p + 6);
  if (frames > CanDatagram::kMaxFrames || n != CanDatagram::kHeaderSize + CanDatagram::kFrameSize * frames)
    return fail(why, std::to_string(n) + " bytes for " + std::to_string(frames) + " frames; expected " +
                         std::to_string(CanDatagram::kHeaderSize + CanDatagram::kFrameSize * frames) + " (at most " +
                         std::to_string(CanDatagram::kMaxFrames) + " frames)");
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<TimeNs>::max());
  CanDatagram d;
  d.kind = static_cast<CanDatagram::Kind>(p[5]);
  const std::uint64_t time = u64(p + 8);
  if (time > kMax) return fail(why, "a time past the clock's range");
  d.time = static_cast<TimeNs>(time);
  d.sequence = u32(p + 16);
  d.lidar_before = u32(p + 20);
  d.objects_before = u32(p + 24);
  for (std::size_t i = 0; i < frames; ++i) {
    const std::uint8_t* f = p + CanDatagram::kHeaderSize + CanDatagram::kFrameSize * i;
    const std::uint64_t stamp = u64(f);
    if (stamp > kMax) return fail(why, "frame " + std::to_string(i) + ": a stamp past the clock's range");
    const std::optional<CanFrame> frame = from_socketcan(f + 8, kSocketCanFrameSize, static_cast<TimeNs>(stamp));
    if (!frame) return fail(why, "frame " + std::to_string(i) + ": no data frame (remote or error frame, or dlc over 8)");
    d.frames.push_back(*frame);
  }
  return d;
}

}  // namespace paddock::hal
