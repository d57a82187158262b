#include "render/canvas.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "render/colormap.h"

namespace paddock::render {

namespace {

Vec2 normalized(Vec2 v) {
  const double n = norm(v);
  return n > 0.0 ? v / n : Vec2{0.0, 0.0};
}

// a side of the framebuffer (0 for a bad size: GlContext says what is wrong)
int framebuffer_side(int n, int supersample) { return n < 1 || supersample < 1 ? 0 : n * supersample; }

}  // namespace

Canvas::Canvas(int width, int height, int supersample, Rgba background)
    : gl_(framebuffer_side(width, supersample), framebuffer_side(height, supersample)),
      width_(width),
      height_(height),
      ss_(supersample) {
  // the whole framebuffer, output pixel coordinates: x right, y down
  glViewport(0, 0, width_ * ss_, height_ * ss_);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0.0, width_, height_, 0.0, -1.0, 1.0);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  // exact flat colours: no dithering, no depth, no culling (strokes have both windings)
  glDisable(GL_DITHER);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glShadeModel(GL_SMOOTH);
  // "over" compositing for colour and for alpha
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glClearColor(background.r / 255.0f, background.g / 255.0f, background.b / 255.0f, background.a / 255.0f);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
}

void Canvas::scissor(const Box& box) {
  const int l = std::clamp(box.left, 0, width_), r = std::clamp(box.right, 0, width_);
  const int t = std::clamp(box.top, 0, height_), b = std::clamp(box.bottom, 0, height_);
  // OpenGL's window y goes up from the bottom row
  glScissor(l * ss_, (height_ - b) * ss_, std::max(0, r - l) * ss_, std::max(0, b - t) * ss_);
}

void Canvas::set_clip(const Box& box) {
  clipped_ = true;
  clip_ = box;
  glEnable(GL_SCISSOR_TEST);
  scissor(box);
}

void Canvas::reset_clip() {
  clipped_ = false;
  glDisable(GL_SCISSOR_TEST);
}

void Canvas::draw(const std::vector<Vertex>& triangles, bool blend) {
  if (triangles.empty()) return;
  if (blend) glEnable(GL_BLEND);
  glVertexPointer(2, GL_FLOAT, sizeof(Vertex), &triangles[0].x);
  glColorPointer(4, GL_UNSIGNED_BYTE, sizeof(Vertex), &triangles[0].r);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangles.size()));
  if (blend) glDisable(GL_BLEND);
}

void Canvas::add_triangle(std::vector<Vertex>& out, Vec2 a, Vec2 b, Vec2 c, Rgba ca, Rgba cb, Rgba cc) const {
  out.push_back({static_cast<float>(a.x), static_cast<float>(a.y), ca.r, ca.g, ca.b, ca.a});
  out.push_back({static_cast<float>(b.x), static_cast<float>(b.y), cb.r, cb.g, cb.b, cb.a});
  out.push_back({static_cast<float>(c.x), static_cast<float>(c.y), cc.r, cc.g, cc.b, cc.a});
}

int Canvas::circle_segments(double radius) const {
  // the chord of an n-gon inscribed in radius r misses the circle by r (1 - cos(pi / n))
  // ~ r pi^2 / (2 n^2): keep that under 0.1 framebuffer pixel
  const double r = std::max(0.0, radius) * ss_;
  return std::clamp(static_cast<int>(std::ceil(kPi * std::sqrt(r / 0.2))), 8, 256);
}

void Canvas::disc(std::vector<Vertex>& out, Vec2 c, double r, Rgba color) const {
  if (!(r > 0.0)) return;
  const int n = circle_segments(r);
  Vec2 prev{c.x + r, c.y};
  for (int i = 1; i <= n; ++i) {
    const double a = 2.0 * kPi * i / n;
    const Vec2 cur = i == n ? Vec2{c.x + r, c.y} : Vec2{c.x + r * std::cos(a), c.y + r * std::sin(a)};
    add_triangle(out, c, prev, cur, color, color, color);
    prev = cur;
  }
}

void Canvas::fill_rect(double x0, double y0, double x1, double y1, Rgba color) {
  fill_convex({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, color);
}

void Canvas::fill_convex(const std::vector<Vec2>& points, Rgba color) {
  if (points.size() < 3 || color.a == 0) return;
  std::vector<Vertex> tris;
  tris.reserve(3 * (points.size() - 2));
  for (std::size_t i = 1; i + 1 < points.size(); ++i) {
    add_triangle(tris, points[0], points[i], points[i + 1], color, color, color);
  }
  draw(tris, color.a < 255);
}

void Canvas::fill_polygon(const std::vector<Vec2>& points, Rgba color) {
  if (points.size() < 3 || color.a == 0) return;
  // even-odd rule: each triangle of a fan from the first point inverts the
  // stencil, so a pixel ends up odd exactly when it is inside; then one
  // rectangle over the bounding box paints where the stencil is odd and clears it
  std::vector<Vertex> tris;
  double x0 = points[0].x, x1 = x0, y0 = points[0].y, y1 = y0;
  for (std::size_t i = 1; i + 1 < points.size(); ++i) {
    add_triangle(tris, points[0], points[i], points[i + 1], color, color, color);
  }
  for (const Vec2& p : points) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  glEnable(GL_STENCIL_TEST);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glStencilMask(1);
  glStencilFunc(GL_ALWAYS, 0, 1);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INVERT);
  draw(tris, false);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glStencilFunc(GL_EQUAL, 1, 1);
  glStencilOp(GL_ZERO, GL_ZERO, GL_ZERO);
  tris.clear();
  const double m = 1.0;  // px beyond the bounding box: every touched sample is covered
  const Vec2 a{x0 - m, y0 - m}, b{x1 + m, y0 - m}, c{x1 + m, y1 + m}, d{x0 - m, y1 + m};
  add_triangle(tris, a, b, c, color, color, color);
  add_triangle(tris, a, c, d, color, color, color);
  draw(tris, color.a < 255);
  glDisable(GL_STENCIL_TEST);
}

void Canvas::stroke_piece(const std::vector<Vec2>& in_pts, const std::vector<Rgba>& in_colors,
                          const Stroke& style, bool closed, std::vector<Vertex>& out) const {
  // drop repeated points (no direction there)
  std::vector<Vec2> p;
  std::vector<Rgba> c;
  for (std::size_t i = 0; i < in_pts.size(); ++i) {
    if (!p.empty() && squared_norm(in_pts[i] - p.back()) < 1e-18) continue;
    p.push_back(in_pts[i]);
    c.push_back(in_colors[i]);
  }
  if (closed && p.size() > 2 && squared_norm(p.front() - p.back()) < 1e-18) {
    p.pop_back();
    c.pop_back();
  }
  if (closed && p.size() < 3) closed = false;
  const double hw = 0.5 * style.width;
  if (p.empty() || !(hw > 0.0)) return;
  if (p.size() == 1) {
    // a lone point: only a round or square cap shows it
    if (style.cap == Cap::Round) disc(out, p[0], hw, c[0]);
    if (style.cap == Cap::Square) {
      const Vec2 q = p[0];
      add_triangle(out, {q.x - hw, q.y - hw}, {q.x + hw, q.y - hw}, {q.x + hw, q.y + hw}, c[0], c[0], c[0]);
      add_triangle(out, {q.x - hw, q.y - hw}, {q.x + hw, q.y + hw}, {q.x - hw, q.y + hw}, c[0], c[0], c[0]);
    }
    return;
  }
  const std::size_t n = p.size();
  const std::size_t segs = closed ? n : n - 1;
  std::vector<Vec2> dir(segs), nrm(segs);
  for (std::size_t i = 0; i < segs; ++i) {
    dir[i] = normalized(p[(i + 1) % n] - p[i]);
    nrm[i] = left_normal(dir[i]);
  }
  // the left and right corners where each segment starts and ends
  std::vector<Vec2> start_l(segs), start_r(segs), end_l(segs), end_r(segs);
  for (std::size_t j = 0; j < n; ++j) {
    const bool has_prev = closed || j > 0;
    const bool has_next = closed || j + 1 < n;
    const std::size_t ip = (j + segs - 1) % segs;  // the segment ending at j
    const std::size_t in = j % segs;               // the segment starting at j
    if (!has_prev) {
      const Vec2 back = style.cap == Cap::Square ? dir[in] * -hw : Vec2{};
      start_l[in] = p[j] + nrm[in] * hw + back;
      start_r[in] = p[j] - nrm[in] * hw + back;
      if (style.cap == Cap::Round) disc(out, p[j], hw, c[j]);
      continue;
    }
    if (!has_next) {
      const Vec2 fwd = style.cap == Cap::Square ? dir[ip] * hw : Vec2{};
      end_l[ip] = p[j] + nrm[ip] * hw + fwd;
      end_r[ip] = p[j] - nrm[ip] * hw + fwd;
      if (style.cap == Cap::Round) disc(out, p[j], hw, c[j]);
      continue;
    }
    // a join: the miter (the bisector of the two normals, hw / cos(half the turn)
    // long) when it is short enough, else each segment ends square and the gap
    // on the outside of the turn is filled (bevel: a triangle; round: a disc)
    const Vec2 m = nrm[ip] + nrm[in];
    const double mlen = norm(m);
    if (style.join == Join::Miter && mlen > 1e-9) {
      const Vec2 mu = m / mlen;
      const double cos_half = dot(mu, nrm[in]);
      if (cos_half > 1.0 / style.miter_limit) {
        const Vec2 off = mu * (hw / cos_half);
        end_l[ip] = start_l[in] = p[j] + off;
        end_r[ip] = start_r[in] = p[j] - off;
        continue;
      }
    }
    end_l[ip] = p[j] + nrm[ip] * hw;
    end_r[ip] = p[j] - nrm[ip] * hw;
    start_l[in] = p[j] + nrm[in] * hw;
    start_r[in] = p[j] - nrm[in] * hw;
    if (style.join == Join::Round) {
      disc(out, p[j], hw, c[j]);
    } else {
      add_triangle(out, p[j], end_l[ip], start_l[in], c[j], c[j], c[j]);
      add_triangle(out, p[j], end_r[ip], start_r[in], c[j], c[j], c[j]);
    }
  }
  for (std::size_t i = 0; i < segs; ++i) {
    const Rgba ca = c[i], cb = c[(i + 1) % n];
    add_triangle(out, start_l[i], start_r[i], end_l[i], ca, ca, cb);
    add_triangle(out, end_l[i], start_r[i], end_r[i], cb, ca, cb);
  }
}

void Canvas::stroke(const std::vector<Vec2>& points, const Stroke& style, Rgba color, bool closed) {
  stroke_impl(points, std::vector<Rgba>(points.size(), color), style, closed);
}

void Canvas::stroke(const std::vector<Vec2>& points, const std::vector<Rgba>& colors, const Stroke& style) {
  if (colors.size() != points.size()) {
    throw RenderError("Canvas::stroke: " + std::to_string(points.size()) + " points but " +
                      std::to_string(colors.size()) + " colours");
  }
  stroke_impl(points, colors, style, false);
}

void Canvas::stroke_impl(const std::vector<Vec2>& points, const std::vector<Rgba>& colors, const Stroke& style,
                         bool closed) {
  // finite runs (a non-finite point breaks the line, and a broken line is open)
  std::vector<std::vector<Vec2>> runs;
  std::vector<std::vector<Rgba>> run_colors;
  bool broken = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!finite(points[i])) {
      broken = true;
      if (!runs.empty() && !runs.back().empty()) runs.emplace_back(), run_colors.emplace_back();
      continue;
    }
    if (runs.empty()) runs.emplace_back(), run_colors.emplace_back();
    runs.back().push_back(points[i]);
    run_colors.back().push_back(colors[i]);
  }
  if (broken) closed = false;
  double period = 0.0;
  for (double d : style.dash) period += std::max(0.0, d);
  const bool dashed = period > 0.0 && style.dash.size() >= 2;

  std::vector<Vertex> tris;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::vector<Vec2>& run = runs[k];
    std::vector<Rgba>& col = run_colors[k];
    if (run.empty()) continue;
    if (!dashed) {
      stroke_piece(run, col, style, closed, tris);
      continue;
    }
    // dashes: walk the arc length through the on/off pattern, each "on" stretch an open piece
    if (closed) run.push_back(run.front()), col.push_back(col.front());
    std::size_t pat = 0;
    double left = std::max(0.0, style.dash[0]);
    bool on = true;
    std::vector<Vec2> piece{run[0]};
    std::vector<Rgba> piece_col{col[0]};
    for (std::size_t i = 0; i + 1 < run.size(); ++i) {
      const Vec2 a = run[i], b = run[i + 1];
      const double len = distance(a, b);
      double at = 0.0;
      while (len - at > left) {
        at += left;
        const double t = at / len;
        const Vec2 q = a + (b - a) * t;
        const Rgba cq = lerp(col[i], col[i + 1], t);
        if (on) {
          piece.push_back(q), piece_col.push_back(cq);
          Stroke solid = style;
          solid.dash.clear();
          stroke_piece(piece, piece_col, solid, false, tris);
        }
        piece.assign(1, q);
        piece_col.assign(1, cq);
        on = !on;
        pat = (pat + 1) % style.dash.size();
        left = std::max(0.0, style.dash[pat]);
        if (left <= 0.0) left = 1e-9;
      }
      left -= len - at;
      if (on) piece.push_back(b), piece_col.push_back(col[i + 1]);
    }
    if (on && piece.size() > 1) {
      Stroke solid = style;
      solid.dash.clear();
      stroke_piece(piece, piece_col, solid, false, tris);
    }
  }
  if (tris.empty()) return;
  const bool blend = std::any_of(colors.begin(), colors.end(), [](Rgba c) { return c.a < 255; });
  if (!blend) return draw(tris, false);
  // translucent: each pixel once (the stencil marks what this stroke has drawn), then clear the marks
  double x0 = tris[0].x, x1 = x0, y0 = tris[0].y, y1 = y0;
  for (const Vertex& v : tris) x0 = std::min<double>(x0, v.x), x1 = std::max<double>(x1, v.x),
                                y0 = std::min<double>(y0, v.y), y1 = std::max<double>(y1, v.y);
  glEnable(GL_STENCIL_TEST);
  glStencilMask(1);
  glStencilFunc(GL_EQUAL, 0, 1);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INVERT);
  draw(tris, true);
  glDisable(GL_STENCIL_TEST);
  Box bb{static_cast<int>(std::floor(x0)) - 1, static_cast<int>(std::floor(y0)) - 1,
         static_cast<int>(std::ceil(x1)) + 2, static_cast<int>(std::ceil(y1)) + 2};
  glEnable(GL_SCISSOR_TEST);
  scissor(bb);
  glClear(GL_STENCIL_BUFFER_BIT);
  if (clipped_) {
    scissor(clip_);
  } else {
    glDisable(GL_SCISSOR_TEST);
  }
}

void Canvas::fill_circle(Vec2 centre, double radius, Rgba color) {
  std::vector<Vertex> tris;
  disc(tris, centre, radius, color);
  draw(tris, color.a < 255);
}

void Canvas::ring(Vec2 centre, double radius, double width, Rgba color) {
  if (!(radius > 0.0) || !(width > 0.0) || color.a == 0) return;
  if (width >= radius) return fill_circle(centre, radius, color);
  const int n = circle_segments(radius);
  const double ri = radius - width;
  std::vector<Vertex> tris;
  Vec2 po{centre.x + radius, centre.y}, pi{centre.x + ri, centre.y};
  for (int i = 1; i <= n; ++i) {
    const double a = 2.0 * kPi * i / n;
    const Vec2 u = i == n ? Vec2{1.0, 0.0} : Vec2{std::cos(a), std::sin(a)};
    const Vec2 co = centre + u * radius, ci = centre + u * ri;
    add_triangle(tris, po, pi, co, color, color, color);
    add_triangle(tris, co, pi, ci, color, color, color);
    po = co;
    pi = ci;
  }
  draw(tris, color.a < 255);
}

void Canvas::marker(Vec2 c, Marker kind, double size, Rgba fill, Rgba edge, double edge_width) {
  if (!finite(c) || !(size > 0.0)) return;
  const double r = 0.5 * size;
  const bool has_edge = edge.a > 0 && edge_width > 0.0;
  const double ew = has_edge ? std::min(edge_width, r) : 0.0;
  switch (kind) {
    case Marker::Circle: {
      // the fill stops where the ring starts (same polygon edges: no seam, no double blend)
      if (fill.a > 0) {
        std::vector<Vertex> tris;
        const int n = circle_segments(r);
        const double rf = r - ew;
        for (int i = 0; i < n && rf > 0.0; ++i) {
          const double a0 = 2.0 * kPi * i / n, a1 = 2.0 * kPi * (i + 1) / n;
          const Vec2 u0 = Vec2{std::cos(a0), std::sin(a0)}, u1 = i + 1 == n ? Vec2{1.0, 0.0} : Vec2{std::cos(a1), std::sin(a1)};
          add_triangle(tris, c, c + u0 * rf, c + u1 * rf, fill, fill, fill);
        }
        draw(tris, fill.a < 255);
      }
      if (has_edge) ring(c, r, ew, edge);
      return;
    }
    case Marker::Square:
    case Marker::Triangle: {
      // a square of the circle's area; an equilateral triangle about its centroid
      std::vector<Vec2> unit;
      double inradius = 0.0;
      if (kind == Marker::Square) {
        const double h = r * 0.886;
        unit = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
        inradius = h;
      } else {
        const double R = r * 1.15;
        for (int i = 0; i < 3; ++i) {
          const double a = -0.5 * kPi + 2.0 * kPi * i / 3.0;  // the first corner points up (-y)
          unit.push_back({R * std::cos(a), R * std::sin(a)});
        }
        inradius = 0.5 * R;
      }
      const auto scaled = [&](double inset) {
        std::vector<Vec2> out;
        const double s = std::max(0.0, (inradius - inset) / inradius);
        for (const Vec2& u : unit) out.push_back(c + u * s);
        return out;
      };
      if (fill.a > 0) fill_convex(scaled(fill.a == 255 ? 0.0 : ew), fill);
      if (has_edge) {
        Stroke s;
        s.width = ew;
        s.join = Join::Miter;
        s.miter_limit = 2.1;  // a triangle's 60 degree corners stay sharp (1 / sin 30 = 2)
        stroke(scaled(0.5 * ew), s, edge, true);
      }
      return;
    }
    case Marker::Cross: {
      const Rgba col = fill.a > 0 ? fill : edge;
      const double h = r * 0.75;
      Stroke s;
      s.width = std::max(ew, 0.2 * size);
      stroke({{c.x - h, c.y - h}, {c.x + h, c.y + h}}, s, col);
      stroke({{c.x - h, c.y + h}, {c.x + h, c.y - h}}, s, col);
      return;
    }
  }
}

Image Canvas::finish() {
  const std::uint8_t* big = gl_.finish();  // the bottom row first
  Image img;
  img.width = width_;
  img.height = height_;
  img.rgba.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4, 0);
  // box filter: the mean of each ss x ss block, rounded (a flat block keeps its value)
  const std::size_t big_row = static_cast<std::size_t>(width_) * static_cast<std::size_t>(ss_) * 4;
  const std::uint32_t n = static_cast<std::uint32_t>(ss_ * ss_);
  std::vector<std::uint32_t> sum(static_cast<std::size_t>(width_) * 4);
  for (int y = 0; y < height_; ++y) {
    std::fill(sum.begin(), sum.end(), 0u);
    for (int sy = 0; sy < ss_; ++sy) {
      const std::size_t big_y = static_cast<std::size_t>(height_) * ss_ - 1 - (static_cast<std::size_t>(y) * ss_ + sy);
      const std::uint8_t* row = big + big_y * big_row;
      for (int x = 0; x < width_; ++x) {
        const std::uint8_t* px = row + static_cast<std::size_t>(x) * ss_ * 4;
        std::uint32_t* s = sum.data() + static_cast<std::size_t>(x) * 4;
        for (int sx = 0; sx < ss_; ++sx, px += 4) {
          s[0] += px[0], s[1] += px[1], s[2] += px[2], s[3] += px[3];
        }
      }
    }
    std::uint8_t* out = img.rgba.data() + static_cast<std::size_t>(y) * width_ * 4;
    for (std::size_t i = 0; i < sum.size(); ++i) out[i] = static_cast<std::uint8_t>((sum[i] + n / 2) / n);
  }
  return img;
}

}  // namespace paddock::render
