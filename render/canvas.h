#pragma once
// 2D drawing in pixel coordinates on an OpenGL (OSMesa) framebuffer: strokes
// with a width and joins, filled polygons, markers, rectangles. Anti-aliased by
// supersampling: the scene is drawn at `supersample` times the resolution and
// box-filtered down on the CPU, so the interior of a flat shape keeps its exact
// colour and its edges get (supersample^2 + 1) levels of coverage.
#include <cstdint>
#include <vector>

#include "autonomy/common/geometry.h"
#include "render/figures.h"
#include "render/gl_context.h"

namespace paddock::render {

enum class Join { Miter, Round, Bevel };
enum class Cap { Butt, Round, Square };

struct Stroke {
  double width = 1.0;          // px
  Join join = Join::Miter;     // a miter longer than miter_limit half-widths becomes a bevel
  Cap cap = Cap::Butt;
  double miter_limit = 2.5;    // in half-widths (2.5: turns up to ~135 degrees stay mitred)
  std::vector<double> dash;    // px: on, off, on, ...; empty: solid
};

class Canvas {
 public:
  // a width x height px picture, cleared to `background`; throws RenderError
  Canvas(int width, int height, int supersample, Rgba background);

  int width() const { return width_; }
  int height() const { return height_; }
  int supersample() const { return ss_; }

  // only pixels inside box are drawn until reset_clip
  void set_clip(const Box& box);
  void reset_clip();

  // the axis-aligned rectangle [x0, x1] x [y0, y1] (px)
  void fill_rect(double x0, double y0, double x1, double y1, Rgba color);
  // a convex polygon (any orientation)
  void fill_convex(const std::vector<Vec2>& points, Rgba color);
  // any polygon, concave or self-intersecting, by the even-odd rule (stencil)
  void fill_polygon(const std::vector<Vec2>& points, Rgba color);
  // a polyline; non-finite points split it into pieces
  void stroke(const std::vector<Vec2>& points, const Stroke& style, Rgba color, bool closed = false);
  // a polyline whose colour is given per point and interpolated along the segments
  void stroke(const std::vector<Vec2>& points, const std::vector<Rgba>& colors, const Stroke& style);
  // a disc and a ring (outer radius r, the ring's width inward)
  void fill_circle(Vec2 centre, double radius, Rgba color);
  void ring(Vec2 centre, double radius, double width, Rgba color);
  // a marker of diameter size (px) centred at c: filled with fill (alpha 0:
  // hollow) and outlined edge_width px wide, inside the size, with edge (alpha
  // 0 or edge_width 0: no outline). A Cross is two strokes in the fill colour
  // (the edge colour when the fill is transparent).
  void marker(Vec2 c, Marker kind, double size, Rgba fill, Rgba edge, double edge_width);

  // the picture downsampled to width x height px
  Image finish();

 private:
  struct Vertex {
    float x, y;
    std::uint8_t r, g, b, a;
  };
  void draw(const std::vector<Vertex>& triangles, bool blend);
  void add_triangle(std::vector<Vertex>& out, Vec2 a, Vec2 b, Vec2 c, Rgba ca, Rgba cb, Rgba cc) const;
  void stroke_impl(const std::vector<Vec2>& points, const std::vector<Rgba>& colors, const Stroke& style, bool closed);
  void stroke_piece(const std::vector<Vec2>& pts, const std::vector<Rgba>& colors, const Stroke& style,
                    bool closed, std::vector<Vertex>& out) const;
  void disc(std::vector<Vertex>& out, Vec2 c, double r, Rgba color) const;
  int circle_segments(double radius) const;
  void scissor(const Box& box);

  GlContext gl_;
  int width_, height_, ss_;
  bool clipped_ = false;
  Box clip_;
};

}  // namespace paddock::render
