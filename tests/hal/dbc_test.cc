// the DBC parser and the signal codec: hand-worked byte patterns for both byte
// orders, saturation, a brute-force check of random layouts against a
// bit-by-bit reference, and the parser's reading and refusals.
#include "autonomy/hal/dbc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace paddock::hal {
namespace {

DbcSignal signal(ByteOrder order, int start, int length, bool is_signed, double factor = 1.0, double offset = 0.0) {
  DbcSignal s;
  s.name = "s";
  s.order = order;
  s.start = start;
  s.length = length;
  s.is_signed = is_signed;
  s.factor = factor;
  s.offset = offset;
  return s;
}

std::uint64_t ones(int length) { return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1; }

// ------------------------------------------------------------ the reference

// the frame bit (byte * 8 + bit) of a signal's i-th bit from its least
// significant, walking the DBC's numbering one bit at a time; -1 off the frame
int ref_bit(const DbcSignal& s, int i) {
  if (s.order == ByteOrder::Intel) return s.start + i < 64 ? s.start + i : -1;
  // Motorola: from the most significant bit at start, down a byte's bits, then the next byte's bit 7
  int b = s.start;
  for (int step = 0; step < s.length - 1 - i; ++step) b = b % 8 == 0 ? b + 15 : b - 1;
  return b < 64 ? b : -1;
}

bool ref_fits(const DbcSignal& s) {
  for (int i = 0; i < s.length; ++i) {
    if (ref_bit(s, i) < 0) return false;
  }
  return true;
}

std::uint64_t ref_footprint(const DbcSignal& s) {
  std::uint64_t bits = 0;
  for (int i = 0; i < s.length; ++i) bits |= std::uint64_t{1} << ref_bit(s, i);
  return bits;
}

std::uint64_t ref_get(const DbcSignal& s, const std::uint8_t* data) {
  std::uint64_t v = 0;
  for (int i = 0; i < s.length; ++i) {
    const int b = ref_bit(s, i);
    v |= static_cast<std::uint64_t>(data[b / 8] >> (b % 8) & 1) << i;
  }
  return v;
}

std::uint64_t sign_extend(const DbcSignal& s, std::uint64_t v) {
  return s.is_signed && s.length < 64 && (v >> (s.length - 1) & 1) ? v | ~ones(s.length) : v;
}

std::uint64_t frame_bits(const std::uint8_t* data) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = v << 8 | data[i];
  return v;
}

// ------------------------------------------------------------ hand-worked patterns

// the DBC descriptions' Motorola example: 12 bits, start bit 7 (byte 0's most
// significant), so byte 0 whole then byte 1's high nibble
TEST(Dbc, Motorola12BitAtStart7) {
  const DbcSignal s = signal(ByteOrder::Motorola, 7, 12, false);
  const std::uint8_t data[8] = {0xAB, 0xCD};
  EXPECT_EQ(s.raw(data), 0xABCu);
  std::uint8_t out[8] = {0xFF, 0xFF, 0xFF};
  EXPECT_TRUE(s.encode(0x123, out));
  EXPECT_EQ(out[0], 0x12);
  EXPECT_EQ(out[1], 0x3F);  // low nibble untouched
  EXPECT_EQ(out[2], 0xFF);
}

// a Motorola signal starting mid-byte: byte 0 bits 2..0, then byte 1 bits 7..5
TEST(Dbc, MotorolaMidByte) {
  const DbcSignal s = signal(ByteOrder::Motorola, 2, 6, false);
  const std::uint8_t data[8] = {0b00000101, 0b10100000};
  EXPECT_EQ(s.raw(data), 0b101101u);
}

// the Intel example: signed 16 bits at start bit 8, byte 1 low, byte 2 high
TEST(Dbc, IntelSigned16AtStart8) {
  const DbcSignal s = signal(ByteOrder::Intel, 8, 16, true, 0.1);
  const std::uint8_t data[8] = {0x00, 0x34, 0xFE};
  EXPECT_EQ(static_cast<std::int64_t>(s.raw(data)), -460);  // 0xFE34
  EXPECT_DOUBLE_EQ(s.decode(data), -46.0);
  std::uint8_t out[8] = {0xAA, 0, 0, 0xBB};
  EXPECT_TRUE(s.encode(-46.0, out));
  EXPECT_EQ(out[0], 0xAA);
  EXPECT_EQ(out[1], 0x34);
  EXPECT_EQ(out[2], 0xFE);
  EXPECT_EQ(out[3], 0xBB);
}

// an Intel signal across a byte boundary: bits 4..11
TEST(Dbc, IntelAcrossBytes) {
  const DbcSignal s = signal(ByteOrder::Intel, 4, 8, false);
  const std::uint8_t data[8] = {0xA0, 0x0B};
  EXPECT_EQ(s.raw(data), 0xBAu);
}

// 64-bit signals: the whole frame, little- and big-endian
TEST(Dbc, SixtyFourBits) {
  const std::uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(signal(ByteOrder::Intel, 0, 64, false).raw(data), 0x0807060504030201u);
  EXPECT_EQ(signal(ByteOrder::Motorola, 7, 64, false).raw(data), 0x0102030405060708u);
  const std::uint8_t all[8] = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  EXPECT_EQ(signal(ByteOrder::Intel, 0, 64, true).decode(all), -1.0);
  EXPECT_EQ(signal(ByteOrder::Intel, 0, 64, false).decode(all), 18446744073709551616.0);
}

// ------------------------------------------------------------ encoding's edges

TEST(Dbc, EncodeSaturatesToTheRawRange) {
  std::uint8_t d[8] = {};
  const DbcSignal s8 = signal(ByteOrder::Intel, 0, 8, true);
  EXPECT_FALSE(s8.encode(200.0, d));
  EXPECT_EQ(s8.decode(d), 127.0);
  EXPECT_FALSE(s8.encode(-200.0, d));
  EXPECT_EQ(s8.decode(d), -128.0);
  EXPECT_TRUE(s8.encode(-128.0, d));
  const DbcSignal u8 = signal(ByteOrder::Intel, 0, 8, false);
  EXPECT_FALSE(u8.encode(-1.0, d));
  EXPECT_EQ(u8.decode(d), 0.0);
  EXPECT_TRUE(u8.encode(255.4, d));  // rounds to 255: in range
  EXPECT_EQ(u8.decode(d), 255.0);
  // 64 bits: the ends of int64 and uint64
  const DbcSignal s64 = signal(ByteOrder::Intel, 0, 64, true), u64 = signal(ByteOrder::Motorola, 7, 64, false);
  EXPECT_FALSE(s64.encode(1e30, d));
  EXPECT_EQ(s64.raw(d), static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()));
  EXPECT_FALSE(s64.encode(-1e30, d));
  EXPECT_EQ(s64.raw(d), static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::min()));
  EXPECT_FALSE(u64.encode(std::ldexp(1.0, 64), d));
  EXPECT_EQ(u64.raw(d), ~std::uint64_t{0});
  EXPECT_TRUE(u64.encode(std::ldexp(1.0, 63), d));
  EXPECT_EQ(u64.raw(d), std::uint64_t{1} << 63);
}

TEST(Dbc, EncodeSaturatesToMinMax) {
  // a fraction: 14 bits of 1e-4 would carry 1.6383, the DBC's [0|1] clips first
  DbcSignal f = signal(ByteOrder::Intel, 0, 14, false, 1e-4);
  f.min = 0.0;
  f.max = 1.0;
  std::uint8_t d[8] = {};
  EXPECT_FALSE(f.encode(1.5, d));
  EXPECT_EQ(f.raw(d), 10000u);
  EXPECT_TRUE(f.encode(1.00004, d));  // rounds onto the limit: not saturated
  EXPECT_EQ(f.raw(d), 10000u);
  EXPECT_FALSE(f.encode(-0.2, d));
  EXPECT_EQ(f.raw(d), 0u);
  EXPECT_EQ(f.lowest(), 0.0);
  EXPECT_EQ(f.highest(), 1.0);
  // [0|0]: no range given, the raw range alone
  f.max = 0.0;
  EXPECT_TRUE(f.encode(1.5, d));
  EXPECT_EQ(f.raw(d), 15000u);
  EXPECT_DOUBLE_EQ(f.highest(), 1.6383);
  // a negative factor turns the range around
  DbcSignal n = signal(ByteOrder::Intel, 0, 8, false, -0.5);
  n.min = -10.0;
  n.max = 0.0;
  EXPECT_TRUE(n.encode(-3.0, d));
  EXPECT_EQ(n.raw(d), 6u);
  EXPECT_FALSE(n.encode(-50.0, d));
  EXPECT_EQ(n.raw(d), 20u);
  EXPECT_FALSE(n.encode(1.0, d));
  EXPECT_EQ(n.raw(d), 0u);
  EXPECT_EQ(n.lowest(), -10.0);
  EXPECT_EQ(n.highest(), 0.0);
}

TEST(Dbc, EncodeNonFinite) {
  const DbcSignal s = signal(ByteOrder::Intel, 8, 16, true, 0.01, 5.0);
  std::uint8_t d[8] = {0xFF, 0xFF, 0xFF, 0xFF};
  EXPECT_FALSE(s.encode(std::numeric_limits<double>::quiet_NaN(), d));
  EXPECT_EQ(s.raw(d), 0u);  // NaN: raw 0 (here the offset, 5)
  EXPECT_EQ(d[0], 0xFF);
  EXPECT_EQ(d[3], 0xFF);
  EXPECT_FALSE(s.encode(std::numeric_limits<double>::infinity(), d));
  EXPECT_EQ(s.raw(d), 0x7FFFu);
  EXPECT_FALSE(s.encode(-std::numeric_limits<double>::infinity(), d));
  EXPECT_EQ(s.raw(d), ~std::uint64_t{0} << 15);
}

// ------------------------------------------------------------ brute force

// a DBC of one 8-byte message holding the signals
std::string dbc_text(const std::vector<DbcSignal>& signals) {
  std::string t = "VERSION \"\"\nBU_: A\nBO_ 291 M: 8 A\n";
  for (const DbcSignal& s : signals) {
    char line[200];
    std::snprintf(line, sizeof line, " SG_ %s : %d|%d@%d%c (%.17g,%.17g) [0|0] \"\" A\n", s.name.c_str(), s.start,
                  s.length, s.order == ByteOrder::Intel ? 1 : 0, s.is_signed ? '-' : '+', s.factor, s.offset);
    t += line;
  }
  return t;
}

// random layouts in an 8-byte frame: the parser takes exactly the ones the
// reference says fit and do not overlap; every signal encodes and decodes its
// value exactly, touches no bit outside itself, and reads what the reference reads
TEST(Dbc, RandomLayoutsAgainstTheBitByBitReference) {
  std::mt19937_64 rng(20240611);
  const double factors[] = {1.0, 0.5, 0.25, 2.0, -1.0, -0.125};
  int signals_checked = 0, refusals_checked = 0;
  for (int layout = 0; layout < 1500; ++layout) {
    std::vector<DbcSignal> sig;
    std::uint64_t used = 0;
    for (int attempt = 0; attempt < 12; ++attempt) {
      const int length = rng() % 2 ? 1 + static_cast<int>(rng() % 64) : 1 + static_cast<int>(rng() % 16);
      DbcSignal s =
          signal(rng() % 2 ? ByteOrder::Intel : ByteOrder::Motorola, static_cast<int>(rng() % 64), length,
                 rng() % 2 == 0, factors[rng() % 6], length <= 48 ? static_cast<double>(rng() % 21) - 10.0 : 0.0);
      s.name = "s" + std::to_string(sig.size());
      const bool ok = ref_fits(s) && (ref_footprint(s) & used) == 0;
      if (!ok && attempt % 4 == 0) {
        // the parser refuses what the reference says does not fit or overlaps
        std::vector<DbcSignal> bad = sig;
        bad.push_back(s);
        EXPECT_THROW(parse_dbc(dbc_text(bad), "r.dbc"), std::invalid_argument) << dbc_text(bad);
        ++refusals_checked;
      }
      if (!ok) continue;
      used |= ref_footprint(s);
      sig.push_back(s);
    }
    // the parser takes the layout as it is
    const Dbc dbc = parse_dbc(dbc_text(sig), "r.dbc");
    ASSERT_EQ(dbc.messages.size(), 1u);
    ASSERT_EQ(dbc.messages[0].signals.size(), sig.size());

    std::uint8_t data[8];
    for (std::uint8_t& b : data) b = static_cast<std::uint8_t>(rng());
    std::vector<double> values;
    for (const DbcSignal& s : dbc.messages[0].signals) {
      ASSERT_EQ(s.raw(data), sign_extend(s, ref_get(s, data))) << s.start << "|" << s.length;
      // a raw value a double holds exactly (at most 50 significant bits)
      std::uint64_t raw = rng() & ones(s.length);
      if (s.length > 50) raw &= ~ones(s.length - 50);
      const std::uint64_t ext = sign_extend(s, raw);
      const double physical =
          (s.is_signed ? static_cast<double>(static_cast<std::int64_t>(ext)) : static_cast<double>(ext)) * s.factor +
          s.offset;
      const std::uint64_t before = frame_bits(data), mine = ref_footprint(s);
      ASSERT_TRUE(s.encode(physical, data)) << s.start << "|" << s.length << " " << physical;
      EXPECT_EQ(frame_bits(data) & ~mine, before & ~mine) << "bits outside " << s.start << "|" << s.length;
      EXPECT_EQ(ref_get(s, data), raw);
      EXPECT_EQ(s.raw(data), ext);
      EXPECT_EQ(s.decode(data), physical);
      values.push_back(physical);
      ++signals_checked;
    }
    // every signal still holds its value once all are written
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(dbc.messages[0].signals[i].decode(data), values[i]);
  }
  EXPECT_GT(signals_checked, 5000);
  EXPECT_GT(refusals_checked, 500);
}

// ------------------------------------------------------------ the parser

// what a real tool writes around the messages: NS_, BS_, attributes, value
// tables, multi-line comments, extended ids, Vector's pseudo-message
constexpr const char* kFull = R"(VERSION "1.0"


NS_ :
	NS_DESC_
	CM_
	BA_DEF_
	VAL_

BS_:

BU_: ECU Logger
VAL_TABLE_ Gear 2 "Two" 1 "One"
 0 "Neutral" ;

BO_ 2566844672 Engine: 8 ECU
 SG_ Rpm : 7|16@0+ (0.25,0) [0|16383.75] "1/min"  Logger,Vector__XXX
 SG_ Temp : 16|8@1- (1,-40) [-40|87] "degC" Logger

BO_ 100 Gear: 1 Logger
 SG_ Gear : 0|3@1+ (1,0) [0|0] "" ECU

BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX
 SG_ Orphan : 0|8@1+ (1,0) [0|0] "" Vector__XXX

CM_ "A bus; its comment
over two lines";
CM_ BU_ ECU "the engine";
CM_ BO_ 2566844672 "engine data, line one;
line two with a \"quote\"";
CM_ SG_ 2566844672 Rpm "crank speed";
CM_ SG_ 3221225472 Orphan "dropped with its message";
BA_DEF_ BO_ "GenMsgCycleTime" INT 0 65535;
BA_DEF_DEF_ "GenMsgCycleTime" 0;
BA_ "GenMsgCycleTime" BO_ 100
  20;
VAL_ 100 Gear 2 "Two"
  1 "One; or first" 0 "Neutral" ;
)";

TEST(DbcParse, ReadsARealToolsFile) {
  const Dbc dbc = parse_dbc(kFull, "full.dbc");
  EXPECT_EQ(dbc.version, "1.0");
  EXPECT_EQ(dbc.comment, "A bus; its comment\nover two lines");
  EXPECT_EQ(dbc.nodes, (std::vector<std::string>{"ECU", "Logger"}));
  ASSERT_EQ(dbc.messages.size(), 2u);  // the pseudo-message is dropped
  const DbcMessage* engine = dbc.find(0x18FEF100, true);
  ASSERT_NE(engine, nullptr);
  EXPECT_EQ(engine, dbc.find("Engine"));
  EXPECT_EQ(dbc.find(0x18FEF100, false), nullptr);
  EXPECT_EQ(engine->dlc, 8);
  EXPECT_EQ(engine->sender, "ECU");
  EXPECT_EQ(engine->line, 16);
  EXPECT_EQ(engine->comment, "engine data, line one;\nline two with a \"quote\"");
  const DbcSignal* rpm = engine->find("Rpm");
  ASSERT_NE(rpm, nullptr);
  EXPECT_EQ(rpm->order, ByteOrder::Motorola);
  EXPECT_EQ(rpm->start, 7);
  EXPECT_EQ(rpm->length, 16);
  EXPECT_FALSE(rpm->is_signed);
  EXPECT_EQ(rpm->factor, 0.25);
  EXPECT_EQ(rpm->max, 16383.75);
  EXPECT_EQ(rpm->unit, "1/min");
  EXPECT_EQ(rpm->receivers, (std::vector<std::string>{"Logger", "Vector__XXX"}));
  EXPECT_EQ(rpm->comment, "crank speed");
  EXPECT_EQ(rpm->line, 17);
  const DbcSignal* temp = engine->find("Temp");
  ASSERT_NE(temp, nullptr);
  EXPECT_TRUE(temp->is_signed);
  EXPECT_EQ(temp->offset, -40.0);
  EXPECT_EQ(engine->find("Orphan"), nullptr);
  EXPECT_EQ(dbc.find(100)->signals.at(0).name, "Gear");
  EXPECT_EQ(dbc.find("Orphan"), nullptr);
  const std::uint8_t d[8] = {0x1F, 0x40, 0x19};
  EXPECT_EQ(rpm->decode(d), 2000.0);  // 0x1F40 / 4
  EXPECT_EQ(temp->decode(d), -15.0);  // 25 - 40
}

// the error text of parsing `text`, "" when it parses
std::string error(const std::string& text) {
  try {
    parse_dbc(text, "t.dbc");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// a one-message DBC: line 3 is the BO_, line 4 the SG_
std::string one(const std::string& bo, const std::string& sg) {
  return "VERSION \"\"\nBU_: A B\n" + bo + "\n" + sg + "\n";
}

TEST(DbcParse, RefusesWithSourceLineAndWhatWasExpected) {
  const std::string sg = " SG_ x : 0|8@1+ (1,0) [0|0] \"\" B";
  // the message
  EXPECT_EQ(error(one("BO_ 1 M: 9 A", sg)), "t.dbc:3: message M: dlc 9, expected 0..8 (classic CAN)");
  EXPECT_EQ(error(one("BO_ 2048 M: 8 A", sg)).rfind("t.dbc:3: message M: id 2048 out of range", 0), 0u);
  EXPECT_EQ(error(one("BO_ 3758096384 M: 8 A", sg)).rfind("t.dbc:3: message M: id", 0), 0u);  // bits 29, 30 set
  EXPECT_EQ(error(one("BO_ 1 M: 8 C", sg)), "t.dbc:3: message M: sender C is no node of BU_, expected one of them");
  EXPECT_EQ(error(one("BO_ 1 M 8 A", sg)), "t.dbc:3: expected ':' after the message name, found '8'");
  EXPECT_EQ(error(one("BO_ 1 M: 8 A B", sg)),
            "t.dbc:3: unexpected 'B' after the sending node, expected the end of the line");
  EXPECT_EQ(error(one("BO_ 1 M: 1 A\nBO_ 1 N: 1 A", "")),
            "t.dbc:4: message N: id 0x1 already used by message M (line 3), expected unique ids");
  EXPECT_EQ(error(one("BO_ 1 M: 1 A\nBO_ 2 M: 1 A", "")),
            "t.dbc:4: message M: name already used (line 3), expected unique message names");
  EXPECT_EQ(error(one("BO_ 2147483649 M: 1 A\nBO_ 1 N: 1 A", "")), "");  // extended 1 and standard 1 differ
  // the signal's syntax
  const std::string bo = "BO_ 1 M: 2 A";
  EXPECT_EQ(error(one(bo, " SG_ x M : 0|8@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: signal x: multiplexed signals are not supported");
  EXPECT_EQ(error(one(bo, " SG_ x m3 : 0|8@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: signal x: multiplexed signals are not supported");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@2+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: expected byte order 0 (Motorola) or 1 (Intel) after '@', found '2+'");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1* (1,0) [0|0] \"\" B")),
            "t.dbc:4: expected '+' (unsigned) or '-' (signed) after the byte order, found '*'");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (1;0) [0|0] \"\" B")),
            "t.dbc:4: expected ',' between the factor and the offset, found ';0)'");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (x,0) [0|0] \"\" B")),
            "t.dbc:4: expected the factor (a number), found 'x,0)'");
  EXPECT_EQ(error(one(bo, " SG_ x : a|8@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: expected the start bit (an unsigned integer), found 'a|8@1+'");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (1,0) [0|0] B")), "t.dbc:4: expected the unit (a quoted string), found 'B'");
  // the signal's layout and values
  EXPECT_EQ(error(one(bo, " SG_ x : 0|0@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: message M: signal x: length 0, expected 1..64 bits");
  EXPECT_EQ(error(one(bo, " SG_ x : 64|1@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: message M: signal x: start bit 64, expected 0..63");
  EXPECT_EQ(error(one(bo, " SG_ x : 9|8@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:4: message M: signal x: bits 9|8@1 run past the message's 2 bytes, expected them within the dlc");
  EXPECT_EQ(error(one(bo, " SG_ x : 12|8@0+ (1,0) [0|0] \"\" B")),  // byte 1 bits 4..0, then byte 2
            "t.dbc:4: message M: signal x: bits 12|8@0 run past the message's 2 bytes, expected them within the dlc");
  EXPECT_EQ(error(one(bo, " SG_ x : 12|5@0+ (1,0) [0|0] \"\" B")), "");  // byte 1 bits 4..0: fits
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (0,0) [0|0] \"\" B")),
            "t.dbc:4: message M: signal x: factor 0, expected a non-zero factor");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (1,0) [2|1] \"\" B")),
            "t.dbc:4: message M: signal x: minimum above maximum, expected [min|max] with min <= max");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|4@1+ (1,0) [100|200] \"\" B")),
            "t.dbc:4: message M: signal x: [100|200] lies outside the [0, 15] its raw bits carry, expected a range "
            "they reach");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|4@1+ (1,0) [10|200] \"\" B")), "");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (1,0) [0|0] \"\" C")),
            "t.dbc:4: message M: signal x: receiver C is no node of BU_, expected one of them");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (1,0) [0|0] \"\" B\n SG_ y : 7|1@0+ (1,0) [0|0] \"\" B")),
            "t.dbc:5: message M: signal y: overlaps signal x (line 4), expected disjoint bits");
  EXPECT_EQ(error(one(bo, " SG_ x : 0|8@1+ (1,0) [0|0] \"\" B\n SG_ x : 8|8@1+ (1,0) [0|0] \"\" B")),
            "t.dbc:5: message M: signal x: name already used in the message (line 4)");
  // statements
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\n\n SG_ x : 0|8@1+ (1,0) [0|0] \"\" A\n"),
            "t.dbc:4: SG_ outside a message, expected it in the lines under its BO_");
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nBO_ 1 M: 1 A\nCM_ SG_ 1 y \"no such\";\n"),
            "t.dbc:4: CM_ SG_: message M has no signal y, expected one of its SG_");
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nCM_ BO_ 7 \"no such\";\n"),
            "t.dbc:3: CM_ BO_ 7: no such message, expected the id of a BO_");
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nBO_ 1 M: 1 A\nCM_ BO_ 1 \"text\"\nBA_ \"x\" 1;\n"),
            "t.dbc:5: expected ';' to end CM_, found 'BA_'");
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nBA_ \"x\" BO_ 1\n 20\n"),
            "t.dbc:3: expected ';' to end BA_, found the end of the file");
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nSIG_VALTYPE_ 1 x : 1;\n"),
            "t.dbc:3: SIG_VALTYPE_: float signals are not supported, expected integer signals only");
  EXPECT_EQ(error("VERSION \"\"\n\nBO_TX_BU_ 1 : A;\nFOO_ 1;\n")
                .rfind("t.dbc:4: unknown keyword 'FOO_', expected a DBC keyword", 0),
            0u);
  EXPECT_EQ(error("VERSION \"\"\n}\n").rfind("t.dbc:2: expected a DBC keyword", 0), 0u);
  // an unterminated string names the line it opened on
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nCM_ \"runs off\n\nthe end;\n"),
            "t.dbc:3: unterminated string: expected a closing '\"' for the comment");
  EXPECT_EQ(error("VERSION \"\"\nBU_: A\nVAL_ 1 x 0 \"off ;\n"),
            "t.dbc:3: unterminated string: expected a closing '\"' for a string in VAL_");
}

}  // namespace
}  // namespace paddock::hal
