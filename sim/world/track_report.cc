// the human-readable summary of a track file that `paddock check-track` prints.
#include <cmath>
#include <sstream>
#include <string>

#include "autonomy/common/format.h"
#include "sim/world/track.h"

namespace paddock::world {

namespace {

std::string point(Vec2 p) { return "(" + fixed(p.x, 2) + ", " + fixed(p.y, 2) + ")"; }

}  // namespace

std::string check_track_report(const TrackModel& m, const TrackFile& f) {
  std::size_t count[5] = {};
  for (const Cone& c : f.cones) ++count[static_cast<int>(c.color)];
  const std::string counts = std::to_string(count[0]) + "/" + std::to_string(count[1]) + "/" +
                             std::to_string(count[2]) + "/" + std::to_string(count[3]) + "/" +
                             std::to_string(count[4]);
  std::ostringstream o;
  // one summary line, then the details
  o << m.name << ": " << track_kind_name(m.kind) << (m.closed ? " (closed)" : " (open)") << ", centreline "
    << fixed(m.centreline_length, 1) << " m, width " << fixed(m.width_min, 2) << "/" << fixed(m.width_mean, 2) << "/"
    << fixed(m.width_max, 2) << " m (min/mean/max), cones b/y/o/B/u " << counts << "\n";
  o << "  file        " << f.source << "\n";
  o << "  cones       " << count[0] << " blue, " << count[1] << " yellow, " << count[2] << " orange, " << count[3]
    << " big orange, " << count[4] << " unknown (" << f.cones.size() << " rows, " << f.doubles.size()
    << " doubled)\n";
  o << "  boundaries  left " << m.left.size() << " cones, right " << m.right.size() << " cones, "
    << (m.closed ? "closed" : "open") << "\n";
  o << "  centreline  " << fixed(m.centreline_length, 1) << " m, " << m.centreline.size() << " points\n";
  o << "  width       min " << fixed(m.width_min, 2) << " m, mean " << fixed(m.width_mean, 2) << " m, max "
    << fixed(m.width_max, 2) << " m\n";
  o << "  start       " << point(m.start.position()) << " yaw " << fixed(m.start.yaw * 180.0 / kPi, 1)
    << " deg (from " << m.start_from << ")\n";
  o << "  gates       " << m.gates.size() << " from " << m.gates_from << "\n";
  for (std::size_t i = 0; i < m.gates.size(); ++i) {
    const Segment& g = m.gates[i];
    o << "    " << i + 1 << ". left " << point(g.a) << ", right " << point(g.b) << ", " << fixed(distance(g.a, g.b), 2)
      << " m wide";
    if (i > 0) o << ", " << fixed(distance((g.a + g.b) * 0.5, (m.gates[0].a + m.gates[0].b) * 0.5), 2)
                 << " m from gate 1";
    o << "\n";
  }
  if (m.skidpad) {
    const SkidpadGeometry& s = *m.skidpad;
    o << "  skidpad     centres right " << point(s.centre_right) << ", left " << point(s.centre_left) << ", "
      << fixed(distance(s.centre_right, s.centre_left), 3) << " m apart\n";
    o << "              radii inner " << fixed(s.inner_radius, 3) << " m, centreline " << fixed(s.radius, 3)
      << " m, outer " << fixed(s.outer_radius, 3) << " m; crossing " << point(s.crossing) << " heading "
      << fixed(s.heading * 180.0 / kPi, 1) << " deg\n";
    o << "              lane " << fixed(2.0 * s.lane_half_width, 2) << " m wide from " << point(s.entry_start)
      << " to " << point(s.exit_end) << "\n";
  }
  if (f.warnings.empty() && m.notes.empty()) {
    o << "  warnings    none\n";
  } else {
    o << "  warnings    " << f.warnings.size() + m.notes.size() << "\n";
    for (const auto& w : f.warnings) o << "    " << w << "\n";
    for (const auto& w : m.notes) o << "    " << w << "\n";
  }
  return o.str();
}

}  // namespace paddock::world
