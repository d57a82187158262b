#pragma once
// a CAN database (Vector's DBC format): the messages of a bus, the signals in
// their bytes, and a codec that reads and writes one signal of a frame's data.
// parse_dbc reads the subset real files use (VERSION, NS_, BS_, BU_, BO_ with
// its SG_ lines, CM_) and skips attribute and value-table statements (BA_DEF_,
// BA_, BA_DEF_DEF_, VAL_, VAL_TABLE_, ...); multiplexed and float signals are
// refused. The caller reads the file: this is a library without I/O.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace paddock::hal {

// a signal's byte order: @0 in a DBC (big-endian) or @1 (little-endian)
enum class ByteOrder { Motorola, Intel };

struct DbcSignal {
  std::string name;
  // the DBC's start bit, numbered byte * 8 + bit (bit 0 = a byte's least
  // significant): Intel, the signal's least significant bit, the rest above
  // it toward higher bytes; Motorola, its most significant bit, the rest below
  // it (bit - 1 within a byte, then the next byte's bit 7)
  int start = 0;
  int length = 1;  // bits, 1..64
  ByteOrder order = ByteOrder::Intel;
  bool is_signed = false;  // '-': two's complement
  double factor = 1.0;     // physical = raw * factor + offset
  double offset = 0.0;
  // the physical range [min, max] values saturate to. min == max means none:
  // [0|0] is how CANdb++ writes a signal without one; a tool that writes the
  // raw range's own ends instead gives the same saturation as none
  double min = 0.0;
  double max = 0.0;
  std::string unit;
  std::vector<std::string> receivers;
  std::string comment;  // its CM_ SG_, if any
  int line = 0;         // of its SG_ in the DBC

  // the raw bits from a frame's data (sign-extended when signed)
  std::uint64_t raw(const std::uint8_t* data) const;
  // the physical value: raw * factor + offset
  double decode(const std::uint8_t* data) const;
  // writes round((physical - offset) / factor) into its bits only, saturated
  // to [min, max] (when min < max; as raw steps, each limit rounded to the
  // nearest) and to the raw range; NaN writes raw 0. Returns false when the
  // value was NaN or saturated, true when it was written as asked
  bool encode(double physical, std::uint8_t* data) const;
  // the physical values it can carry: the raw range through factor and
  // offset, within [min, max] when given
  double lowest() const;
  double highest() const;
};

struct DbcMessage {
  std::uint32_t id = 0;   // 11-bit (standard) or 29-bit (extended) identifier
  bool extended = false;  // the DBC's id has bit 31 set
  std::string name;
  std::uint8_t dlc = 0;  // data bytes, 0..8 (classic CAN)
  std::string sender;
  std::string comment;  // its CM_ BO_, if any
  int line = 0;         // of its BO_ in the DBC
  std::vector<DbcSignal> signals;

  const DbcSignal* find(std::string_view signal) const;
};

struct Dbc {
  std::string version;
  std::string comment;  // the file's own CM_ "..."
  std::vector<std::string> nodes;
  std::vector<DbcMessage> messages;

  const DbcMessage* find(std::uint32_t id, bool extended = false) const;
  const DbcMessage* find(std::string_view name) const;
};

// parses a DBC file's text. source names it in errors: throws
// std::invalid_argument("source:line: what is wrong, what was expected") on
// bad syntax or an invalid bus (dlc over 8, a signal past its message or
// overlapping another, a repeated id or name, an unknown node, ...)
Dbc parse_dbc(std::string_view text, const std::string& source);

}  // namespace paddock::hal
