#pragma once
// track files and track geometry: parse a cone-map CSV (tracks/README.md), then
// order its cones into boundaries and derive the centreline, widths, gates,
// start pose and the on-track region the events module asks at 100 Hz.
//
// Nothing here touches the file system: it works on text and values, and the
// program's edge (sim/runner) reads the files.
//
// Where it is done: track_file.cc parses; track.cc decides the kind and
// finishes the model, each kind built in track_circuit.cc,
// track_acceleration.cc or track_skidpad.cc from the shared pieces of
// track_build.h (internal); track_region.cc is the on-track test and
// track_report.cc the check-track text.
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"

namespace paddock::world {

// a track file or its geometry cannot be used; the message reads
// "source:line: what is wrong, what was expected" (geometry errors: "source: ...")
class TrackError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// a cone that repeats an earlier cone of the same colour (within kDoubledConeDistance)
struct DoubledCone {
  std::size_t cone = 0;      // index into TrackFile::cones of the later row
  std::size_t original = 0;  // index of the earlier row it doubles
  double distance = 0.0;     // m
};

inline constexpr double kDoubledConeDistance = 0.05;  // m
// the most cones a track file may hold: a Formula Student track has a few
// hundred; a file of millions is no track, and checking it for doubled cones
// would take hours
inline constexpr std::size_t kMaxTrackCones = 10000;
// the farthest a cone, the start or a timekeeping post may lie from the first
// cone: the shipped tracks span at most 170 m; a file spread over kilometres
// is no track (and would make a centreline of millions of points)
inline constexpr double kMaxTrackSpan = 5000.0;  // m

// the content of one track file, as written
struct TrackFile {
  std::string source;                   // file name used in messages
  std::vector<Cone> cones;              // in file order
  std::vector<int> cone_lines;          // 1-based file line of each cone (same size as cones)
  std::optional<Pose2> start;           // from "# start X Y YAW"
  int start_line = 0;
  std::vector<Vec2> timekeeping;        // "# timekeeping X Y" posts; consecutive pairs form a gate
  std::vector<int> timekeeping_lines;
  std::vector<DoubledCone> doubles;     // kept in `cones`; build_track merges them
  std::vector<std::string> warnings;    // "source:line: ..." (doubled cones)
};

// parse the text of a track file; `source` names it in messages. Throws
// TrackError (also for a file of more than kMaxTrackCones cones, at its first
// cone too many, and for one spread wider than kMaxTrackSpan, at the first
// line beyond it).
TrackFile parse_track(std::string_view text, const std::string& source);

enum class TrackKind { Circuit, Acceleration, Skidpad };

// "circuit", "acceleration", "skidpad"
std::string_view track_kind_name(TrackKind kind);

// the figure of eight fitted to the ring cones (rules: ring radii 7.475 and
// 10.775 m around centres 18.25 m apart)
struct SkidpadGeometry {
  Vec2 centre_right;          // the circle on the right of `heading` at the crossing (driven first)
  Vec2 centre_left;
  double radius = 0.0;        // m, centreline (mean of inner and outer)
  double inner_radius = 0.0;  // m, inner ring of cones (mean of both circles)
  double outer_radius = 0.0;  // m, outer ring of cones
  Vec2 crossing;              // midpoint of the centres
  double heading = 0.0;       // rad, driving direction at the crossing
  Vec2 entry_start;           // start of the entry lane, on the lane axis
  Vec2 exit_end;              // end of the exit lane, on the lane axis
  double lane_half_width = 0.0;  // m, half the distance between the lane's orange lines
};

// the point set on which the events module decides "on track" (see on_track);
// built once, read-only afterwards
class TrackRegion {
 public:
  // inside when inside an odd number of `xor_polygons`, or in one of the annuli
  void add_xor_polygon(const std::vector<Vec2>& polygon);
  void add_annulus(Vec2 centre, double inner_radius, double outer_radius);
  bool contains(Vec2 p) const;

 private:
  // a polygon with its edges bucketed in horizontal slabs, so that the
  // even-odd ray test only visits the few edges of the query's slab
  struct IndexedPolygon {
    std::vector<Vec2> pts;
    double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;
    double slab_height = 1.0;
    std::vector<std::size_t> slab_begin;  // slab k holds edges[slab_begin[k] .. slab_begin[k+1])
    std::vector<std::size_t> edges;       // edge i runs pts[i] -> pts[i+1 mod n]
    bool contains(Vec2 p) const;
  };
  struct Annulus {
    Vec2 centre;
    double r2_min = 0.0, r2_max = 0.0;
  };
  std::vector<IndexedPolygon> polygons_;
  std::vector<Annulus> annuli_;
};

// the geometry of a track, derived from a TrackFile by build_track
struct TrackModel {
  TrackKind kind = TrackKind::Circuit;
  std::string name;             // file stem
  std::vector<Cone> cones;      // every cone of the file except doubles (merged into the first)

  // boundaries in driving order: left from the blue cones, right from the
  // yellow ones (unknown cones are ignored; a big orange cone joins a line
  // where it fills a gap of more than 10 m). Circuits: closed loops. Open
  // for acceleration. Skidpad: the cones on the driver's left (right) over the
  // right circle then the left circle, with one jump between the circles; use
  // `skidpad` for the ring geometry.
  std::vector<Vec2> left;
  std::vector<Vec2> right;
  bool closed = false;          // true for circuits (boundaries and centreline)

  // centreline in driving order, starting near the start pose, ~0.5 m
  // spacing; width[i] is the track width across centreline[i] (the chord
  // between the boundaries along the centreline's normal). Circuit: the line
  // equidistant from both boundaries, lightly smoothed. Acceleration: the
  // lane axis from the start pose to the last cone. Skidpad: entry lane from
  // the start, right circle once, left circle once, exit lane to its last cone.
  std::vector<Vec2> centreline;
  std::vector<double> width;
  double centreline_length = 0.0;  // m (closed: including the closing segment)
  double width_min = 0.0, width_mean = 0.0, width_max = 0.0;  // m

  // from "# start", else on the centreline 6 m before the first gate
  // (skidpad: at the first cone of the entry lane)
  Pose2 start;
  std::string start_from;        // "file" or "geometry"
  // timekeeping lines in driving order (acceleration: start, finish; skidpad:
  // the one at the crossing first). a = left post, b = right post, so driving
  // forward crosses each from its right side to its left side (crossing_right_to_left)
  std::vector<Segment> gates;
  std::string gates_from;        // "timekeeping", "big_orange" or "geometry"

  std::optional<SkidpadGeometry> skidpad;  // set for TrackKind::Skidpad
  // oddities found while building ("source: ..."): swapped colours, a start
  // facing against the colours, long gaps, ring cones that fit no ring
  std::vector<std::string> notes;

  TrackRegion region;

  // the ground between the boundaries (circuit: inside exactly one of the two
  // boundary polygons; acceleration: between the lines of cones, from 3 m
  // behind the start to 3 m past the last cone; skidpad: the two annuli
  // between the fitted ring radii and the lane through the crossing, with the
  // same 3 m at its ends). Tens of nanoseconds per call.
  bool on_track(Vec2 p) const { return region.contains(p); }
};

// order the cones into boundaries and derive the geometry; throws TrackError
// naming the source when the layout cannot be made sense of
TrackModel build_track(const TrackFile& file);

// human-readable summary of one file (what `paddock check-track` prints)
std::string check_track_report(const TrackModel& model, const TrackFile& file);

}  // namespace paddock::world
