#pragma once
// an Ouster OS-series LiDAR in the LEGACY lidar packet format (firmware
// v2.x): its metadata file (SensorInfo: parse, write, the LidarLayout it
// gives), the packets a rotation makes (encode: the simulator's side of the
// wire) and the decoder the car's side runs on the UDP payloads (Decoder:
// packets in, hal::LidarScan out). Cited: Ouster Software User Manual
// (firmware v2.x), "Lidar Data Format" (the legacy packet) and "Lidar Range
// to XYZ" (the points).
//
// The stack's intensity in [0, 1] is the legacy `signal` field (photons) over
// its 16-bit full scale (kSignalFullScale); reflectivity and near_ir travel in
// the packets and the RangeImage but reach no LidarPoint.
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/time.h"
#include "autonomy/hal/lidar_layout.h"
#include "autonomy/hal/messages.h"

namespace paddock::hal::ouster {

// encoder ticks in one turn of the head ("Lidar Data Format": encoder_count)
inline constexpr std::uint32_t kEncoderTicks = 90112;
// an azimuth block's status word: a valid column (0: an invalid one)
inline constexpr std::uint32_t kValidColumn = 0xFFFFFFFFu;
// a data block's range: the low 20 bits of its u32 (mm)
inline constexpr std::uint32_t kRangeMask = 0xFFFFFu;
// the full scale of the 16-bit `signal` field: intensity = signal / this
inline constexpr double kSignalFullScale = 65535.0;

// the sensor's metadata: what ouster-sdk writes next to a recording, or the
// legacy TCP commands get_sensor_info, get_beam_intrinsics,
// get_lidar_intrinsics and get_lidar_data_format give together
struct SensorInfo {
  std::string prod_line;  // "OS-2-32-U0"
  std::string prod_sn;
  std::string build_rev;  // firmware, "v2.4.0"
  // lidar_mode "<columns_per_frame>x<frequency>" ("1024x10")
  int columns_per_frame = 1024;
  double frequency = 10.0;  // Hz, rotations a second
  // per pixel (the packet's data block order, not rings)
  std::vector<double> beam_altitude_angles;     // deg, > 0 up
  std::vector<double> beam_azimuth_angles;      // deg, > 0 clockwise seen from above
  double lidar_origin_to_beam_origin_mm = 0.0;  // mm
  // row-major 4x4, translation in mm: Ouster's lidar frame (x toward the
  // connector) in its sensor frame; a rotation about z only
  std::array<double, 16> lidar_to_sensor_transform{-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::array<double, 16> imu_to_sensor_transform{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  // data_format (udp_profile_lidar is always LEGACY: the only one read)
  int pixels_per_column = 32;
  int columns_per_packet = 16;
  std::array<int, 2> column_window{0, 1023};  // the first and last column sent (wraps when first > last)
  std::vector<int> pixel_shift_by_row;        // per pixel (destaggering; unused here)
};
bool operator==(const SensorInfo& a, const SensorInfo& b);
inline bool operator!=(const SensorInfo& a, const SensorInfo& b) { return !(a == b); }

// parses the metadata JSON `json_text` read from `source` (a file name, for
// the messages): the flat form above, or the nested one of newer ouster-sdk
// (sensor_info, beam_intrinsics, lidar_intrinsics, imu_intrinsics,
// lidar_data_format, config_params). Throws std::invalid_argument
// "source:line: what is wrong, what was expected".
SensorInfo parse_sensor_info(const std::string& json_text, const std::string& source);
// the flat form (parse_sensor_info(to_json(x), ...) == x)
std::string to_json(const SensorInfo& info);
// "" when `info` can describe packets (sizes, counts, the transform), else
// the first problem; what encode and Decoder check
std::string check(const SensorInfo& info);

// the ring (0 = the lowest beam) of each pixel: the altitudes' ascending order
std::vector<int> ring_of_pixel(const SensorInfo& info);
// its inverse: the pixel of each ring
std::vector<int> pixel_of_ring(const SensorInfo& info);
// what the metadata's lidar_to_sensor rotation adds to every azimuth (rad):
// its angle about z minus pi (turn_azimuth's pi is the standard
// diag(-1, -1, 1)); 0 for the standard transform
double azimuth_offset(const SensorInfo& info);

// the layout the metadata gives, mounted where `mounting` says (its mount_*
// only): rings sorted by altitude, the beam azimuths (empty when all are 0),
// the beam origin, a clockwise head, 1 mm ranges
LidarLayout layout_of(const SensorInfo& info, const LidarLayout& mounting);

// one rotation as the sensor measures it, in its own order
struct RangeImage {
  struct Column {
    TimeNs time = 0;            // ns, the azimuth block's timestamp
    std::uint32_t encoder = 0;  // ticks, [0, kEncoderTicks)
    bool valid = false;         // false: a dropped column (its pixels ignored)
  };
  // a data block's fields in its order (12 bytes, the last 2 its unused
  // field's: the decoder copies a column's blocks whole)
  struct Pixel {
    std::uint32_t range_mm = 0;  // mm, 0: no return
    std::uint16_t reflectivity = 0;
    std::uint16_t signal = 0;  // photons
    std::uint16_t near_ir = 0;
  };
  std::uint16_t frame_id = 0;
  int pixels_per_column = 0;
  std::vector<Column> columns;  // columns_per_frame, by measurement_id
  std::vector<Pixel> pixels;    // [column * pixels_per_column + pixel]
};
// a rotation of valid columns with no returns, sized for `info`: nominal
// encoder counts (c * kEncoderTicks / columns_per_frame), column c at
// t0 + c / (frequency * columns_per_frame) s
RangeImage make_range_image(const SensorInfo& info, std::uint16_t frame_id = 0, TimeNs t0 = 0);

// bytes in one lidar packet: columns_per_packet azimuth blocks
std::size_t packet_size(const SensorInfo& info);
// appends the rotation's packets (columns_per_frame / columns_per_packet of
// packet_size bytes) to `out`; ranges beyond 20 bits clamp to kRangeMask.
// Throws std::invalid_argument when check(info) fails or `image` is not
// sized for `info`.
void encode(const SensorInfo& info, const RangeImage& image, std::vector<std::uint8_t>& out);

// the car's side: UDP payloads in, one LidarScan per rotation out. Columns go
// by their own measurement_id into the rotation of their own frame_id; a
// rotation is emitted when every column of column_window arrived, or when a
// column of a newer frame (modulo 2^16) arrives, or at flush. Bad packets are
// counted, never thrown. Memory is bounded: one rotation open at a time (a
// newer frame's column closes it: a later column of the old one is late) and
// the emitted scans until popped (a push emits at most columns_per_packet;
// pop after each push).
class Decoder {
 public:
  struct Counters {
    std::uint64_t packets = 0;      // push calls
    std::uint64_t bad_size = 0;     // packets of the wrong length (dropped whole)
    std::uint64_t bad_columns = 0;  // status not valid, measurement_id or encoder out of range, outside column_window
    std::uint64_t columns = 0;      // columns placed in a rotation
    std::uint64_t duplicate_columns = 0;  // a column its rotation already had
    std::uint64_t late_columns = 0;       // of a rotation emitted (or older than the one open)
    std::uint64_t lost_columns = 0;       // window columns an emitted rotation went without
    std::uint64_t partial_first = 0;      // the first rotation, dropped: it lacked its first column
    std::uint64_t rotations = 0;          // scans emitted
    std::uint64_t resyncs = 0;            // starts over after a window of late columns in a row
  };

  // layout: layout_of(info, mounting). Throws std::invalid_argument when
  // check(info) fails or the layout does not fit the metadata.
  Decoder(const SensorInfo& info, const LidarLayout& layout);

  // one UDP payload
  void push(const std::uint8_t* data, std::size_t size);
  // the oldest completed rotation
  std::optional<LidarScan> pop();
  // end of stream: emits the open rotation (it has a valid column)
  void flush();
  // forgets the stream (a sensor that restarted, a new log): as just
  // constructed, without building the angle tables again
  void reset();
  const Counters& counters() const { return counters_; }
  // only every n-th rotation emitted becomes a scan (the first, the
  // (n+1)-th, ...: counters().rotations counts them all), for a reader that
  // wants a few (the log's point clouds): the others cost the copy of their
  // columns, not their points. n >= 1 (else std::invalid_argument); 1, the
  // default: every rotation. reset() keeps it
  void set_scan_every(int n);

  // the points of a rotation: column by column in measurement_id order,
  // rings ascending, returns only; stamp and end the first and last valid
  // column's times. Throws std::invalid_argument when `image` is not sized
  // for the metadata.
  LidarScan scan(const RangeImage& image) const;

 private:
  void place(std::uint16_t frame, std::uint16_t column, TimeNs time, std::uint32_t encoder, const std::uint8_t* data);
  void open(std::uint16_t frame);
  void close();
  bool late();
  bool in_window(int column) const;
  // cos, sin of the head's azimuth at `encoder` into head[0..1] and, unless
  // beams is null, of each ring's beam into beams[2 ring ..]
  void azimuths(std::uint32_t encoder, double* head, double* beams) const;

  LidarLayout layout_;
  int pixels_ = 0, columns_ = 0, per_packet_ = 0;
  std::size_t packet_size_ = 0;
  int window_first_ = 0, window_last_ = 0, window_size_ = 0;
  double offset_ = 0.0;  // rad, azimuth_offset
  double origin_ = 0.0;  // m, beam_origin
  std::vector<int> pixel_of_ring_;
  std::vector<double> cos_el_, sin_el_;  // per ring
  std::vector<std::uint32_t> nominal_;   // per column: its nominal encoder count
  std::vector<double> head_trig_;        // per column: cos, sin of the head's azimuth
  std::vector<double> beam_trig_;        // per (column, ring): cos, sin of the beam's (empty: the head's)

  RangeImage image_;   // the open rotation
  bool open_ = false;  // image_ holds one
  int received_ = 0;   // its window columns placed
  bool first_ = true;  // no rotation closed yet
  int late_run_ = 0;   // late columns in a row
  std::uint16_t last_closed_ = 0;
  int scan_every_ = 1;
  std::deque<LidarScan> done_;
  Counters counters_;
};

}  // namespace paddock::hal::ouster
