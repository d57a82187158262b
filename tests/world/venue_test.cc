// the venue's barrier rows: on every real track, checked by brute force on
// the blocks' footprints (every cone far enough, nothing on the track, no two
// blocks overlapping) and for how much of the track they line.
#include "sim/world/venue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/common/polyline.h"

namespace paddock::world {
namespace {

const std::string kTracks = std::string(PADDOCK_SOURCE_DIR) + "/tracks";

TrackModel load(const std::string& name) {
  const std::string path = kTracks + "/" + name + ".csv";
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return build_track(parse_track(ss.str(), path));
}

std::vector<std::string> track_names() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(kTracks)) {
    if (e.path().extension() == ".csv") out.push_back(e.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// points every `step` along the outline of a block's footprint
std::vector<Vec2> outline(const Block& b, double step) {
  const std::vector<Vec2> c = block_corners(b);
  std::vector<Vec2> out;
  for (std::size_t k = 0; k < 4; ++k) {
    const Vec2 a = c[k], d = c[(k + 1) % 4];
    const int n = std::max(1, static_cast<int>(std::ceil(distance(a, d) / step)));
    for (int i = 0; i < n; ++i) out.push_back(a + (d - a) * (i / double(n)));
  }
  return out;
}

// a point inside the footprint (a rectangle)
bool inside(const Block& b, Vec2 p) {
  const Vec2 u = unit_from_angle(b.yaw);
  const Vec2 d = p - b.centre;
  return std::abs(dot(d, u)) <= 0.5 * b.length && std::abs(cross(u, d)) <= 0.5 * b.width;
}

class VenueOnTrack : public ::testing::TestWithParam<std::string> {};

TEST_P(VenueOnTrack, BlocksStandClearOfConesAndTrackWithoutOverlapping) {
  const TrackModel track = load(GetParam());
  VenueParams p;
  EXPECT_TRUE(venue_blocks(track, track.cones, p).empty()) << "barrier_offset 0: no barriers";
  p.barrier_offset = 3.0;
  const std::vector<Block> blocks = venue_blocks(track, track.cones, p);
  ASSERT_FALSE(blocks.empty());
  // the same again (deterministic)
  const std::vector<Block> again = venue_blocks(track, track.cones, p);
  ASSERT_EQ(again.size(), blocks.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    EXPECT_EQ(again[i].centre, blocks[i].centre);
    EXPECT_EQ(again[i].yaw, blocks[i].yaw);
  }
  double total = 0.0;
  const double keep = 0.9 * p.barrier_offset;
  for (const Block& b : blocks) {
    EXPECT_DOUBLE_EQ(b.width, p.barrier_width);
    EXPECT_DOUBLE_EQ(b.height, p.barrier_height);
    // (a block at a bend gives way to its neighbour by up to half its length)
    EXPECT_GT(b.length, 0.25 * p.block_length - p.block_gap - 1e-9);
    EXPECT_LE(b.length, 2.0 * p.block_length);
    total += b.length;
    // the footprint (its outline and its axis, densely): every cone at least
    // keep - width / 2 away, nothing on the track
    std::vector<Vec2> pts = outline(b, 0.05);
    const Vec2 u = unit_from_angle(b.yaw) * (0.5 * b.length);
    for (int i = 0; i <= 40; ++i) pts.push_back(b.centre - u + 2.0 * u * (i / 40.0));
    for (const Vec2 q : pts) {
      for (const Cone& c : track.cones) {
        ASSERT_GE(distance(q, c.position), keep - 0.5 * b.width - 1e-9) << GetParam() << ": a cone too near a block";
      }
    }
    for (int i = 0; i <= 40; ++i) {
      ASSERT_FALSE(track.on_track(b.centre - u + 2.0 * u * (i / 40.0))) << GetParam() << ": a block on the track";
    }
  }
  // no two footprints overlap: no outline point of one inside the other
  // shrunk by 1 mm (blocks that touch pass)
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (std::size_t j = 0; j < blocks.size(); ++j) {
      if (i == j || distance(blocks[i].centre, blocks[j].centre) > blocks[i].length + blocks[j].length) continue;
      Block shrunk = blocks[i];
      shrunk.length -= 2e-3;
      shrunk.width -= 2e-3;
      for (const Vec2 q : outline(blocks[j], 0.02)) {
        ASSERT_FALSE(inside(shrunk, q)) << GetParam() << ": blocks " << i << " and " << j << " overlap";
      }
    }
  }
  // how much they line: against the boundaries' length
  const double lines = polyline_length(track.left, track.closed) + polyline_length(track.right, track.closed);
  std::printf("%s: %zu blocks, %.0f m of barrier along %.0f m of boundary (%.0f %%)\n", GetParam().c_str(),
              blocks.size(), total, lines, 100.0 * total / lines);
  if (track.kind == TrackKind::Circuit) {
    EXPECT_GT(total, 0.5 * lines) << "the barriers line most of a circuit";
  }
}

INSTANTIATE_TEST_SUITE_P(Tracks, VenueOnTrack, ::testing::ValuesIn(track_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

TEST(Venue, ARowAlongAStraightLiesAtTheOffsetWithItsGaps) {
  // a straight lane 200 m long: blue line y = +1.5, yellow y = -1.5, every
  // 5 m (built by hand: the boundaries, the region between them)
  TrackModel track;
  track.kind = TrackKind::Acceleration;
  for (int i = 0; i <= 40; ++i) {
    track.cones.push_back({{5.0 * i, 1.5}, ConeColor::Blue});
    track.cones.push_back({{5.0 * i, -1.5}, ConeColor::Yellow});
    track.left.push_back({5.0 * i, 1.5});
    track.right.push_back({5.0 * i, -1.5});
  }
  track.region.add_xor_polygon({{-3.0, -1.5}, {203.0, -1.5}, {203.0, 1.5}, {-3.0, 1.5}});
  VenueParams p;
  p.barrier_offset = 4.0;
  const std::vector<Block> blocks = venue_blocks(track, track.cones, p);
  ASSERT_EQ(blocks.size(), 200u);  // 100 of 2 m on each 200 m line
  int left = 0, right = 0;
  for (const Block& b : blocks) {
    EXPECT_GE(b.centre.x - 0.5 * b.length, -1e-9);
    EXPECT_LE(b.centre.x + 0.5 * b.length, 200.0 + 1e-9);
    // along the lane (yaw 0 or pi), 4 m outside the lines of cones
    EXPECT_NEAR(std::abs(std::sin(b.yaw)), 0.0, 1e-9);
    if (b.centre.y > 0.0) {
      ++left;
      EXPECT_NEAR(b.centre.y, 5.5, 1e-9);
    } else {
      ++right;
      EXPECT_NEAR(b.centre.y, -5.5, 1e-9);
    }
    EXPECT_NEAR(b.length, p.block_length - p.block_gap, 1e-9);
  }
  EXPECT_EQ(left, right);
}

TEST(Venue, BadParametersAreRefused) {
  VenueParams p;
  p.barrier_offset = 0.4;
  EXPECT_FALSE(params::validate(p).empty());
  p.barrier_offset = 3.0;
  EXPECT_TRUE(params::validate(p).empty());
  p.block_length = 0.1;
  EXPECT_FALSE(params::validate(p).empty());
}

}  // namespace
}  // namespace paddock::world
