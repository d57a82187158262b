#include "autonomy/hal/dbc.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "autonomy/common/params.h"

namespace paddock::hal {

namespace {

// bit 31 of a DBC's BO_ id: an extended (29-bit) frame
constexpr std::uint64_t kDbcExtended = 0x80000000u;
constexpr std::uint32_t kStandardMax = 0x7FFu;
constexpr std::uint32_t kExtendedMax = 0x1FFFFFFFu;
// Vector's pseudo-message holding the signals of no message (CANdb++ writes
// it with a dlc of 0): its signals are read and dropped
constexpr std::uint64_t kIndependentSignals = 0xC0000000u;

// a mask of `length` ones
std::uint64_t ones(int length) { return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1; }

// the end of a signal's raw range (exclusive): 2^length unsigned, 2^(length - 1) signed
double raw_top(const DbcSignal& s) {
  const int bits = s.is_signed ? s.length - 1 : s.length;
  return bits >= 64 ? 18446744073709551616.0 : static_cast<double>(std::uint64_t{1} << bits);
}

// where a signal lies: bytes first..last read as one word (Intel little-, Motorola
// big-endian), the signal's least significant bit at bit `shift` of it
struct Window {
  int first, last, shift;
  bool big_endian;
};

// a Motorola signal's least significant bit, counted from the end of the frame
// read big-endian (byte 0 most significant); < 0 when it runs past byte 7
int motorola_lsb(const DbcSignal& s) { return (7 - s.start / 8) * 8 + s.start % 8 - s.length + 1; }

// the window of a signal that fits its frame
Window window(const DbcSignal& s) {
  if (s.order == ByteOrder::Intel) return {s.start / 8, (s.start + s.length - 1) / 8, s.start % 8, false};
  const int lsb = motorola_lsb(s);
  return {s.start / 8, 7 - lsb / 8, lsb % 8, true};
}

// a window's bytes as one word
std::uint64_t load(const std::uint8_t* data, const Window& w) {
  std::uint64_t v = 0;
  if (w.big_endian) {
    for (int i = w.first; i <= w.last; ++i) v = v << 8 | data[i];
  } else {
    for (int i = w.last; i >= w.first; --i) v = v << 8 | data[i];
  }
  return v;
}

// a word back into a window's bytes
void store(std::uint8_t* data, const Window& w, std::uint64_t v) {
  if (w.big_endian) {
    for (int i = w.last; i >= w.first; --i, v >>= 8) data[i] = static_cast<std::uint8_t>(v);
  } else {
    for (int i = w.first; i <= w.last; ++i, v >>= 8) data[i] = static_cast<std::uint8_t>(v);
  }
}

// whether the signal's bits all lie in a frame of dlc bytes
bool fits(const DbcSignal& s, int dlc) {
  if (s.start < 0 || s.start > 63 || s.length < 1 || s.length > 64) return false;
  if (s.order == ByteOrder::Intel) return s.start + s.length <= 8 * dlc;
  const int lsb = motorola_lsb(s);
  return lsb >= 0 && 7 - lsb / 8 < dlc;
}

// the frame bits (byte * 8 + bit) a fitting signal covers
std::uint64_t footprint(const DbcSignal& s) {
  const Window w = window(s);
  std::uint8_t data[8] = {};
  store(data, w, ones(s.length) << w.shift);
  std::uint64_t bits = 0;
  for (int i = 7; i >= 0; --i) bits = bits << 8 | data[i];
  return bits;
}

// the raw steps a signal saturates to, as doubles: its raw range, within the
// DBC's [min, max] when given (each limit rounded to the nearest step); the
// upper one of a signal over 53 bits may round up past the raw range. False
// when [min, max] reaches no raw step (then the raw range alone)
bool raw_limits(const DbcSignal& s, double& lo, double& hi) {
  const double top = raw_top(s);
  lo = s.is_signed ? -top : 0.0;
  hi = top - 1.0;
  if (s.min < s.max) {
    double a = std::round((s.min - s.offset) / s.factor), b = std::round((s.max - s.offset) / s.factor);
    if (a > b) std::swap(a, b);
    if (b < lo || a > hi) return false;
    lo = std::max(lo, a);
    hi = std::min(hi, b);
  }
  return true;
}

// 0x1A0
std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(v));
  return buf;
}

// a cursor over the DBC text that knows its line, and reads its tokens
class Cursor {
 public:
  Cursor(std::string_view text, const std::string& source) : s_(text), source_(source) {}

  int line() const { return line_; }
  bool done() const { return pos_ >= s_.size(); }
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw std::invalid_argument(source_ + ":" + std::to_string(line) + ": " + what);
  }
  [[noreturn]] void fail(const std::string& what) const { fail(line_, what); }

  // skips spaces and tabs on this line
  void blanks() {
    while (!done() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\r')) ++pos_;
  }
  // skips whitespace, line ends included
  void space() {
    for (blanks(); !done() && s_[pos_] == '\n'; blanks()) {
      ++pos_;
      ++line_;
    }
  }
  // skips the rest of this line
  void skip_line() {
    while (!done() && s_[pos_] != '\n') ++pos_;
    if (!done()) {
      ++pos_;
      ++line_;
    }
  }
  // at a line's start: whether the line is blank or indented (an NS_ block's)
  bool indented_or_blank() const {
    return !done() && std::string_view(" \t\r\n").find(s_[pos_]) != std::string_view::npos;
  }
  // the next character on this line, '\n' at its end
  char peek() {
    blanks();
    return done() ? '\n' : s_[pos_];
  }
  bool accept(char c) {
    if (peek() != c) return false;
    ++pos_;
    return true;
  }
  void expect(char c, const std::string& where) {
    if (!accept(c)) fail(std::string("expected '") + c + "' " + where + ", found " + found());
  }
  // nothing more on this line
  void end_line(const std::string& after) {
    if (peek() != '\n') fail("unexpected " + found() + " after " + after + ", expected the end of the line");
  }

  // the next token as errors quote it
  std::string found() {
    blanks();
    if (done()) return "the end of the file";
    if (s_[pos_] == '\n') return "the end of the line";
    std::size_t end = pos_ + 1;
    while (end < s_.size() && end - pos_ < 24 && !std::isspace(static_cast<unsigned char>(s_[end]))) ++end;
    return "'" + std::string(s_.substr(pos_, end - pos_)) + "'";
  }

  // an identifier: letters, digits and '_'
  std::string_view ident(const std::string& what) {
    const std::string_view t = run([](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (t.empty()) fail("expected " + what + ", found " + found());
    return t;
  }
  // an unsigned decimal integer
  std::uint64_t integer(const std::string& what) {
    const std::size_t at = (blanks(), pos_);
    const std::string_view t = run([](char c) { return c >= '0' && c <= '9'; });
    std::uint64_t v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || r.ec != std::errc()) {
      pos_ = at;
      fail("expected " + what + " (an unsigned integer), found " + found());
    }
    return v;
  }
  // a finite decimal number
  double number(const std::string& what) {
    const std::size_t at = (blanks(), pos_);
    std::string_view t =
        run([](char c) { return std::string_view("+-.0123456789eE").find(c) != std::string_view::npos; });
    if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
    double v = 0.0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size() || !std::isfinite(v)) {
      pos_ = at;
      fail("expected " + what + " (a number), found " + found());
    }
    return v;
  }
  // a double-quoted string, possibly over several lines; \" and \\ escape
  std::string quoted(const std::string& what) {
    if (peek() != '"') fail("expected " + what + " (a quoted string), found " + found());
    const int opened = line_;
    std::string out;
    for (++pos_;; ++pos_) {
      if (done()) fail(opened, "unterminated string: expected a closing '\"' for " + what);
      char c = s_[pos_];
      if (c == '"') break;
      if (c == '\\' && pos_ + 1 < s_.size()) c = s_[++pos_];
      if (c == '\n') ++line_;
      out += c;
    }
    ++pos_;
    return out;
  }
  // skips a statement to its ';' (it may span lines, quoted strings may hold ';')
  void skip_statement(int opened, std::string_view keyword) {
    while (!done() && s_[pos_] != ';') {
      if (s_[pos_] == '"') {
        quoted("a string in " + std::string(keyword));
        continue;
      }
      if (s_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (done()) fail(opened, "expected ';' to end " + std::string(keyword) + ", found the end of the file");
    ++pos_;
  }

 private:
  template <class Pred>
  std::string_view run(Pred in) {
    blanks();
    const std::size_t begin = pos_;
    while (!done() && in(s_[pos_])) ++pos_;
    return s_.substr(begin, pos_ - begin);
  }

  std::string_view s_;
  const std::string& source_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

// statements read and dropped: attributes, value tables, signal groups, ...
bool skipped(std::string_view kw) {
  static constexpr std::string_view kSkipped[] = {
      "BA_DEF_",        "BA_",        "BA_DEF_DEF_", "BA_DEF_REL_", "BA_REL_",       "BA_DEF_DEF_REL_",
      "BA_DEF_SGTYPE_", "BA_SGTYPE_", "VAL_",        "VAL_TABLE_",  "BO_TX_BU_",     "EV_",
      "ENVVAR_DATA_",   "SGTYPE_",    "SGTYPE_VAL_", "SIG_GROUP_",  "SIG_TYPE_REF_", "SG_MUL_VAL_",
      "CAT_DEF_",       "CAT_",       "FILTER",      "BU_SG_REL_",  "BU_EV_REL_",    "BU_BO_REL_"};
  return std::find(std::begin(kSkipped), std::end(kSkipped), kw) != std::end(kSkipped);
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& source) : c_(text, source) {}

  Dbc run() {
    for (c_.space(); !c_.done(); c_.space()) {
      const int line = c_.line();
      const std::string kw(c_.ident("a DBC keyword (VERSION, NS_, BS_, BU_, BO_, SG_, CM_, BA_, VAL_, ...)"));
      if (kw != "SG_") in_message_ = in_independent_ = false;
      if (kw == "VERSION") {
        dbc_.version = c_.quoted("the version");
        c_.end_line("VERSION");
      } else if (kw == "NS_") {
        // the new-symbols block: its names are the indented lines after it
        c_.expect(':', "after NS_");
        for (c_.skip_line(); c_.indented_or_blank();) c_.skip_line();
      } else if (kw == "BS_") {
        // the bit timing: obsolete, ignored
        c_.expect(':', "after BS_");
        c_.skip_line();
      } else if (kw == "BU_") {
        c_.expect(':', "after BU_");
        while (c_.peek() != '\n') dbc_.nodes.emplace_back(c_.ident("a node name"));
      } else if (kw == "BO_") {
        message(line);
      } else if (kw == "SG_") {
        signal(line);
      } else if (kw == "CM_") {
        comment(line);
      } else if (kw == "SIG_VALTYPE_") {
        c_.fail(line, "SIG_VALTYPE_: float signals are not supported, expected integer signals only");
      } else if (skipped(kw)) {
        c_.skip_statement(line, kw);
      } else {
        c_.fail(line, "unknown keyword '" + kw +
                          "', expected a DBC keyword (VERSION, NS_, BS_, BU_, BO_, SG_, CM_, BA_, VAL_, ...)");
      }
    }
    return std::move(dbc_);
  }

 private:
  // a node of BU_, or Vector's "no node"
  bool known_node(const std::string& n) const {
    return n == "Vector__XXX" || std::find(dbc_.nodes.begin(), dbc_.nodes.end(), n) != dbc_.nodes.end();
  }

  // BO_ <id> <name>: <dlc> <sender>
  void message(int line) {
    DbcMessage m;
    m.line = line;
    const std::uint64_t raw = c_.integer("the message id");
    m.name = c_.ident("the message name");
    c_.expect(':', "after the message name");
    const std::uint64_t dlc = c_.integer("the dlc");
    m.sender = c_.ident("the sending node");
    c_.end_line("the sending node");
    if (raw == kIndependentSignals) {
      in_independent_ = true;
      return;
    }
    const std::string what = "message " + m.name + ": ";
    m.extended = (raw & kDbcExtended) != 0;
    const std::uint64_t id = raw & ~kDbcExtended;
    if (raw > 0xFFFFFFFFu || id > (m.extended ? kExtendedMax : kStandardMax)) {
      c_.fail(line, what + "id " + std::to_string(raw) +
                        " out of range, expected an 11-bit id (0..2047) or 0x80000000 | a 29-bit id");
    }
    m.id = static_cast<std::uint32_t>(id);
    if (dlc > 8) c_.fail(line, what + "dlc " + std::to_string(dlc) + ", expected 0..8 (classic CAN)");
    m.dlc = static_cast<std::uint8_t>(dlc);
    if (!known_node(m.sender)) c_.fail(line, what + "sender " + m.sender + " is no node of BU_, expected one of them");
    for (const DbcMessage& o : dbc_.messages) {
      if (o.id == m.id && o.extended == m.extended) {
        c_.fail(line, what + "id " + hex(m.id) + " already used by message " + o.name + " (line " +
                          std::to_string(o.line) + "), expected unique ids");
      }
      if (o.name == m.name) {
        c_.fail(line, what + "name already used (line " + std::to_string(o.line) + "), expected unique message names");
      }
    }
    dbc_.messages.push_back(std::move(m));
    in_message_ = true;
  }

  // SG_ <name> : <start>|<length>@<order><sign> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
  void signal(int line) {
    if (!in_message_ && !in_independent_)
      c_.fail(line, "SG_ outside a message, expected it in the lines under its BO_");
    DbcSignal s;
    s.line = line;
    s.name = c_.ident("the signal name");
    if (c_.peek() != ':') {
      const std::string_view mux = c_.ident("':' after the signal name");
      if (mux == "M" || (mux.size() > 1 && mux[0] == 'm' && std::isdigit(static_cast<unsigned char>(mux[1]))))
        c_.fail(line, "signal " + s.name + ": multiplexed signals are not supported");
      c_.fail(line, "signal " + s.name + ": unexpected '" + std::string(mux) + "', expected ':' after the signal name");
    }
    c_.expect(':', "after the signal name");
    const std::uint64_t start = c_.integer("the start bit");
    c_.expect('|', "between the start bit and the length");
    const std::uint64_t length = c_.integer("the length");
    c_.expect('@', "before the byte order");
    if (c_.accept('0')) {
      s.order = ByteOrder::Motorola;
    } else if (!c_.accept('1')) {
      c_.fail("expected byte order 0 (Motorola) or 1 (Intel) after '@', found " + c_.found());
    }
    if (c_.accept('-')) {
      s.is_signed = true;
    } else if (!c_.accept('+')) {
      c_.fail("expected '+' (unsigned) or '-' (signed) after the byte order, found " + c_.found());
    }
    c_.expect('(', "before the factor");
    s.factor = c_.number("the factor");
    c_.expect(',', "between the factor and the offset");
    s.offset = c_.number("the offset");
    c_.expect(')', "after the offset");
    c_.expect('[', "before the minimum");
    s.min = c_.number("the minimum");
    c_.expect('|', "between the minimum and the maximum");
    s.max = c_.number("the maximum");
    c_.expect(']', "after the maximum");
    s.unit = c_.quoted("the unit");
    while (c_.peek() != '\n') {
      s.receivers.emplace_back(c_.ident("a receiving node"));
      c_.accept(',');
    }
    if (in_independent_) return;

    // the signal itself
    DbcMessage& m = dbc_.messages.back();
    const std::string what = "message " + m.name + ": signal " + s.name + ": ";
    if (length < 1 || length > 64) c_.fail(line, what + "length " + std::to_string(length) + ", expected 1..64 bits");
    if (start > 63) c_.fail(line, what + "start bit " + std::to_string(start) + ", expected 0..63");
    s.start = static_cast<int>(start);
    s.length = static_cast<int>(length);
    if (!fits(s, m.dlc)) {
      c_.fail(line, what + "bits " + std::to_string(start) + "|" + std::to_string(length) + "@" +
                        (s.order == ByteOrder::Intel ? "1" : "0") + " run past the message's " + std::to_string(m.dlc) +
                        " bytes, expected them within the dlc");
    }
    if (s.factor == 0.0) c_.fail(line, what + "factor 0, expected a non-zero factor");
    if (s.min > s.max) c_.fail(line, what + "minimum above maximum, expected [min|max] with min <= max");
    double lo = 0.0, hi = 0.0;
    if (!raw_limits(s, lo, hi)) {
      c_.fail(line, what + "[" + params::number(s.min) + "|" + params::number(s.max) + "] lies outside the [" +
                        params::number(s.lowest()) + ", " + params::number(s.highest()) +
                        "] its raw bits carry, expected a range they reach");
    }
    for (const std::string& r : s.receivers) {
      if (!known_node(r)) c_.fail(line, what + "receiver " + r + " is no node of BU_, expected one of them");
    }
    // against the message's other signals
    const std::uint64_t bits = footprint(s);
    for (const DbcSignal& o : m.signals) {
      if (o.name == s.name)
        c_.fail(line, what + "name already used in the message (line " + std::to_string(o.line) + ")");
      if ((footprint(o) & bits) != 0) {
        c_.fail(line,
                what + "overlaps signal " + o.name + " (line " + std::to_string(o.line) + "), expected disjoint bits");
      }
    }
    m.signals.push_back(std::move(s));
  }

  // CM_ ["text" | BU_ <node> "text" | BO_ <id> "text" | SG_ <id> <signal> "text" | EV_ <var> "text"];
  void comment(int line) {
    if (c_.peek() == '"') {
      dbc_.comment = c_.quoted("the comment");
    } else {
      const std::string_view kind = c_.ident("BU_, BO_, SG_, EV_ or a quoted comment after CM_");
      if (kind == "BU_" || kind == "EV_") {
        c_.ident("a name");
        c_.quoted("the comment");
      } else if (kind == "BO_" || kind == "SG_") {
        const std::uint64_t raw = c_.integer("the message id");
        const std::string sig = kind == "SG_" ? std::string(c_.ident("the signal name")) : std::string();
        std::string text = c_.quoted("the comment");
        if (raw != kIndependentSignals) {
          DbcMessage* m = nullptr;
          for (DbcMessage& o : dbc_.messages) {
            if (o.id == (raw & ~kDbcExtended) && o.extended == ((raw & kDbcExtended) != 0)) m = &o;
          }
          if (!m)
            c_.fail(line, "CM_ " + std::string(kind) + " " + std::to_string(raw) +
                              ": no such message, expected the id of a BO_");
          if (sig.empty()) {
            m->comment = std::move(text);
          } else {
            auto it =
                std::find_if(m->signals.begin(), m->signals.end(), [&](const DbcSignal& s) { return s.name == sig; });
            if (it == m->signals.end())
              c_.fail(line, "CM_ SG_: message " + m->name + " has no signal " + sig + ", expected one of its SG_");
            it->comment = std::move(text);
          }
        }
      } else {
        c_.fail(line, "CM_ " + std::string(kind) + ": expected BU_, BO_, SG_, EV_ or a quoted comment");
      }
    }
    c_.space();
    c_.expect(';', "to end CM_");
  }

  Cursor c_;
  Dbc dbc_;
  bool in_message_ = false;      // SG_ lines go to the last BO_
  bool in_independent_ = false;  // SG_ lines of Vector's pseudo-message: dropped
};

}  // namespace

std::uint64_t DbcSignal::raw(const std::uint8_t* data) const {
  const Window w = window(*this);
  const std::uint64_t mask = ones(length);
  std::uint64_t v = load(data, w) >> w.shift & mask;
  // sign extension: the top bit of a signed signal fills the bits above it
  if (is_signed && length < 64 && (v >> (length - 1) & 1)) v |= ~mask;
  return v;
}

double DbcSignal::decode(const std::uint8_t* data) const {
  const std::uint64_t v = raw(data);
  return (is_signed ? static_cast<double>(static_cast<std::int64_t>(v)) : static_cast<double>(v)) * factor + offset;
}

bool DbcSignal::encode(double physical, std::uint8_t* data) const {
  // the raw steps asked for, saturated to the limits (NaN: raw 0)
  const bool nan = std::isnan(physical);
  double r = nan ? 0.0 : std::round((physical - offset) / factor);
  bool exact = !nan;
  // (a value within [min, max] rounds within its limits: only the raw range to check)
  const double top = raw_top(*this);
  if (!nan && (r < (is_signed ? -top : 0.0) || r > top - 1.0 || (min < max && (physical < min || physical > max)))) {
    double lo = 0.0, hi = 0.0;
    raw_limits(*this, lo, hi);
    if (r < lo || r > hi) {
      r = std::clamp(r, lo, hi);
      exact = false;
    }
  }
  // to an integer: top is exact as a double, its step below may not be (over 53 bits)
  const std::uint64_t mask = ones(length);
  std::uint64_t v = 0;
  if (r >= top) {
    v = is_signed ? mask >> 1 : mask;
    exact = false;
  } else {
    v = is_signed ? static_cast<std::uint64_t>(static_cast<std::int64_t>(r)) : static_cast<std::uint64_t>(r);
  }
  // into its bits only
  const Window w = window(*this);
  store(data, w, (load(data, w) & ~(mask << w.shift)) | (v & mask) << w.shift);
  return exact;
}

double DbcSignal::lowest() const {
  double lo = 0.0, hi = 0.0;
  raw_limits(*this, lo, hi);
  return std::min(lo * factor + offset, hi * factor + offset);
}

double DbcSignal::highest() const {
  double lo = 0.0, hi = 0.0;
  raw_limits(*this, lo, hi);
  return std::max(lo * factor + offset, hi * factor + offset);
}

const DbcSignal* DbcMessage::find(std::string_view signal) const {
  for (const DbcSignal& s : signals) {
    if (s.name == signal) return &s;
  }
  return nullptr;
}

const DbcMessage* Dbc::find(std::uint32_t id, bool extended) const {
  for (const DbcMessage& m : messages) {
    if (m.id == id && m.extended == extended) return &m;
  }
  return nullptr;
}

const DbcMessage* Dbc::find(std::string_view name) const {
  for (const DbcMessage& m : messages) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

Dbc parse_dbc(std::string_view text, const std::string& source) { return Parser(text, source).run(); }

}  // namespace paddock::hal
