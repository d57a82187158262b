// track geometry: boundaries, centreline, widths, gates, start pose and the
// on-track region, derived from the cones of a TrackFile.
//
// the kind comes from the layout, not the file name: a skidpad when most
// blue/yellow cones vote (circle through each cone and its two nearest
// same-coloured neighbours) for two centres 10-30 m apart, each with an inner
// and an outer ring; an acceleration when the blue and the yellow cones each
// lie on a straight line; else a circuit, whose blue and yellow cones are
// chained into two nested loops and oriented so that blue is on the left.
// Unknown cones never take part; exact doubles are merged first.
//
// this file decides the kind and finishes the model (name, widths, the
// rules' checks); each kind is built in its own file (track_circuit.cc,
// track_acceleration.cc, track_skidpad.cc) from the pieces in
// track_build.h, and the on-track region is track_region.cc.
#include "sim/world/track.h"

#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

#include "autonomy/common/format.h"
#include "autonomy/common/polyline.h"
#include "sim/world/track_build.h"

namespace paddock::world {

namespace {

using detail::ConeSets;

// ---------------------------------------------------------------------------
// cones by colour, doubles merged

ConeSets sort_cones(const TrackFile& f) {
  std::vector<bool> drop(f.cones.size(), false);
  for (const auto& d : f.doubles) drop[d.cone] = true;
  ConeSets s;
  for (std::size_t i = 0; i < f.cones.size(); ++i) {
    if (drop[i]) continue;
    const Cone& c = f.cones[i];
    s.all.push_back(c);
    switch (c.color) {
      case ConeColor::Blue: s.blue.push_back(c.position); break;
      case ConeColor::Yellow: s.yellow.push_back(c.position); break;
      case ConeColor::SmallOrange: s.orange.push_back(c.position); break;
      case ConeColor::BigOrange: s.big_orange.push_back(c.position); break;
      case ConeColor::Unknown: break;
    }
  }
  return s;
}

std::string file_stem(const std::string& source) {
  const auto slash = source.find_last_of("/\\");
  std::string base = slash == std::string::npos ? source : source.substr(slash + 1);
  const auto dot_pos = base.find_last_of('.');
  if (dot_pos != std::string::npos && dot_pos > 0) base.erase(dot_pos);
  return base;
}

}  // namespace

std::string_view track_kind_name(TrackKind kind) {
  switch (kind) {
    case TrackKind::Circuit: return "circuit";
    case TrackKind::Acceleration: return "acceleration";
    case TrackKind::Skidpad: return "skidpad";
  }
  return "circuit";
}

// ---------------------------------------------------------------------------

TrackModel build_track(const TrackFile& f) {
  TrackModel m;
  m.name = file_stem(f.source);
  const ConeSets cs = sort_cones(f);
  m.cones = cs.all;
  if (cs.blue.empty() && cs.yellow.empty()) {
    throw TrackError(f.source + ": no blue or yellow cones, expected the boundaries of a circuit, an acceleration or "
                                "a skidpad layout");
  }
  std::vector<std::string> unassigned;
  if (auto circles = detail::find_skidpad(cs, unassigned)) {
    m.kind = TrackKind::Skidpad;
    detail::build_skidpad(m, f, cs, *circles, unassigned);
  } else if (detail::looks_like_acceleration(cs)) {
    m.kind = TrackKind::Acceleration;
    detail::build_acceleration(m, f, cs);
  } else {
    m.kind = TrackKind::Circuit;
    detail::build_circuit(m, f, cs);
  }
  m.centreline_length = polyline_length(m.centreline, m.closed);
  if (!m.width.empty()) {
    m.width_min = *std::min_element(m.width.begin(), m.width.end());
    m.width_max = *std::max_element(m.width.begin(), m.width.end());
    m.width_mean = std::accumulate(m.width.begin(), m.width.end(), 0.0) / static_cast<double>(m.width.size());
  }
  // the rules' limits for a trackdrive circuit (ORACLES.md: width >= 3 m, lap 200..500 m)
  if (m.kind == TrackKind::Circuit) {
    if (m.width_min < 2.95) {
      const auto i = static_cast<std::size_t>(std::min_element(m.width.begin(), m.width.end()) - m.width.begin());
      m.notes.push_back(f.source + ": narrowest width " + fixed(m.width_min, 2) + " m at (" +
                        fixed(m.centreline[i].x, 2) + ", " + fixed(m.centreline[i].y, 2) +
                        "), below the rules' 3 m minimum");
    }
    if (m.centreline_length < 200.0 || m.centreline_length > 500.0) {
      m.notes.push_back(f.source + ": lap of " + fixed(m.centreline_length, 1) +
                        " m, outside the rules' 200 to 500 m");
    }
  }
  return m;
}

}  // namespace paddock::world
