// the four figures: track map, controller data, lap chart, sweep heat map.
// Each lays out its axes from measured text (margins, ticks, labels), draws
// the shapes on the GL canvas in layers, queues the text, and returns the
// composited image with its axes frames and the boxes of its named parts.
#include "render/figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "render/colormap.h"
#include "render/page.h"
#include "render/plot.h"

namespace paddock::render {

namespace {

constexpr double kRadToDeg = 180.0 / kPi;

// ---- layout of one axes ----

struct ColorbarSpec {
  double lo = 0.0, hi = 1.0;
  std::string label;
};

// fits ax.frame.plot into the page: the title and top_extra px above it, a
// colour bar's room on the right when cb is given, the ticks' and labels' room
// around it. set_ranges fills in the data ranges once the plot box is known
// (the map grows a range for equal aspect, the lap chart leaves headroom).
// Ticks depend on the box and the box on the tick labels: three rounds settle it.
void fit_axes(Page& page, Axes& ax, const std::string& title, double top_extra, const ColorbarSpec* cb,
              const std::function<void(AxesFrame&)>& set_ranges, bool equal_step) {
  const double pad = page.px(kTheme.pad);
  const double top = pad + title_space(page, title) + top_extra;
  Margins m;
  m.left = m.bottom = page.px(40.0);
  m.right = m.top = page.px(5.0);
  for (int round = 0; round < 3; ++round) {
    const double plot_h = page.height() - top - pad - m.top - m.bottom;
    const double cb_w = cb ? colorbar_space(page, cb->lo, cb->hi, cb->label, plot_h) : 0.0;
    const double right = cb ? std::max(m.right, page.px(4.0)) + cb_w : m.right;
    ax.frame.plot.left = static_cast<int>(std::lround(pad + m.left));
    ax.frame.plot.top = static_cast<int>(std::lround(top + m.top));
    ax.frame.plot.right = std::max(ax.frame.plot.left + 1, static_cast<int>(std::lround(page.width() - pad - right)));
    ax.frame.plot.bottom = std::max(ax.frame.plot.top + 1, static_cast<int>(std::lround(page.height() - pad - m.bottom)));
    set_ranges(ax.frame);
    ax.update_ticks(page, equal_step);
    m = ax.margins(page);
  }
}

void draw_colorbar_for(Page& page, const AxesFrame& f, const ColorbarSpec& cb) {
  const int gap = static_cast<int>(std::lround(page.px(kTheme.colorbar_gap)));
  const int w = static_cast<int>(std::lround(page.px(kTheme.colorbar_width)));
  const Box strip{f.plot.right + gap, f.plot.top, f.plot.right + gap + w, f.plot.bottom};
  draw_colorbar(page, strip, cb.lo, cb.hi, cb.label);
}

// a [lo, hi] that is never a point: a single value v becomes [v - 0.5, v + 0.5]
void widen(double& lo, double& hi) {
  if (!(hi - lo > 1e-6 * std::max({1.0, std::abs(lo), std::abs(hi)}))) {
    const double c = 0.5 * (lo + hi);
    lo = c - 0.5, hi = c + 0.5;
  }
}

}  // namespace

// ---- the track map ----

const char* cone_label(ConeColor c) {
  switch (c) {
    case ConeColor::Blue: return "blue cone";
    case ConeColor::Yellow: return "yellow cone";
    case ConeColor::SmallOrange: return "small orange cone";
    case ConeColor::BigOrange: return "big orange cone";
    case ConeColor::Unknown: break;
  }
  return "unknown cone";
}

double cone_radius(ConeColor c) { return c == ConeColor::BigOrange ? 0.1425 : 0.114; }

Rgba cone_color(ConeColor c) {
  switch (c) {
    case ConeColor::Blue: return {0, 90, 255, 255};
    case ConeColor::Yellow: return {255, 210, 0, 255};
    case ConeColor::SmallOrange: return {255, 140, 0, 255};
    case ConeColor::BigOrange: return {235, 80, 0, 255};
    case ConeColor::Unknown: break;
  }
  return {140, 140, 140, 255};
}

Figure draw_track_map(const TrackMapData& d, const FigureStyle& style) {
  Page page(style);
  const Theme& th = kTheme;
  if (!d.speed.empty() && d.speed.size() != d.trajectory.size()) {
    throw RenderError("draw_track_map: " + std::to_string(d.trajectory.size()) + " trajectory points but " +
                      std::to_string(d.speed.size()) + " speeds (give one speed per point, or none)");
  }
  const bool has_start =
      d.start && std::isfinite(d.start->x) && std::isfinite(d.start->y) && std::isfinite(d.start->yaw);
  // everything given, in metres
  Range xr, yr;
  const auto add = [&](Vec2 p) {
    if (!finite(p)) return;
    xr.include(p.x);
    yr.include(p.y);
  };
  for (const Cone& c : d.cones) add(c.position);
  for (const Cone& c : d.estimated_cones) add(c.position);
  for (const Vec2& p : d.left) add(p);
  for (const Vec2& p : d.right) add(p);
  for (const Segment& s : d.gates) add(s.a), add(s.b);
  for (const Vec2& p : d.trajectory) add(p);
  for (const MapLayer& l : d.layers) for (const Vec2& p : l.points) add(p);
  if (has_start) add(d.start->position()), add(d.start->position() + d.start->heading() * 3.0);  // the arrow
  const Range xs = xr.padded(0.04, 2.0, -10.0, 10.0), ys = yr.padded(0.04, 2.0, -10.0, 10.0);

  // the speed scale: the colour bar shows [lo, hi]; one speed only: [v - 0.5, v + 0.5]
  Range sr;
  for (double v : d.speed) sr.include(v);
  const bool has_speed = !sr.empty;
  ColorbarSpec cb;
  if (has_speed) {
    cb.lo = sr.lo, cb.hi = sr.hi;
    widen(cb.lo, cb.hi);
    cb.label = d.speed_label;
  }

  // the legend: what is shown, in drawing order
  const Rgba gate_color{40, 40, 40, 255}, start_color{200, 20, 60, 255};
  std::vector<LegendEntry> legend;
  if (!d.gates.empty()) legend.push_back({LegendEntry::Kind::Line, "timekeeping line", gate_color, {}, 1.6});
  for (const MapLayer& l : d.layers) {
    if (l.label.empty()) continue;
    LegendEntry e;
    e.label = l.label;
    e.color = l.color;
    e.size = l.kind == MapLayer::Kind::Points ? std::max(4.0, l.size) : std::max(1.0, l.size);
    e.kind = l.kind == MapLayer::Kind::Points ? LegendEntry::Kind::Marker : LegendEntry::Kind::Line;
    e.marker = l.marker;
    legend.push_back(e);
  }
  if (!d.trajectory.empty()) {
    legend.push_back({has_speed ? LegendEntry::Kind::Gradient : LegendEntry::Kind::Line, d.trajectory_label, kTabRed, {},
                      2.2});
  }
  bool present[5] = {false, false, false, false, false};
  for (const Cone& cone : d.cones) present[static_cast<int>(cone.color)] |= finite(cone.position);
  for (ConeColor cc : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange,
                       ConeColor::Unknown}) {
    if (!present[static_cast<int>(cc)]) continue;
    const Rgba col = cone_color(cc);
    legend.push_back({LegendEntry::Kind::Marker, cone_label(cc), col, darken(col, 0.4),
                      cc == ConeColor::BigOrange ? 6.5 : 5.5});
  }
  if (!d.estimated_cones.empty()) {
    LegendEntry e{LegendEntry::Kind::Marker, "estimated cone", {90, 90, 90, 255}, {}, 7.0};
    e.hollow = true;
    legend.push_back(e);
  }
  if (has_start) legend.push_back({LegendEntry::Kind::Arrow, "start", start_color, {}, 1.8});

  // where the data is in pixels (points along every line), for the legend to avoid
  const auto data_pixels = [&](const AxesFrame& f) {
    std::vector<Vec2> out;
    const double step = page.px(3.0);
    const auto line = [&](const std::vector<Vec2>& pts, bool closed, std::size_t every) {
      const std::size_t n = pts.size();
      for (std::size_t i = 0; i < n; i += every) {
        const std::size_t j = i + every < n ? i + every : (closed ? 0 : n - 1);
        if (!finite(pts[i]) || !finite(pts[j])) continue;
        const Vec2 a = f.to_pixel(pts[i]), b = f.to_pixel(pts[j]);
        const int k = std::max(1, static_cast<int>(std::ceil(distance(a, b) / step)));
        for (int m = 0; m < k; ++m) out.push_back(a + (b - a) * (static_cast<double>(m) / k));
        out.push_back(b);
      }
    };
    for (const Cone& c : d.cones) if (finite(c.position)) out.push_back(f.to_pixel(c.position));
    for (const Cone& c : d.estimated_cones) if (finite(c.position)) out.push_back(f.to_pixel(c.position));
    line(d.left, d.closed, 1);
    line(d.right, d.closed, 1);
    line(d.trajectory, false, 4);
    for (const Segment& s : d.gates) line({s.a, s.b}, false, 1);
    for (const MapLayer& l : d.layers) {
      if (l.kind == MapLayer::Kind::Polyline) line(l.points, l.closed, 1);
      if (l.kind != MapLayer::Kind::Polyline) for (const Vec2& p : l.points) if (finite(p)) out.push_back(f.to_pixel(p));
    }
    if (has_start) {
      const double len = std::max(3.0 * box_w(f.plot) / (f.x_max - f.x_min), page.px(22.0));
      const Vec2 p = f.to_pixel(d.start->position()), h = d.start->heading();
      for (int m = 0; m <= 8; ++m) out.push_back(p + Vec2{h.x, -h.y} * (len * m / 8.0));
    }
    return out;
  };

  // equal-aspect axes around the data; reserve_top/right px of the plot box
  // are kept free of data (for the legend when it would hide data otherwise)
  const auto layout = [&](double reserve_top, double reserve_right) {
    Axes a;
    a.x.label = "x [m]";
    a.y.label = "y [m]";
    fit_axes(page, a, d.title, 0.0, has_speed ? &cb : nullptr,
             [&](AxesFrame& f) {
               AxesFrame inner = f;
               inner.plot.top = std::min(f.plot.bottom - 1, f.plot.top + static_cast<int>(std::lround(reserve_top)));
               inner.plot.right = std::max(f.plot.left + 1, f.plot.right - static_cast<int>(std::lround(reserve_right)));
               inner.x_min = xs.lo, inner.x_max = xs.hi, inner.y_min = ys.lo, inner.y_max = ys.hi;
               make_equal_aspect(inner);
               // the same scale over the whole box, the data where the inner box put it
               const double s = box_w(inner.plot) / (inner.x_max - inner.x_min);
               f.x_min = inner.x_min, f.x_max = inner.x_min + box_w(f.plot) / s;
               f.y_min = inner.y_min, f.y_max = inner.y_min + box_h(f.plot) / s;
             },
             true);
    return a;
  };
  Axes ax = layout(0.0, 0.0);
  const Vec2 lsize = legend_size(page, legend, false);
  std::size_t hidden = 0;
  legend_box(page, ax.frame, lsize, LegendPlace::Best, data_pixels(ax.frame), &hidden);
  if (!legend.empty() && hidden > 0) {
    // no free corner: make room above or beside the data, whichever keeps the larger scale
    const double inset = 2.0 * page.px(6.0);
    Axes top = layout(lsize.y + inset, 0.0), side = layout(0.0, lsize.x + inset);
    const auto scale = [](const Axes& a) { return box_w(a.frame.plot) / (a.frame.x_max - a.frame.x_min); };
    ax = scale(top) >= scale(side) ? top : side;
  }
  const AxesFrame& f = ax.frame;
  const double scale = box_w(f.plot) / (f.x_max - f.x_min);  // px per m
  const auto P = [&](Vec2 p) { return f.to_pixel(p); };
  const auto Ps = [&](const std::vector<Vec2>& pts) {
    std::vector<Vec2> out;
    out.reserve(pts.size());
    for (const Vec2& p : pts) out.push_back(finite(p) ? P(p) : p);
    return out;
  };
  Canvas& c = page.canvas();

  ax.draw_grid(page);
  c.set_clip(f.plot);

  // boundaries: thin lines in the cones' colours
  Stroke thin;
  thin.width = page.px(0.8);
  c.stroke(Ps(d.left), thin, lighten(cone_color(ConeColor::Blue), 0.3), d.closed);
  c.stroke(Ps(d.right), thin, darken(cone_color(ConeColor::Yellow), 0.08), d.closed);

  // timekeeping lines
  Stroke gate;
  gate.width = page.px(1.6);
  for (const Segment& s : d.gates) {
    if (finite(s.a) && finite(s.b)) c.stroke({P(s.a), P(s.b)}, gate, gate_color);
  }

  // optional layers, in order
  for (const MapLayer& l : d.layers) {
    const std::vector<Vec2> pts = Ps(l.points);
    Stroke s;
    s.width = page.px(l.size);
    switch (l.kind) {
      case MapLayer::Kind::Points:
        for (const Vec2& p : pts) c.marker(p, l.marker, page.px(l.size), l.color, {0, 0, 0, 0}, 0.0);
        break;
      case MapLayer::Kind::Polyline:
        c.stroke(pts, s, l.color, l.closed);
        break;
      case MapLayer::Kind::Segments:
        for (std::size_t i = 0; i + 1 < pts.size(); i += 2) c.stroke({pts[i], pts[i + 1]}, s, l.color);
        break;
    }
  }

  // the driven path, coloured by speed (a lone point: a dot)
  std::vector<Vec2> traj = Ps(d.trajectory);
  if (!traj.empty()) {
    const double nan = std::nan("");
    std::vector<Rgba> cols(traj.size(), kTabRed);
    if (has_speed) {
      for (std::size_t i = 0; i < traj.size(); ++i) {
        // a point without a speed is a gap in the line
        if (!std::isfinite(d.speed[i])) traj[i] = {nan, nan};
        cols[i] = colorbar_color(d.speed[i], cb.lo, cb.hi);
      }
    }
    Stroke s;
    s.width = page.px(2.2);
    s.join = Join::Miter;
    s.cap = Cap::Round;
    c.stroke(traj, cols, s);
    // a lone point (no finite neighbour) shows as a dot
    for (std::size_t i = 0; i < traj.size(); ++i) {
      const bool prev = i > 0 && finite(traj[i - 1]), next = i + 1 < traj.size() && finite(traj[i + 1]);
      if (finite(traj[i]) && !prev && !next) c.fill_circle(traj[i], 1.4 * s.width, cols[i]);
    }
  }

  // cones at their true size, never smaller than a dot one can see, outlined darker
  for (const Cone& cone : d.cones) {
    if (!finite(cone.position)) continue;
    const bool big = cone.color == ConeColor::BigOrange;
    const double r = std::max(cone_radius(cone.color) * scale, page.px(big ? 2.6 : 2.0));
    const Rgba col = cone_color(cone.color);
    const double ew = r > page.px(1.6) ? std::max(1.0, page.px(0.45)) : 0.0;
    c.marker(P(cone.position), Marker::Circle, 2.0 * r, col, darken(col, 0.4), ew);
  }

  // the cone map estimated by SLAM: hollow rings around where the cones were seen
  for (const Cone& cone : d.estimated_cones) {
    if (!finite(cone.position)) continue;
    const double r = std::max(cone_radius(cone.color) * scale * 1.8, page.px(3.4));
    c.ring(P(cone.position), r, std::max(1.0, page.px(0.8)), darken(cone_color(cone.color), 0.25));
  }

  // the start pose: an arrow along its heading
  if (has_start) {
    const Vec2 p = P(d.start->position());
    const Vec2 h = d.start->heading();
    const Vec2 dir{h.x, -h.y};  // a unit vector; y down in pixels
    const double len = std::max(3.0 * scale, page.px(22.0));
    const double head = std::min(0.45 * len, page.px(9.0));
    Stroke s;
    s.width = page.px(1.8);
    const Vec2 tip = p + dir * len;
    c.stroke({p, tip - dir * (0.8 * head)}, s, start_color);
    const Vec2 n = left_normal(dir);
    c.fill_convex({tip, tip - dir * head + n * (0.42 * head), tip - dir * head - n * (0.42 * head)}, start_color);
    c.fill_circle(p, page.px(2.0), start_color);
  }
  c.reset_clip();

  ax.draw_frame(page);
  if (has_speed) draw_colorbar_for(page, f, cb);
  draw_title(page, d.title, f.plot.left, f.plot.right, page.px(th.pad));
  if (!legend.empty()) page.boxes()["legend"] = draw_legend(page, f, legend, LegendPlace::Best, data_pixels(f));
  return page.finish({f});
}

// ---- the controller data ----

namespace {

struct Series {
  const std::vector<double>* values;
  double scale;  // to the unit drawn
  std::string label;
  Rgba color;
};

struct Panel {
  std::string y_label;
  std::vector<Series> series;
  bool include_zero;
  double min_span;
};

}  // namespace

Figure draw_controller_data(const ControllerData& d, const FigureStyle& style) {
  Page page(style);
  const Theme& th = kTheme;
  const std::size_t n = d.t.size();
  const std::vector<Panel> panels = {
      {"steering [deg]", {{&d.steer_cmd, kRadToDeg, "commanded", kTabBlue}, {&d.steer, kRadToDeg, "actual", kTabOrange}},
       false, 1.0},
      {"speed [m/s]", {{&d.v_ref, 1.0, "reference", kTabBlue}, {&d.v, 1.0, "actual", kTabOrange}}, false, 0.5},
      {"lateral error [m]", {{&d.lateral_error, 1.0, "", kTabGreen}}, true, 0.1},
      {"heading error [deg]", {{&d.heading_error, kRadToDeg, "", kTabPurple}}, true, 1.0},
  };
  for (const Panel& p : panels) {
    for (const Series& s : p.series) {
      if (!s.values->empty() && s.values->size() != n) {
        throw RenderError("draw_controller_data: " + std::to_string(n) + " times but " +
                          std::to_string(s.values->size()) + " values for \"" + p.y_label +
                          "\" (give one value per time, or none)");
      }
    }
  }
  // the shared time axis: the samples' span, no padding
  Range tr;
  for (double t : d.t) tr.include(t);
  double t0 = tr.empty ? 0.0 : tr.lo, t1 = tr.empty ? 1.0 : tr.hi;
  widen(t0, t1);

  const std::size_t np = panels.size();
  std::vector<Axes> axes(np);
  std::vector<Range> yr(np);
  for (std::size_t i = 0; i < np; ++i) {
    Range r;
    if (panels[i].include_zero) r.include(0.0);
    for (const Series& s : panels[i].series) {
      for (double v : *s.values) r.include(v * s.scale);
    }
    yr[i] = r.padded(0.08, panels[i].min_span, -1.0, 1.0);
    axes[i].y.label = panels[i].y_label;
    axes[i].x.tick_labels = i + 1 == np;
    if (i + 1 == np) axes[i].x.label = "time [s]";
    axes[i].max_ticks = 6;
  }

  // the panels: one column, one height, a common left edge from the widest labels
  const double pad = page.px(th.pad);
  const double top = pad + title_space(page, d.title);
  const double gap = page.px(10.0);
  // the legends of the two-series panels stand right of the plots
  double legend_w = 0.0;
  for (const Panel& p : panels) {
    std::vector<LegendEntry> entries;
    for (const Series& s : p.series) {
      if (!s.label.empty() && !s.values->empty()) entries.push_back({LegendEntry::Kind::Line, s.label, s.color, {}, 1.6});
    }
    if (entries.size() > 1) legend_w = std::max(legend_w, legend_size(page, entries, false).x + page.px(th.legend_gap));
  }
  Margins m;
  m.left = m.bottom = page.px(40.0);
  m.right = page.px(5.0);
  m.top = page.px(5.0);
  for (int round = 0; round < 3; ++round) {
    const double avail = page.height() - top - pad - m.top - m.bottom - gap * static_cast<double>(np - 1);
    const double ph = std::max(1.0, avail / static_cast<double>(np));
    Margins next;
    for (std::size_t i = 0; i < np; ++i) {
      AxesFrame& f = axes[i].frame;
      const double y0 = top + m.top + static_cast<double>(i) * (ph + gap);
      f.plot = {static_cast<int>(std::lround(pad + m.left)), static_cast<int>(std::lround(y0)),
                static_cast<int>(std::lround(page.width() - pad - m.right)), static_cast<int>(std::lround(y0 + ph))};
      f.plot.right = std::max(f.plot.right, f.plot.left + 1);
      f.plot.bottom = std::max(f.plot.bottom, f.plot.top + 1);
      f.x_min = t0, f.x_max = t1, f.y_min = yr[i].lo, f.y_max = yr[i].hi;
      axes[i].update_ticks(page);
      const Margins mi = axes[i].margins(page);
      next.left = std::max(next.left, mi.left);
      next.right = std::max(next.right, mi.right);
      if (i == 0) next.top = mi.top;
      if (i + 1 == np) next.bottom = mi.bottom;
    }
    // one column of y labels: every panel leaves the room of the widest tick labels
    double room = 0.0;
    for (Axes& a : axes) a.y_tick_room = 0.0, room = std::max(room, a.y_labels_width(page));
    for (Axes& a : axes) a.y_tick_room = room;
    m = next;
    m.right = std::max(m.right, legend_w);
  }

  Canvas& c = page.canvas();
  std::vector<AxesFrame> frames;
  for (std::size_t i = 0; i < np; ++i) {
    const Axes& ax = axes[i];
    const AxesFrame& f = ax.frame;
    ax.draw_grid(page);
    c.set_clip(f.plot);
    // lap boundaries: dashed grey verticals
    Stroke lap;
    lap.width = page.px(0.9);
    lap.dash = {page.px(4.0), page.px(3.0)};
    for (double ls : d.lap_starts) {
      // (one on the frame would only thicken it)
      if (!std::isfinite(ls) || ls <= t0 + 1e-9 * (t1 - t0) || ls >= t1 - 1e-9 * (t1 - t0)) continue;
      c.stroke({f.to_pixel({ls, f.y_max}), f.to_pixel({ls, f.y_min})}, lap, {120, 120, 120, 255});
    }
    std::vector<Vec2> avoid;
    std::vector<LegendEntry> legend;
    for (const Series& s : panels[i].series) {
      if (s.values->empty()) continue;
      std::vector<Vec2> pts(n);
      for (std::size_t k = 0; k < n; ++k) {
        const double v = (*s.values)[k] * s.scale;
        // a non-finite sample breaks the line
        pts[k] = std::isfinite(v) && std::isfinite(d.t[k]) ? f.to_pixel({d.t[k], v})
                                                            : Vec2{std::nan(""), std::nan("")};
      }
      Stroke st;
      st.width = page.px(1.2);
      st.join = Join::Miter;
      st.cap = Cap::Round;
      c.stroke(pts, st, s.color);
      const std::size_t every = std::max<std::size_t>(1, n / 400);
      for (std::size_t k = 0; k < n; k += every) avoid.push_back(pts[k]);
      if (!s.label.empty()) legend.push_back({LegendEntry::Kind::Line, s.label, s.color, {}, 1.6});
    }
    c.reset_clip();
    ax.draw_frame(page, "x_label", "y_label_" + std::to_string(i));
    if (legend.size() > 1) {
      page.boxes()["legend_" + std::to_string(i)] = draw_legend(page, f, legend, LegendPlace::Right, avoid);
    }
    frames.push_back(f);
  }
  draw_title(page, d.title, frames.front().plot.left, frames.front().plot.right, pad);
  return page.finish(frames);
}

// ---- the lap chart ----

Figure draw_lap_chart(const LapChartData& d, const FigureStyle& style) {
  Page page(style);
  const Theme& th = kTheme;
  const std::size_t n = d.lap_times.size();
  const auto at = [](const auto& v, std::size_t i, auto fallback) { return i < v.size() ? v[i] : fallback; };
  std::vector<double> penalty(n, 0.0), total(n, 0.0);
  double max_total = 0.0;
  bool any_untimed = false, any_penalty = false;
  for (std::size_t i = 0; i < n; ++i) {
    const int doo = at(d.doo, i, 0), oc = at(d.oc, i, 0);
    penalty[i] = doo * d.doo_penalty + oc * d.oc_penalty;
    total[i] = d.lap_times[i] + penalty[i];
    if (std::isfinite(total[i])) max_total = std::max(max_total, total[i]);
    any_untimed |= !at(d.timed, i, true);
    any_penalty |= doo > 0 || oc > 0;
  }
  if (!(max_total > 0.0)) max_total = 1.0;

  const Rgba timed_color = kTabBlue, untimed_color = lighten(kTabBlue, 0.6), penalty_color = kTabRed;
  std::vector<LegendEntry> legend;
  if (n > 0) legend.push_back({LegendEntry::Kind::Patch, "timed lap", timed_color});
  if (any_untimed) legend.push_back({LegendEntry::Kind::Patch, "lap not timed", untimed_color});
  if (any_penalty) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "penalty (%s s per DOO, %s s per OC)", format_compact(d.doo_penalty).c_str(),
                  format_compact(d.oc_penalty).c_str());
    legend.push_back({LegendEntry::Kind::Patch, buf, penalty_color});
  }
  const double legend_h = legend.empty() ? 0.0 : legend_size(page, legend, true).y + page.px(th.title_gap * 0.5);

  // above each bar: its total time, and the penalties in red above that
  const LineMetrics note = page.font().metrics(th.note_size);
  const double headroom = 2.0 * (note.height() + page.px(2.0)) + page.px(4.0);
  Axes ax;
  ax.x.label = "lap";
  ax.y.label = "time [s]";
  ax.x.grid = false;
  const double nx = static_cast<double>(std::max<std::size_t>(n, 1));
  fit_axes(page, ax, d.title, legend_h, nullptr,
           [&](AxesFrame& f) {
             f.x_min = 0.4, f.x_max = nx + 0.6;
             f.y_min = 0.0;
             const double h = std::max(1.0, box_h(f.plot));
             f.y_max = max_total * 1.02 * h / std::max(0.25 * h, h - headroom);
           },
           false);
  // whole laps on x: every lap, or a round step when they crowd
  {
    Ticks t = ax.xticks;
    const double step = std::max(1.0, std::ceil(t.step));
    t = ticks_with_step(1.0, nx, step);
    ax.xticks = t;
    ax.xticks.decimals = 0;
  }
  const AxesFrame& f = ax.frame;
  Canvas& c = page.canvas();
  ax.draw_grid(page);
  c.set_clip(f.plot);
  TextStyle ts;
  ts.size = th.note_size;
  ts.h = HAlign::Center, ts.v = VAlign::Baseline;
  const double pitch = box_w(f.plot) / (f.x_max - f.x_min);  // px per lap
  for (std::size_t i = 0; i < n; ++i) {
    const double raw = d.lap_times[i];
    if (!std::isfinite(raw)) continue;
    const double x = static_cast<double>(i + 1);
    const Vec2 a = f.to_pixel({x - 0.3, 0.0}), b = f.to_pixel({x + 0.3, raw});
    const bool timed = at(d.timed, i, true);
    c.fill_rect(std::round(a.x), std::round(b.y), std::round(b.x), a.y, timed ? timed_color : untimed_color);
    double top_px = b.y;
    if (penalty[i] > 0.0) {
      const Vec2 q = f.to_pixel({x + 0.3, total[i]});
      c.fill_rect(std::round(a.x), std::round(q.y), std::round(b.x), std::round(b.y), penalty_color);
      top_px = q.y;
    }
    // the labels, when they fit the bar's pitch
    const std::string tlabel = format_number(total[i], 2);
    double y = top_px - page.px(3.0);
    if (page.font().width(tlabel, th.note_size) < 0.95 * pitch) {
      ts.color = th.text;
      page.text(tlabel, {f.to_pixel({x, 0.0}).x, y}, ts);
      y -= note.height() + page.px(2.0);
    }
    const int doo = at(d.doo, i, 0), oc = at(d.oc, i, 0);
    if (doo > 0 || oc > 0) {
      std::string p;
      if (doo > 0) p += std::to_string(doo) + " DOO";
      if (oc > 0) p += (p.empty() ? "" : ", ") + std::to_string(oc) + " OC";
      if (page.font().width(p, th.note_size) >= 0.95 * pitch) {
        p.clear();
        if (doo > 0) p += std::to_string(doo) + "D";
        if (oc > 0) p += (p.empty() ? "" : " ") + std::to_string(oc) + "OC";
      }
      ts.color = darken(penalty_color, 0.15);
      page.text(p, {f.to_pixel({x, 0.0}).x, y}, ts);
    }
  }
  c.reset_clip();
  ax.draw_frame(page);
  const double title_top = page.px(th.pad);
  draw_title(page, d.title, f.plot.left, f.plot.right, title_top);
  if (!legend.empty()) page.boxes()["legend"] = draw_legend(page, f, legend, LegendPlace::Above);
  return page.finish({f});
}

// ---- the sweep heat map ----

Figure draw_heatmap(const HeatmapData& d, const FigureStyle& style) {
  Page page(style);
  const std::size_t nx = d.x.size(), ny = d.y.size();
  if (d.values.size() != nx * ny) {
    throw RenderError("draw_heatmap: " + std::to_string(d.values.size()) + " values for a " + std::to_string(nx) +
                      " x " + std::to_string(ny) + " grid (give y.size() * x.size(), row by row)");
  }
  Range vr;
  for (double v : d.values) vr.include(v);
  ColorbarSpec cb;
  if (!vr.empty) {
    cb.lo = vr.lo, cb.hi = vr.hi;
    widen(cb.lo, cb.hi);
    cb.label = d.value_label;
  }
  Axes ax;
  ax.x.label = d.x_label;
  ax.y.label = d.y_label;
  ax.x.grid = ax.y.grid = false;
  // cells in index units: cell (i, j) is centred on (i, j), labelled with x[i] and y[j]
  const auto index_axis = [&](AxisStyle& a, const std::vector<double>& values, double len_px, bool horizontal) {
    a.custom = true;
    a.custom_ticks.clear();
    a.custom_labels.clear();
    if (values.empty()) return;
    double need = page.font().metrics(kTheme.tick_size).height() + page.px(4.0);
    if (horizontal) {
      need = 0.0;
      for (double v : values) need = std::max(need, static_cast<double>(page.font().width(format_compact(v), kTheme.tick_size)));
      need += page.px(8.0);
    }
    const double cell = len_px / static_cast<double>(values.size());
    const std::size_t every = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(need / std::max(1.0, cell))));
    for (std::size_t i = 0; i < values.size(); i += every) {
      a.custom_ticks.push_back(static_cast<double>(i));
      a.custom_labels.push_back(format_compact(values[i]));
    }
  };
  fit_axes(page, ax, d.title, 0.0, vr.empty ? nullptr : &cb,
           [&](AxesFrame& f) {
             f.x_min = -0.5, f.x_max = nx > 0 ? static_cast<double>(nx) - 0.5 : 0.5;
             f.y_min = -0.5, f.y_max = ny > 0 ? static_cast<double>(ny) - 0.5 : 0.5;
             index_axis(ax.x, d.x, box_w(f.plot), true);
             index_axis(ax.y, d.y, box_h(f.plot), false);
           },
           false);
  const AxesFrame& f = ax.frame;
  Canvas& c = page.canvas();
  const Rgba nan_fill{232, 232, 232, 255}, nan_hatch{165, 165, 165, 255};
  for (std::size_t j = 0; j < ny; ++j) {
    for (std::size_t i = 0; i < nx; ++i) {
      // whole-pixel cell edges: neighbours share them exactly, no seams
      const Vec2 a = f.to_pixel({static_cast<double>(i) - 0.5, static_cast<double>(j) - 0.5});
      const Vec2 b = f.to_pixel({static_cast<double>(i) + 0.5, static_cast<double>(j) + 0.5});
      const Box cell{static_cast<int>(std::lround(a.x)), static_cast<int>(std::lround(b.y)),
                     static_cast<int>(std::lround(b.x)), static_cast<int>(std::lround(a.y))};
      const double v = d.values[j * nx + i];
      if (std::isfinite(v)) {
        c.fill_rect(cell.left, cell.top, cell.right, cell.bottom, colorbar_color(v, cb.lo, cb.hi));
        continue;
      }
      // no value: grey, hatched at 45 degrees
      c.fill_rect(cell.left, cell.top, cell.right, cell.bottom, nan_fill);
      c.set_clip(cell);
      Stroke s;
      s.width = page.px(0.8);
      const double spacing = page.px(5.0);
      const double w = box_w(cell), h = box_h(cell);
      for (double k = -h; k < w + h; k += spacing) {
        c.stroke({{cell.left + k, static_cast<double>(cell.bottom)}, {cell.left + k + h, static_cast<double>(cell.top)}}, s,
                 nan_hatch);
      }
      c.reset_clip();
    }
  }
  if (nx == 0 || ny == 0) {
    TextStyle ts;
    ts.size = kTheme.label_size;
    ts.color = {120, 120, 120, 255};
    ts.h = HAlign::Center, ts.v = VAlign::Middle;
    page.text("no data", {0.5 * (f.plot.left + f.plot.right), 0.5 * (f.plot.top + f.plot.bottom)}, ts);
  }
  ax.draw_frame(page);
  if (!vr.empty) draw_colorbar_for(page, f, cb);
  draw_title(page, d.title, f.plot.left, f.plot.right, page.px(kTheme.pad));
  return page.finish({f});
}

// ---- the line chart ----

Figure draw_line_chart(const LineChartData& d, const FigureStyle& style) {
  Page page(style);
  Range xr, yr;
  if (d.include_zero) yr.include(0.0);
  for (const LineSeries& s : d.series) {
    if (s.x.size() != s.y.size()) {
      throw RenderError("draw_line_chart: series \"" + s.label + "\" has " + std::to_string(s.x.size()) + " x but " +
                        std::to_string(s.y.size()) + " y values (give one y per x)");
    }
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xr.include(s.x[i]);
      yr.include(s.y[i]);
    }
  }
  const Range xp = xr.padded(0.04, 1e-6), yp = yr.padded(0.06, 1e-6);
  Axes ax;
  ax.x.label = d.x_label;
  ax.y.label = d.y_label;
  fit_axes(page, ax, d.title, 0.0, nullptr,
           [&](AxesFrame& f) {
             f.x_min = xp.lo, f.x_max = xp.hi, f.y_min = yp.lo, f.y_max = yp.hi;
             widen(f.x_min, f.x_max);
             widen(f.y_min, f.y_max);
           },
           false);
  const AxesFrame& f = ax.frame;
  Canvas& c = page.canvas();
  ax.draw_grid(page);
  c.set_clip(f.plot);
  std::vector<Vec2> avoid;
  std::vector<LegendEntry> legend;
  for (const LineSeries& s : d.series) {
    std::vector<Vec2> pts;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const bool ok = std::isfinite(s.x[i]) && std::isfinite(s.y[i]);
      pts.push_back(ok ? f.to_pixel({s.x[i], s.y[i]}) : Vec2{std::nan(""), std::nan("")});
    }
    Stroke st;
    st.width = page.px(1.6);
    st.join = Join::Round;
    st.cap = Cap::Round;
    c.stroke(pts, st, s.color);
    for (const Vec2& q : pts) {
      if (!std::isfinite(q.x)) continue;
      c.marker(q, s.marker, page.px(5.5), s.color, kBlack, 0.0);
      avoid.push_back(q);
    }
    // the segments between points too, so the legend keeps off the lines
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      for (double t : {0.25, 0.5, 0.75}) avoid.push_back(pts[i] + (pts[i + 1] - pts[i]) * t);
    }
    if (!s.label.empty()) legend.push_back({LegendEntry::Kind::Line, s.label, s.color, {}, 1.6});
  }
  c.reset_clip();
  ax.draw_frame(page);
  draw_title(page, d.title, f.plot.left, f.plot.right, page.px(kTheme.pad));
  if (!legend.empty()) page.boxes()["legend"] = draw_legend(page, f, legend, LegendPlace::Best, avoid);
  return page.finish({f});
}

}  // namespace paddock::render
