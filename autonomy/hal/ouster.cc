// the Ouster LEGACY lidar packets (ouster.h). Cited: Ouster Software User
// Manual (firmware v2.x), "Lidar Data Format" and "Lidar Range to XYZ".
#include "autonomy/hal/ouster.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace paddock::hal::ouster {
namespace {

using nlohmann::json;

// the packets' integers are little-endian: written and read with memcpy
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the Ouster packet codec assumes a little-endian machine");

// "Lidar Data Format", legacy: an azimuth block is a 16-byte header
// (timestamp u64 ns at 0, measurement_id u16 at 8, frame_id u16 at 10,
// encoder_count u32 at 12), a 12-byte data block per pixel (range u32 at 0,
// reflectivity u16 at 4, signal u16 at 6, near_ir u16 at 8, unused u16 at 10)
// and a u32 status
constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kPixelBytes = 12;
constexpr std::size_t kStatusBytes = 4;
constexpr int kMaxPixels = 1024;
constexpr int kMaxColumns = 65536;  // measurement_id is a u16

// RangeImage::Pixel is a data block's layout
static_assert(sizeof(RangeImage::Pixel) == kPixelBytes && offsetof(RangeImage::Pixel, range_mm) == 0 &&
                  offsetof(RangeImage::Pixel, reflectivity) == 4 && offsetof(RangeImage::Pixel, signal) == 6 &&
                  offsetof(RangeImage::Pixel, near_ir) == 8,
              "RangeImage::Pixel must lay out as a data block");

std::size_t column_bytes(int pixels) {
  return kHeaderBytes + kPixelBytes * static_cast<std::size_t>(pixels) + kStatusBytes;
}

template <class T>
void put(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}
template <class T>
T get(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// the signed step from frame a to frame b, modulo 2^16 (> 0: b is newer)
int frame_step(std::uint16_t a, std::uint16_t b) {
  const int d = (static_cast<int>(b) - static_cast<int>(a)) & 0xFFFF;
  return d >= 0x8000 ? d - 0x10000 : d;
}

// the sensor's lidar modes: columns per rotation x rotations a second
struct Mode {
  const char* name;
  int columns;
  double frequency;  // Hz
};
constexpr Mode kModes[] = {{"512x10", 512, 10.0},   {"512x20", 512, 20.0},   {"1024x10", 1024, 10.0},
                           {"1024x20", 1024, 20.0}, {"2048x10", 2048, 10.0}, {"4096x5", 4096, 5.0}};
constexpr const char* kModeList = "512x10, 512x20, 1024x10, 1024x20, 2048x10, 4096x5";

std::string mode_name(const SensorInfo& info) {
  return std::to_string(info.columns_per_frame) + "x" + std::to_string(std::lround(info.frequency));
}

// "" when m (row-major 4x4) is a rotation about z plus a translation
std::string z_rotation_problem(const std::array<double, 16>& m) {
  for (const double v : m) {
    if (!std::isfinite(v)) return "a number is not finite";
  }
  constexpr double tol = 1e-6;
  const double c = m[0], s = m[4];
  const bool ok = std::abs(m[5] - c) <= tol && std::abs(m[1] + s) <= tol && std::abs(c * c + s * s - 1.0) <= tol &&
                  std::abs(m[2]) <= tol && std::abs(m[6]) <= tol && std::abs(m[8]) <= tol && std::abs(m[9]) <= tol &&
                  std::abs(m[10] - 1.0) <= tol && std::abs(m[12]) <= tol && std::abs(m[13]) <= tol &&
                  std::abs(m[14]) <= tol && std::abs(m[15] - 1.0) <= tol;
  return ok ? ""
            : "not a rotation about z plus a translation, expected [c, -s, 0, x, s, c, 0, y, 0, 0, 1, z, 0, 0, 0, 1]";
}

// ------------------------------------------------------------------ parsing

// the 1-based line of byte `pos` of `text` (the last byte's beyond the end)
int line_at(const std::string& text, std::size_t pos) {
  pos = std::min(pos, text.empty() ? 0 : text.size() - 1);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

// where "key" stands as a key (a ':' after it) at or after byte `from`
std::size_t key_at(const std::string& text, const std::string& key, std::size_t from) {
  const std::string quoted = '"' + key + '"';
  for (std::size_t p = text.find(quoted, from); p != std::string::npos; p = text.find(quoted, p + 1)) {
    std::size_t q = p + quoted.size();
    while (q < text.size() && std::isspace(static_cast<unsigned char>(text[q])) != 0) ++q;
    if (q < text.size() && text[q] == ':') return p;
  }
  return std::string::npos;
}

// an object of the metadata and where it starts in the text (its key, or the
// root's brace)
struct Section {
  const json* obj;
  std::string name;  // "" for the root
  std::size_t pos;
};

// a value of the metadata and where its key stands
struct Field {
  const json* v;
  std::string key;
  std::size_t pos;
};

// reads typed values out of the sections, failing with "source:line: ..."
class Reader {
 public:
  Reader(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  [[noreturn]] void fail(std::size_t pos, const std::string& what) const {
    throw std::invalid_argument(source_ + ":" + std::to_string(line_at(text_, pos)) + ": " + what);
  }
  [[noreturn]] void fail(const Field& f, const std::string& what) const { fail(f.pos, f.key + ": " + what); }
  // "key: expected WHAT, got V" or, of an array's entry, "key: entry i is V, expected WHAT"
  [[noreturn]] void bad_value(const json& v, const Field& f, const std::string& expected, int entry) const {
    if (entry < 0) fail(f, "expected " + expected + ", got " + v.dump());
    fail(f, "entry " + std::to_string(entry) + " is " + v.dump() + ", expected " + expected);
  }

  // the key's value, or nullptr; missing keys fail at the section's line
  const json* find(const Section& s, const std::string& key) const {
    const auto it = s.obj->find(key);
    return it == s.obj->end() ? nullptr : &*it;
  }
  Field field(const Section& s, const std::string& key, const std::string& expected) const {
    const json* v = find(s, key);
    if (v == nullptr) {
      fail(s.pos, "missing key \"" + key + "\"" + (s.name.empty() ? "" : " in " + s.name) + ", expected " + expected);
    }
    const std::size_t p = key_at(text_, key, s.pos);
    return {v, key, p == std::string::npos ? s.pos : p};
  }
  Section section(const Section& s, const std::string& key) const {
    const Field f = field(s, key, "an object");
    if (!f.v->is_object()) fail(f, std::string("expected an object, got ") + f.v->type_name());
    return {f.v, key, f.pos};
  }

  std::string string(const Field& f) const {
    if (!f.v->is_string()) fail(f, std::string("expected a string, got ") + f.v->type_name());
    return f.v->get<std::string>();
  }
  std::string string(const Section& s, const std::string& key) const { return string(field(s, key, "a string")); }

  // a whole number in [lo, hi]; entry >= 0: the array's entry
  std::int64_t integer(const json& v, const Field& f, std::int64_t lo, std::int64_t hi, const std::string& what,
                       int entry = -1) const {
    const bool in = v.is_number_integer() &&
                    !(v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) &&
                    v.get<std::int64_t>() >= lo && v.get<std::int64_t>() <= hi;
    if (!in) bad_value(v, f, what + " in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", entry);
    return v.get<std::int64_t>();
  }
  int integer(const Section& s, const std::string& key, int lo, int hi, const std::string& what) const {
    const Field f = field(s, key, what);
    return static_cast<int>(integer(*f.v, f, lo, hi, what));
  }

  // a finite number in [lo, hi]; entry >= 0: the array's entry
  double number(const json& v, const Field& f, double lo, double hi, const std::string& what, int entry = -1) const {
    const double x = v.is_number() ? v.get<double>() : 0.0;
    if (!v.is_number() || !(x >= lo && x <= hi)) {
      bad_value(v, f, what + " in [" + json(lo).dump() + ", " + json(hi).dump() + "]", entry);
    }
    return x;
  }
  double number(const Section& s, const std::string& key, double lo, double hi, const std::string& what) const {
    const Field f = field(s, key, what);
    return number(*f.v, f, lo, hi, what);
  }

  // an array of n entries ("expected n numbers (why), got m")
  const json& array(const Field& f, std::size_t n, const std::string& what) const {
    if (!f.v->is_array() || f.v->size() != n) {
      const std::string got = f.v->is_array() ? std::to_string(f.v->size()) : std::string("a ") + f.v->type_name();
      fail(f, "expected " + what + ", got " + got);
    }
    return *f.v;
  }
  std::vector<double> numbers(const Section& s, const std::string& key, std::size_t n, double lo, double hi,
                              const std::string& why) const {
    const std::string what = std::to_string(n) + " numbers (" + why + ")";
    const Field f = field(s, key, what);
    std::vector<double> out;
    for (const json& v : array(f, n, what))
      out.push_back(number(v, f, lo, hi, "a number", static_cast<int>(out.size())));
    return out;
  }
  std::vector<int> integers(const Section& s, const std::string& key, std::size_t n, int lo, int hi,
                            const std::string& why) const {
    const std::string what = std::to_string(n) + " integers (" + why + ")";
    const Field f = field(s, key, what);
    std::vector<int> out;
    for (const json& v : array(f, n, what)) {
      out.push_back(static_cast<int>(integer(v, f, lo, hi, "an integer", static_cast<int>(out.size()))));
    }
    return out;
  }
  std::array<double, 16> matrix(const Section& s, const std::string& key) const {
    const std::vector<double> m = numbers(s, key, 16, -1e9, 1e9, "a row-major 4x4 matrix");
    std::array<double, 16> out{};
    std::copy(m.begin(), m.end(), out.begin());
    return out;
  }

 private:
  const std::string& text_;
  const std::string& source_;
};

// what nlohmann says is wrong, without its prefix and position
std::string parse_what(const json::parse_error& e) {
  const std::string w = e.what();
  const std::size_t c = w.find("column ");
  const std::size_t d = c == std::string::npos ? c : w.find(": ", c);
  return d == std::string::npos ? w : w.substr(d + 2);
}

}  // namespace

bool operator==(const SensorInfo& a, const SensorInfo& b) {
  const auto tie = [](const SensorInfo& s) {
    return std::tie(s.prod_line, s.prod_sn, s.build_rev, s.columns_per_frame, s.frequency, s.beam_altitude_angles,
                    s.beam_azimuth_angles, s.lidar_origin_to_beam_origin_mm, s.lidar_to_sensor_transform,
                    s.imu_to_sensor_transform, s.pixels_per_column, s.columns_per_packet, s.column_window,
                    s.pixel_shift_by_row);
  };
  return tie(a) == tie(b);
}

SensorInfo parse_sensor_info(const std::string& json_text, const std::string& source) {
  const Reader rd(json_text, source);
  // the JSON itself: nlohmann's byte is the 1-based offset of the character
  // it stopped at
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::parse_error& e) {
    rd.fail(e.byte > 0 ? e.byte - 1 : 0, "not valid JSON (" + parse_what(e) + "), expected the sensor's metadata");
  } catch (const json::exception& e) {
    // a number out of range ("number overflow parsing '1e400'"): at its token
    const std::string w = e.what();
    const std::size_t a = w.find('\''), b = w.rfind('\''), at = a < b ? json_text.find(w.substr(a + 1, b - a - 1)) : 0;
    const std::string what = w.substr(std::min(w.find("] "), w.size() - 2) + 2);
    rd.fail(at == std::string::npos ? 0 : at, "not valid JSON (" + what + "), expected the sensor's metadata");
  }
  const std::size_t brace = std::min(json_text.find_first_not_of(" \t\r\n"), json_text.size());
  if (!root.is_object())
    rd.fail(brace, std::string("expected a JSON object (the sensor's metadata), got ") + root.type_name());

  // the sections: all the root in the flat form; in the nested form of
  // newer ouster-sdk, one object each
  const Section top{&root, "", brace};
  const bool nested = root.contains("beam_intrinsics");
  const Section unit = nested ? rd.section(top, "sensor_info") : top;
  const Section beams = nested ? rd.section(top, "beam_intrinsics") : top;
  const Section lidar = nested ? rd.section(top, "lidar_intrinsics") : top;
  const Section imu = nested ? rd.section(top, "imu_intrinsics") : top;
  const Section config = nested ? rd.section(top, "config_params") : top;
  const Section format = rd.section(top, nested ? "lidar_data_format" : "data_format");
  SensorInfo info;

  // the unit
  info.prod_line = rd.string(unit, "prod_line");
  info.prod_sn = rd.string(unit, "prod_sn");
  info.build_rev = rd.string(unit, "build_rev");

  // the profile: LEGACY, or absent (firmware before 2.2 knows no other); the
  // nested form may give it in config_params only
  const Section& said = nested && rd.find(format, "udp_profile_lidar") == nullptr ? config : format;
  if (rd.find(said, "udp_profile_lidar") != nullptr) {
    const Field f = rd.field(said, "udp_profile_lidar", "\"LEGACY\"");
    const std::string profile = rd.string(f);
    if (profile != "LEGACY") rd.fail(f, "\"" + profile + "\" is not supported: only the LEGACY profile is supported");
  }

  // lidar_mode: one of the sensor's modes; data_format agrees with it
  const Field mode = rd.field(config, "lidar_mode", std::string("one of ") + kModeList);
  const std::string mode_text = rd.string(mode);
  const auto m = std::find_if(std::begin(kModes), std::end(kModes), [&](const Mode& x) { return mode_text == x.name; });
  if (m == std::end(kModes)) rd.fail(mode, "\"" + mode_text + "\" is not a lidar mode, expected one of " + kModeList);
  info.columns_per_frame = m->columns;
  info.frequency = m->frequency;
  const int n = info.columns_per_frame;
  const int frame = rd.integer(format, "columns_per_frame", 1, kMaxColumns, "the columns per rotation");
  if (frame != n) {
    rd.fail(rd.field(format, "columns_per_frame", ""),
            std::to_string(frame) + " disagrees with lidar_mode " + mode_text + ", expected " + std::to_string(n));
  }

  // data_format: the packet's shape
  info.pixels_per_column = rd.integer(format, "pixels_per_column", 1, kMaxPixels, "the pixels per column");
  const auto pixels = static_cast<std::size_t>(info.pixels_per_column);
  info.columns_per_packet = rd.integer(format, "columns_per_packet", 1, n, "the columns per packet");
  if (n % info.columns_per_packet != 0) {
    rd.fail(rd.field(format, "columns_per_packet", ""), std::to_string(info.columns_per_packet) +
                                                            " does not divide columns_per_frame " + std::to_string(n) +
                                                            ", expected a divisor of it");
  }
  const std::vector<int> window = rd.integers(format, "column_window", 2, 0, n - 1, "the first and last column");
  info.column_window = {window[0], window[1]};
  info.pixel_shift_by_row = rd.integers(format, "pixel_shift_by_row", pixels, -n, n, "pixels_per_column");

  // the beams: altitudes distinct, azimuths, the origin's offset
  info.beam_altitude_angles = rd.numbers(beams, "beam_altitude_angles", pixels, -90.0, 90.0, "pixels_per_column");
  const std::vector<int> order = pixel_of_ring(info);
  for (std::size_t j = 1; j < pixels; ++j) {
    const auto a = static_cast<std::size_t>(order[j - 1]), b = static_cast<std::size_t>(order[j]);
    if (info.beam_altitude_angles[a] == info.beam_altitude_angles[b]) {
      rd.fail(rd.field(beams, "beam_altitude_angles", ""),
              "pixels " + std::to_string(std::min(a, b)) + " and " + std::to_string(std::max(a, b)) +
                  " have the same altitude " + json(info.beam_altitude_angles[a]).dump() +
                  " deg, expected distinct altitudes");
    }
  }
  info.beam_azimuth_angles = rd.numbers(beams, "beam_azimuth_angles", pixels, -180.0, 180.0, "pixels_per_column");
  info.lidar_origin_to_beam_origin_mm =
      rd.number(beams, "lidar_origin_to_beam_origin_mm", -1000.0, 1000.0, "a distance in mm");

  // the transforms: the lidar frame turns about z only
  info.lidar_to_sensor_transform = rd.matrix(lidar, "lidar_to_sensor_transform");
  const std::string bad = z_rotation_problem(info.lidar_to_sensor_transform);
  if (!bad.empty()) rd.fail(rd.field(lidar, "lidar_to_sensor_transform", ""), bad);
  info.imu_to_sensor_transform = rd.matrix(imu, "imu_to_sensor_transform");

  // what the lines above did not catch
  const std::string problem = check(info);
  if (!problem.empty()) rd.fail(brace, problem);
  return info;
}

std::string to_json(const SensorInfo& info) {
  // one key a line, arrays on theirs
  std::string out = "{\n";
  const auto line = [&out](const std::string& indent, const char* key, const json& v, bool last) {
    std::string text = v.dump();
    if (v.is_array()) {
      text = "[";
      for (std::size_t i = 0; i < v.size(); ++i) text += (i > 0 ? ", " : "") + v[i].dump();
      text += "]";
    }
    out += indent + "\"" + key + "\": " + text + (last ? "\n" : ",\n");
  };
  line("  ", "prod_line", info.prod_line, false);
  line("  ", "prod_sn", info.prod_sn, false);
  line("  ", "build_rev", info.build_rev, false);
  line("  ", "lidar_mode", mode_name(info), false);
  line("  ", "beam_altitude_angles", info.beam_altitude_angles, false);
  line("  ", "beam_azimuth_angles", info.beam_azimuth_angles, false);
  line("  ", "lidar_origin_to_beam_origin_mm", info.lidar_origin_to_beam_origin_mm, false);
  line("  ", "lidar_to_sensor_transform", info.lidar_to_sensor_transform, false);
  line("  ", "imu_to_sensor_transform", info.imu_to_sensor_transform, false);
  out += "  \"data_format\": {\n";
  line("    ", "pixels_per_column", info.pixels_per_column, false);
  line("    ", "columns_per_packet", info.columns_per_packet, false);
  line("    ", "columns_per_frame", info.columns_per_frame, false);
  line("    ", "column_window", info.column_window, false);
  line("    ", "pixel_shift_by_row", info.pixel_shift_by_row, false);
  line("    ", "udp_profile_lidar", "LEGACY", true);
  out += "  }\n}\n";
  return out;
}

std::string check(const SensorInfo& info) {
  const int n = info.columns_per_frame, p = info.pixels_per_column;
  if (p < 1 || p > kMaxPixels) return "pixels_per_column must be in [1, " + std::to_string(kMaxPixels) + "]";
  if (n < 1 || n > kMaxColumns) return "columns_per_frame must be in [1, " + std::to_string(kMaxColumns) + "]";
  if (info.columns_per_packet < 1 || n % info.columns_per_packet != 0)
    return "columns_per_packet must divide columns_per_frame";
  if (!std::isfinite(info.frequency) || info.frequency <= 0.0) return "frequency must be > 0 Hz";
  const auto pixels = static_cast<std::size_t>(p);
  if (info.beam_altitude_angles.size() != pixels || info.beam_azimuth_angles.size() != pixels ||
      info.pixel_shift_by_row.size() != pixels)
    return "beam_altitude_angles, beam_azimuth_angles and pixel_shift_by_row need pixels_per_column entries";
  std::vector<double> alt = info.beam_altitude_angles;
  std::sort(alt.begin(), alt.end());
  for (std::size_t j = 0; j < pixels; ++j) {
    if (!(std::abs(alt[j]) <= 90.0) || (j > 0 && alt[j] == alt[j - 1]))
      return "beam_altitude_angles must be distinct, in [-90, 90] deg";
    if (!(std::abs(info.beam_azimuth_angles[j]) <= 180.0)) return "beam_azimuth_angles must be in [-180, 180] deg";
  }
  if (!(std::abs(info.lidar_origin_to_beam_origin_mm) <= 1000.0))
    return "lidar_origin_to_beam_origin_mm must be in [-1000, 1000] mm";
  for (const int c : info.column_window) {
    if (c < 0 || c >= n) return "column_window must hold columns of the frame";
  }
  const std::string bad = z_rotation_problem(info.lidar_to_sensor_transform);
  if (!bad.empty()) return "lidar_to_sensor_transform: " + bad;
  for (const double v : info.imu_to_sensor_transform) {
    if (!std::isfinite(v)) return "imu_to_sensor_transform must be finite";
  }
  return "";
}

std::vector<int> pixel_of_ring(const SensorInfo& info) {
  const auto& alt = info.beam_altitude_angles;
  std::vector<int> order(alt.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&alt](int a, int b) {
    return alt[static_cast<std::size_t>(a)] < alt[static_cast<std::size_t>(b)];
  });
  return order;
}

std::vector<int> ring_of_pixel(const SensorInfo& info) {
  const std::vector<int> order = pixel_of_ring(info);
  std::vector<int> ring(order.size());
  for (std::size_t j = 0; j < order.size(); ++j) ring[static_cast<std::size_t>(order[j])] = static_cast<int>(j);
  return ring;
}

double azimuth_offset(const SensorInfo& info) {
  // the rotation's angle about z, less the standard transform's pi, in (-pi, pi]
  const auto& m = info.lidar_to_sensor_transform;
  double off = std::atan2(m[4], m[0]) - kPi;
  if (off <= -kPi) off += 2.0 * kPi;
  return off;
}

LidarLayout layout_of(const SensorInfo& info, const LidarLayout& mounting) {
  const std::string problem = check(info);
  if (!problem.empty()) throw std::invalid_argument("ouster::layout_of: " + problem);
  LidarLayout l;
  l.mount_x = mounting.mount_x;
  l.mount_y = mounting.mount_y;
  l.mount_z = mounting.mount_z;
  l.mount_pitch = mounting.mount_pitch;
  l.channels = info.pixels_per_column;
  l.columns = info.columns_per_frame;
  // the rings' elevations (rad), ascending: deg * kPi / 180.0, the layout
  // defaults' own expression
  const std::vector<int> order = pixel_of_ring(info);
  for (const int p : order)
    l.beam_elevation.push_back(info.beam_altitude_angles[static_cast<std::size_t>(p)] * kPi / 180.0);
  l.elevation_min = l.beam_elevation.front();
  l.elevation_max = l.beam_elevation.back();
  // the beams' azimuths (rad, > 0 counter-clockwise): "Lidar Range to XYZ",
  // theta_azimuth = -2 pi beam_azimuth_angle / 360; none when all are 0
  const auto& az = info.beam_azimuth_angles;
  if (std::any_of(az.begin(), az.end(), [](double a) { return a != 0.0; })) {
    for (const int p : order) l.beam_azimuth.push_back(-az[static_cast<std::size_t>(p)] * kPi / 180.0);
  }
  // the beam origin (m), a clockwise head, 1 mm ranges, a 16-bit signal
  l.beam_origin = info.lidar_origin_to_beam_origin_mm / 1000.0;
  l.clockwise = true;
  l.range_resolution = 0.001;
  l.intensity_full_scale = kSignalFullScale;
  return l;
}

RangeImage make_range_image(const SensorInfo& info, std::uint16_t frame_id, TimeNs t0) {
  RangeImage im;
  im.frame_id = frame_id;
  im.pixels_per_column = info.pixels_per_column;
  const int n = info.columns_per_frame;
  // column c at its nominal encoder count and time
  im.columns.resize(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) {
    auto& col = im.columns[static_cast<std::size_t>(c)];
    col.time = t0 + from_seconds(static_cast<double>(c) / (info.frequency * static_cast<double>(n)));
    col.encoder =
        static_cast<std::uint32_t>(static_cast<std::uint64_t>(c) * kEncoderTicks / static_cast<std::uint64_t>(n));
    col.valid = true;
  }
  im.pixels.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(info.pixels_per_column));
  return im;
}

std::size_t packet_size(const SensorInfo& info) {
  return static_cast<std::size_t>(info.columns_per_packet) * column_bytes(info.pixels_per_column);
}

namespace {
bool sized_for(const SensorInfo& info, const RangeImage& im) {
  const auto n = static_cast<std::size_t>(info.columns_per_frame);
  return im.pixels_per_column == info.pixels_per_column && im.columns.size() == n &&
         im.pixels.size() == n * static_cast<std::size_t>(info.pixels_per_column);
}
}  // namespace

void encode(const SensorInfo& info, const RangeImage& image, std::vector<std::uint8_t>& out) {
  const std::string problem = check(info);
  if (!problem.empty()) throw std::invalid_argument("ouster::encode: " + problem);
  if (!sized_for(info, image)) throw std::invalid_argument("ouster::encode: the image is not sized for the metadata");
  // the packets are the azimuth blocks back to back, columns_per_packet each
  const std::size_t stride = column_bytes(info.pixels_per_column);
  const std::size_t at = out.size();
  out.resize(at + stride * image.columns.size());
  std::uint8_t* b = out.data() + at;
  const RangeImage::Pixel* px = image.pixels.data();
  for (std::size_t c = 0; c < image.columns.size(); ++c) {
    const RangeImage::Column& col = image.columns[c];
    // the header: timestamp (ns), measurement_id, frame_id, encoder_count
    put(b, static_cast<std::uint64_t>(col.time));
    put(b + 8, static_cast<std::uint16_t>(c));
    put(b + 10, image.frame_id);
    put(b + 12, col.encoder);
    // the data blocks: range (mm, 20 bits), reflectivity, signal, near_ir, unused
    std::uint8_t* d = b + kHeaderBytes;
    for (int p = 0; p < info.pixels_per_column; ++p, ++px, d += kPixelBytes) {
      put(d, std::min(px->range_mm, kRangeMask));
      put(d + 4, px->reflectivity);
      put(d + 6, px->signal);
      put(d + 8, px->near_ir);
      put(d + 10, std::uint16_t{0});
    }
    // the status: the column valid or not
    put(d, col.valid ? kValidColumn : std::uint32_t{0});
    b += stride;
  }
}

// ------------------------------------------------------------------ decoder

Decoder::Decoder(const SensorInfo& info, const LidarLayout& layout) : layout_(layout) {
  std::string problem = check(info);
  if (problem.empty()) problem = layout.check();
  if (problem.empty() && (layout.channels != info.pixels_per_column || layout.columns != info.columns_per_frame))
    problem = "the layout's channels x columns are not the metadata's pixels_per_column x columns_per_frame";
  if (!problem.empty()) throw std::invalid_argument("ouster::Decoder: " + problem);
  pixels_ = info.pixels_per_column;
  columns_ = info.columns_per_frame;
  per_packet_ = info.columns_per_packet;
  packet_size_ = packet_size(info);
  // the window: first .. last column, wrapping past the seam when first > last
  window_first_ = info.column_window[0];
  window_last_ = info.column_window[1];
  window_size_ = (window_last_ - window_first_ + columns_) % columns_ + 1;
  offset_ = azimuth_offset(info);
  origin_ = layout.beam_origin;
  pixel_of_ring_ = pixel_of_ring(info);

  // per ring: the elevation's cos and sin (the layout's, as the simulator's)
  const auto np = static_cast<std::size_t>(pixels_), nc = static_cast<std::size_t>(columns_);
  for (int j = 0; j < pixels_; ++j) {
    const double el = ring_elevation(layout_, j);
    cos_el_.push_back(std::cos(el));
    sin_el_.push_back(std::sin(el));
  }
  // per column at its nominal encoder count: the head's and the beams' azimuths
  nominal_.resize(nc);
  head_trig_.resize(2 * nc);
  if (!layout_.beam_azimuth.empty()) beam_trig_.resize(2 * nc * np);
  for (std::size_t c = 0; c < nc; ++c) {
    nominal_[c] = static_cast<std::uint32_t>(static_cast<std::uint64_t>(c) * kEncoderTicks / nc);
    azimuths(nominal_[c], &head_trig_[2 * c], beam_trig_.empty() ? nullptr : &beam_trig_[2 * c * np]);
  }
  image_ = make_range_image(info);
  for (auto& col : image_.columns) col.valid = false;
}

void Decoder::azimuths(std::uint32_t encoder, double* head, double* beams) const {
  // the head's azimuth at the encoder's turn ("Lidar Range to XYZ":
  // theta_encoder, in paddock's sensor frame through turn_azimuth), turned by
  // the metadata's lidar_to_sensor rotation beyond the standard one
  const double az0 = turn_azimuth(layout_, static_cast<double>(encoder) / static_cast<double>(kEncoderTicks)) + offset_;
  head[0] = std::cos(az0);
  head[1] = std::sin(az0);
  if (beams == nullptr) return;
  // each beam's: the head's plus its own (theta_azimuth)
  for (std::size_t j = 0; j < layout_.beam_azimuth.size(); ++j) {
    const double az = az0 + layout_.beam_azimuth[j];
    beams[2 * j] = std::cos(az);
    beams[2 * j + 1] = std::sin(az);
  }
}

bool Decoder::in_window(int column) const {
  return window_first_ <= window_last_ ? column >= window_first_ && column <= window_last_
                                       : column >= window_first_ || column <= window_last_;
}

void Decoder::push(const std::uint8_t* data, std::size_t size) {
  ++counters_.packets;
  // a packet is exactly columns_per_packet azimuth blocks
  if (data == nullptr || size != packet_size_) {
    ++counters_.bad_size;
    return;
  }
  const std::size_t stride = column_bytes(pixels_);
  for (int k = 0; k < per_packet_; ++k) {
    const std::uint8_t* b = data + static_cast<std::size_t>(k) * stride;
    // the azimuth block's header and status: a valid column of the window
    const auto time = get<std::uint64_t>(b);
    const auto column = get<std::uint16_t>(b + 8);
    const auto frame = get<std::uint16_t>(b + 10);
    const auto encoder = get<std::uint32_t>(b + 12);
    const auto status = get<std::uint32_t>(b + stride - kStatusBytes);
    if (status != kValidColumn || column >= columns_ || encoder >= kEncoderTicks || !in_window(column)) {
      ++counters_.bad_columns;
      continue;
    }
    place(frame, column, static_cast<TimeNs>(time), encoder, b + kHeaderBytes);
  }
}

void Decoder::place(std::uint16_t frame, std::uint16_t column, TimeNs time, std::uint32_t encoder,
                    const std::uint8_t* data) {
  // a column of a newer frame closes the open rotation; one of an older frame
  // (or of the one last closed) is late
  if (open_ && frame != image_.frame_id) {
    if (frame_step(image_.frame_id, frame) >= 0) {
      close();
    } else if (late()) {
      return;
    }
  }
  if (!open_) {
    if (!first_ && frame_step(last_closed_, frame) <= 0 && late()) return;
    open(frame);
  }
  late_run_ = 0;
  // the column, once
  RangeImage::Column& col = image_.columns[column];
  if (col.valid) {
    ++counters_.duplicate_columns;
    return;
  }
  col.time = time;
  col.encoder = encoder;
  col.valid = true;
  // its data blocks whole (Pixel is their layout), then the ranges' low 20 bits (mm)
  RangeImage::Pixel* px = &image_.pixels[static_cast<std::size_t>(column) * static_cast<std::size_t>(pixels_)];
  std::memcpy(static_cast<void*>(px), data, kPixelBytes * static_cast<std::size_t>(pixels_));
  for (int p = 0; p < pixels_; ++p) px[p].range_mm &= kRangeMask;
  ++counters_.columns;
  // the rotation is done when its window is
  if (++received_ == window_size_) close();
}

// a column the stream's order calls late: dropped (true). A whole window of
// them in a row means the stream went back (a sensor that restarted its
// frame count, or one bogus frame_id far ahead that ran the decoder on):
// the open rotation is dropped and decoding starts over at this column
// (false), as at the stream's start
bool Decoder::late() {
  if (++late_run_ < window_size_) {
    ++counters_.late_columns;
    return true;
  }
  ++counters_.resyncs;
  if (open_) counters_.lost_columns += static_cast<std::uint64_t>(received_);
  late_run_ = 0;
  open_ = false;
  first_ = true;
  return false;
}

void Decoder::open(std::uint16_t frame) {
  image_.frame_id = frame;
  for (auto& col : image_.columns) col.valid = false;
  received_ = 0;
  open_ = true;
}

void Decoder::close() {
  // the first rotation without its first column began before the stream did:
  // dropped; any other is emitted, its missing columns lost
  if (first_ && !image_.columns[static_cast<std::size_t>(window_first_)].valid) {
    ++counters_.partial_first;
  } else {
    counters_.lost_columns += static_cast<std::uint64_t>(window_size_ - received_);
    if (counters_.rotations++ % static_cast<std::uint64_t>(scan_every_) == 0) done_.push_back(scan(image_));
  }
  first_ = false;
  last_closed_ = image_.frame_id;
  open_ = false;
}

void Decoder::set_scan_every(int n) {
  if (n < 1) throw std::invalid_argument("ouster::Decoder: a scan every " + std::to_string(n) + " rotations");
  scan_every_ = n;
}

void Decoder::flush() {
  if (open_) close();
}

void Decoder::reset() {
  image_.frame_id = 0;
  for (auto& col : image_.columns) col.valid = false;
  open_ = false;
  received_ = 0;
  first_ = true;
  late_run_ = 0;
  last_closed_ = 0;
  done_.clear();
  counters_ = Counters{};
}

std::optional<LidarScan> Decoder::pop() {
  if (done_.empty()) return std::nullopt;
  LidarScan s = std::move(done_.front());
  done_.pop_front();
  return s;
}

LidarScan Decoder::scan(const RangeImage& image) const {
  const auto np = static_cast<std::size_t>(pixels_), nc = static_cast<std::size_t>(columns_);
  if (image.pixels_per_column != pixels_ || image.columns.size() != nc || image.pixels.size() != nc * np)
    throw std::invalid_argument("ouster::Decoder::scan: the image is not sized for the metadata");
  LidarScan out;
  // the returns to make room for; the first and last valid column's times
  std::size_t count = 0;
  bool any = false;
  for (std::size_t c = 0; c < nc; ++c) {
    const RangeImage::Column& col = image.columns[c];
    if (!col.valid) continue;
    if (!any) out.stamp = col.time;
    any = true;
    out.end = col.time;
    const RangeImage::Pixel* px = &image.pixels[c * np];
    for (std::size_t p = 0; p < np; ++p) count += px[p].range_mm != 0 ? 1 : 0;
  }
  // one slot spare: every pixel is written, the slot kept only for a return
  // (no branch on the returns, which come and go at random)
  out.points.resize(count + 1);
  LidarPoint* dst = out.points.data();
  // the points, column by column, rings ascending ("Lidar Range to XYZ")
  std::vector<double> own;  // a column off its nominal encoder count: its azimuths
  const bool per_beam = !beam_trig_.empty();
  for (std::size_t c = 0; c < nc; ++c) {
    const RangeImage::Column& col = image.columns[c];
    if (!col.valid) continue;
    // the column's azimuths: the table's at the nominal count, else computed
    const double* head = &head_trig_[2 * c];
    const double* beams = per_beam ? &beam_trig_[2 * c * np] : nullptr;
    if (col.encoder != nominal_[c]) {
      own.resize(2 + (per_beam ? 2 * np : 0));
      azimuths(col.encoder, own.data(), per_beam ? own.data() + 2 : nullptr);
      head = own.data();
      beams = per_beam ? own.data() + 2 : nullptr;
    }
    const RangeImage::Pixel* px = &image.pixels[c * np];
    for (std::size_t j = 0; j < np; ++j) {
      const RangeImage::Pixel& q = px[static_cast<std::size_t>(pixel_of_ring_[j])];
      // r in m: the reported range's k * 0.001
      const double r = static_cast<double>(q.range_mm) * 0.001;
      const double* beam = beams != nullptr ? beams + 2 * j : head;
      float xyz[3];
      beam_point(r, origin_, cos_el_[j], sin_el_[j], beam[0], beam[1], head[0], head[1], xyz);
      dst->x = xyz[0];
      dst->y = xyz[1];
      dst->z = xyz[2];
      // intensity: signal over its 16-bit full scale
      dst->intensity = static_cast<float>(static_cast<double>(q.signal) / kSignalFullScale);
      dst->ring = static_cast<std::uint16_t>(j);
      dst->t = col.time;
      dst += q.range_mm != 0 ? 1 : 0;
    }
  }
  out.points.pop_back();
  return out;
}

}  // namespace paddock::hal::ouster
