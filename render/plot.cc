#include "render/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "render/colormap.h"

namespace paddock::render {

// ---- frames and boxes ----

Vec2 AxesFrame::to_pixel(Vec2 data) const {
  // pixel (i, j) covers [i, i + 1) x [j, j + 1): the plot box's edges are the range's ends
  const double dx = x_max - x_min, dy = y_max - y_min;
  const double fx = dx != 0.0 ? (data.x - x_min) / dx : 0.5;
  const double fy = dy != 0.0 ? (data.y - y_min) / dy : 0.5;
  return {plot.left + fx * (plot.right - plot.left), plot.bottom - fy * (plot.bottom - plot.top)};
}

Box united(const Box& a, const Box& b) {
  if (is_empty(a)) return b;
  if (is_empty(b)) return a;
  return {std::min(a.left, b.left), std::min(a.top, b.top), std::max(a.right, b.right), std::max(a.bottom, b.bottom)};
}

bool overlaps(const Box& a, const Box& b) {
  return !is_empty(a) && !is_empty(b) && a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom;
}

bool is_empty(const Box& b) { return b.right <= b.left || b.bottom <= b.top; }

void make_equal_aspect(AxesFrame& ax) {
  const double w = box_w(ax.plot), h = box_h(ax.plot);
  const double dx = ax.x_max - ax.x_min, dy = ax.y_max - ax.y_min;
  if (!(w > 0.0) || !(h > 0.0) || !(dx > 0.0) || !(dy > 0.0)) return;
  // the common scale (px per unit) is the smaller one: the other range grows to fill its side
  const double s = std::min(w / dx, h / dy);
  const double cx = 0.5 * (ax.x_min + ax.x_max), cy = 0.5 * (ax.y_min + ax.y_max);
  const double hx = 0.5 * w / s, hy = 0.5 * h / s;
  ax.x_min = cx - hx, ax.x_max = cx + hx;
  ax.y_min = cy - hy, ax.y_max = cy + hy;
}

// ---- ranges ----

void Range::include(double v) {
  if (!std::isfinite(v)) return;
  if (empty) {
    lo = hi = v;
    empty = false;
  } else {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
}

Range Range::padded(double frac, double min_span, double fallback_lo, double fallback_hi) const {
  Range r;
  r.empty = false;
  if (empty) {
    r.lo = fallback_lo, r.hi = fallback_hi;
    return r;
  }
  double span = hi - lo;
  double a = lo - frac * span, b = hi + frac * span;
  if (b - a < min_span) {
    const double c = 0.5 * (lo + hi);
    a = c - 0.5 * min_span, b = c + 0.5 * min_span;
  }
  r.lo = a, r.hi = b;
  return r;
}

// ---- ticks ----

int decimals_for_step(double step) {
  if (!(step > 0.0) || !std::isfinite(step)) return 0;
  // step = m x 10^n with m in {1, 2, 5}: n < 0 needs -n decimals
  const int n = static_cast<int>(std::floor(std::log10(step) + 1e-9));
  return std::clamp(-n, 0, 15);
}

Ticks ticks_with_step(double lo, double hi, double step) {
  Ticks t;
  t.step = step;
  t.decimals = decimals_for_step(step);
  if (!(step > 0.0) || !std::isfinite(lo) || !std::isfinite(hi)) return t;
  if (hi < lo) std::swap(lo, hi);
  // the multiples k * step in [lo, hi] (a tick a hair outside by rounding still counts)
  const double eps = 1e-9;
  const double k0 = std::ceil(lo / step - eps), k1 = std::floor(hi / step + eps);
  if (k1 - k0 > 1000) return t;
  for (double k = k0; k <= k1; k += 1.0) t.values.push_back(k == 0.0 ? 0.0 : k * step);
  return t;
}

Ticks nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  if (hi < lo) std::swap(lo, hi);
  if (hi - lo <= std::max(std::abs(lo), std::abs(hi)) * 1e-12) {
    const double half = lo != 0.0 ? 0.05 * std::abs(lo) : 0.5;
    lo -= half, hi += half;
  }
  target = std::max(2, target);
  const double raw = (hi - lo) / target;
  const int e = static_cast<int>(std::floor(std::log10(raw)));
  // the step among {1, 2, 5} x 10^n near raw whose tick count is closest to the
  // target, counts outside [target - 2, target + 4] last; a tie goes to the
  // smaller step (more ticks). Steps grow by at most 2.5 times, so when one
  // step gives 3 ticks the next smaller gives 4 to 10: a target of 6 always
  // ends with 4 to 10 ticks.
  const int lo_count = std::max(2, target - 2), hi_count = target + 4;
  Ticks best;
  int best_score = std::numeric_limits<int>::max();
  for (int n = e - 1; n <= e + 1; ++n) {
    for (double m : {1.0, 2.0, 5.0}) {
      const double step = m * std::pow(10.0, n);
      const double eps = 1e-9;
      const double count = std::floor(hi / step + eps) - std::ceil(lo / step - eps) + 1.0;
      const bool outside = count < lo_count || count > hi_count;
      const int score = static_cast<int>(std::abs(count - target)) + (outside ? 1000 : 0);
      if (score < best_score || (score == best_score && step < best.step)) {
        best_score = score;
        best.step = step;
      }
    }
  }
  return ticks_with_step(lo, hi, best.step);
}

std::string format_number(double v, int decimals) {
  char buf[64];
  if (std::abs(v) >= 1e15) {
    std::snprintf(buf, sizeof(buf), "%.3g", v);
    return buf;
  }
  std::snprintf(buf, sizeof(buf), "%.*f", std::clamp(decimals, 0, 15), v);
  std::string s = buf;
  // "-0", "-0.00": a zero has no sign
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

std::string format_tick(double v, int decimals) {
  std::string s = format_number(v, decimals);
  if (!s.empty() && s[0] == '-') s.replace(0, 1, "\u2212");
  return s;
}

std::string format_compact(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

// ---- axes ----

namespace {

// a pixel coordinate for a line of odd/even whole width: crisp on the pixel grid
double snap(double x, int width) {
  return width % 2 == 1 ? std::floor(x) + 0.5 : std::round(x);
}

Ticks fitting_ticks(const Page& page, double lo, double hi, double len_px, double max_ticks, bool horizontal) {
  const Theme& th = kTheme;
  // about one tick per 50 pt across, per 28 pt up (labels stack tighter than they line up)
  const double per = page.px(horizontal ? 50.0 : 28.0);
  const int start = std::clamp(static_cast<int>(std::lround(len_px / per)), 3, static_cast<int>(max_ticks));
  const LineMetrics m = page.font().metrics(th.tick_size);
  Ticks t;
  for (int target = start; target >= 2; --target) {
    t = nice_ticks(lo, hi, target);
    const double spacing = len_px * t.step / std::max(1e-300, hi - lo);
    double need = m.height() + page.px(4.0);
    if (horizontal) {
      double w = 0.0;
      for (double v : t.values) w = std::max(w, static_cast<double>(page.font().width(format_tick(v, t.decimals), th.tick_size)));
      need = w + page.px(8.0);
    }
    if (spacing >= need) break;
  }
  return t;
}

}  // namespace

void Axes::update_ticks(const Page& page, bool equal_step) {
  const double w = std::max(1.0, box_w(frame.plot)), h = std::max(1.0, box_h(frame.plot));
  xticks = fitting_ticks(page, frame.x_min, frame.x_max, w, max_ticks, true);
  yticks = fitting_ticks(page, frame.y_min, frame.y_max, h, max_ticks, false);
  if (equal_step) {
    const double step = std::max(xticks.step, yticks.step);
    xticks = ticks_with_step(frame.x_min, frame.x_max, step);
    yticks = ticks_with_step(frame.y_min, frame.y_max, step);
  }
  if (x.custom) {
    xticks.values = x.custom_ticks;
  }
  if (y.custom) {
    yticks.values = y.custom_ticks;
  }
}

std::vector<std::string> Axes::x_labels() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < xticks.values.size(); ++i) {
    out.push_back(x.custom ? (i < x.custom_labels.size() ? x.custom_labels[i] : std::string())
                           : format_tick(xticks.values[i], xticks.decimals));
  }
  return out;
}

std::vector<std::string> Axes::y_labels() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < yticks.values.size(); ++i) {
    out.push_back(y.custom ? (i < y.custom_labels.size() ? y.custom_labels[i] : std::string())
                           : format_tick(yticks.values[i], yticks.decimals));
  }
  return out;
}

double Axes::y_labels_width(const Page& page) const {
  double w = y_tick_room;
  for (const auto& s : y_labels()) w = std::max(w, static_cast<double>(page.font().width(s, kTheme.tick_size)));
  return w;
}

double Axes::y_label_size(const Page& page) const {
  const double size = kTheme.label_size;
  if (y.label.empty()) return size;
  const double w = page.font().width(y.label, size), room = box_h(frame.plot);
  return w <= room || w <= 0 ? size : std::max(5.0, size * room / w);
}

Margins Axes::margins(const Page& page) const {
  const Theme& th = kTheme;
  const Font& f = page.font();
  const double fw = page.px_int(th.frame_width), tl = page.px(th.tick_length), gap = page.px(th.tick_gap);
  const LineMetrics tick_m = f.metrics(th.tick_size), label_m = f.metrics(th.label_size);
  Margins m;
  m.left = m.right = m.top = m.bottom = fw;
  const auto xl = x_labels(), yl = y_labels();
  // bottom: ticks, their labels, the axis label
  m.bottom += tl;
  if (x.tick_labels && !xl.empty()) m.bottom += gap + tick_m.height();
  if (!x.label.empty()) m.bottom += page.px(th.label_gap) + label_m.height();
  // left: ticks, the widest label, the rotated axis label
  m.left += tl;
  if (y.tick_labels && (!yl.empty() || y_tick_room > 0.0)) m.left += gap + y_labels_width(page);
  if (!y.label.empty()) m.left += page.px(th.label_gap) + f.metrics(y_label_size(page)).height();
  // right and top: what the outermost tick labels stick out
  if (x.tick_labels) {
    for (std::size_t i = 0; i < xl.size(); ++i) {
      const double px = frame.to_pixel({xticks.values[i], frame.y_min}).x;
      const double half = 0.5 * f.width(xl[i], th.tick_size);
      m.right = std::max(m.right, px + half - frame.plot.right);
    }
  }
  if (y.tick_labels) {
    for (double v : yticks.values) {
      const double py = frame.to_pixel({frame.x_min, v}).y;
      m.top = std::max(m.top, tick_m.ascent - 0.5 * tick_m.cap_height - (py - frame.plot.top));
    }
  }
  return m;
}

void Axes::draw_grid(Page& page) const {
  const Theme& th = kTheme;
  Canvas& c = page.canvas();
  const int gw = page.px_int(th.grid_width);
  const Box& b = frame.plot;
  if (x.grid) {
    for (double v : xticks.values) {
      const double px = snap(frame.to_pixel({v, frame.y_min}).x, gw);
      if (px - 0.5 * gw <= b.left || px + 0.5 * gw >= b.right) continue;
      c.fill_rect(px - 0.5 * gw, b.top, px + 0.5 * gw, b.bottom, th.grid);
    }
  }
  if (y.grid) {
    for (double v : yticks.values) {
      const double py = snap(frame.to_pixel({frame.x_min, v}).y, gw);
      if (py - 0.5 * gw <= b.top || py + 0.5 * gw >= b.bottom) continue;
      c.fill_rect(b.left, py - 0.5 * gw, b.right, py + 0.5 * gw, th.grid);
    }
  }
}

void Axes::draw_frame(Page& page, const std::string& x_name, const std::string& y_name) const {
  const Theme& th = kTheme;
  Canvas& c = page.canvas();
  const Font& f = page.font();
  const Box& b = frame.plot;
  const double fw = page.px_int(th.frame_width), tl = page.px(th.tick_length), gap = page.px(th.tick_gap);
  const int tw = page.px_int(th.tick_width);
  const LineMetrics tick_m = f.metrics(th.tick_size);
  // the frame just outside the plot box
  c.fill_rect(b.left - fw, b.top - fw, b.right + fw, b.top, th.frame);
  c.fill_rect(b.left - fw, b.bottom, b.right + fw, b.bottom + fw, th.frame);
  c.fill_rect(b.left - fw, b.top, b.left, b.bottom, th.frame);
  c.fill_rect(b.right, b.top, b.right + fw, b.bottom, th.frame);
  TextStyle ts;
  ts.size = th.tick_size;
  ts.color = th.text;
  // x: ticks down from the frame, labels centred below them
  const auto xl = x_labels();
  for (std::size_t i = 0; i < xticks.values.size(); ++i) {
    const double px = snap(frame.to_pixel({xticks.values[i], frame.y_min}).x, tw);
    if (px < b.left - 0.5 || px > b.right + 0.5) continue;
    c.fill_rect(px - 0.5 * tw, b.bottom + fw, px + 0.5 * tw, b.bottom + fw + tl, th.frame);
    if (x.tick_labels) {
      ts.h = HAlign::Center, ts.v = VAlign::Top;
      page.text(xl[i], {px, b.bottom + fw + tl + gap}, ts);
    }
  }
  // y: ticks left of the frame, labels right-aligned
  const auto yl = y_labels();
  double wmax = 0.0;
  for (std::size_t i = 0; i < yticks.values.size(); ++i) {
    const double py = snap(frame.to_pixel({frame.x_min, yticks.values[i]}).y, tw);
    if (py < b.top - 0.5 || py > b.bottom + 0.5) continue;
    c.fill_rect(b.left - fw - tl, py - 0.5 * tw, b.left - fw, py + 0.5 * tw, th.frame);
    if (y.tick_labels) {
      ts.h = HAlign::Right, ts.v = VAlign::Middle;
      page.text(yl[i], {b.left - fw - tl - gap, py}, ts);
    }
  }
  wmax = y_labels_width(page);
  // the axis labels
  TextStyle ls;
  ls.size = th.label_size;
  ls.color = th.text;
  if (!x.label.empty()) {
    ls.h = HAlign::Center, ls.v = VAlign::Top;
    double y0 = b.bottom + fw + tl;
    if (x.tick_labels && !xl.empty()) y0 += gap + tick_m.height();
    page.boxes()[x_name] = page.text(x.label, {0.5 * (b.left + b.right), y0 + page.px(th.label_gap)}, ls);
  }
  if (!y.label.empty()) {
    ls.h = HAlign::Center, ls.v = VAlign::Bottom, ls.vertical = true;
    ls.size = y_label_size(page);
    double x0 = b.left - fw - tl;
    if (y.tick_labels && (!yl.empty() || y_tick_room > 0.0)) x0 -= gap + wmax;
    page.boxes()[y_name] = page.text(y.label, {x0 - page.px(th.label_gap), 0.5 * (b.top + b.bottom)}, ls);
  }
}

// ---- colour bar ----

namespace {

Ticks colorbar_ticks(const Page& page, double lo, double hi, double height_px) {
  const int target = std::clamp(static_cast<int>(std::lround(height_px / page.px(45.0))), 2, 8);
  return nice_ticks(lo, hi, target);
}

}  // namespace

Rgba colorbar_color(double v, double lo, double hi) { return viridis(hi > lo ? (v - lo) / (hi - lo) : 0.5); }

double colorbar_space(const Page& page, double lo, double hi, const std::string& label, double height_px) {
  const Theme& th = kTheme;
  const Ticks t = colorbar_ticks(page, lo, hi, height_px);
  double wmax = 0.0;
  for (double v : t.values) {
    wmax = std::max(wmax, static_cast<double>(page.font().width(format_tick(v, t.decimals), th.tick_size)));
  }
  double w = page.px(th.colorbar_gap) + page.px(th.colorbar_width) + page.px_int(th.frame_width) +
             page.px(th.tick_length) + page.px(th.tick_gap) + wmax;
  if (!label.empty()) w += page.px(th.label_gap) + page.font().metrics(th.label_size).height();
  return w;
}

void draw_colorbar(Page& page, const Box& strip, double lo, double hi, const std::string& label) {
  const Theme& th = kTheme;
  Canvas& c = page.canvas();
  const int h = strip.bottom - strip.top;
  if (h <= 0 || strip.right <= strip.left) return;
  // one band per image row: row r shows t = (bottom - 1 - r) / (h - 1)
  for (int r = strip.top; r < strip.bottom; ++r) {
    const double t = h > 1 ? static_cast<double>(strip.bottom - 1 - r) / (h - 1) : 0.5;
    c.fill_rect(strip.left, r, strip.right, r + 1, viridis(t));
  }
  const double fw = page.px_int(th.frame_width), tl = page.px(th.tick_length), gap = page.px(th.tick_gap);
  const int tw = page.px_int(th.tick_width);
  c.fill_rect(strip.left - fw, strip.top - fw, strip.right + fw, strip.top, th.frame);
  c.fill_rect(strip.left - fw, strip.bottom, strip.right + fw, strip.bottom + fw, th.frame);
  c.fill_rect(strip.left - fw, strip.top, strip.left, strip.bottom, th.frame);
  c.fill_rect(strip.right, strip.top, strip.right + fw, strip.bottom, th.frame);
  const Ticks t = colorbar_ticks(page, lo, hi, h);
  TextStyle ts;
  ts.size = th.tick_size;
  ts.color = th.text;
  ts.h = HAlign::Left, ts.v = VAlign::Middle;
  double wmax = 0.0;
  for (double v : t.values) {
    // the value's row centre, as the bands
    const double y = strip.bottom - 0.5 - (hi > lo ? (v - lo) / (hi - lo) : 0.5) * (h - 1);
    const double ys = snap(y, tw);
    c.fill_rect(strip.right + fw, ys - 0.5 * tw, strip.right + fw + tl, ys + 0.5 * tw, th.frame);
    const std::string s = format_tick(v, t.decimals);
    page.text(s, {strip.right + fw + tl + gap, ys}, ts);
    wmax = std::max(wmax, static_cast<double>(page.font().width(s, th.tick_size)));
  }
  page.boxes()["colorbar"] = strip;
  if (!label.empty()) {
    TextStyle ls;
    ls.size = th.label_size;
    ls.color = th.text;
    ls.h = HAlign::Center, ls.v = VAlign::Top, ls.vertical = true;
    const double x = strip.right + fw + tl + gap + wmax + page.px(th.label_gap);
    page.boxes()["colorbar_label"] = page.text(label, {x, 0.5 * (strip.top + strip.bottom)}, ls);
  }
}

// ---- legend ----

namespace {

struct LegendLayout {
  double pad, swatch, sgap, row_h, spacing;
  LineMetrics m;
};

LegendLayout legend_layout(const Page& page) {
  const Theme& th = kTheme;
  LegendLayout l;
  l.m = page.font().metrics(th.legend_size);
  l.pad = page.px(5.0);
  l.swatch = page.px(20.0);
  l.sgap = page.px(5.0);
  l.row_h = l.m.height() + page.px(2.5);
  l.spacing = page.px(12.0);
  return l;
}

void draw_swatch(Page& page, const LegendEntry& e, double x0, double yc, const LegendLayout& l) {
  Canvas& c = page.canvas();
  const double x1 = x0 + l.swatch;
  Stroke s;
  s.width = page.px(e.size);
  switch (e.kind) {
    case LegendEntry::Kind::Line:
      c.stroke({{x0, yc}, {x1, yc}}, s, e.color);
      break;
    case LegendEntry::Kind::DashedLine:
      s.dash = {page.px(3.0), page.px(2.0)};
      c.stroke({{x0, yc}, {x1, yc}}, s, e.color);
      break;
    case LegendEntry::Kind::Gradient: {
      std::vector<Vec2> pts;
      std::vector<Rgba> cols;
      for (int i = 0; i <= 16; ++i) {
        pts.push_back({x0 + l.swatch * i / 16.0, yc});
        cols.push_back(viridis(0.1 + 0.8 * i / 16.0));
      }
      c.stroke(pts, cols, s);
      break;
    }
    case LegendEntry::Kind::Marker: {
      const double size = std::min(page.px(e.size), l.row_h);
      const double ew = std::max(1.0, page.px(0.8));
      if (e.hollow) {
        c.marker({0.5 * (x0 + x1), yc}, e.marker, size, {0, 0, 0, 0}, e.color, ew);
      } else {
        c.marker({0.5 * (x0 + x1), yc}, e.marker, size, e.color, e.edge, ew);
      }
      break;
    }
    case LegendEntry::Kind::Patch: {
      const double hh = 0.55 * l.m.cap_height + page.px(1.0);
      c.fill_rect(x0 + 0.1 * l.swatch, yc - hh, x1 - 0.1 * l.swatch, yc + hh, e.color);
      break;
    }
    case LegendEntry::Kind::Arrow: {
      const double head = std::min(page.px(7.0), 0.6 * l.swatch);
      s.width = page.px(1.4);
      c.stroke({{x0, yc}, {x1 - head * 0.8, yc}}, s, e.color);
      c.fill_convex({{x1, yc}, {x1 - head, yc - 0.45 * head}, {x1 - head, yc + 0.45 * head}}, e.color);
      break;
    }
  }
}

}  // namespace

Vec2 legend_size(const Page& page, const std::vector<LegendEntry>& entries, bool row) {
  const LegendLayout l = legend_layout(page);
  double w = 0.0, h = 0.0;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double ew = l.swatch + l.sgap + page.font().width(entries[i].label, kTheme.legend_size);
    if (row) {
      w += ew + (i > 0 ? l.spacing : 0.0);
      h = l.row_h;
    } else {
      w = std::max(w, ew);
      h += l.row_h;
    }
  }
  return {std::ceil(w + 2 * l.pad), std::ceil(h + 2 * l.pad)};
}

Box legend_box(const Page& page, const AxesFrame& ax, Vec2 size, LegendPlace place, const std::vector<Vec2>& avoid,
                std::size_t* covered) {
  const int w = static_cast<int>(size.x), h = static_cast<int>(size.y);
  const Box& p = ax.plot;
  const int inset = static_cast<int>(std::lround(page.px(6.0)));
  const auto corner = [&](LegendPlace c) {
    switch (c) {
      case LegendPlace::UpperLeft: return Box{p.left + inset, p.top + inset, p.left + inset + w, p.top + inset + h};
      case LegendPlace::LowerLeft:
        return Box{p.left + inset, p.bottom - inset - h, p.left + inset + w, p.bottom - inset};
      case LegendPlace::LowerRight:
        return Box{p.right - inset - w, p.bottom - inset - h, p.right - inset, p.bottom - inset};
      case LegendPlace::Above: {
        const int left = static_cast<int>(std::lround(0.5 * (p.left + p.right) - 0.5 * w));
        const int bottom = p.top - static_cast<int>(std::lround(page.px(kTheme.title_gap * 0.5)));
        return Box{left, bottom - h, left + w, bottom};
      }
      case LegendPlace::Right: {
        const int left = p.right + static_cast<int>(std::lround(page.px(kTheme.legend_gap)));
        return Box{left, p.top, left + w, p.top + h};
      }
      default: return Box{p.right - inset - w, p.top + inset, p.right - inset, p.top + inset + h};
    }
  };
  const auto count = [&](const Box& b) {
    const Box grown{b.left - inset, b.top - inset, b.right + inset, b.bottom + inset};
    std::size_t n = 0;
    for (const Vec2& q : avoid) {
      n += grown.contains(static_cast<int>(std::floor(q.x)), static_cast<int>(std::floor(q.y)));
    }
    return n;
  };
  Box box = corner(place);
  std::size_t best = count(box);
  if (place == LegendPlace::Best) {
    // the corner with the fewest points to avoid under it (ties: this order)
    best = std::numeric_limits<std::size_t>::max();
    for (LegendPlace c : {LegendPlace::UpperRight, LegendPlace::UpperLeft, LegendPlace::LowerLeft,
                          LegendPlace::LowerRight}) {
      const Box b = corner(c);
      const std::size_t n = count(b);
      if (n < best) best = n, box = b;
    }
  }
  if (covered != nullptr) *covered = best;
  return box;
}

void draw_legend_in(Page& page, const Box& box, const std::vector<LegendEntry>& entries, bool row) {
  const Theme& th = kTheme;
  const LegendLayout l = legend_layout(page);
  Canvas& c = page.canvas();
  if (!row) {
    // a white card with a thin grey border
    const double bw = page.px_int(0.6);
    c.fill_rect(box.left, box.top, box.right, box.bottom, {200, 200, 200, 255});
    c.fill_rect(box.left + bw, box.top + bw, box.right - bw, box.bottom - bw, {255, 255, 255, 255});
  }
  TextStyle ts;
  ts.size = th.legend_size;
  ts.color = th.text;
  ts.h = HAlign::Left, ts.v = VAlign::Middle;
  double x = box.left + l.pad, y = box.top + l.pad;
  for (const LegendEntry& e : entries) {
    const double yc = y + 0.5 * l.row_h;
    draw_swatch(page, e, x, yc, l);
    page.text(e.label, {x + l.swatch + l.sgap, yc}, ts);
    if (row) {
      x += l.swatch + l.sgap + page.font().width(e.label, th.legend_size) + l.spacing;
    } else {
      y += l.row_h;
    }
  }
}

Box draw_legend(Page& page, const AxesFrame& ax, const std::vector<LegendEntry>& entries, LegendPlace place,
                const std::vector<Vec2>& avoid) {
  if (entries.empty()) return {};
  const bool row = place == LegendPlace::Above;
  const Box box = legend_box(page, ax, legend_size(page, entries, row), place, avoid);
  draw_legend_in(page, box, entries, row);
  return box;
}

// ---- title ----

double title_space(const Page& page, const std::string& title) {
  if (title.empty()) return 0.0;
  return page.font().metrics(kTheme.title_size).height() + page.px(kTheme.title_gap);
}

Box draw_title(Page& page, const std::string& title, double left, double right, double top) {
  if (title.empty()) return {};
  TextStyle ts;
  ts.size = kTheme.title_size;
  ts.color = kTheme.text;
  ts.h = HAlign::Center, ts.v = VAlign::Top;
  const Box b = page.text(title, {0.5 * (left + right), top}, ts);
  page.boxes()["title"] = b;
  return b;
}

}  // namespace paddock::render
