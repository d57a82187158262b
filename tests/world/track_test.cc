// track loading and geometry: every real track against facts known from
// elsewhere (the README's tables, the rules, brute force), and bad files.
#include "sim/world/track.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/common/polyline.h"

namespace paddock::world {
namespace {

// the file's text through parse_track, as the runner feeds it
TrackFile load_track_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TrackError(path + ": cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_track(ss.str(), path);
}


using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kSource = PADDOCK_SOURCE_DIR;
const std::string kTracks = kSource + "/tracks";
const std::string kBad = kSource + "/tests/data/tracks";

std::vector<std::string> track_names() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(kTracks)) {
    if (e.path().extension() == ".csv") out.push_back(e.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// the rows of the markdown table that follows `heading` in tracks/README.md,
// keyed by the first cell, each the list of cells
std::map<std::string, std::vector<std::string>> readme_table(const std::string& heading) {
  std::map<std::string, std::vector<std::string>> rows;
  std::istringstream in(read_text(kTracks + "/README.md"));
  std::string line;
  bool in_section = false;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) in_section = line == heading;
    if (!in_section || line.rfind("| ", 0) != 0) continue;
    auto cells = split(line, '|');
    std::vector<std::string> c;
    for (std::size_t i = 1; i < cells.size(); ++i) c.push_back(trim(cells[i]));
    if (!c.empty() && c[0].size() > 4 && c[0].substr(c[0].size() - 4) == ".csv") rows[c[0]] = c;
  }
  return rows;
}

struct Loaded {
  TrackFile file;
  TrackModel model;
};

const Loaded& load(const std::string& name) {
  static std::map<std::string, Loaded> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    Loaded l;
    l.file = load_track_file(kTracks + "/" + name + ".csv");
    l.model = build_track(l.file);
    it = cache.emplace(name, std::move(l)).first;
  }
  return it->second;
}

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }

TrackKind expected_kind(const std::string& name) {
  if (starts_with(name, "acceleration")) return TrackKind::Acceleration;
  if (starts_with(name, "skidpad")) return TrackKind::Skidpad;
  return TrackKind::Circuit;
}

bool has_note(const TrackModel& m, const std::string& what) {
  return std::any_of(m.notes.begin(), m.notes.end(), [&](const std::string& n) { return n.find(what) != n.npos; });
}

bool proper_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

std::size_t segments(const std::vector<Vec2>& p, bool closed) { return closed ? p.size() : p.size() - 1; }

// ---------------------------------------------------------------------------
// every real track

class RealTrack : public ::testing::TestWithParam<std::string> {};

TEST_P(RealTrack, ConeCountsMatchTheReadme) {
  const Loaded& t = load(GetParam());
  const auto table = readme_table("## Files");
  const auto row = table.find(GetParam() + ".csv");
  ASSERT_NE(row, table.end()) << "no row in tracks/README.md";
  std::size_t count[5] = {};
  for (const Cone& c : t.file.cones) ++count[static_cast<int>(c.color)];
  const std::string got = std::to_string(count[0]) + "/" + std::to_string(count[1]) + "/" +
                          std::to_string(count[2]) + "/" + std::to_string(count[3]) + "/" +
                          std::to_string(count[4]);
  EXPECT_EQ(got, row->second[2]);
  EXPECT_EQ(t.file.cone_lines.size(), t.file.cones.size());
  EXPECT_EQ(t.model.cones.size(), t.file.cones.size() - t.file.doubles.size());
}

TEST_P(RealTrack, KindAndClosure) {
  const TrackModel& m = load(GetParam()).model;
  EXPECT_EQ(m.kind, expected_kind(GetParam())) << track_kind_name(m.kind);
  EXPECT_EQ(m.closed, m.kind == TrackKind::Circuit);
  EXPECT_EQ(m.skidpad.has_value(), m.kind == TrackKind::Skidpad);
  EXPECT_EQ(m.name, GetParam());
}

TEST_P(RealTrack, EveryBoundaryConeIsUsedOnce) {
  const Loaded& t = load(GetParam());
  const TrackModel& m = t.model;
  // the AMZ skidpad's colours are swapped: its blue cones are on the driver's right
  const bool swapped = has_note(m, "colours swapped");
  EXPECT_EQ(swapped, GetParam() == "skidpad_amz_fssim");
  std::vector<bool> doubled(t.file.cones.size(), false);
  for (const auto& d : t.file.doubles) doubled[d.cone] = true;
  for (ConeColor color : {ConeColor::Blue, ConeColor::Yellow}) {
    const bool on_left = (color == ConeColor::Blue) != swapped;
    const auto& side = on_left ? m.left : m.right;
    std::size_t n = 0;
    for (std::size_t i = 0; i < t.file.cones.size(); ++i) {
      if (t.file.cones[i].color != color || doubled[i]) continue;
      ++n;
      const Vec2 p = t.file.cones[i].position;
      EXPECT_EQ(std::count(side.begin(), side.end(), p), 1)
          << cone_tag(color) << " cone of line " << t.file.cone_lines[i] << " used "
          << std::count(side.begin(), side.end(), p) << " times";
    }
    // the rest of the boundary: big orange cones standing in it at the timekeeping line
    std::size_t big = 0;
    for (const Vec2& p : side) {
      big += std::any_of(t.file.cones.begin(), t.file.cones.end(),
                         [&](const Cone& c) { return c.color == ConeColor::BigOrange && c.position == p; });
    }
    EXPECT_EQ(side.size(), n + big);
    EXPECT_LE(big, 2u);
  }
}

TEST_P(RealTrack, BoundariesAreShortStepsAndDoNotCross) {
  const TrackModel& m = load(GetParam()).model;
  // the skidpad's boundaries jump once from the right circle to the left one (see track.h)
  auto circle_of = [&](Vec2 p) {
    return distance(p, m.skidpad->centre_right) < distance(p, m.skidpad->centre_left) ? 0 : 1;
  };
  for (const auto* side : {&m.left, &m.right}) {
    ASSERT_GE(side->size(), 3u);
    int jumps = 0;
    for (std::size_t i = 0; i < segments(*side, m.closed); ++i) {
      const Vec2 a = (*side)[i], b = (*side)[(i + 1) % side->size()];
      if (m.skidpad && circle_of(a) != circle_of(b)) {
        ++jumps;
        EXPECT_EQ(circle_of(a), 0) << "the right circle comes first";
        continue;
      }
      EXPECT_LE(distance(a, b), 10.0) << "segment " << i;
    }
    EXPECT_EQ(jumps, m.skidpad ? 1 : 0);
  }
  // brute force over all pairs of segments (own and other boundary)
  const std::vector<Vec2>& l = m.left;
  const std::vector<Vec2>& r = m.right;
  for (std::size_t i = 0; i < segments(l, m.closed); ++i) {
    for (std::size_t j = 0; j < segments(r, m.closed); ++j) {
      EXPECT_FALSE(proper_cross(l[i], l[(i + 1) % l.size()], r[j], r[(j + 1) % r.size()])) << i << " x " << j;
    }
  }
  for (const auto* side : {&l, &r}) {
    const auto& p = *side;
    for (std::size_t i = 0; i < segments(p, m.closed); ++i) {
      for (std::size_t j = i + 1; j < segments(p, m.closed); ++j) {
        EXPECT_FALSE(proper_cross(p[i], p[(i + 1) % p.size()], p[j], p[(j + 1) % p.size()])) << i << " x " << j;
      }
    }
  }
}

TEST_P(RealTrack, CentrelineIsOnTrackAndSmooth) {
  const TrackModel& m = load(GetParam()).model;
  ASSERT_GE(m.centreline.size(), 10u);
  ASSERT_EQ(m.width.size(), m.centreline.size());
  for (std::size_t i = 0; i < m.centreline.size(); ++i) {
    EXPECT_TRUE(m.on_track(m.centreline[i])) << "centreline point " << i;
    EXPECT_GE(m.width[i], 2.5) << i;
    EXPECT_LE(m.width[i], 8.0) << i;
  }
  // smooth: steps of ~0.5 m, no sharp turn from one step to the next, and no
  // zig-zag (three turns in a row of alternating sign, each over 4 degrees)
  std::vector<double> turn;
  const std::size_t n = m.centreline.size();
  for (std::size_t i = 0; i < segments(m.centreline, m.closed); ++i) {
    EXPECT_NEAR(distance(m.centreline[i], m.centreline[(i + 1) % n]), 0.5, 0.1) << "segment " << i;
  }
  // every point with two neighbours
  for (std::size_t i = m.closed ? 0 : 1; i < (m.closed ? n : n - 1); ++i) {
    const Vec2 a = m.centreline[(i + n - 1) % n], b = m.centreline[i], c = m.centreline[(i + 1) % n];
    turn.push_back(wrap_angle(angle_of(c - b) - angle_of(b - a)));
    EXPECT_LT(std::abs(turn.back()), 20.0 * kPi / 180.0) << "turn at point " << i;
  }
  const double deg3 = 4.0 * kPi / 180.0;
  for (std::size_t i = 2; i < turn.size(); ++i) {
    const bool zig = std::abs(turn[i - 2]) > deg3 && std::abs(turn[i - 1]) > deg3 && std::abs(turn[i]) > deg3 &&
                     (turn[i - 2] > 0) != (turn[i - 1] > 0) && (turn[i - 1] > 0) != (turn[i] > 0);
    EXPECT_FALSE(zig) << "zig-zag at point " << i;
  }
}

TEST_P(RealTrack, StartIsOnTrackAndFacesAlongTheCentreline) {
  const TrackModel& m = load(GetParam()).model;
  EXPECT_TRUE(m.on_track(m.start.position()));
  const Projection pr = project(m.centreline, m.closed, m.start.position());
  const Vec2 a = m.centreline[pr.segment], b = m.centreline[(pr.segment + 1) % m.centreline.size()];
  EXPECT_LT(std::abs(wrap_angle(m.start.yaw - angle_of(b - a))), 30.0 * kPi / 180.0);
  // the centreline starts near the start pose
  EXPECT_LT(distance(m.centreline.front(), m.start.position()), 1.0);
}

TEST_P(RealTrack, GatesAreCrossedForwardNotBackward) {
  const TrackModel& m = load(GetParam()).model;
  ASSERT_FALSE(m.gates.empty());
  const std::size_t n = m.centreline.size();
  for (std::size_t g = 0; g < m.gates.size(); ++g) {
    int forward = 0, backward = 0;
    for (std::size_t i = 0; i < segments(m.centreline, m.closed); ++i) {
      const Vec2 a = m.centreline[i], b = m.centreline[(i + 1) % n];
      forward += crossing_right_to_left(a, b, m.gates[g]).has_value();
      backward += crossing_right_to_left(b, a, m.gates[g]).has_value();
    }
    EXPECT_GE(forward, 1) << "gate " << g;
    EXPECT_EQ(backward, 0) << "gate " << g;
  }
  // gates in driving order: the first one is the first the car meets
  if (m.gates.size() >= 2 && m.kind != TrackKind::Skidpad) {
    const double s0 = project(m.centreline, m.closed, (m.gates[0].a + m.gates[0].b) * 0.5).s;
    const double s1 = project(m.centreline, m.closed, (m.gates[1].a + m.gates[1].b) * 0.5).s;
    EXPECT_LT(s0, s1);
  }
}

TEST_P(RealTrack, PointsOutsideTheBoundariesAreOffTrack) {
  const TrackModel& m = load(GetParam()).model;
  if (m.kind == TrackKind::Skidpad) GTEST_SKIP() << "rings: see Skidpad.OffTrackAroundTheRings";
  // 3 m outside each boundary along its outward normal, unless that lands
  // on another part of the track (brute force: close to the centreline, at a
  // point more than 10 m along the track from the boundary segment's own)
  const double length = polyline_length(m.centreline, m.closed);
  auto along_gap = [&](double s1, double s2) {
    const double d = std::abs(s1 - s2);
    return m.closed ? std::min(d, length - d) : d;
  };
  std::size_t tested = 0, skipped = 0;
  for (int side = 0; side < 2; ++side) {
    const auto& p = side == 0 ? m.left : m.right;
    for (std::size_t i = 0; i < segments(p, m.closed); ++i) {
      const Vec2 a = p[i], b = p[(i + 1) % p.size()];
      Vec2 out = left_normal(b - a) / distance(a, b);
      if (side == 1) out = -out;
      const Vec2 q = (a + b) * 0.5 + out * 3.0;
      const Projection own = project(m.centreline, m.closed, (a + b) * 0.5);
      const Projection there = project(m.centreline, m.closed, q);
      if (there.distance < 2.5 && along_gap(own.s, there.s) > 10.0) {
        ++skipped;
        continue;
      }
      ++tested;
      EXPECT_FALSE(m.on_track(q)) << (side == 0 ? "left" : "right") << " segment " << i;
    }
  }
  EXPECT_LT(skipped, tested / 4 + 1);
}

TEST_P(RealTrack, RegionAgreesWithBruteForcePolygons) {
  const TrackModel& m = load(GetParam()).model;
  if (m.kind != TrackKind::Circuit) GTEST_SKIP();
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (const Vec2& p : m.right) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  for (const Vec2& p : m.left) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(x0 - 5, x1 + 5), uy(y0 - 5, y1 + 5);
  for (int k = 0; k < 5000; ++k) {
    const Vec2 q{ux(rng), uy(rng)};
    EXPECT_EQ(m.on_track(q), polygon_contains(m.left, q) != polygon_contains(m.right, q)) << q.x << ", " << q.y;
  }
}

TEST_P(RealTrack, LengthAndWidthAgreeWithTheIndependentFigures) {
  const TrackModel& m = load(GetParam()).model;
  const auto table = readme_table("## Centreline length and width (independent figures)");
  const auto row = table.find(GetParam() + ".csv");
  ASSERT_NE(row, table.end()) << "no row in the README's independent table";
  ASSERT_EQ(row->second.size(), 5u);
  const double want[4] = {std::stod(row->second[1]), std::stod(row->second[2]), std::stod(row->second[3]),
                          std::stod(row->second[4])};
  const double got[4] = {m.centreline_length, m.width_min, m.width_mean, m.width_max};
  const char* what[4] = {"length", "width min", "width mean", "width max"};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(got[i], want[i], 0.03 * want[i]) << what[i];
}

TEST_P(RealTrack, ReportNamesTheFigures) {
  const Loaded& t = load(GetParam());
  const std::string r = check_track_report(t.model, t.file);
  EXPECT_THAT(r, StartsWith(GetParam() + ": " + std::string(track_kind_name(t.model.kind))));
  EXPECT_THAT(r, HasSubstr("centreline"));
  EXPECT_THAT(r, HasSubstr("width"));
  EXPECT_THAT(r, HasSubstr("gates"));
  EXPECT_THAT(r, HasSubstr("start"));
  for (const auto& w : t.file.warnings) EXPECT_THAT(r, HasSubstr(w));
}

// the undirected edges of a polyline, to compare boundaries whatever their first vertex
std::vector<std::pair<std::pair<double, double>, std::pair<double, double>>> edges(const std::vector<Vec2>& p,
                                                                                  bool closed) {
  std::vector<std::pair<std::pair<double, double>, std::pair<double, double>>> out;
  for (std::size_t i = 0; i < segments(p, closed); ++i) {
    auto a = std::make_pair(p[i].x, p[i].y), b = std::make_pair(p[(i + 1) % p.size()].x, p[(i + 1) % p.size()].y);
    out.push_back(a < b ? std::make_pair(a, b) : std::make_pair(b, a));
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST_P(RealTrack, RowOrderAndStartLineDoNotChangeTheBoundaries) {
  const Loaded& t = load(GetParam());
  // the same file with its cone rows shuffled and without its "# start" line
  std::vector<std::string> head, rows;
  std::istringstream in(read_text(kTracks + "/" + GetParam() + ".csv"));
  std::string line;
  bool seen_header = false;
  while (std::getline(in, line)) {
    if (line.rfind("# start", 0) == 0) continue;
    if (!seen_header) {
      head.push_back(line);
      seen_header = line == "tag,x,y";
    } else {
      rows.push_back(line);
    }
  }
  std::shuffle(rows.begin(), rows.end(), std::mt19937(11));
  std::string text;
  for (const auto& l : head) text += l + "\n";
  for (const auto& l : rows) text += l + "\n";
  const TrackModel m = build_track(parse_track(text, GetParam() + ".csv"));
  EXPECT_EQ(m.kind, t.model.kind);
  // without a start, colours decide the direction: the AMZ skidpad's are
  // swapped, so it is driven the other way round, left and right exchanged
  const bool swapped = GetParam() == "skidpad_amz_fssim";
  if (swapped) {
    auto sorted = [](std::vector<Vec2> p) {
      std::sort(p.begin(), p.end(), [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
      return p;
    };
    EXPECT_TRUE(sorted(m.right) == sorted(t.model.left));
    EXPECT_TRUE(sorted(m.left) == sorted(t.model.right));
  } else {
    EXPECT_EQ(edges(m.left, m.closed), edges(t.model.left, t.model.closed));
    EXPECT_EQ(edges(m.right, m.closed), edges(t.model.right, t.model.closed));
  }
  if (m.closed) {
    EXPECT_NEAR(m.centreline_length, t.model.centreline_length, 0.01 * t.model.centreline_length);
  }
  // the start made from the geometry is on the track and faces along it
  EXPECT_EQ(m.start_from, "geometry");
  EXPECT_TRUE(m.on_track(m.start.position()));
  const Projection pr = project(m.centreline, m.closed, m.start.position());
  const Vec2 a = m.centreline[pr.segment], b = m.centreline[(pr.segment + 1) % m.centreline.size()];
  EXPECT_LT(std::abs(wrap_angle(m.start.yaw - angle_of(b - a))), 30.0 * kPi / 180.0);
  const double facing = dot(m.start.heading(), t.model.start.heading());
  if (swapped) {
    EXPECT_LT(facing, -0.5);
  } else {
    EXPECT_GT(facing, 0.5);
  }
}

INSTANTIATE_TEST_SUITE_P(Tracks, RealTrack, ::testing::ValuesIn(track_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

TEST(Tracks, TheFolderHoldsEveryTrackOfTheReadme) {
  const auto names = track_names();
  EXPECT_EQ(names.size(), readme_table("## Files").size());
  EXPECT_GE(names.size(), 18u);
}

// ---------------------------------------------------------------------------
// reference facts (rules, ORACLES.md "FS dynamic events")

TEST(Acceleration, GatesAre75MetresApart) {
  for (const char* name : {"acceleration", "acceleration_amz_fssim"}) {
    const TrackModel& m = load(name).model;
    ASSERT_EQ(m.gates.size(), 2u) << name;
    const Vec2 g0 = (m.gates[0].a + m.gates[0].b) * 0.5, g1 = (m.gates[1].a + m.gates[1].b) * 0.5;
    EXPECT_NEAR(distance(g0, g1), 75.0, 0.75) << name;
    EXPECT_GT(dot(g1 - g0, m.start.heading()), 0.0) << name << ": start gate first";
  }
}

TEST(Skidpad, FittedCirclesMatchTheRules) {
  for (const char* name : {"skidpad", "skidpad_amz_fssim"}) {
    const TrackModel& m = load(name).model;
    ASSERT_TRUE(m.skidpad) << name;
    const SkidpadGeometry& g = *m.skidpad;
    EXPECT_NEAR(distance(g.centre_left, g.centre_right), 18.25, 0.03 * 18.25) << name;
    EXPECT_NEAR(g.radius, 9.125, 0.03 * 9.125) << name;
    EXPECT_NEAR(g.inner_radius, 7.475, 0.03 * 7.475) << name;
    EXPECT_NEAR(g.outer_radius, 10.775, 0.03 * 10.775) << name;
    // the right circle is on the right of the driving direction at the crossing
    const Vec2 h = unit_from_angle(g.heading);
    EXPECT_LT(cross(h, g.centre_right - g.crossing), 0.0) << name;
    EXPECT_GT(cross(h, g.centre_left - g.crossing), 0.0) << name;
    EXPECT_GT(dot(h, m.start.heading()), 0.9) << name;
    // the first gate is the one at the crossing
    EXPECT_LT(distance((m.gates[0].a + m.gates[0].b) * 0.5, g.crossing), 1.0) << name;
    EXPECT_LT(dot(g.entry_start - g.crossing, h), -10.0) << name;
    EXPECT_GT(dot(g.exit_end - g.crossing, h), 10.0) << name;
  }
}

TEST(Skidpad, OffTrackAroundTheRings) {
  for (const char* name : {"skidpad", "skidpad_amz_fssim"}) {
    const TrackModel& m = load(name).model;
    const SkidpadGeometry& g = *m.skidpad;
    const Vec2 h = unit_from_angle(g.heading);
    for (const Vec2 c : {g.centre_right, g.centre_left}) {
      const Vec2 other = c == g.centre_right ? g.centre_left : g.centre_right;
      for (int k = 0; k < 72; ++k) {
        const Vec2 u = unit_from_angle(2.0 * kPi * k / 72.0);
        EXPECT_TRUE(m.on_track(c + u * g.radius)) << name << " " << k;
        EXPECT_FALSE(m.on_track(c + u * (g.inner_radius - 3.0))) << name << " " << k;
        const Vec2 q = c + u * (g.outer_radius + 3.0);
        const bool in_lane = std::abs(cross(h, q - g.crossing)) < g.lane_half_width + 0.1;
        if (in_lane || distance(q, other) < g.outer_radius + 0.1) continue;
        EXPECT_FALSE(m.on_track(q)) << name << " " << k;
      }
    }
  }
}

TEST(Circuits, FsgLapLengthAndWidthAreRealistic) {
  for (const char* name : {"fsg_2019", "fsg_2021", "fsg_2023", "fsg_2024"}) {
    const TrackModel& m = load(name).model;
    EXPECT_GE(m.centreline_length, 200.0) << name;
    EXPECT_LE(m.centreline_length, 500.0) << name;
    EXPECT_GE(m.width_mean, 3.0) << name;
    EXPECT_LE(m.width_mean, 5.0) << name;
  }
}

TEST(Circuits, StartFromGeometryWhenTheFileHasNone) {
  // fsds_training has no "# start" and no "# timekeeping": its gate comes
  // from the big orange cones and the start is 6 m before it
  const TrackModel& m = load("fsds_training").model;
  EXPECT_EQ(m.start_from, "geometry");
  EXPECT_EQ(m.gates_from, "big_orange");
  ASSERT_EQ(m.gates.size(), 1u);
  const Vec2 gate_mid = (m.gates[0].a + m.gates[0].b) * 0.5;
  EXPECT_NEAR(distance(m.start.position(), gate_mid), 6.0, 0.3);
  // the four big orange cones stand about 3.5 m apart across the track
  EXPECT_NEAR(distance(m.gates[0].a, m.gates[0].b), 3.45, 0.3);
}

TEST(Circuits, OnTrackAtTheCentrelineOffTrackBeyondTheBoundary) {
  const TrackModel& m = load("fsg_2023").model;
  for (std::size_t i = 0; i < m.centreline.size(); i += 7) {
    const Vec2 c = m.centreline[i];
    const Vec2 t = m.centreline[(i + 1) % m.centreline.size()] - c;
    const Vec2 n = left_normal(t) / norm(t);
    EXPECT_TRUE(m.on_track(c));
    // just inside the left boundary is on track, 3 m past it is not
    const double dl = project(m.left, true, c).distance;
    EXPECT_TRUE(m.on_track(c + n * (0.8 * dl))) << i;
    const Vec2 q = c + n * (dl + 3.0);
    if (project(m.centreline, true, q).distance > 2.5) {
      EXPECT_FALSE(m.on_track(q)) << i;
    }
  }
}

// ---------------------------------------------------------------------------
// a small synthetic circuit: a stadium of two 20 m straights and two half
// circles of centreline radius 8 m, 3.5 m wide, one blue cone doubled

TEST(Synthetic, DoubledConeIsAWarningAndMerged) {
  const std::string path = kBad + "/doubled_cone.csv";
  const TrackFile f = load_track_file(path);
  ASSERT_EQ(f.warnings.size(), 1u);
  EXPECT_EQ(f.warnings[0], path + ":8: cone doubles the one at line 7 (0.020 m apart)");
  ASSERT_EQ(f.doubles.size(), 1u);
  EXPECT_EQ(f.cone_lines[f.doubles[0].cone], 8);
  EXPECT_EQ(f.cone_lines[f.doubles[0].original], 7);
  const TrackModel m = build_track(f);
  std::size_t blue = 0;
  for (const Cone& c : f.cones) blue += c.color == ConeColor::Blue;
  EXPECT_EQ(m.left.size(), blue - 1);
  EXPECT_EQ(m.cones.size(), f.cones.size() - 1);
  // analytic: 2 x 20 m + 2 pi 8 m; cones on polygons cut the corners a little
  EXPECT_NEAR(m.centreline_length, 40.0 + 2.0 * kPi * 8.0, 0.02 * (40.0 + 2.0 * kPi * 8.0));
  EXPECT_NEAR(m.width_mean, 3.5, 0.1);
  EXPECT_THAT(check_track_report(m, f), HasSubstr("doubles the one at line 7"));
}

// ---------------------------------------------------------------------------
// bad files: the exact file:line: prefix and a useful message

std::string error_of(const std::string& file) {
  try {
    load_track_file(kBad + "/" + file);
  } catch (const TrackError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(BadFiles, UnknownTag) {
  const std::string e = error_of("unknown_tag.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/unknown_tag.csv:5: "));
  EXPECT_THAT(e, HasSubstr("unknown cone tag 'purple'"));
  EXPECT_THAT(e, HasSubstr("blue, yellow, orange, big_orange, unknown"));
}

TEST(BadFiles, BadNumber) {
  const std::string e = error_of("bad_number.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/bad_number.csv:4: "));
  EXPECT_THAT(e, HasSubstr("bad number '1.5x' for x"));
}

TEST(BadFiles, NonFiniteNumber) {
  const std::string e = error_of("non_finite.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/non_finite.csv:4: "));
  EXPECT_THAT(e, HasSubstr("non-finite number 'inf'"));
}

TEST(BadFiles, WrongColumnCount) {
  const std::string e = error_of("wrong_columns.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/wrong_columns.csv:5: "));
  EXPECT_THAT(e, HasSubstr("found 4 columns, expected 3 (tag,x,y)"));
}

TEST(BadFiles, MalformedStart) {
  const std::string e = error_of("bad_start.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/bad_start.csv:3: "));
  EXPECT_THAT(e, HasSubstr("malformed '# start' line"));
  EXPECT_THAT(e, HasSubstr("'# start X Y YAW'"));
}

TEST(BadFiles, NoCones) {
  const std::string e = error_of("no_cones.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/no_cones.csv:3: "));
  EXPECT_THAT(e, HasSubstr("no cones"));
}

TEST(BadFiles, MissingHeaderRow) {
  const std::string e = error_of("missing_header.csv");
  EXPECT_THAT(e, StartsWith(kBad + "/missing_header.csv:2: "));
  EXPECT_THAT(e, HasSubstr("missing header row"));
  EXPECT_THAT(e, HasSubstr("'tag,x,y'"));
}

TEST(Parse, HeaderLinesCommentsAndCrlf) {
  const TrackFile f = parse_track(
      "# source: somewhere\r\n# start 1.5 -2 0.25\r\n# timekeeping 0 2\r\n# timekeeping 0 -2\r\n"
      "# note: start pose from elsewhere\r\ntag,x,y\r\n\r\nblue, 1.0 ,2.0\r\nbig_orange,+3,-4e0\r\n",
      "mem.csv");
  ASSERT_TRUE(f.start);
  EXPECT_EQ(f.start->x, 1.5);
  EXPECT_EQ(f.start->y, -2.0);
  EXPECT_EQ(f.start->yaw, 0.25);
  EXPECT_EQ(f.start_line, 2);
  ASSERT_EQ(f.timekeeping.size(), 2u);
  EXPECT_EQ(f.timekeeping_lines[1], 4);
  ASSERT_EQ(f.cones.size(), 2u);
  EXPECT_EQ(f.cones[1].color, ConeColor::BigOrange);
  EXPECT_EQ(f.cones[1].position.y, -4.0);
  EXPECT_EQ(f.cone_lines[0], 8);
  EXPECT_EQ(f.cone_lines[1], 9);
  EXPECT_TRUE(f.warnings.empty());
}

TEST(Parse, MoreErrors) {
  auto error = [](const std::string& text) {
    try {
      parse_track(text, "t.csv");
    } catch (const TrackError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_THAT(error("# timekeeping 1\ntag,x,y\nblue,1,2\n"), StartsWith("t.csv:1: malformed '# timekeeping' line"));
  EXPECT_THAT(error("# timekeeping 1 2\ntag,x,y\nblue,1,2\n"), StartsWith("t.csv:1: '# timekeeping' post without"));
  EXPECT_THAT(error("# start 0 0 0\n# start 1 1 1\ntag,x,y\nblue,1,2\n"), StartsWith("t.csv:2: second '# start'"));
  EXPECT_THAT(error("# start 0 nan 0\ntag,x,y\nblue,1,2\n"), StartsWith("t.csv:1: non-finite number 'nan'"));
  EXPECT_THAT(error("tag,x,y\nblue,,2\n"), StartsWith("t.csv:2: bad number '' for x"));
  EXPECT_THAT(error("tag,x,y\nBlue,1,2\n"), StartsWith("t.csv:2: unknown cone tag 'Blue'"));
  EXPECT_THAT(error(""), StartsWith("t.csv:1: missing header row"));
  EXPECT_THAT(error("# only comments\n"), StartsWith("t.csv:1: missing header row"));
  // spread over kilometres: the first line beyond kMaxTrackSpan of the first cone
  EXPECT_THAT(error("tag,x,y\nblue,100,0\nyellow,4000,3000\nblue,4100,3100\nblue,-5000,0\n"),
              StartsWith("t.csv:4: cone at (4100.0, 3100.0) is 5.1 km from the first cone (line 2)"));
  EXPECT_THAT(error("# timekeeping 0 1\n# timekeeping 0 9000\ntag,x,y\nblue,0,0\n"), StartsWith("t.csv:2: '# timekeeping' post at (0.0, 9000.0)"));
  EXPECT_THAT(error("tag,x,y\nblue,0,0\n# start 1e6 0 0\n"), StartsWith("t.csv:3: '# start' at (1000000.0, 0.0) is 1000.0 km"));
  EXPECT_EQ(error("tag,x,y\nblue,100,0\nyellow,4100,3000\n"), "(no error)");  // 5 km exactly: kept
}

TEST(Build, LayoutsThatMakeNoSenseNameTheSource) {
  // only orange cones
  const TrackFile a = parse_track("tag,x,y\norange,0,0\norange,5,0\n", "a.csv");
  EXPECT_THAT([&] { build_track(a); }, ::testing::ThrowsMessage<TrackError>(StartsWith("a.csv: ")));
  // two blue and two yellow cones: nothing to close
  const TrackFile b = parse_track("tag,x,y\nblue,0,2\nblue,5,2\nyellow,0,-2\nyellow,5,-2\n", "b.csv");
  EXPECT_THAT([&] { build_track(b); }, ::testing::ThrowsMessage<TrackError>(StartsWith("b.csv: ")));
  // a ring whose boundaries have a hole of 12.7 m (blue) and 18.2 m (yellow)
  std::string text = "tag,x,y\n";
  for (int k = 0; k < 24; ++k) {
    if (k >= 3 && k <= 8) continue;
    const double a0 = 2.0 * kPi * k / 24.0;
    text += "blue," + std::to_string(8.0 * std::cos(a0)) + "," + std::to_string(8.0 * std::sin(a0)) + "\n";
    text += "yellow," + std::to_string(11.5 * std::cos(a0)) + "," + std::to_string(11.5 * std::sin(a0)) + "\n";
  }
  const TrackFile c = parse_track(text, "c.csv");
  EXPECT_THAT([&] { build_track(c); }, ::testing::ThrowsMessage<TrackError>(HasSubstr("c.csv: cannot order")));
}

// found by the fuzzer: a real track's 82 blue cones around 4 yellow ones
// hundreds of metres apart. The centreline swung from side to side and grew
// to 3,680 km (7.4 million points, 10 s) before its length was checked
TEST(Build, ACentrelineThatDoesNotSettleIsRefused) {
  const TrackFile f = load_track_file(kBad + "/no_settle.csv");
  EXPECT_THAT([&] { build_track(f); },
              ::testing::ThrowsMessage<TrackError>(AllOf(StartsWith(kBad + "/no_settle.csv: the centreline does not settle"),
                                                         HasSubstr("the cones do not make a track"))));
}


}  // namespace
}  // namespace paddock::world
