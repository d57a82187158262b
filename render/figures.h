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
  std::string trajectory_label = "trajectory";  // its legend entry
  std::string speed_label = "speed [m/s]";      // the colour bar's label
  std::vector<MapLayer> layers;              // optional layers
  std::vector<Cone> estimated_cones;         // optional: a cone map estimated by SLAM (hollow markers)
};

// equal-aspect axes in metres around everything given; throws RenderError for a
// bad style (no font, bad size) or speeds not matching the trajectory
Figure draw_track_map(const TrackMapData& data, const FigureStyle& style);
// the map's fill colour of a cone type (blue, yellow, small orange, big orange, unknown: grey)
Rgba cone_color(ConeColor color);
// the legend's name of a cone type ("blue cone", ..., "unknown cone")
const char* cone_label(ConeColor color);
// the base radius of a cone (m): FS rules, small cones 228 mm across, big ones 285 mm
double cone_radius(ConeColor color);

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

// ---- the line chart (the vehicle report's g-g-v envelope) ----

struct LineSeries {
  std::string label;            // in the legend; empty: not listed
  std::vector<double> x, y;     // one y per x; a non-finite point breaks the line and has no marker
  Rgba color{31, 119, 180, 255};
  Marker marker = Marker::Circle;  // drawn at every point
};

struct LineChartData {
  std::string title, x_label, y_label;
  std::vector<LineSeries> series;
  bool include_zero = true;     // the y range reaches down (or up) to 0
};

// each series as a line with a marker at each point over a grid with nice
// ticks (the data's range, padded), the legend in the plot's emptiest corner;
// x.size() != y.size() in a series is a RenderError. Boxes: "title",
// "legend", "x_label", "y_label"
Figure draw_line_chart(const LineChartData& data, const FigureStyle& style);

// ---- colour maps and PNG ----

// viridis at t in [0, 1] (clamped): a perceptually uniform map, dark blue to yellow
Rgba viridis(double t);

// the image as a PNG file's bytes (libpng); throws RenderError
std::vector<std::uint8_t> encode_png(const Image& image);
// a PNG file's bytes as an image (libpng); throws RenderError
Image decode_png(const std::vector<std::uint8_t>& png);

// ---- the perception figures (the paper's LiDAR segmentation and fusion figures) ----
// (render/perception_figures.cc)

// one LiDAR return in the vehicle base frame (m: x forward, y left); label:
// 0 ground, 1 non-ground, 2 cone point (any other label is drawn as non-ground)
struct LidarViewPoint { float x, y; std::uint8_t label; };

struct LidarViewData {
  std::string title;
  std::vector<LidarViewPoint> points;   // one scan, motion-corrected, base frame (x forward, y left)
  std::vector<Cone> detected;           // the cones perception output (base frame), drawn as green circles with
                                        // a thin ring of their colour (unknown: grey)
  std::vector<Cone> truth;              // optional: the true cones (base frame) as small hollow black squares
  double range = 25.0;                  // m (finite, > 0): the window, see draw_lidar_view
};

// a top-down view of one scan in the base frame, forward UP the page and left
// to the LEFT: the horizontal axis is y (increasing to the left), the vertical
// axis x. The window is at least x in [-range/3, range] and y in
// [-range/2, range/2]; equal aspect, the range that is short for the plot box's
// shape grows about its centre (a square figure shows y in about +-2/3 range).
// Points are 1-2 px squares (ground blue, non-ground red, cone points green,
// drawn in that order, outside the window left out), the detected cones green
// discs ringed in their colour, the true cones hollow black squares, the car a
// dark triangle at the origin pointing +x. The legend stands in a row above the
// plot (right of it when the row is too wide).
// axes[0] maps (y, x): the pixel of base-frame point p is to_pixel({p.y, p.x})
// (x_min > x_max there: x_min is the left edge, the largest y).
// Boxes: "title", "legend", "x_label", "y_label". RenderError: a bad style, a
// bad range.
Figure draw_lidar_view(const LidarViewData& data, const FigureStyle& style);

// a detector box in camera image pixels (x right, y down, origin at the image's top-left corner)
struct CameraBox { double x_min, y_min, x_max, y_max; ConeColor color; };

struct CameraViewData {
  std::string title;
  int width = 0, height = 0;              // the camera image's size (px), both > 0
  std::vector<std::uint8_t> rgb;          // row-major, 3 bytes a pixel, row 0 at the top; empty: no image
                                          // (a light grey field of width x height)
  std::vector<CameraBox> boxes;           // the detector's boxes, outlined in their class colour (unknown: grey)
  std::vector<Vec2> projected;            // LiDAR cluster centres projected to pixels: green crosses
  std::vector<Vec2> dropped;              // projected centres fusion dropped: red crosses (optional)
};

// the camera image filling the axes (nearest-neighbour, one scale for x and y,
// the plot box having the image's aspect), the boxes outlined 2 pt wide, the
// crosses, a legend in a row above, a title. Axes in image pixels: axes[0] has
// x_min = 0, x_max = width, y_min = height, y_max = 0 (flipped), so
// to_pixel({u, v}) of continuous image coordinates (u right, v down; image
// pixel (i, j) covers [i, i + 1) x [j, j + 1)) is the figure pixel: image
// pixel (i, j) is drawn under to_pixel({i + 0.5, j + 0.5}).
// Boxes: "title", "legend", "x_label", "y_label". RenderError: a bad style,
// width or height <= 0, rgb.size() != width * height * 3 (when not empty).
Figure draw_camera_view(const CameraViewData& data, const FigureStyle& style);

}  // namespace paddock::render
