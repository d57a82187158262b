// the GL canvas: exact flat colours inside shapes, strokes through their
// pixels, even-odd polygons, markers, clipping, dashes, translucency without
// double blending, and the same pixels every time.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/canvas.h"
#include "render/gl_context.h"

namespace paddock::render {
namespace {

const Rgba kWhite{255, 255, 255, 255};
const Rgba kRed{220, 30, 40, 255};
const Rgba kBlue{20, 60, 230, 255};

Rgba px(const Image& img, double x, double y) {
  return img.pixel(static_cast<int>(std::floor(x)), static_cast<int>(std::floor(y)));
}

TEST(GlContext, SizeLimitsAreErrors) {
  EXPECT_THROW(GlContext(0, 10), RenderError);
  EXPECT_THROW(GlContext(10, -1), RenderError);
  EXPECT_THROW(GlContext(GlContext::max_size() + 1, 10), RenderError);
  GlContext ok(16, 8);
  EXPECT_EQ(ok.read_rgba().size(), 16u * 8u * 4u);
}

TEST(Canvas, RectanglesKeepExactColours) {
  for (int ss : {1, 2, 3, 4}) {
    Canvas c(100, 80, ss, kWhite);
    c.fill_rect(10, 10, 50, 40, kRed);
    c.fill_rect(60.5, 10, 90, 40, kBlue);  // an edge through the middle of column 60
    const Image img = c.finish();
    ASSERT_EQ(img.width, 100);
    ASSERT_EQ(img.height, 80);
    EXPECT_EQ(img.pixel(10, 10), kRed);
    EXPECT_EQ(img.pixel(49, 39), kRed);
    EXPECT_EQ(img.pixel(50, 39), kWhite);
    EXPECT_EQ(img.pixel(9, 20), kWhite);
    EXPECT_EQ(img.pixel(0, 0), kWhite);
    EXPECT_EQ(img.pixel(61, 20), kBlue);
    if (ss % 2 == 0) {
      // half covered: half way between blue and white
      const Rgba edge = img.pixel(60, 20);
      EXPECT_NEAR(edge.r, (kBlue.r + 255) / 2.0, 1.0) << ss;
      EXPECT_NEAR(edge.b, (kBlue.b + 255) / 2.0, 1.0) << ss;
    }
  }
}

TEST(Canvas, StrokesPassThroughTheirPixels) {
  Canvas c(200, 160, 3, kWhite);
  Stroke s;
  s.width = 5.0;
  const std::vector<Vec2> zig{{20, 20}, {100, 60}, {40, 120}, {180, 140}};
  c.stroke(zig, s, kRed);
  Stroke thin;
  thin.width = 3.0;
  c.stroke({{10.0, 150.5}, {100.0, 150.5}}, thin, kBlue);
  const Image img = c.finish();
  for (std::size_t i = 0; i + 1 < zig.size(); ++i) {
    for (double t = 0.0; t <= 1.0; t += 0.05) {
      const Vec2 p = zig[i] + (zig[i + 1] - zig[i]) * t;
      EXPECT_EQ(px(img, p.x, p.y), kRed) << i << " " << t;
    }
  }
  // a 3 px horizontal line on row 150 covers rows 149-151 exactly and nothing more
  for (int x = 12; x < 98; x += 5) {
    EXPECT_EQ(img.pixel(x, 149), kBlue);
    EXPECT_EQ(img.pixel(x, 150), kBlue);
    EXPECT_EQ(img.pixel(x, 151), kBlue);
    EXPECT_EQ(img.pixel(x, 147), kWhite);
    EXPECT_EQ(img.pixel(x, 153), kWhite);
  }
  // nothing far from the lines
  EXPECT_EQ(img.pixel(150, 30), kWhite);
}

TEST(Canvas, SharpTurnsAndClosedStrokes) {
  Canvas c(200, 200, 3, kWhite);
  Stroke s;
  s.width = 4.0;
  // a hairpin: the miter would be long, a bevel replaces it; nothing spikes far out
  c.stroke({{20, 50}, {180, 55}, {20, 60}}, s, kRed);
  // a closed square
  c.stroke({{50, 100}, {150, 100}, {150, 180}, {50, 180}}, s, kBlue, true);
  const Image img = c.finish();
  EXPECT_EQ(img.pixel(100, 52), kRed);
  EXPECT_EQ(img.pixel(190, 55), kWhite);
  EXPECT_EQ(img.pixel(100, 140), kWhite);
  for (const Vec2 corner : {Vec2{50, 100}, Vec2{150, 100}, Vec2{150, 180}, Vec2{50, 180}}) {
    EXPECT_EQ(px(img, corner.x, corner.y), kBlue);
  }
  EXPECT_EQ(img.pixel(50, 140), kBlue);  // the closing side
}

TEST(Canvas, EvenOddPolygons) {
  Canvas c(200, 200, 2, kWhite);
  // a pentagram: its tips inside, its centre pentagon outside (even-odd)
  std::vector<Vec2> star;
  for (int i = 0; i < 5; ++i) {
    const double a = -0.5 * kPi + 4.0 * kPi * i / 5.0;
    star.push_back({100 + 90 * std::cos(a), 100 + 90 * std::sin(a)});
  }
  c.fill_polygon(star, kRed);
  // a concave L
  c.fill_polygon({{5, 5}, {40, 5}, {40, 15}, {15, 15}, {15, 40}, {5, 40}}, kBlue);
  const Image img = c.finish();
  EXPECT_EQ(img.pixel(100, 100), kWhite);
  EXPECT_EQ(img.pixel(100, 25), kRed);  // below the top tip
  EXPECT_EQ(img.pixel(10, 30), kBlue);
  EXPECT_EQ(img.pixel(30, 10), kBlue);
  EXPECT_EQ(img.pixel(30, 30), kWhite);  // the L's notch
}

TEST(Canvas, MarkersHaveTheirFillAtTheCentre) {
  Canvas c(200, 60, 3, kWhite);
  const Rgba edge{0, 0, 0, 255};
  c.marker({20, 30}, Marker::Circle, 24, kRed, edge, 2);
  c.marker({60, 30}, Marker::Square, 24, kRed, edge, 2);
  c.marker({100, 30}, Marker::Triangle, 24, kRed, edge, 2);
  c.marker({140, 30}, Marker::Cross, 24, kBlue, edge, 2);
  c.marker({180, 30}, Marker::Circle, 24, {0, 0, 0, 0}, kBlue, 3);  // hollow
  const Image img = c.finish();
  EXPECT_EQ(img.pixel(20, 30), kRed);
  EXPECT_EQ(img.pixel(60, 30), kRed);
  EXPECT_EQ(img.pixel(100, 30), kRed);
  EXPECT_EQ(img.pixel(140, 30), kBlue);
  EXPECT_EQ(img.pixel(180, 30), kWhite);
  EXPECT_EQ(img.pixel(180 + 10, 30), kBlue);  // on the ring (radius 12, 3 px wide)
  EXPECT_EQ(img.pixel(20 + 10, 30), edge);    // on the circle's outline
  EXPECT_EQ(img.pixel(20 + 14, 30), kWhite);  // outside it
}

TEST(Canvas, ClippingAndDashes) {
  Canvas c(100, 100, 2, kWhite);
  c.set_clip({20, 20, 60, 60});
  c.fill_rect(0, 0, 100, 100, kRed);
  c.reset_clip();
  Stroke dashed;
  dashed.width = 3.0;
  dashed.dash = {6.0, 4.0};
  c.stroke({{0.0, 80.5}, {100.0, 80.5}}, dashed, kBlue);
  const Image img = c.finish();
  EXPECT_EQ(img.pixel(20, 20), kRed);
  EXPECT_EQ(img.pixel(59, 59), kRed);
  EXPECT_EQ(img.pixel(19, 40), kWhite);
  EXPECT_EQ(img.pixel(60, 40), kWhite);
  int on = 0, off = 0;
  for (int x = 0; x < 100; ++x) {
    on += img.pixel(x, 80) == kBlue;
    off += img.pixel(x, 80) == kWhite;
  }
  EXPECT_NEAR(on, 60 - 8, 9);  // 6 on of every 10, less the anti-aliased ends
  EXPECT_GT(off, 30);
}

TEST(Canvas, TranslucentStrokesBlendOnce) {
  Canvas c(100, 100, 2, kWhite);
  Stroke s;
  s.width = 6.0;
  const Rgba half{0, 0, 255, 128};
  // a stroke that crosses itself: where it overlaps it is no darker
  c.stroke({{10, 10}, {90, 90}, {90, 10}, {10, 90}}, s, half);
  const Image img = c.finish();
  const Rgba once = img.pixel(30, 30), crossing = img.pixel(50, 50);
  EXPECT_EQ(crossing, once);
  EXPECT_NEAR(once.r, 127, 2);
  EXPECT_EQ(once.b, 255);
}

TEST(Canvas, PerPointColoursAndSamePixelsEveryTime) {
  const auto draw = [] {
    Canvas c(300, 100, 3, kWhite);
    std::vector<Vec2> pts;
    std::vector<Rgba> cols;
    for (int i = 0; i <= 50; ++i) {
      pts.push_back({10.0 + 5.6 * i, 50.0 + 30.0 * std::sin(0.2 * i)});
      cols.push_back(viridis(i / 50.0));
    }
    Stroke s;
    s.width = 6.0;
    c.stroke(pts, cols, s);
    for (int i = 0; i < 40; ++i) c.marker({7.0 * i + 3.3, 10.0}, Marker::Circle, 5.0, kRed, kBlue, 1.0);
    return c.finish();
  };
  const Image a = draw(), b = draw();
  EXPECT_EQ(a.rgba, b.rgba);
  // the line starts at the low end of the map and ends at the high end
  const Rgba first = px(a, 11.0, 50.5), last = px(a, 289.0, 50.0 + 30.0 * std::sin(10.0));
  EXPECT_NEAR(first.r, viridis(0.0).r, 3) << int(first.g);
  EXPECT_NEAR(first.g, viridis(0.0).g, 3);
  EXPECT_NEAR(last.r, viridis(1.0).r, 6) << int(last.g);
  EXPECT_NEAR(last.g, viridis(1.0).g, 6);
}

TEST(Canvas, MismatchedColoursAreAnError) {
  Canvas c(10, 10, 1, kWhite);
  EXPECT_THROW(c.stroke({{0, 0}, {5, 5}}, {kRed}, Stroke{}), RenderError);
}

}  // namespace
}  // namespace paddock::render
