// the perception figures (the LiDAR view and the camera view), read back from
// PNG and checked at known data points: the point classes' colours, the
// orientation and window of the LiDAR view, clipping, the camera image's pixels
// in place, the boxes' and crosses' colours, bad input.
// Set PADDOCK_RENDER_OUT=DIR to keep the figures as PNG files for a look.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "render/figures.h"
#include "tests/render/figure_test_util.h"

namespace paddock::render {
namespace {

using testing::font;
using testing::round_trip;
using testing::style;

bool same(Rgba a, Rgba b, int tol) {
  return std::abs(a.r - b.r) <= tol && std::abs(a.g - b.g) <= tol && std::abs(a.b - b.b) <= tol &&
         std::abs(a.a - b.a) <= tol;
}

std::string str(Rgba c) {
  return "(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + ")";
}

Rgba under(const Image& img, Vec2 px) {
  return img.pixel(static_cast<int>(std::floor(px.x)), static_cast<int>(std::floor(px.y)));
}

// the pixel under a base-frame point of the LiDAR view (its axes map (y, x))
Rgba at_base(const Image& img, const AxesFrame& ax, Vec2 base) { return under(img, ax.to_pixel({base.y, base.x})); }

// one channel clearly above the other two
bool blueish(Rgba c) { return c.b > c.r + 40 && c.b > c.g + 20; }
bool reddish(Rgba c) { return c.r > c.g + 60 && c.r > c.b + 60; }
bool greenish(Rgba c) { return c.g > c.r + 40 && c.g > c.b + 40; }

int ink_pixels(const Image& img, const Box& b) {
  int n = 0;
  for (int y = std::max(0, b.top); y < std::min(img.height, b.bottom); ++y) {
    for (int x = std::max(0, b.left); x < std::min(img.width, b.right); ++x) {
      n += !(img.pixel(x, y) == Rgba{255, 255, 255, 255});
    }
  }
  return n;
}

// every named box holds ink and lies in the image
void expect_boxes(const Figure& fig, const Image& img, const std::vector<std::string>& names) {
  for (const std::string& n : names) {
    ASSERT_TRUE(fig.boxes.count(n)) << "no box " << n;
    const Box& b = fig.boxes.at(n);
    EXPECT_TRUE(b.left >= 0 && b.top >= 0 && b.right <= img.width && b.bottom <= img.height) << n;
    EXPECT_GT(ink_pixels(img, b), 10) << "nothing drawn in " << n;
  }
}

// a square patch of n x n points of one label, spaced 1 cm, centred on c
void patch(std::vector<LidarViewPoint>& pts, Vec2 c, int n, std::uint8_t label) {
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      pts.push_back({static_cast<float>(c.x + 0.01 * (i - 0.5 * (n - 1))), static_cast<float>(c.y + 0.01 * (j - 0.5 * (n - 1))),
                     label});
    }
  }
}

// ---- the LiDAR view ----

TEST(LidarView, PointClassesHaveTheirColours) {
  LidarViewData d;
  d.title = "segmented scan";
  patch(d.points, {8.3, 3.3}, 5, 0);    // ground
  patch(d.points, {6.3, -4.3}, 5, 1);   // non-ground
  d.points.push_back({11.3f, -2.3f, 2});  // one cone point
  const Figure fig = draw_lidar_view(d, style(900, 900));
  const Image img = round_trip(fig, "lidar_classes");
  ASSERT_EQ(fig.axes.size(), 1u);
  const AxesFrame& ax = fig.axes[0];
  EXPECT_TRUE(blueish(at_base(img, ax, {8.3, 3.3}))) << str(at_base(img, ax, {8.3, 3.3}));
  EXPECT_TRUE(reddish(at_base(img, ax, {6.3, -4.3}))) << str(at_base(img, ax, {6.3, -4.3}));
  EXPECT_TRUE(greenish(at_base(img, ax, {11.3, -2.3}))) << str(at_base(img, ax, {11.3, -2.3}));
  // the dots are small: 4 px beside the lone cone point is background (white or the grid)
  const Vec2 q = ax.to_pixel({-2.3, 11.3});
  EXPECT_FALSE(greenish(under(img, {q.x + 4.0, q.y})));
  expect_boxes(fig, img, {"title", "legend", "x_label", "y_label"});
}

TEST(LidarView, ForwardIsUpLeftIsLeftAndTheWindowHoldsTheRange) {
  LidarViewData d;
  d.range = 30.0;
  patch(d.points, {10.0, 5.0}, 5, 1);  // ahead and to the left
  const Figure fig = draw_lidar_view(d, style(1000, 800));
  const Image img = round_trip(fig, "lidar_orientation");
  const AxesFrame& ax = fig.axes[0];
  const Vec2 origin = ax.to_pixel({0.0, 0.0});
  const Vec2 ahead = ax.to_pixel({0.0, 10.0}), left = ax.to_pixel({5.0, 0.0});
  EXPECT_LT(ahead.y, origin.y - 10.0);
  EXPECT_NEAR(ahead.x, origin.x, 1e-6);
  EXPECT_LT(left.x, origin.x - 10.0);
  EXPECT_NEAR(left.y, origin.y, 1e-6);
  EXPECT_TRUE(reddish(at_base(img, ax, {10.0, 5.0})));
  // the window: at least [-range/3, range] forward, [-range/2, range/2] sideways, equal aspect
  EXPECT_LE(ax.y_min, -10.0 + 1e-9);
  EXPECT_GE(ax.y_max, 30.0 - 1e-9);
  EXPECT_GE(ax.x_min, 15.0 - 1e-9);   // flipped: the left edge is the largest y
  EXPECT_LE(ax.x_max, -15.0 + 1e-9);
  EXPECT_NEAR(ax.x_min, -ax.x_max, 1e-9);
  const double sx = (ax.plot.right - ax.plot.left) / (ax.x_min - ax.x_max);
  const double sy = (ax.plot.bottom - ax.plot.top) / (ax.y_max - ax.y_min);
  EXPECT_NEAR(sx, sy, 1e-9 * sx);
  // the car: a dark triangle just ahead of the origin
  const Rgba car = under(img, {origin.x, origin.y - 2.0});
  EXPECT_LT(car.r + car.g + car.b, 3 * 100) << str(car);
}

TEST(LidarView, DetectedConeIsGreenRingedInItsColourAndTruthIsABlackSquare) {
  LidarViewData d;
  d.detected = {{{12.0, 4.0}, ConeColor::Blue}, {{9.0, -3.0}, ConeColor::Yellow}};
  d.truth = {{{12.0, 4.0}, ConeColor::Blue}};
  const Figure fig = draw_lidar_view(d, style(1200, 1200));
  const Image img = round_trip(fig, "lidar_detected");
  const AxesFrame& ax = fig.axes[0];
  for (const Cone& c : d.detected) {
    EXPECT_TRUE(same(at_base(img, ax, c.position), {0, 200, 0, 255}, 3)) << str(at_base(img, ax, c.position));
    // walking right from the centre: the ring in the cone's colour
    const Vec2 p = ax.to_pixel({c.position.y, c.position.x});
    bool ring = false;
    for (int dx = 1; dx < 30 && !ring; ++dx) ring = same(under(img, {p.x + dx, p.y}), cone_color(c.color), 20);
    EXPECT_TRUE(ring) << c.position.x;
  }
  // around the true cone (and nowhere near the yellow one): black
  const auto dark_near = [&](Vec2 base) {
    const Vec2 p = ax.to_pixel({base.y, base.x});
    int n = 0;
    for (int dy = -30; dy <= 30; ++dy) {
      for (int dx = -30; dx <= 30; ++dx) {
        const Rgba c = under(img, {p.x + dx, p.y + dy});
        n += c.r < 60 && c.g < 60 && c.b < 60;
      }
    }
    return n;
  };
  EXPECT_GT(dark_near({12.0, 4.0}), 20);
  EXPECT_EQ(dark_near({9.0, -3.0}), 0);
  expect_boxes(fig, img, {"legend"});
}

TEST(LidarView, PointsOutsideTheWindowAreLeftOut) {
  LidarViewData d;
  d.range = 20.0;
  const float inf = INFINITY, nan = NAN;
  for (float y : {-40.0f, -11.0f, 11.0f, 40.0f, 1e30f}) d.points.push_back({5.0f, y, 1});
  for (float x : {-30.0f, -8.0f, 21.0f, 300.0f, -1e30f}) d.points.push_back({x, 0.0f, 1});
  d.points.push_back({nan, 0.0f, 1});
  d.points.push_back({0.0f, inf, 1});
  d.points.push_back({4.0f, 2.0f, 7});  // an unknown label: non-ground
  d.detected = {{{500.0, 0.0}, ConeColor::Blue}, {{nan, 1.0}, ConeColor::Yellow}};
  d.truth = {{{0.0, -inf}, ConeColor::Blue}};
  const Figure fig = draw_lidar_view(d, style(700, 500));
  const Image img = round_trip(fig, "lidar_clipped");
  const AxesFrame& ax = fig.axes[0];
  EXPECT_TRUE(reddish(at_base(img, ax, {4.0, 2.0})));
  // no red outside the plot box but in the legend's swatch
  const Box& legend = fig.boxes.at("legend");
  int red_outside = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      if (ax.plot.contains(x, y) || legend.contains(x, y)) continue;
      red_outside += reddish(img.pixel(x, y));
    }
  }
  EXPECT_EQ(red_outside, 0);
}

TEST(LidarView, EmptyScanAndBadInput) {
  const Figure fig = draw_lidar_view(LidarViewData{}, style(400, 300));
  EXPECT_EQ(fig.image.width, 400);
  EXPECT_EQ(fig.axes.size(), 1u);
  EXPECT_TRUE(fig.boxes.count("legend"));  // the car
  for (double r : {0.0, -5.0, static_cast<double>(NAN), static_cast<double>(INFINITY)}) {
    LidarViewData d;
    d.range = r;
    EXPECT_THROW(draw_lidar_view(d, style(400, 300)), RenderError) << r;
  }
  FigureStyle s = style(400, 300);
  s.font = nullptr;
  EXPECT_THROW(draw_lidar_view(LidarViewData{}, s), RenderError);
}

// a synthetic scan: 16 rings of ground points, walls of non-ground points,
// cones as little vertical stacks of cone points; ~30k points
LidarViewData synthetic_scan() {
  LidarViewData d;
  d.title = "LiDAR scan: ground (blue), non-ground (red), cones (green)";
  const int columns = 1800;
  for (int ring = 0; ring < 16; ++ring) {
    const double r = 3.0 + 1.35 * ring + 0.08 * ring * ring;
    for (int k = 0; k < columns; ++k) {
      const double a = 2.0 * kPi * k / columns;
      d.points.push_back({static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)), 0});
    }
  }
  for (int k = 0; k < 600; ++k) {  // a barrier left and a tyre wall ahead-right
    d.points.push_back({static_cast<float>(-5.0 + 0.05 * k), static_cast<float>(11.0 + 0.02 * std::sin(0.3 * k)), 1});
    if (k < 300) d.points.push_back({static_cast<float>(22.0 + 0.01 * (k % 7)), static_cast<float>(-6.0 - 0.02 * k), 1});
  }
  for (int i = 0; i < 8; ++i) {
    for (int side = -1; side <= 1; side += 2) {
      const Vec2 c{3.0 + 3.5 * i, side * (1.6 + 0.02 * i * i)};
      const ConeColor col = side > 0 ? ConeColor::Blue : ConeColor::Yellow;
      for (int k = 0; k < 24; ++k) {
        const double a = 2.0 * kPi * k / 24.0;
        d.points.push_back({static_cast<float>(c.x - 0.1 + 0.08 * std::cos(a)), static_cast<float>(c.y + 0.08 * std::sin(a)), 2});
      }
      if (i < 7) d.detected.push_back({{c.x + 0.05, c.y - 0.04}, i == 6 ? ConeColor::Unknown : col});
      d.truth.push_back({c, col});
    }
  }
  return d;
}

TEST(LidarView, ThirtyThousandPointsAt1600px) {
  const LidarViewData d = synthetic_scan();
  ASSERT_GT(d.points.size(), 29000u);
  const auto t0 = std::chrono::steady_clock::now();
  const Figure fig = draw_lidar_view(d, style(1600, 1600));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("draw_lidar_view: %zu points at 1600 x 1600 px in %.3f s\n", d.points.size(), s);
  RecordProperty("seconds", std::to_string(s));
  const auto t1 = std::chrono::steady_clock::now();
  draw_lidar_view(LidarViewData{}, style(1600, 1600));
  std::printf("draw_lidar_view: no points at 1600 x 1600 px in %.3f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  const Image img = round_trip(fig, "lidar_view");
  EXPECT_EQ(img.width, 1600);
  expect_boxes(fig, img, {"title", "legend", "x_label", "y_label"});
  // same input, same bytes
  EXPECT_EQ(draw_lidar_view(d, style(1600, 1600)).image.rgba, fig.image.rgba);
}

// ---- the camera view ----

CameraViewData solid(int w, int h, Rgba c) {
  CameraViewData d;
  d.width = w;
  d.height = h;
  for (int i = 0; i < w * h; ++i) d.rgb.insert(d.rgb.end(), {c.r, c.g, c.b});
  return d;
}

TEST(CameraView, SolidImageFillsTheAxesWithItsAspect) {
  const Rgba grey{90, 90, 90, 255};
  CameraViewData d = solid(64, 48, grey);
  d.title = "camera";
  const Figure fig = draw_camera_view(d, style(800, 700));
  const Image img = round_trip(fig, "camera_solid");
  ASSERT_EQ(fig.axes.size(), 1u);
  const AxesFrame& ax = fig.axes[0];
  // image coordinates: (0, 0) the plot box's top-left corner, (w, h) its bottom-right
  EXPECT_NEAR(ax.to_pixel({0.0, 0.0}).x, ax.plot.left, 1e-9);
  EXPECT_NEAR(ax.to_pixel({0.0, 0.0}).y, ax.plot.top, 1e-9);
  EXPECT_NEAR(ax.to_pixel({64.0, 48.0}).x, ax.plot.right, 1e-9);
  EXPECT_NEAR(ax.to_pixel({64.0, 48.0}).y, ax.plot.bottom, 1e-9);
  const double w = ax.plot.right - ax.plot.left, h = ax.plot.bottom - ax.plot.top;
  EXPECT_NEAR(w / h, 64.0 / 48.0, 1.5 / h);
  EXPECT_GT(w, 500.0);
  // every pixel of the plot box is the image's
  int off = 0;
  for (int y = ax.plot.top; y < ax.plot.bottom; ++y) {
    for (int x = ax.plot.left; x < ax.plot.right; ++x) off += !(img.pixel(x, y) == grey);
  }
  EXPECT_EQ(off, 0);
  EXPECT_EQ(under(img, ax.to_pixel({32.0, 24.0})), grey);
  expect_boxes(fig, img, {"title", "x_label", "y_label"});
  EXPECT_FALSE(fig.boxes.count("legend"));  // nothing to list
}

TEST(CameraView, ImagePixelsAtTheirPlacesRowZeroOnTop) {
  CameraViewData d;
  d.width = 5;
  d.height = 3;
  std::vector<Rgba> cols;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 5; ++i) {
      const Rgba c{static_cast<std::uint8_t>(40 * i + 10), static_cast<std::uint8_t>(90 * j + 20),
                   static_cast<std::uint8_t>((i + j) % 2 ? 230 : 30), 255};
      cols.push_back(c);
      d.rgb.insert(d.rgb.end(), {c.r, c.g, c.b});
    }
  }
  const Figure fig = draw_camera_view(d, style(733, 517));  // a non-integer scale
  const Image img = round_trip(fig, "camera_pixels");
  const AxesFrame& ax = fig.axes[0];
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 5; ++i) {
      for (Vec2 o : {Vec2{0.5, 0.5}, Vec2{0.1, 0.1}, Vec2{0.9, 0.9}}) {
        const Rgba got = under(img, ax.to_pixel({i + o.x, j + o.y}));
        EXPECT_EQ(got, cols[static_cast<std::size_t>(j * 5 + i)]) << i << ", " << j << ": " << str(got);
      }
    }
  }
}

TEST(CameraView, BoxesInTheirClassColourAndCrossesAtTheCentres) {
  CameraViewData d = solid(64, 48, {128, 128, 128, 255});
  d.boxes = {{10.0, 8.0, 26.0, 40.0, ConeColor::Yellow}, {40.0, 20.0, 50.0, 36.0, ConeColor::Blue},
             {2.0, 2.0, 8.0, 6.0, ConeColor::Unknown}};
  d.projected = {{18.0, 30.0}, {45.0, 30.0}};
  d.dropped = {{58.0, 10.0}};
  const Figure fig = draw_camera_view(d, style(900, 760));
  const Image img = round_trip(fig, "camera_boxes");
  const AxesFrame& ax = fig.axes[0];
  for (const CameraBox& b : d.boxes) {
    const double ym = 0.5 * (b.y_min + b.y_max), xm = 0.5 * (b.x_min + b.x_max);
    for (Vec2 e : {Vec2{b.x_min, ym}, Vec2{b.x_max, ym}, Vec2{xm, b.y_min}, Vec2{xm, b.y_max}}) {
      EXPECT_TRUE(same(under(img, ax.to_pixel(e)), cone_color(b.color), 2)) << str(under(img, ax.to_pixel(e)));
    }
  }
  // inside a box: the image
  EXPECT_EQ(under(img, ax.to_pixel({18.0, 14.0})), (Rgba{128, 128, 128, 255}));
  for (const Vec2& p : d.projected) EXPECT_TRUE(same(under(img, ax.to_pixel(p)), {0, 210, 0, 255}, 2));
  EXPECT_TRUE(same(under(img, ax.to_pixel(d.dropped[0])), {225, 20, 20, 255}, 2));
  expect_boxes(fig, img, {"legend", "x_label", "y_label"});
}

TEST(CameraView, NoImageAndBadInput) {
  CameraViewData d;
  d.width = 640;
  d.height = 480;
  d.projected = {{120.0, 100.0}, {NAN, 3.0}, {1e9, -1e9}};
  d.boxes = {{NAN, 0.0, 10.0, 10.0, ConeColor::Blue}, {-100.0, -50.0, 5000.0, 20.0, ConeColor::BigOrange}};
  const Figure fig = draw_camera_view(d, style(500, 400));
  EXPECT_EQ(fig.image.width, 500);
  const Image& img = fig.image;
  EXPECT_TRUE(same(under(img, fig.axes[0].to_pixel({120.0, 100.0})), {0, 210, 0, 255}, 2));
  EXPECT_TRUE(same(under(img, fig.axes[0].to_pixel({600.0, 400.0})), {232, 232, 232, 255}, 2));  // the grey field

  CameraViewData bad = solid(64, 48, {1, 2, 3, 255});
  bad.rgb.pop_back();
  EXPECT_THROW(draw_camera_view(bad, style(400, 300)), RenderError);
  try {
    draw_camera_view(bad, style(400, 300));
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("9215"), std::string::npos) << e.what();
  }
  for (Vec2 size : {Vec2{0, 48}, Vec2{64, 0}, Vec2{-64, -48}}) {
    CameraViewData z = solid(64, 48, {1, 2, 3, 255});
    z.width = static_cast<int>(size.x);
    z.height = static_cast<int>(size.y);
    EXPECT_THROW(draw_camera_view(z, style(400, 300)), RenderError);
  }
  CameraViewData none;
  EXPECT_THROW(draw_camera_view(none, style(400, 300)), RenderError);
  FigureStyle s = style(400, 300);
  s.font = nullptr;
  EXPECT_THROW(draw_camera_view(solid(8, 8, {1, 2, 3, 255}), s), RenderError);
}

// a synthetic 800 x 500 frame: sky, grass, asphalt, cones as striped triangles
CameraViewData synthetic_frame() {
  CameraViewData d;
  d.title = "camera: detections and projected LiDAR cluster centres";
  d.width = 800;
  d.height = 500;
  d.rgb.resize(800 * 500 * 3);
  const auto put = [&](int x, int y, Rgba c) {
    if (x < 0 || y < 0 || x >= 800 || y >= 500) return;
    std::uint8_t* p = &d.rgb[3 * (static_cast<std::size_t>(y) * 800 + static_cast<std::size_t>(x))];
    p[0] = c.r, p[1] = c.g, p[2] = c.b;
  };
  const int horizon = 210;
  for (int y = 0; y < 500; ++y) {
    for (int x = 0; x < 800; ++x) {
      Rgba c;
      if (y < horizon) {
        const double t = y / static_cast<double>(horizon);
        c = {static_cast<std::uint8_t>(120 + 80 * t), static_cast<std::uint8_t>(170 + 60 * t), 235, 255};
      } else {
        // the road between two lines converging at (400, horizon)
        const double half = 20.0 + 1.6 * (y - horizon);
        const bool road = std::abs(x - 400.0) < half;
        const int n = ((x * 7 + y * 13) % 11) - 5;  // a little texture
        c = road ? Rgba{static_cast<std::uint8_t>(95 + n), static_cast<std::uint8_t>(95 + n), static_cast<std::uint8_t>(100 + n), 255}
                 : Rgba{static_cast<std::uint8_t>(70 + n), static_cast<std::uint8_t>(130 + n), static_cast<std::uint8_t>(60 + n), 255};
      }
      put(x, y, c);
    }
  }
  // cones: (base centre x, base y, height px, colour)
  struct C {
    double x, y, h;
    ConeColor col;
  };
  const C cones[] = {{160, 460, 70, ConeColor::Blue},   {640, 460, 70, ConeColor::Yellow},
                     {270, 330, 38, ConeColor::Blue},   {530, 330, 38, ConeColor::Yellow},
                     {330, 270, 22, ConeColor::Blue},   {470, 270, 22, ConeColor::Yellow},
                     {362, 240, 13, ConeColor::Blue},   {438, 240, 13, ConeColor::Yellow}};
  for (const C& c : cones) {
    const Rgba body = c.col == ConeColor::Blue ? Rgba{20, 60, 200, 255} : Rgba{240, 200, 10, 255};
    const Rgba stripe = c.col == ConeColor::Blue ? Rgba{240, 240, 240, 255} : Rgba{20, 20, 20, 255};
    for (int y = static_cast<int>(c.y - c.h); y <= static_cast<int>(c.y); ++y) {
      const double t = (y - (c.y - c.h)) / c.h;  // 0 at the tip
      const double half = 0.1 * c.h + 0.3 * c.h * t;
      const bool band = t > 0.4 && t < 0.6;
      for (int x = static_cast<int>(c.x - half); x <= static_cast<int>(c.x + half); ++x) put(x, y, band ? stripe : body);
    }
    const double w = 0.45 * c.h;
    d.boxes.push_back({c.x - w, c.y - c.h - 3, c.x + w, c.y + 3, c.col});
    d.projected.push_back({c.x + 0.04 * c.h, c.y - 0.45 * c.h});
  }
  d.boxes.back().color = ConeColor::Unknown;
  d.dropped = {{700.0, 300.0}, {90.0, 250.0}};
  return d;
}

TEST(CameraView, SyntheticFrame) {
  const CameraViewData d = synthetic_frame();
  const auto t0 = std::chrono::steady_clock::now();
  const Figure fig = draw_camera_view(d, style(1600, 1100));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("draw_camera_view: 800 x 500 image at 1600 x 1100 px in %.3f s\n", s);
  const Image img = round_trip(fig, "camera_view");
  expect_boxes(fig, img, {"title", "legend", "x_label", "y_label"});
  const AxesFrame& ax = fig.axes[0];
  for (const Vec2& p : d.projected) EXPECT_TRUE(same(under(img, ax.to_pixel(p)), {0, 210, 0, 255}, 2));
  // the image's pixels where nothing is drawn over them: the sky, and the
  // textured grass and road bottom left (every pixel a run of its own)
  int checked = 0, wrong = 0;
  const auto check = [&](int u, int v) {
    const std::size_t k = 3 * (static_cast<std::size_t>(v) * 800 + static_cast<std::size_t>(u));
    const Rgba want{d.rgb[k], d.rgb[k + 1], d.rgb[k + 2], 255};
    ++checked;
    wrong += !(under(img, ax.to_pixel({u + 0.5, v + 0.5})) == want);
  };
  for (int v = 0; v < 200; v += 3) for (int u = 0; u < 800; u += 7) check(u, v);
  for (int v = 470; v < 500; ++v) for (int u = 0; u < 110; ++u) check(u, v);
  EXPECT_GT(checked, 10000);
  EXPECT_EQ(wrong, 0);
}

}  // namespace
}  // namespace paddock::render
