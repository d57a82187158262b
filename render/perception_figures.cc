// the perception figures of the paper: the LiDAR scan segmented into ground,
// non-ground and cone points with the detected cones (a top-down view in the
// base frame), and the camera image with the detector's boxes and the LiDAR
// cluster centres projected onto it. Same layout rules as figures.cc: measured
// margins, the legend in a row above the plot, the title on top.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "render/colormap.h"
#include "render/figures.h"
#include "render/page.h"
#include "render/plot.h"

namespace paddock::render {

namespace {

constexpr Rgba kNone{0, 0, 0, 0};  // no outline


// where the legend goes: a row above the plot (top px reserved between the
// title and the plot), or a column right of it (side px reserved)
struct LegendSpace {
  bool right = false;
  double top = 0.0, side = 0.0;
};

LegendSpace legend_above(const Page& page, const std::vector<LegendEntry>& entries) {
  LegendSpace s;
  if (!entries.empty()) s.top = legend_size(page, entries, true).y + page.px(kTheme.title_gap * 0.5);
  return s;
}

LegendSpace legend_right(const Page& page, const std::vector<LegendEntry>& entries) {
  LegendSpace s;
  s.right = true;
  if (!entries.empty()) s.side = legend_size(page, entries, false).x + page.px(kTheme.legend_gap);
  return s;
}

// a row legend centred over the plot that stays inside the page
bool row_fits(const Page& page, const AxesFrame& f, const std::vector<LegendEntry>& entries) {
  const double w = legend_size(page, entries, true).x;
  const double c = 0.5 * (f.plot.left + f.plot.right);
  const double pad = page.px(kTheme.pad);
  return c - 0.5 * w >= pad - 0.5 && c + 0.5 * w <= page.width() - pad + 0.5;
}

// where the plot box may go: the page less its padding, the title, the
// legend and the axes' margins (px, not rounded)
struct PlotRoom {
  double left = 0.0, top = 0.0, right = 0.0, bottom = 0.0;
};

// the axis whose range runs backwards once its ticks are chosen
enum class Flip { X, Y };

// axes laid out in three rounds: each puts the plot box in the room that the
// previous round's tick labels left (first guess 40 px left and below, 5 px
// right and above), chooses the ticks, flips one axis and measures the
// margins again; place(frame, room) sets the frame's plot box and window.
// The legend goes in a row above the plot, or right of it where the row does
// not fit; `space` says where.
template <class Place>
Axes layout_axes(const Page& page, const std::string& title, const std::vector<LegendEntry>& legend,
                 const char* x_label, const char* y_label, Flip flip, Place place, LegendSpace& space) {
  const auto layout = [&](const LegendSpace& ls) {
    Axes a;
    a.x.label = x_label;
    a.y.label = y_label;
    const double pad = page.px(kTheme.pad);
    const double top = pad + title_space(page, title) + ls.top;
    Margins m;
    m.left = m.bottom = page.px(40.0);
    m.right = m.top = page.px(5.0);
    for (int round = 0; round < 3; ++round) {
      AxesFrame& f = a.frame;
      place(f, PlotRoom{pad + m.left, top + m.top, page.width() - pad - m.right - ls.side,
                        page.height() - pad - m.bottom});
      a.update_ticks(page, true);
      if (flip == Flip::X) {
        std::swap(f.x_min, f.x_max);
      } else {
        std::swap(f.y_min, f.y_max);
      }
      m = a.margins(page);
    }
    return a;
  };
  space = legend_above(page, legend);
  Axes ax = layout(space);
  if (!row_fits(page, ax.frame, legend)) {
    space = legend_right(page, legend);
    ax = layout(space);
  }
  return ax;
}

// squares of side `size` px centred on the points, each in its colour, in one
// draw call: lone points of one stroke (NaN between them) with square caps
void draw_dots(Canvas& c, const std::vector<Vec2>& centres, const std::vector<Rgba>& colors, double size) {
  if (centres.empty()) return;
  const double nan = std::nan("");
  std::vector<Vec2> pts;
  std::vector<Rgba> cols;
  pts.reserve(2 * centres.size());
  cols.reserve(2 * centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    pts.push_back(centres[i]);
    cols.push_back(colors[i]);
    pts.push_back({nan, nan});
    cols.push_back(colors[i]);
  }
  Stroke s;
  s.width = size;
  s.cap = Cap::Square;
  c.stroke(pts, cols, s);
}

// an RGB image (row 0 at the top) filling the plot box of f, nearest
// neighbour: each image row is one horizontal stroke as tall as the row, its
// colour changing at the pixel edges (within 1e-3 px); runs of one colour are
// one segment. An image finer than the framebuffer is first decimated to it.
// Rows go to the canvas in chunks to bound the memory.
void draw_image(Canvas& c, const AxesFrame& f, int w, int h, const std::vector<std::uint8_t>& rgb) {
  const int ss = c.supersample();
  const int gw = std::max(1, std::min(w, ss * (f.plot.right - f.plot.left)));
  const int gh = std::max(1, std::min(h, ss * (f.plot.bottom - f.plot.top)));
  // the image pixel a grid cell shows (identity when not decimated)
  std::vector<int> col_of(static_cast<std::size_t>(gw)), row_of(static_cast<std::size_t>(gh));
  for (int i = 0; i < gw; ++i) col_of[static_cast<std::size_t>(i)] = gw == w ? i : std::min(w - 1, static_cast<int>((i + 0.5) * w / gw));
  for (int j = 0; j < gh; ++j) row_of[static_cast<std::size_t>(j)] = gh == h ? j : std::min(h - 1, static_cast<int>((j + 0.5) * h / gh));
  const auto pixel = [&](int i, int j) {
    const std::size_t k =
        3 * (static_cast<std::size_t>(row_of[static_cast<std::size_t>(j)]) * static_cast<std::size_t>(w) +
             static_cast<std::size_t>(col_of[static_cast<std::size_t>(i)]));
    return Rgba{rgb[k], rgb[k + 1], rgb[k + 2], 255};
  };
  const double left = f.plot.left, top = f.plot.top;
  const double sx = box_w(f.plot) / gw, sy = box_h(f.plot) / gh;
  const double eps = std::min(1e-3, 0.25 * sx);
  const double nan = std::nan("");
  Stroke s;
  s.width = sy + 2e-3;  // neighbouring rows overlap a hair: no seam
  s.cap = Cap::Butt;
  s.join = Join::Miter;
  std::vector<Vec2> pts;
  std::vector<Rgba> cols;
  const int chunk = std::max(1, 262144 / gw);  // rows per draw call
  for (int j0 = 0; j0 < gh; j0 += chunk) {
    pts.clear();
    cols.clear();
    for (int j = j0; j < std::min(gh, j0 + chunk); ++j) {
      // the row's centre line, from its pixel edges as to_pixel puts them
      const double yc = top + (j + 0.5) * sy;
      int i = 0;
      while (i < gw) {
        const Rgba col = pixel(i, j);
        int k = i + 1;
        while (k < gw && pixel(k, j) == col) ++k;
        const double x0 = left + box_w(f.plot) * i / gw, x1 = left + box_w(f.plot) * k / gw;
        pts.push_back({i > 0 ? x0 + eps : x0, yc});
        cols.push_back(col);
        pts.push_back({k < gw ? x1 - eps : x1, yc});
        cols.push_back(col);
        i = k;
      }
      pts.push_back({nan, nan});
      cols.push_back(Rgba{});
    }
    c.stroke(pts, cols, s);
  }
}

}  // namespace

// ---- the LiDAR view ----

Figure draw_lidar_view(const LidarViewData& d, const FigureStyle& style) {
  Page page(style);
  const Theme& th = kTheme;
  if (!(std::isfinite(d.range) && d.range > 0.0)) {
    throw RenderError("draw_lidar_view: range " + std::to_string(d.range) + " m (give a finite range > 0)");
  }
  const double range = d.range;
  const Rgba kind_color[3] = {kTabBlue, kTabRed, kTabGreen};  // ground, non-ground, cone points
  const Rgba detected_fill{0, 200, 0, 255}, truth_color = kBlack, car_color{60, 60, 60, 255};
  const auto kind = [](std::uint8_t label) { return label == 0 ? 0 : label == 2 ? 2 : 1; };

  bool present[3] = {false, false, false};
  for (const LidarViewPoint& p : d.points) {
    if (std::isfinite(p.x) && std::isfinite(p.y)) present[kind(p.label)] = true;
  }
  std::vector<LegendEntry> legend;
  const char* kind_label[3] = {"ground", "non-ground", "cone points"};
  for (int k = 0; k < 3; ++k) {
    if (present[k]) legend.push_back({LegendEntry::Kind::Marker, kind_label[k], kind_color[k], kNone, 4.0});
  }
  if (!d.detected.empty()) {
    legend.push_back({LegendEntry::Kind::Marker, "detected cone", detected_fill,
                      cone_color(d.detected.front().color), 7.0});
  }
  if (!d.truth.empty()) {
    LegendEntry e{LegendEntry::Kind::Marker, "true cone", truth_color, kNone, 7.0, Marker::Square};
    e.hollow = true;
    legend.push_back(e);
  }
  legend.push_back({LegendEntry::Kind::Marker, "car", car_color, kNone, 7.0, Marker::Triangle});

  // the plot box fills the page; the window [-range/3, range] forward and
  // [-range/2, range/2] sideways grows for equal aspect. The horizontal axis is
  // y with left positive: the frame's x range is flipped once the ticks are
  // chosen (y grows to the left; symmetric: the same window)
  const auto place = [&](AxesFrame& f, const PlotRoom& room) {
    f.plot.left = static_cast<int>(std::lround(room.left));
    f.plot.top = static_cast<int>(std::lround(room.top));
    f.plot.right = std::max(f.plot.left + 1, static_cast<int>(std::lround(room.right)));
    f.plot.bottom = std::max(f.plot.top + 1, static_cast<int>(std::lround(room.bottom)));
    f.x_min = -0.5 * range, f.x_max = 0.5 * range;
    f.y_min = -range / 3.0, f.y_max = range;
    make_equal_aspect(f);
  };
  LegendSpace space;
  Axes ax = layout_axes(page, d.title, legend, "y (left) [m]", "x (forward) [m]", Flip::X, place, space);
  const AxesFrame& f = ax.frame;
  const double scale = box_w(f.plot) / std::abs(f.x_max - f.x_min);  // px per m
  const double y_lo = std::min(f.x_min, f.x_max), y_hi = std::max(f.x_min, f.x_max);
  const auto P = [&](Vec2 base) { return f.to_pixel({base.y, base.x}); };
  const auto in_window = [&](double x, double y) { return x >= f.y_min && x <= f.y_max && y >= y_lo && y <= y_hi; };
  Canvas& c = page.canvas();

  ax.draw_grid(page);
  c.set_clip(f.plot);

  // the points, in one batch: ground, then non-ground, then cone points on top
  {
    std::vector<Vec2> centres;
    std::vector<Rgba> colors;
    centres.reserve(d.points.size());
    colors.reserve(d.points.size());
    for (int k = 0; k < 3; ++k) {
      if (!present[k]) continue;
      for (const LidarViewPoint& p : d.points) {
        if (kind(p.label) != k || !in_window(p.x, p.y)) continue;
        centres.push_back(P({p.x, p.y}));
        colors.push_back(kind_color[k]);
      }
    }
    draw_dots(c, centres, colors, std::clamp(page.px(0.75), 1.0, 2.0));
  }

  // the detected cones: green discs (a little larger than a cone) ringed in their colour
  const double det_r = std::max(1.3 * cone_radius(ConeColor::SmallOrange) * scale, page.px(3.2));
  const double ring_w = std::max(1.0, page.px(1.0));
  for (const Cone& cone : d.detected) {
    if (!finite(cone.position)) continue;
    c.marker(P(cone.position), Marker::Circle, 2.0 * det_r, detected_fill, cone_color(cone.color), ring_w);
  }
  // the true cones: hollow black squares around where a detection should be
  const double truth_half = det_r + page.px(1.6);
  for (const Cone& cone : d.truth) {
    if (!finite(cone.position)) continue;
    c.marker(P(cone.position), Marker::Square, 2.0 * truth_half / 0.886, {0, 0, 0, 0}, truth_color,
             std::max(1.0, page.px(0.8)));
  }
  // the car: a dark triangle at the origin pointing +x (up), edged white to stand out of the points
  {
    const double len = page.px(12.0), half = page.px(4.5);
    const Vec2 o = P({0.0, 0.0});
    const Vec2 tip{o.x, o.y - 0.6 * len}, bl{o.x - half, o.y + 0.4 * len}, br{o.x + half, o.y + 0.4 * len};
    Stroke edge;
    edge.width = std::max(1.0, page.px(1.2));
    edge.join = Join::Round;
    c.stroke({tip, bl, br}, edge, {255, 255, 255, 255}, true);
    c.fill_convex({tip, bl, br}, car_color);
  }
  c.reset_clip();

  ax.draw_frame(page);
  draw_title(page, d.title, f.plot.left, f.plot.right, page.px(th.pad));
  page.boxes()["legend"] = draw_legend(page, f, legend, space.right ? LegendPlace::Right : LegendPlace::Above);
  return page.finish({f});
}

// ---- the camera view ----

Figure draw_camera_view(const CameraViewData& d, const FigureStyle& style) {
  Page page(style);
  const Theme& th = kTheme;
  if (d.width <= 0 || d.height <= 0) {
    throw RenderError("draw_camera_view: image size " + std::to_string(d.width) + " x " + std::to_string(d.height) +
                      " px (give the camera image's width and height, both > 0)");
  }
  const std::size_t want = static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height) * 3;
  if (!d.rgb.empty() && d.rgb.size() != want) {
    throw RenderError("draw_camera_view: " + std::to_string(d.rgb.size()) + " bytes of RGB for a " +
                      std::to_string(d.width) + " x " + std::to_string(d.height) + " image (give width * height * 3 = " +
                      std::to_string(want) + ", or none)");
  }
  const double iw = d.width, ih = d.height;
  const Rgba projected_color{0, 210, 0, 255}, dropped_color{225, 20, 20, 255};

  std::vector<LegendEntry> legend;
  bool present[5] = {false, false, false, false, false};
  for (const CameraBox& b : d.boxes) present[static_cast<int>(b.color)] = true;
  for (ConeColor cc : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange,
                       ConeColor::Unknown}) {
    if (!present[static_cast<int>(cc)]) continue;
    LegendEntry e{LegendEntry::Kind::Marker, cone_label(cc), cone_color(cc), kNone, 8.0, Marker::Square};
    e.hollow = true;
    legend.push_back(e);
  }
  if (!d.projected.empty()) {
    legend.push_back({LegendEntry::Kind::Marker, "LiDAR cluster centre", projected_color, kNone, 8.0, Marker::Cross});
  }
  if (!d.dropped.empty()) {
    legend.push_back({LegendEntry::Kind::Marker, "dropped by fusion", dropped_color, kNone, 8.0, Marker::Cross});
  }

  // the largest plot box of the image's aspect that the margins leave, centred;
  // ticks in image pixels, then the y range flipped (v grows downwards)
  double shift = 0.0;  // px: the whole figure moved down to centre it vertically
  const auto place = [&](AxesFrame& f, const PlotRoom& room) {
    const double aw = std::max(1.0, room.right - room.left);
    const double ah = std::max(1.0, room.bottom - room.top);
    const double s = std::min(aw / iw, ah / ih);
    const int w = std::max(1, static_cast<int>(std::lround(iw * s)));
    const int h = std::max(1, static_cast<int>(std::lround(ih * s)));
    f.plot.left = static_cast<int>(std::lround(room.left + 0.5 * (aw - w)));
    shift = std::floor(0.5 * std::max(0.0, ah - h));
    f.plot.top = static_cast<int>(std::lround(room.top + shift));
    f.plot.right = f.plot.left + w;
    f.plot.bottom = f.plot.top + h;
    f.x_min = 0.0, f.x_max = iw, f.y_min = 0.0, f.y_max = ih;
  };
  LegendSpace space;
  Axes ax = layout_axes(page, d.title, legend, "u [px]", "v [px]", Flip::Y, place, space);
  const AxesFrame& f = ax.frame;
  const auto P = [&](Vec2 uv) { return f.to_pixel(uv); };
  Canvas& c = page.canvas();

  c.set_clip(f.plot);
  if (d.rgb.empty()) {
    c.fill_rect(f.plot.left, f.plot.top, f.plot.right, f.plot.bottom, {232, 232, 232, 255});
    TextStyle ts;
    ts.size = th.label_size;
    ts.color = {120, 120, 120, 255};
    ts.h = HAlign::Center, ts.v = VAlign::Middle;
    page.text("no image", {0.5 * (f.plot.left + f.plot.right), 0.5 * (f.plot.top + f.plot.bottom)}, ts);
  } else {
    draw_image(c, f, d.width, d.height, d.rgb);
  }

  // the detector's boxes, 2 pt outlines centred on their edges
  Stroke box_stroke;
  box_stroke.width = page.px(2.0);
  box_stroke.join = Join::Miter;
  for (const CameraBox& b : d.boxes) {
    if (!std::isfinite(b.x_min) || !std::isfinite(b.y_min) || !std::isfinite(b.x_max) || !std::isfinite(b.y_max)) {
      continue;
    }
    const Vec2 a = P({std::min(b.x_min, b.x_max), std::min(b.y_min, b.y_max)});
    const Vec2 z = P({std::max(b.x_min, b.x_max), std::max(b.y_min, b.y_max)});
    c.stroke({{a.x, a.y}, {z.x, a.y}, {z.x, z.y}, {a.x, z.y}}, box_stroke, cone_color(b.color), true);
  }

  // the projected cluster centres: crosses with a dark halo (legible on any image), dropped ones under kept ones
  const double cross = page.px(9.0), line = page.px(1.8), halo = line + std::max(1.0, page.px(1.2));
  const auto crosses = [&](const std::vector<Vec2>& pts, Rgba col) {
    for (const Vec2& p : pts) {
      if (!finite(p)) continue;
      const Rgba dark{20, 20, 20, 255};
      c.marker(P(p), Marker::Cross, cross + (halo - line), dark, dark, halo);
    }
    for (const Vec2& p : pts) {
      if (finite(p)) c.marker(P(p), Marker::Cross, cross, col, col, line);
    }
  };
  crosses(d.dropped, dropped_color);
  crosses(d.projected, projected_color);
  c.reset_clip();

  ax.draw_frame(page);
  draw_title(page, d.title, f.plot.left, f.plot.right, page.px(th.pad) + shift);
  if (!legend.empty()) {
    page.boxes()["legend"] = draw_legend(page, f, legend, space.right ? LegendPlace::Right : LegendPlace::Above);
  }
  return page.finish({f});
}

}  // namespace paddock::render
