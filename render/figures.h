#pragma once
// the figures a team puts on the wall, each one function from data to an
// image: the track map, the controller data, the lap chart, a sweep heat map.
// No file I/O here: the caller reads the font and writes the PNG.
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"

namespace paddock::render {

class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Rgba {
  std::uint8_t r = 0, g = 0, b = 0, a = 255;
  bool operator==(const Rgba& o) const { return r == o.r && g == o.g && b == o.b && a == o.a; }
};

// 8-bit RGBA pixels, row-major, the top row first
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
  Rgba pixel(int x, int y) const;
};

// a pixel rectangle of an image: x from left to right, y from top to bottom (px)
struct Box {
  int left = 0, top = 0, right = 0, bottom = 0;  // right and bottom exclusive
  bool contains(int x, int y) const { return x >= left && x < right && y >= top && y < bottom; }
};

// where one axes sits in the image and how data maps to its pixels
struct AxesFrame {
  Box plot;                    // the plotting area inside the axes lines
  double x_min = 0.0, x_max = 1.0, y_min = 0.0, y_max = 1.0;  // data range shown
  // the pixel centre (x right, y down) of a data point
  // (continuous pixel coordinates: pixel (i, j) covers [i, i + 1) x [j, j + 1),
  // so the pixel under a point is (floor(x), floor(y)); the plot box's edges are
  // the range's ends)
  Vec2 to_pixel(Vec2 data) const;
};

// what a figure function returns: the picture, and where its parts are (for
// tests and for anyone who wants to annotate it)
struct Figure {
  Image image;
  std::vector<AxesFrame> axes;       // in drawing order (the map: one; controller data: one per panel)
                                     // data units: the map in m; the controller panels t [s] and deg,
                                     // m/s, m, deg; the lap chart lap number (lap k's bar centred on
                                     // x = k) and s; the heat map cell indices (cell (i, j) centred on (i, j))
  std::map<std::string, Box> boxes;  // named parts: "title", "colorbar" (the colour strip itself),
                                     // "colorbar_label", "legend", "x_label", "y_label"
                                     // (the controller figure: "y_label_0", "y_label_1", ...,
                                     // "legend_0" and "legend_1" for its two-series panels)
};

// size and resolution; the font is the bytes of a TrueType file read by the caller
struct FigureStyle {
  int width = 1600;         // px
  int height = 1600;        // px
  double dpi = 150.0;       // px per inch: text and line sizes are given in points (1/72 in)
  const std::vector<std::uint8_t>* font = nullptr;  // required; not owned
  Rgba background{255, 255, 255, 255};
  int supersample = 3;      // anti-aliasing: drawn at this many times the size and box-filtered down (1..4)
};

// ---- the track map (the paper's "planned path" figure) ----

enum class Marker { Circle, Triangle, Cross, Square };

// an optional layer of the map, drawn in order after the boundaries and before
// the cones: later issues add the Delaunay triangulation (segments), the
// midpoints (points) and the chosen centreline points (markers)
struct MapLayer {
  enum class Kind { Points, Polyline, Segments };
  Kind kind = Kind::Points;
  std::string label;           // in the legend; empty: not listed
  Rgba color{128, 128, 128, 255};
  double size = 1.0;           // line width or marker size (pt)
  Marker marker = Marker::Circle;
  std::vector<Vec2> points;    // Segments: consecutive pairs
  bool closed = false;         // Polyline: back to the first point
};

struct TrackMapData {
  std::string title;
  std::vector<Cone> cones;                   // coloured by type (unknown: grey)
  std::vector<Vec2> left, right;             // boundaries
  bool closed = false;
  std::vector<Segment> gates;                // timekeeping lines
  std::optional<Pose2> start;                // start pose (an arrow)
  std::vector<Vec2> trajectory;              // the driven path ...
  std::vector<double> speed;                 // ... coloured by speed (m/s), same size; a colour bar
                                             // over [min, max] ([v - 0.5, v + 0.5] for one speed v);
                                             // empty: one colour, no colour bar; NaN: a gap
  std::vector<MapLayer> layers;              // optional layers
  std::vector<Cone> estimated_cones;         // optional: a cone map estimated by SLAM (hollow markers)
};

// equal-aspect axes in metres around everything given; throws RenderError for a
// bad style (no font, bad size) or speeds not matching the trajectory
Figure draw_track_map(const TrackMapData& data, const FigureStyle& style);
// the map's fill colour of a cone type (blue, yellow, small orange, big orange, unknown: grey)
Rgba cone_color(ConeColor color);

// ---- the controller data (the paper's "controller data" figure) ----

struct ControllerData {
  std::string title;
  std::vector<double> t;              // s
  std::vector<double> steer_cmd;      // rad (drawn in degrees)
  std::vector<double> steer;          // rad
  std::vector<double> v_ref;          // m/s
  std::vector<double> v;              // m/s
  std::vector<double> lateral_error;  // m
  std::vector<double> heading_error;  // rad (drawn in degrees)
  std::vector<double> lap_starts;     // s: vertical markers at the lap boundaries
};

// four stacked panels sharing the time axis: steering commanded vs actual,
// speed reference vs actual, lateral error, heading error. A series is left out
// when empty; one of another size than t is a RenderError; NaN: a gap
Figure draw_controller_data(const ControllerData& data, const FigureStyle& style);

// ---- the lap chart ----

struct LapChartData {
  std::string title;
  std::vector<double> lap_times;   // s, lap 1 first
  std::vector<bool> timed;         // counts for the score (same size)
  std::vector<int> doo;            // cones down or out in each lap
  std::vector<int> oc;             // off-course excursions in each lap
  double doo_penalty = 2.0;        // s each
  double oc_penalty = 10.0;        // s each
};

// a bar per lap (raw time) with its penalty seconds stacked on top and marked
Figure draw_lap_chart(const LapChartData& data, const FigureStyle& style);

// ---- the sweep heat map ----

struct HeatmapData {
  std::string title, x_label, y_label, value_label;
  std::vector<double> x;       // column parameter values (ascending)
  std::vector<double> y;       // row parameter values (ascending)
  std::vector<double> values;  // y.size() * x.size(), row by row (y[0] first); NaN: no value (drawn hatched grey)
};

// one cell per (x, y) coloured by viridis over the finite values' range (one
// value v: [v - 0.5, v + 0.5]); values.size() != x.size() * y.size() is a RenderError
Figure draw_heatmap(const HeatmapData& data, const FigureStyle& style);

// ---- colour maps and PNG ----

// viridis at t in [0, 1] (clamped): a perceptually uniform map, dark blue to yellow
Rgba viridis(double t);

// the image as a PNG file's bytes (libpng); throws RenderError
std::vector<std::uint8_t> encode_png(const Image& image);
// a PNG file's bytes as an image (libpng); throws RenderError
Image decode_png(const std::vector<std::uint8_t>& png);

}  // namespace paddock::render
