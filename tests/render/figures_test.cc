// the four figures, read back from PNG and checked pixel by pixel: sizes,
// background, the colours of cones, trajectory and colour bar, text where the
// labels are, degenerate inputs, determinism, equal aspect.
// Set PADDOCK_RENDER_OUT=DIR to keep the figures as PNG files for a look.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "render/figures.h"
#include "tests/render/figure_test_util.h"

namespace paddock::render {
namespace {

using testing::font;
using testing::round_trip;
using testing::style;

// ---- a real track: FSG 2023 ----

struct Track {
  std::vector<Cone> cones;
  std::vector<Vec2> left, right;
  std::vector<Segment> gates;
  Pose2 start;
};

Track read_track(const std::string& path) {
  Track t;
  std::ifstream in(path);
  std::string line;
  std::vector<Vec2> keeping;
  while (std::getline(in, line)) {
    if (line.rfind("# start", 0) == 0) {
      std::istringstream ss(line.substr(7));
      ss >> t.start.x >> t.start.y >> t.start.yaw;
      continue;
    }
    if (line.rfind("# timekeeping", 0) == 0) {
      std::istringstream ss(line.substr(13));
      Vec2 p;
      ss >> p.x >> p.y;
      keeping.push_back(p);
      continue;
    }
    if (line.empty() || line[0] == '#' || line.rfind("tag,", 0) == 0) continue;
    std::istringstream ss(line);
    std::string tag, xs, ys;
    std::getline(ss, tag, ',');
    std::getline(ss, xs, ',');
    std::getline(ss, ys, ',');
    Cone c;
    c.position = {std::stod(xs), std::stod(ys)};
    c.color = tag == "blue"         ? ConeColor::Blue
              : tag == "yellow"     ? ConeColor::Yellow
              : tag == "orange"     ? ConeColor::SmallOrange
              : tag == "big_orange" ? ConeColor::BigOrange
                                    : ConeColor::Unknown;
    t.cones.push_back(c);
    if (c.color == ConeColor::Blue) t.left.push_back(c.position);
    if (c.color == ConeColor::Yellow) t.right.push_back(c.position);
  }
  for (std::size_t i = 0; i + 1 < keeping.size(); i += 2) t.gates.push_back({keeping[i], keeping[i + 1]});
  return t;
}

// a lap along the midpoints of each blue cone and its nearest yellow one,
// densified to about n points, with a speed from the curvature
void synthetic_lap(const Track& t, int n, std::vector<Vec2>& path, std::vector<double>& speed) {
  std::vector<Vec2> mid;
  for (const Vec2& b : t.left) {
    double best = 1e18;
    Vec2 q;
    for (const Vec2& y : t.right) {
      const double d = squared_norm(y - b);
      if (d < best) best = d, q = y;
    }
    mid.push_back(0.5 * (b + q));
  }
  double len = 0.0;
  for (std::size_t i = 0; i < mid.size(); ++i) len += distance(mid[i], mid[(i + 1) % mid.size()]);
  const double ds = len / n;
  for (std::size_t i = 0; i < mid.size(); ++i) {
    const Vec2 a = mid[i], b = mid[(i + 1) % mid.size()];
    const int k = std::max(1, static_cast<int>(std::round(distance(a, b) / ds)));
    for (int j = 0; j < k; ++j) path.push_back(a + (b - a) * (static_cast<double>(j) / k));
  }
  const std::size_t m = path.size();
  std::vector<double> raw(m);
  for (std::size_t i = 0; i < m; ++i) {
    const Vec2 a = path[(i + m - 8) % m], b = path[i], c = path[(i + 8) % m];
    const double k = 2.0 * std::abs(cross(b - a, c - b)) / (distance(a, b) * distance(b, c) * distance(a, c) + 1e-9);
    raw[i] = std::clamp(std::sqrt(9.0 / std::max(k, 1e-3)), 4.0, 17.0);
  }
  speed.assign(m, 0.0);
  for (std::size_t i = 0; i < m; ++i) {
    double s = 0.0;
    for (int j = -40; j <= 40; ++j) s += raw[(i + m + static_cast<std::size_t>(j + 40) - 40) % m];
    speed[i] = s / 81.0;
  }
}

TrackMapData fsg_map() {
  const Track t = read_track(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  TrackMapData d;
  d.title = "FSG 2023: trackdrive, lap 1";
  d.cones = t.cones;
  d.left = t.left;
  d.right = t.right;
  d.closed = true;
  d.gates = t.gates;
  d.start = t.start;
  synthetic_lap(t, 3500, d.trajectory, d.speed);
  return d;
}

// ---- helpers ----

bool same(Rgba a, Rgba b, int tol) {
  return std::abs(a.r - b.r) <= tol && std::abs(a.g - b.g) <= tol && std::abs(a.b - b.b) <= tol &&
         std::abs(a.a - b.a) <= tol;
}

std::string str(Rgba c) {
  return "(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + ", " +
         std::to_string(c.a) + ")";
}

// the pixel under a data point of an axes
Rgba at(const Image& img, const AxesFrame& ax, Vec2 p) {
  const Vec2 q = ax.to_pixel(p);
  return img.pixel(static_cast<int>(std::floor(q.x)), static_cast<int>(std::floor(q.y)));
}

int ink_pixels(const Image& img, const Box& b, Rgba background) {
  int n = 0;
  for (int y = b.top; y < b.bottom; ++y) {
    for (int x = b.left; x < b.right; ++x) n += !(img.pixel(x, y) == background);
  }
  return n;
}

bool inside(const Box& inner, const Box& outer) {
  return inner.left >= outer.left && inner.top >= outer.top && inner.right <= outer.right &&
         inner.bottom <= outer.bottom;
}

bool overlap(const Box& a, const Box& b) {
  return a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom;
}

// every named text box holds ink, lies in the image, and no two of them overlap
void expect_text_boxes(const Figure& fig, const Image& img, const std::vector<std::string>& names) {
  const Box whole{0, 0, img.width, img.height};
  for (const std::string& n : names) {
    ASSERT_TRUE(fig.boxes.count(n)) << "no box " << n;
    const Box& b = fig.boxes.at(n);
    EXPECT_TRUE(inside(b, whole)) << n;
    EXPECT_GT(b.right - b.left, 2) << n;
    EXPECT_GT(b.bottom - b.top, 2) << n;
    EXPECT_GT(ink_pixels(img, b, {255, 255, 255, 255}), 10) << "no text drawn in " << n;
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    for (std::size_t j = i + 1; j < names.size(); ++j) {
      EXPECT_FALSE(overlap(fig.boxes.at(names[i]), fig.boxes.at(names[j]))) << names[i] << " overlaps " << names[j];
    }
  }
}

// a synthetic track on a 40 m x 24 m patch: a ring of cones of every type
TrackMapData small_map() {
  TrackMapData d;
  d.title = "small test track";
  const ConeColor kinds[] = {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange,
                             ConeColor::Unknown};
  for (int i = 0; i < 20; ++i) {
    const double a = 2.0 * kPi * i / 20.0;
    d.cones.push_back({{20.0 * std::cos(a), 12.0 * std::sin(a)}, kinds[i % 5]});
  }
  return d;
}

// ---- the track map ----

TEST(TrackMap, FsgFigure) {
  const TrackMapData d = fsg_map();
  const Figure fig = draw_track_map(d, style(1600, 1600));
  const Image img = round_trip(fig, "fsg_2023_map");
  ASSERT_EQ(img.width, 1600);
  ASSERT_EQ(img.height, 1600);
  EXPECT_EQ(img.pixel(0, 0), (Rgba{255, 255, 255, 255}));
  EXPECT_EQ(img.pixel(1599, 1599), (Rgba{255, 255, 255, 255}));
  ASSERT_EQ(fig.axes.size(), 1u);
  const AxesFrame& ax = fig.axes[0];
  // the whole track is in the plot
  for (const Cone& c : d.cones) {
    const Vec2 p = ax.to_pixel(c.position);
    EXPECT_TRUE(ax.plot.contains(static_cast<int>(p.x), static_cast<int>(p.y)));
    EXPECT_EQ(at(img, ax, c.position), cone_color(c.color)) << c.position.x << ", " << c.position.y;
  }
  // the trajectory's colour is its speed's on the colour bar, where no cone is near
  double lo = 1e9, hi = -1e9;
  for (double v : d.speed) lo = std::min(lo, v), hi = std::max(hi, v);
  int checked = 0;
  for (std::size_t i = 0; i < d.trajectory.size(); i += 25) {
    bool near = false;
    for (const Cone& c : d.cones) near |= distance(c.position, d.trajectory[i]) < 1.0;
    near |= distance(d.start->position(), d.trajectory[i]) < 5.0;  // under the start arrow
    if (near) continue;
    const Rgba want = viridis((d.speed[i] - lo) / (hi - lo));
    EXPECT_TRUE(same(at(img, ax, d.trajectory[i]), want, 3)) << i << ": " << str(at(img, ax, d.trajectory[i]))
                                                             << " vs " << str(want);
    ++checked;
  }
  EXPECT_GT(checked, 100);
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "colorbar_label", "legend"});
}

TEST(TrackMap, ConeColoursAtTheirCentres) {
  const TrackMapData d = small_map();
  const Figure fig = draw_track_map(d, style(900, 700));
  const Image img = round_trip(fig, "small_map");
  const AxesFrame& ax = fig.axes[0];
  for (const Cone& c : d.cones) EXPECT_EQ(at(img, ax, c.position), cone_color(c.color));
  // and the cone types' colours are what the figure promises
  EXPECT_TRUE(same(cone_color(ConeColor::Blue), {0, 90, 255, 255}, 30));
  EXPECT_TRUE(same(cone_color(ConeColor::Yellow), {255, 210, 0, 255}, 30));
  EXPECT_FALSE(fig.boxes.count("colorbar"));  // no trajectory, no speed scale
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "legend"});
}

TEST(TrackMap, ConstantSpeedTrajectoryHasTheMidColour) {
  TrackMapData d = small_map();
  for (int i = 0; i <= 400; ++i) {
    const double a = 2.0 * kPi * i / 400.0;
    d.trajectory.push_back({8.0 * std::cos(a), 5.0 * std::sin(a)});
    d.speed.push_back(10.0);
  }
  const Figure fig = draw_track_map(d, style(1000, 800));
  const Image img = round_trip(fig, "constant_speed");
  const AxesFrame& ax = fig.axes[0];
  // one speed: the scale is [9.5, 10.5], the line at its middle
  const Rgba want = viridis(0.5);
  for (std::size_t i = 0; i + 1 < d.trajectory.size(); i += 7) {
    const Vec2 p = 0.5 * (d.trajectory[i] + d.trajectory[i + 1]);
    EXPECT_EQ(at(img, ax, p), want) << i << ": " << str(at(img, ax, p));
  }
  ASSERT_TRUE(fig.boxes.count("colorbar"));
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "colorbar_label", "legend"});
}

TEST(TrackMap, SpeedRampFollowsTheColourScale) {
  TrackMapData d;
  for (int i = 0; i <= 300; ++i) {
    d.trajectory.push_back({0.1 * i, 0.05 * i});
    d.speed.push_back(5.0 + 10.0 * i / 300.0);
  }
  const Figure fig = draw_track_map(d, style(1200, 900));
  const Image img = round_trip(fig, "speed_ramp");
  for (int i = 3; i < 300; i += 11) {
    const Rgba want = viridis(i / 300.0);
    const Rgba got = at(img, fig.axes[0], d.trajectory[static_cast<std::size_t>(i)]);
    EXPECT_TRUE(same(got, want, 2)) << i << ": " << str(got) << " vs " << str(want);
  }
}

TEST(TrackMap, PolylineLayerPassesThroughItsPixels) {
  TrackMapData d = small_map();
  MapLayer l;
  l.kind = MapLayer::Kind::Polyline;
  l.label = "centreline";
  l.color = {200, 30, 160, 255};
  l.size = 3.0;
  l.points = {{-10.0, -6.0}, {0.0, 4.0}, {10.0, -6.0}, {14.0, 0.0}};
  d.layers.push_back(l);
  const Figure fig = draw_track_map(d, style(1000, 800));
  const Image img = round_trip(fig, "layer");
  const AxesFrame& ax = fig.axes[0];
  for (std::size_t k = 0; k + 1 < l.points.size(); ++k) {
    for (double t = 0.05; t < 1.0; t += 0.1) {
      const Vec2 p = l.points[k] + (l.points[k + 1] - l.points[k]) * t;
      EXPECT_EQ(at(img, ax, p), l.color) << k << " " << t;
    }
  }
  // and not far off it
  EXPECT_EQ(at(img, ax, {0.7, -3.3}), (Rgba{255, 255, 255, 255}));
}

TEST(TrackMap, ColourBarEndsAreTheMapsEnds) {
  TrackMapData d = small_map();
  for (int i = 0; i < 100; ++i) {
    d.trajectory.push_back({-15.0 + 0.3 * i, 0.0});
    d.speed.push_back(3.0 + 0.1 * i);
  }
  const Figure fig = draw_track_map(d, style(1000, 800));
  const Image img = round_trip(fig, "colorbar");
  ASSERT_TRUE(fig.boxes.count("colorbar"));
  const Box& b = fig.boxes.at("colorbar");
  ASSERT_GT(b.bottom - b.top, 100);
  ASSERT_GT(b.right - b.left, 6);
  for (int x = b.left + 2; x < b.right - 2; ++x) {
    EXPECT_EQ(img.pixel(x, b.top), viridis(1.0)) << x;
    EXPECT_EQ(img.pixel(x, b.bottom - 1), viridis(0.0)) << x;
    EXPECT_TRUE(same(img.pixel(x, (b.top + b.bottom) / 2), viridis(0.5), 3));
  }
  EXPECT_EQ(viridis(0.0), (Rgba{68, 1, 84, 255}));
  EXPECT_EQ(viridis(1.0), (Rgba{253, 231, 37, 255}));
}

TEST(TrackMap, EqualAspectOnAWideImage) {
  TrackMapData d;
  d.cones = {{{0.0, 0.0}, ConeColor::Blue}, {{10.0, 0.0}, ConeColor::Blue}, {{10.0, 10.0}, ConeColor::Yellow},
             {{0.0, 10.0}, ConeColor::Yellow}};
  d.left = {{0.0, 0.0}, {10.0, 0.0}, {10.0, 10.0}, {0.0, 10.0}};
  d.closed = true;
  for (const auto& [w, h] : {std::pair{1400, 600}, std::pair{600, 1400}}) {
    const Figure fig = draw_track_map(d, style(w, h));
    const Image img = round_trip(fig, "square_" + std::to_string(w));
    const AxesFrame& ax = fig.axes[0];
    const Vec2 a = ax.to_pixel({0.0, 0.0}), b = ax.to_pixel({10.0, 0.0}), c = ax.to_pixel({0.0, 10.0});
    EXPECT_NEAR(b.x - a.x, a.y - c.y, 1e-6);  // 10 m is as many pixels across as up
    EXPECT_NEAR(b.y, a.y, 1e-9);
    EXPECT_GT(b.x - a.x, 100.0);
    // the drawn square: its corners' cones where the frame says
    for (const Cone& cone : d.cones) EXPECT_EQ(at(img, ax, cone.position), cone_color(cone.color));
    // the side's midpoints on the boundary line (light blue, not the background)
    EXPECT_FALSE(at(img, ax, {5.0, 0.0}) == (Rgba{255, 255, 255, 255}));
    EXPECT_FALSE(at(img, ax, {0.0, 5.0}) == (Rgba{255, 255, 255, 255}));
  }
}

TEST(TrackMap, DegenerateInputsStillGiveAnImage) {
  // nothing at all
  {
    const Figure fig = draw_track_map(TrackMapData{}, style(800, 600));
    const Image img = round_trip(fig, "empty_map");
    EXPECT_EQ(img.width, 800);
    EXPECT_EQ(img.height, 600);
    EXPECT_EQ(img.pixel(0, 0), (Rgba{255, 255, 255, 255}));
    EXPECT_FALSE(fig.boxes.count("colorbar"));
  }
  // an empty trajectory on a track
  {
    TrackMapData d = small_map();
    const Image img = round_trip(draw_track_map(d, style(800, 600)), "no_trajectory");
    EXPECT_EQ(img.width, 800);
  }
  // one point with one speed: a dot of the scale's middle colour, a colour bar
  {
    TrackMapData d;
    d.trajectory = {{3.0, 4.0}};
    d.speed = {7.0};
    const Figure fig = draw_track_map(d, style(800, 600));
    const Image img = round_trip(fig, "single_point");
    EXPECT_EQ(at(img, fig.axes[0], {3.0, 4.0}), viridis(0.5));
    EXPECT_TRUE(fig.boxes.count("colorbar"));
  }
  // one point without speeds; non-finite points; a start pose alone
  {
    TrackMapData d;
    d.trajectory = {{3.0, 4.0}};
    EXPECT_EQ(round_trip(draw_track_map(d, style(800, 600)), "single_point_no_speed").width, 800);
    d.trajectory = {{0.0, 0.0}, {std::nan(""), 1.0}, {5.0, 5.0}, {6.0, 5.0}};
    d.speed = {1.0, 2.0, std::nan(""), 4.0};
    EXPECT_EQ(round_trip(draw_track_map(d, style(800, 600)), "nan_points").width, 800);
    TrackMapData s;
    s.start = Pose2{1.0, 2.0, 0.5};
    EXPECT_EQ(round_trip(draw_track_map(s, style(800, 600)), "start_only").width, 800);
  }
  // a tiny image
  {
    const Image img = round_trip(draw_track_map(small_map(), style(40, 30)), "tiny");
    EXPECT_EQ(img.width, 40);
    EXPECT_EQ(img.height, 30);
  }
}

TEST(TrackMap, AllLayersAndEstimatedCones) {
  TrackMapData d = fsg_map();
  d.title = "FSG 2023 with every layer";
  MapLayer tri;
  tri.kind = MapLayer::Kind::Segments;
  tri.label = "Delaunay edges";
  tri.color = {170, 170, 170, 255};
  tri.size = 0.5;
  for (std::size_t i = 0; i + 1 < d.left.size(); ++i) {
    tri.points.push_back(d.left[i]);
    tri.points.push_back(d.right[std::min(i, d.right.size() - 1)]);
  }
  MapLayer mids;
  mids.kind = MapLayer::Kind::Points;
  mids.label = "midpoints";
  mids.color = {40, 40, 40, 255};
  mids.size = 3.0;
  mids.marker = Marker::Cross;
  for (std::size_t i = 0; i < d.trajectory.size(); i += 60) mids.points.push_back(d.trajectory[i]);
  d.layers = {tri, mids};
  for (std::size_t i = 0; i < d.cones.size(); i += 3) {
    Cone c = d.cones[i];
    const double k = static_cast<double>(i);
    c.position += Vec2{0.3 * std::sin(k * 1.7), 0.3 * std::cos(k * 0.9)};
    d.estimated_cones.push_back(c);
  }
  const Figure fig = draw_track_map(d, style(1600, 1600));
  const Image img = round_trip(fig, "fsg_2023_layers");
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "colorbar_label", "legend"});
}

TEST(TrackMap, SameInputSameBytes) {
  const TrackMapData d = fsg_map();
  const FigureStyle s = style(1000, 1000);
  const std::vector<std::uint8_t> a = encode_png(draw_track_map(d, s).image);
  const std::vector<std::uint8_t> b = encode_png(draw_track_map(d, s).image);
  EXPECT_EQ(a, b);
}

TEST(TrackMap, MismatchedSpeedsAreAnError) {
  TrackMapData d;
  d.trajectory = {{0.0, 0.0}, {1.0, 0.0}};
  d.speed = {1.0};
  EXPECT_THROW(draw_track_map(d, style(400, 300)), RenderError);
}

// llvmpipe may raster on several threads (LP_NUM_THREADS, read once per
// process): the same figure from a child process with 0 and with 3 raster
// threads has the same bytes as here
TEST(TrackMap, SameBytesWhateverTheRasterThreads) {
  const std::vector<std::uint8_t> png = encode_png(draw_track_map(fsg_map(), style(700, 700)).image);
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
  for (std::uint8_t b : png) hash = (hash ^ b) * 1099511628211ull;
  const std::string mine = "hash=" + std::to_string(hash);
  if (std::getenv("PADDOCK_RENDER_CHILD") != nullptr) {
    std::printf("%s\n", mine.c_str());
    return;
  }
  char self[4096] = {0};
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (n <= 0) GTEST_SKIP() << "no /proc/self/exe";
  for (const char* threads : {"0", "3"}) {
    const std::string cmd = std::string("PADDOCK_RENDER_CHILD=1 LP_NUM_THREADS=") + threads + " '" + self +
                            "' --gtest_filter=TrackMap.SameBytesWhateverTheRasterThreads 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[512];
    while (std::fgets(buf, sizeof(buf), p) != nullptr) out += buf;
    EXPECT_EQ(pclose(p), 0) << out;
    EXPECT_NE(out.find(mine), std::string::npos) << "LP_NUM_THREADS=" << threads << ":\n" << out;
  }
}

// ---- the style ----

TEST(Style, MissingOrBadFontIsAClearError) {
  FigureStyle s = style(400, 300);
  s.font = nullptr;
  try {
    draw_track_map(small_map(), s);
    FAIL() << "no error without a font";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("font"), std::string::npos) << e.what();
  }
  const std::vector<std::uint8_t> empty, junk(1000, 0x5a);
  s.font = &empty;
  try {
    draw_lap_chart({}, s);
    FAIL() << "no error for an empty font";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
  }
  s.font = &junk;
  EXPECT_THROW(draw_heatmap({}, s), RenderError);
  s = style(0, 300);
  EXPECT_THROW(draw_controller_data({}, s), RenderError);
  s = style(400, 300);
  s.dpi = 0.0;
  EXPECT_THROW(draw_controller_data({}, s), RenderError);
}

TEST(Style, BackgroundAndSupersampling) {
  FigureStyle s = style(600, 500);
  s.background = {250, 245, 230, 255};
  const Figure fig = draw_track_map(small_map(), s);
  EXPECT_EQ(fig.image.pixel(0, 0), s.background);
  EXPECT_EQ(fig.image.pixel(599, 499), s.background);
  // without anti-aliasing the cones are still where they are
  s.supersample = 1;
  const Figure plain = draw_track_map(small_map(), s);
  round_trip(plain, "no_supersampling");
  for (const Cone& c : small_map().cones) EXPECT_EQ(at(plain.image, plain.axes[0], c.position), cone_color(c.color));
}

// ---- the controller data ----

ControllerData controller_data(int n) {
  ControllerData d;
  d.title = "FSG 2023: controller data";
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    d.t.push_back(t);
    d.steer_cmd.push_back(0.3 * std::sin(0.7 * t) + 0.05 * std::sin(3.1 * t));
    d.steer.push_back(0.3 * std::sin(0.7 * (t - 0.08)) + 0.05 * std::sin(3.1 * (t - 0.08)));
    d.v_ref.push_back(11.0 + 4.0 * std::sin(0.35 * t));
    d.v.push_back(11.0 + 4.0 * std::sin(0.35 * (t - 0.3)) - 0.2);
    d.lateral_error.push_back(0.15 * std::sin(1.3 * t) + 0.03);
    d.heading_error.push_back(0.04 * std::cos(0.9 * t));
  }
  d.lap_starts = {0.0, 21.0, 41.5};
  return d;
}

TEST(Controller, PanelsLabelsAndSeries) {
  const ControllerData d = controller_data(6000);
  const Figure fig = draw_controller_data(d, style(1600, 1200));
  const Image img = round_trip(fig, "controller");
  ASSERT_EQ(img.width, 1600);
  ASSERT_EQ(img.height, 1200);
  ASSERT_EQ(fig.axes.size(), 4u);
  // one time axis: the panels are stacked, aligned, not overlapping
  for (std::size_t i = 1; i < 4; ++i) {
    EXPECT_EQ(fig.axes[i].plot.left, fig.axes[0].plot.left);
    EXPECT_EQ(fig.axes[i].plot.right, fig.axes[0].plot.right);
    EXPECT_GT(fig.axes[i].plot.top, fig.axes[i - 1].plot.bottom);
    EXPECT_EQ(fig.axes[i].x_min, fig.axes[0].x_min);
    EXPECT_EQ(fig.axes[i].x_max, fig.axes[0].x_max);
  }
  expect_text_boxes(fig, img, {"title", "x_label", "y_label_0", "y_label_1", "y_label_2", "y_label_3"});
  EXPECT_TRUE(fig.boxes.count("legend_0"));
  EXPECT_TRUE(fig.boxes.count("legend_1"));
  // the rotated y labels are taller than wide, and only the bottom panel labels time
  const Box& yl = fig.boxes.at("y_label_1");
  EXPECT_GT(yl.bottom - yl.top, yl.right - yl.left);
  EXPECT_GT(fig.boxes.at("x_label").top, fig.axes[3].plot.bottom);
  // the actual speed line passes where its samples are (in degrees for the steering)
  int hits = 0, tries = 0;
  for (std::size_t k = 100; k < d.t.size(); k += 97) {
    const Rgba got = at(img, fig.axes[1], {d.t[k], d.v[k]});
    const Box& lg = fig.boxes.at("legend_1");
    const Vec2 p = fig.axes[1].to_pixel({d.t[k], d.v[k]});
    if (lg.contains(static_cast<int>(p.x), static_cast<int>(p.y))) continue;
    ++tries;
    hits += !(got == Rgba{255, 255, 255, 255});
  }
  EXPECT_GE(hits, tries - 2);
  const Vec2 s0 = fig.axes[0].to_pixel({0.0, 0.3 * 180.0 / kPi});
  EXPECT_TRUE(fig.axes[0].plot.contains(static_cast<int>(s0.x) + 1, static_cast<int>(s0.y)));
}

TEST(Controller, NoSamplesAndBadSizes) {
  const Figure fig = draw_controller_data({}, style(800, 600));
  const Image img = round_trip(fig, "controller_empty");
  EXPECT_EQ(img.width, 800);
  EXPECT_EQ(fig.axes.size(), 4u);
  ControllerData d = controller_data(10);
  d.v.pop_back();
  EXPECT_THROW(draw_controller_data(d, style(800, 600)), RenderError);
  // one sample, and a series left out
  d = controller_data(1);
  d.steer.clear();
  EXPECT_EQ(round_trip(draw_controller_data(d, style(800, 600)), "controller_one").width, 800);
}

// ---- the lap chart ----

TEST(LapChart, BarsPenaltiesAndLabels) {
  LapChartData d;
  d.title = "FSG 2023: lap times";
  d.lap_times = {31.4, 24.2, 23.9, 24.5, 23.7, 24.0};
  d.timed = {false, true, true, true, true, true};
  d.doo = {0, 0, 2, 0, 0, 1};
  d.oc = {0, 0, 0, 1, 0, 0};
  const Figure fig = draw_lap_chart(d, style(1600, 1200));
  const Image img = round_trip(fig, "laps");
  const AxesFrame& ax = fig.axes.at(0);
  const Rgba timed = at(img, ax, {2.0, 10.0});
  const Rgba untimed = at(img, ax, {1.0, 10.0});
  EXPECT_FALSE(timed == untimed);
  EXPECT_GT(untimed.r + untimed.g + untimed.b, timed.r + timed.g + timed.b);  // lighter
  for (int lap = 2; lap <= 6; ++lap) EXPECT_EQ(at(img, ax, {static_cast<double>(lap), 12.0}), timed);
  // penalties in red on top: 2 DOO x 2 s on lap 3, 1 OC x 10 s on lap 4
  const Rgba red = at(img, ax, {3.0, 23.9 + 2.0}), red2 = at(img, ax, {4.0, 24.5 + 5.0});
  EXPECT_GT(red.r, 150);
  EXPECT_LT(red.g, 100);
  EXPECT_EQ(red, red2);
  EXPECT_EQ(at(img, ax, {2.0, 24.2 + 3.0}).r, 255);  // nothing above a clean lap but its label
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "legend"});
}

TEST(LapChart, NoLaps) {
  const Image img = round_trip(draw_lap_chart({}, style(800, 600)), "laps_empty");
  EXPECT_EQ(img.width, 800);
  LapChartData d;
  d.lap_times = {std::nan(""), 30.0};
  EXPECT_EQ(round_trip(draw_lap_chart(d, style(800, 600)), "laps_nan").width, 800);
}

// ---- the heat map ----

TEST(Heatmap, CellsHaveTheirValuesColour) {
  HeatmapData d;
  d.title = "x times y";
  d.x_label = "x";
  d.y_label = "y";
  d.value_label = "x y";
  d.x = {1, 2, 3, 4, 5, 6};
  d.y = {1, 2, 3, 4, 5};
  for (double y : d.y) {
    for (double x : d.x) d.values.push_back(x * y);
  }
  d.values[7] = std::nan("");  // (x = 2, y = 2) has no value
  const Figure fig = draw_heatmap(d, style(1200, 900));
  const Image img = round_trip(fig, "heatmap");
  const AxesFrame& ax = fig.axes.at(0);
  const double lo = 1.0, hi = 30.0;
  for (std::size_t j = 0; j < d.y.size(); ++j) {
    for (std::size_t i = 0; i < d.x.size(); ++i) {
      const double v = d.values[j * d.x.size() + i];
      const Rgba got = at(img, ax, {static_cast<double>(i), static_cast<double>(j)});
      if (std::isnan(v)) {
        EXPECT_EQ(got.r, got.g);  // grey
        EXPECT_EQ(got.g, got.b);
        continue;
      }
      EXPECT_TRUE(same(got, viridis((v - lo) / (hi - lo)), 1)) << i << "," << j << ": " << str(got);
      // and the whole middle of the cell
      const Vec2 c = ax.to_pixel({static_cast<double>(i) + 0.3, static_cast<double>(j) - 0.3});
      EXPECT_EQ(img.pixel(static_cast<int>(c.x), static_cast<int>(c.y)), got);
    }
  }
  ASSERT_TRUE(fig.boxes.count("colorbar"));
  const Box& b = fig.boxes.at("colorbar");
  EXPECT_EQ(img.pixel((b.left + b.right) / 2, b.top), viridis(1.0));
  EXPECT_EQ(img.pixel((b.left + b.right) / 2, b.bottom - 1), viridis(0.0));
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "colorbar_label"});
}

TEST(Heatmap, DegenerateGrids) {
  EXPECT_EQ(round_trip(draw_heatmap({}, style(800, 600)), "heatmap_empty").width, 800);
  HeatmapData d;
  d.x = {1.0, 2.0};
  d.y = {1.0};
  d.values = {std::nan(""), std::nan("")};
  const Figure fig = draw_heatmap(d, style(800, 600));
  EXPECT_FALSE(fig.boxes.count("colorbar"));
  d.values = {3.0, 3.0};
  const Figure one = draw_heatmap(d, style(800, 600));
  EXPECT_EQ(at(one.image, one.axes[0], {0.0, 0.0}), viridis(0.5));
  d.values = {1.0};
  EXPECT_THROW(draw_heatmap(d, style(800, 600)), RenderError);
}

// ---- the line chart ----

TEST(LineChart, SeriesPassThroughTheirPointsInTheirColours) {
  LineChartData d;
  d.title = "g-g-v envelope";
  d.x_label = "speed [m/s]";
  d.y_label = "acceleration [g]";
  const Rgba blue{31, 119, 180, 255}, red{214, 39, 40, 255};
  d.series = {{"max lateral", {5, 10, 15, 20, 25}, {0.9, 1.7, 1.9, 2.2, 2.5}, blue, Marker::Circle},
              {"max braking", {5, 10, 15, 20, 25}, {1.2, 1.3, 1.4, 1.5, 1.6}, red, Marker::Square}};
  const Figure fig = draw_line_chart(d, style(1200, 900));
  const Image img = round_trip(fig, "line_chart");
  EXPECT_EQ(img.width, 1200);
  EXPECT_EQ(img.height, 900);
  const AxesFrame& ax = fig.axes.at(0);
  // the range covers the data and reaches down to 0
  EXPECT_LE(ax.x_min, 5.0);
  EXPECT_GE(ax.x_max, 25.0);
  EXPECT_LE(ax.y_min, 0.0);
  EXPECT_GE(ax.y_max, 2.5);
  for (const LineSeries& s : d.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      // the marker at the point, and the line half way to the next one
      EXPECT_TRUE(same(at(img, ax, {s.x[i], s.y[i]}), s.color, 2)) << s.label << " " << i;
      if (i + 1 == s.x.size()) continue;
      const Vec2 mid{0.5 * (s.x[i] + s.x[i + 1]), 0.5 * (s.y[i] + s.y[i + 1])};
      EXPECT_TRUE(same(at(img, ax, mid), s.color, 2)) << s.label << " " << i << ": " << str(at(img, ax, mid));
    }
  }
  // nothing where no series is (white, or a light grid line)
  const Rgba empty = at(img, ax, {20.0, 0.5});
  EXPECT_TRUE(empty.r == empty.g && empty.g == empty.b && empty.r > 200) << str(empty);
  expect_text_boxes(fig, img, {"title", "x_label", "y_label", "legend"});
}

TEST(LineChart, GapsNoDataAndBadSizes) {
  EXPECT_EQ(round_trip(draw_line_chart({}, style(800, 600)), "line_chart_empty").width, 800);
  LineChartData d;
  d.series = {{"one", {1.0, 2.0, 3.0}, {1.0, std::nan(""), 3.0}, {0, 0, 0, 255}, Marker::Triangle}};
  const Figure fig = draw_line_chart(d, style(800, 600));
  EXPECT_GT(at(fig.image, fig.axes[0], {1.5, 1.5}).r, 200);  // a gap: no black line from (1, 1) to (2, 2)
  EXPECT_LT(at(fig.image, fig.axes[0], {1.0, 1.0}).r, 50);   // but the marker of (1, 1)
  d.series[0].y.pop_back();
  EXPECT_THROW(draw_line_chart(d, style(800, 600)), RenderError);
}

}  // namespace
}  // namespace paddock::render
