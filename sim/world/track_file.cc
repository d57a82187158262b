// track files: the CSV cone map of tracks/README.md, parsed with line-accurate errors.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "autonomy/common/format.h"
#include "sim/world/track.h"

namespace paddock::world {

namespace {

constexpr std::string_view kWhitespace = " \t\r\v\f";
constexpr std::string_view kTagList = "blue, yellow, orange, big_orange, unknown";

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(kWhitespace);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(kWhitespace);
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  std::size_t b = 0;
  for (;;) {
    const auto e = s.find(sep, b);
    out.push_back(s.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b));
    if (e == std::string_view::npos) return out;
    b = e + 1;
  }
}

std::vector<std::string_view> split_words(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b = s.find_first_not_of(kWhitespace, i);
    if (b == std::string_view::npos) break;
    auto e = s.find_first_of(kWhitespace, b);
    if (e == std::string_view::npos) e = s.size();
    out.push_back(s.substr(b, e - b));
    i = e;
  }
  return out;
}

// every error of a file names the file and line first
[[noreturn]] void fail(const std::string& source, int line, const std::string& what) {
  throw TrackError(source + ":" + std::to_string(line) + ": " + what);
}

// a finite decimal number, all of the field; `what` names the field in messages
double parse_number(std::string_view field, const std::string& source, int line, const std::string& what) {
  const std::string_view f = trim(field);
  double v = 0.0;
  const char* first = f.data();
  const char* last = f.data() + f.size();
  if (!f.empty() && *first == '+') ++first;  // from_chars rejects a leading '+'
  const auto r = std::from_chars(first, last, v);
  if (f.empty() || r.ec != std::errc() || r.ptr != last) {
    fail(source, line, "bad number '" + std::string(f) + "' for " + what + ", expected a decimal number such as 12.5");
  }
  if (!std::isfinite(v)) {
    fail(source, line, "non-finite number '" + std::string(f) + "' for " + what + ", expected a finite decimal number");
  }
  return v;
}

std::optional<ConeColor> color_from_tag(std::string_view tag) {
  for (ConeColor c : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange,
                      ConeColor::Unknown}) {
    if (cone_tag(c) == tag) return c;
  }
  return std::nullopt;
}

// "# start X Y YAW" and "# timekeeping X Y"; other '#' lines are comments
void parse_header_line(std::string_view body, int line, const std::string& source, TrackFile& f) {
  const auto words = split_words(body);
  if (words.empty()) return;
  if (words[0] == "start") {
    if (words.size() != 4) {
      fail(source, line, "malformed '# start' line: found " + std::to_string(words.size() - 1) +
                             " values, expected '# start X Y YAW' (m, m, rad)");
    }
    if (f.start) {
      fail(source, line, "second '# start' line (the first is on line " + std::to_string(f.start_line) +
                             "), expected one start pose per file");
    }
    Pose2 p;
    p.x = parse_number(words[1], source, line, "'# start' X");
    p.y = parse_number(words[2], source, line, "'# start' Y");
    p.yaw = parse_number(words[3], source, line, "'# start' YAW");
    f.start = p;
    f.start_line = line;
  } else if (words[0] == "timekeeping") {
    if (words.size() != 3) {
      fail(source, line, "malformed '# timekeeping' line: found " + std::to_string(words.size() - 1) +
                             " values, expected '# timekeeping X Y' (m, m)");
    }
    const double x = parse_number(words[1], source, line, "'# timekeeping' X");
    const double y = parse_number(words[2], source, line, "'# timekeeping' Y");
    f.timekeeping.push_back({x, y});
    f.timekeeping_lines.push_back(line);
  }
}

// doubled cones: a later cone of the same colour within kDoubledConeDistance of an earlier one
void find_doubles(TrackFile& f) {
  const std::size_t n = f.cones.size();
  for (std::size_t j = 1; j < n; ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      if (f.cones[i].color != f.cones[j].color) continue;
      const double d = distance(f.cones[i].position, f.cones[j].position);
      if (d > kDoubledConeDistance) continue;
      f.doubles.push_back({j, i, d});
      f.warnings.push_back(f.source + ":" + std::to_string(f.cone_lines[j]) + ": cone doubles the one at line " +
                           std::to_string(f.cone_lines[i]) + " (" + fixed(d, 3) + " m apart)");
      break;
    }
  }
}

// every cone, the start and the timekeeping posts within kMaxTrackSpan of the
// first cone: else the first line (in the file) of one that is not
void check_span(const TrackFile& f) {
  const Vec2 first = f.cones.front().position;
  int worst_line = 0;
  std::string what;
  auto consider = [&](Vec2 p, int line, const char* kind) {
    const double d = distance(p, first);
    if (d <= kMaxTrackSpan || (worst_line != 0 && line >= worst_line)) return;
    worst_line = line;
    what = std::string(kind) + " at (" + fixed(p.x, 1) + ", " + fixed(p.y, 1) + ") is " + fixed(d / 1000.0, 1) +
           " km from the first cone (line " + std::to_string(f.cone_lines.front()) + "), expected every cone, the start and the posts within " +
           fixed(kMaxTrackSpan / 1000.0, 0) + " km of it (a Formula Student track spans a few hundred metres)";
  };
  for (std::size_t i = 0; i < f.cones.size(); ++i) consider(f.cones[i].position, f.cone_lines[i], "cone");
  if (f.start) consider({f.start->x, f.start->y}, f.start_line, "'# start'");
  for (std::size_t i = 0; i < f.timekeeping.size(); ++i) consider(f.timekeeping[i], f.timekeeping_lines[i], "'# timekeeping' post");
  if (worst_line != 0) fail(f.source, worst_line, what);
}

}  // namespace

TrackFile parse_track(std::string_view text, const std::string& source) {
  TrackFile f;
  f.source = source;
  bool header_seen = false;
  int header_line = 0;
  int line = 0;
  for (std::string_view raw : split(text, '\n')) {
    ++line;
    const std::string_view s = trim(raw);
    if (s.empty()) continue;
    // header and comment lines
    if (s.front() == '#') {
      parse_header_line(s.substr(1), line, source, f);
      continue;
    }
    // the column header row comes before the first cone
    if (!header_seen) {
      const auto cols = split(s, ',');
      bool is_header = cols.size() == 3 && trim(cols[0]) == "tag" && trim(cols[1]) == "x" && trim(cols[2]) == "y";
      if (!is_header) {
        fail(source, line, "missing header row: found '" + std::string(s) +
                               "', expected the column names 'tag,x,y' before the first cone");
      }
      header_seen = true;
      header_line = line;
      continue;
    }
    // a cone row: tag,x,y
    const auto cols = split(s, ',');
    if (cols.size() != 3) {
      fail(source, line, "wrong column count: found " + std::to_string(cols.size()) +
                             " columns, expected 3 (tag,x,y)");
    }
    const std::string_view tag = trim(cols[0]);
    const auto color = color_from_tag(tag);
    if (!color) {
      fail(source, line, "unknown cone tag '" + std::string(tag) + "', expected one of " + std::string(kTagList));
    }
    if (f.cones.size() == kMaxTrackCones) {
      fail(source, line, "more than " + std::to_string(kMaxTrackCones) +
                             " cones: a Formula Student track has a few hundred; refused");
    }
    Cone c;
    c.color = *color;
    c.position.x = parse_number(cols[1], source, line, "x");
    c.position.y = parse_number(cols[2], source, line, "y");
    f.cones.push_back(c);
    f.cone_lines.push_back(line);
  }
  // the whole file has been read: what is still missing (a final newline
  // does not start another line)
  if (!text.empty() && text.back() == '\n') --line;
  const int last_line = std::max(line, 1);
  if (!header_seen) {
    fail(source, last_line, "missing header row: the file ends without the column names 'tag,x,y' and cone rows");
  }
  if (f.cones.empty()) {
    fail(source, header_line, "no cones: the header row is not followed by any cone row, expected rows 'tag,x,y'");
  }
  if (f.timekeeping.size() % 2 != 0) {
    fail(source, f.timekeeping_lines.back(),
         "'# timekeeping' post without a partner: posts come in pairs (one gate per pair), found " +
             std::to_string(f.timekeeping.size()));
  }
  check_span(f);
  find_doubles(f);
  return f;
}

}  // namespace paddock::world
