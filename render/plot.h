#pragma once
// the axes layer: data ranges to pixels, "nice" ticks and their labels, grid,
// frame, axis labels, a colour bar, a legend; sizes in points (FigureStyle::dpi).
#include <cstddef>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "render/figures.h"
#include "render/page.h"

namespace paddock::render {

// sizes (pt) and colours shared by every figure
struct Theme {
  double title_size = 13.0;
  double label_size = 11.0;   // axis labels, colour bar label
  double tick_size = 9.5;     // tick labels
  double legend_size = 9.5;
  double note_size = 8.5;     // annotations in the plot
  double frame_width = 0.8;
  double tick_length = 3.5;
  double tick_width = 0.8;
  double grid_width = 0.6;
  double pad = 8.0;           // the figure's outer margin
  double tick_gap = 3.0;      // tick -> tick label
  double label_gap = 5.0;     // tick labels -> axis label
  double title_gap = 8.0;     // title -> plot
  double colorbar_width = 12.0;
  double colorbar_gap = 12.0;  // plot -> colour bar
  double legend_gap = 8.0;     // plot -> a legend right of it
  Rgba text{0, 0, 0, 255};
  Rgba frame{0, 0, 0, 255};
  Rgba grid{228, 228, 228, 255};
};
inline const Theme kTheme{};

// ---- ticks ----

// tick values k * step (step = {1, 2, 5} x 10^n) inside [lo, hi]; decimals: the
// digits after the point that show every tick exactly
struct Ticks {
  std::vector<double> values;
  double step = 1.0;
  int decimals = 0;
};

// about `target` ticks at round numbers inside [lo, hi] (a degenerate range is widened)
Ticks nice_ticks(double lo, double hi, int target = 6);
// the ticks of a given step inside [lo, hi]
Ticks ticks_with_step(double lo, double hi, double step);
// the fewest decimals that show multiples of step exactly
int decimals_for_step(double step);
// a number with fixed decimals, without float noise or "-0"
std::string format_number(double v, int decimals);
// the same as a tick label: a typographic minus sign (U+2212) for negative numbers
std::string format_tick(double v, int decimals);
// a parameter value in at most 4 significant digits ("0.25", "1500", "1e-05")
std::string format_compact(double v);

// ---- ranges ----

// a data range built from values (non-finite ones ignored)
struct Range {
  double lo = 0.0, hi = 0.0;
  bool empty = true;
  void include(double v);
  void include(Vec2 p, bool x_axis) { include(x_axis ? p.x : p.y); }
  // widened by frac of the span on each side and to at least min_span; [fallback_lo, fallback_hi] when empty
  Range padded(double frac, double min_span, double fallback_lo = 0.0, double fallback_hi = 1.0) const;
};

// grows the x or the y range of ax about its centre so that one data unit is
// the same number of pixels along x and along y
void make_equal_aspect(AxesFrame& ax);
// the plot box of a frame as doubles
inline double box_w(const Box& b) { return b.right - b.left; }
inline double box_h(const Box& b) { return b.bottom - b.top; }
Box united(const Box& a, const Box& b);
bool overlaps(const Box& a, const Box& b);
bool is_empty(const Box& b);

// ---- axes ----

struct AxisStyle {
  std::string label;
  bool tick_labels = true;              // false: ticks without labels (shared axes)
  bool grid = true;
  bool custom = false;                  // true: the ticks and labels below instead of nice ticks
  std::vector<double> custom_ticks;
  std::vector<std::string> custom_labels;
};

// the space (px) the decoration needs outside a plot box
struct Margins {
  double left = 0.0, right = 0.0, top = 0.0, bottom = 0.0;
};

class Axes {
 public:
  AxesFrame frame;
  AxisStyle x, y;
  Ticks xticks, yticks;
  double max_ticks = 8;  // per axis
  double y_tick_room = 0.0;  // px: at least this much room for the y tick labels (aligns stacked panels' y labels)

  // nice ticks for the current ranges and plot box: about one per 50 pt, fewer
  // when the labels would touch. equal_step: one step for both axes (maps)
  void update_ticks(const Page& page, bool equal_step = false);
  // the space outside the plot box the ticks, tick labels and axis labels need
  Margins margins(const Page& page) const;
  // light lines at the ticks, under the data
  void draw_grid(Page& page) const;
  // the frame, ticks, tick labels and axis labels (over the data); the label
  // boxes go to page.boxes() as x_name and y_name when there is a label
  void draw_frame(Page& page, const std::string& x_name = "x_label", const std::string& y_name = "y_label") const;

  std::vector<std::string> x_labels() const;
  std::vector<std::string> y_labels() const;
  // the widest y tick label (px), y_tick_room at least
  double y_labels_width(const Page& page) const;
  // the y label's size (pt): the theme's, smaller when it is longer than the plot is high
  double y_label_size(const Page& page) const;
};

// ---- colour bar ----

// the width (px) a vertical colour bar with ticks and a label takes right of the plot (gap included)
double colorbar_space(const Page& page, double lo, double hi, const std::string& label, double height_px);
// a vertical viridis strip in `strip` (its pixels exactly viridis: the top row
// is viridis(1), the bottom row viridis(0)), framed, with ticks for [lo, hi] on
// the right and the label rotated beside them; boxes "colorbar", "colorbar_label"
void draw_colorbar(Page& page, const Box& strip, double lo, double hi, const std::string& label);
// the colour of v on a colour bar over [lo, hi]
Rgba colorbar_color(double v, double lo, double hi);

// ---- legend ----

struct LegendEntry {
  enum class Kind { Line, DashedLine, Marker, Patch, Gradient, Arrow };
  Kind kind = Kind::Line;
  std::string label;
  Rgba color{0, 0, 0, 255};
  Rgba edge{0, 0, 0, 0};     // markers and patches: the outline
  double size = 1.5;         // pt: line width or marker diameter
  Marker marker = Marker::Circle;
  bool hollow = false;       // markers: only the outline (in color)
};

// inside the plot box at a corner (Best: the one with the fewest points to
// avoid under it), Above it in one row, or Right of it (top-aligned, outside)
enum class LegendPlace { Best, UpperRight, UpperLeft, LowerLeft, LowerRight, Above, Right };

// the legend's size (px)
Vec2 legend_size(const Page& page, const std::vector<LegendEntry>& entries, bool row);
// where a legend of `size` goes for ax; covered: how many avoid points (px) it hides
Box legend_box(const Page& page, const AxesFrame& ax, Vec2 size, LegendPlace place, const std::vector<Vec2>& avoid,
               std::size_t* covered = nullptr);
// draws a legend into box (a card; row: one line of entries without a card)
void draw_legend_in(Page& page, const Box& box, const std::vector<LegendEntry>& entries, bool row);
// draws the legend in the plot box of ax (Best: the corner with the fewest
// `avoid` points (px) under it), or Above the plot box in one row; returns its box
Box draw_legend(Page& page, const AxesFrame& ax, const std::vector<LegendEntry>& entries, LegendPlace place,
                const std::vector<Vec2>& avoid = {});

// a title centred over [left, right] with its top at y; returns its box
Box draw_title(Page& page, const std::string& title, double left, double right, double top);
// the height (px) a title takes with its gap below (0 for no title)
double title_space(const Page& page, const std::string& title);

}  // namespace paddock::render
