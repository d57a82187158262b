#pragma once
// the figures of a finished run, drawn from its files: DIR/scenario.ini (which
// names the track), DIR/log.csv and DIR/summary.json. `paddock run --plots`
// and `paddock plot DIR` both come here, so a redraw is the same picture.
#include <cstdint>
#include <string>
#include <vector>

#include "render/figures.h"
#include "sim/runner/simulation.h"

namespace paddock::runner {

struct PlotOptions {
  int map_size = 1600;       // px, the square track map
  int chart_width = 1600;    // px, the controller data and lap charts
  int chart_height = 1200;   // px
  double dpi = 150.0;        // px per inch: text and line sizes are in points
  // a TrueType font from Debian's fonts-dejavu-core
  std::string font_path = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
};

// draws DIR/map.png, DIR/controller.png and DIR/laps.png (each written
// atomically), the perception views when the run kept a snapshot, and
// DIR/slam_map.png and DIR/slam_error.png when it wrote slam.csv, and returns
// their paths; throws UserError naming the file and
// line of anything it cannot read
std::vector<std::string> plot_run(const std::string& dir, const PlotOptions& options);

// the options' font, read once: the styles below point into it
std::vector<std::uint8_t> read_font(const PlotOptions& options);
// the square map's and the charts' styles at the options' sizes and dpi
render::FigureStyle map_style(const PlotOptions& options, const std::vector<std::uint8_t>& font);
render::FigureStyle chart_style(const PlotOptions& options, const std::vector<std::uint8_t>& font);

// the image as a PNG file at path, written atomically
void write_png(const std::string& path, const render::Image& image);

// log.csv as written by log_csv(); throws UserError "source:line: ..."
std::vector<LogRow> parse_log_csv(const std::string& text, const std::string& source);
// slam.csv as written by slam_csv() (no heading error); throws UserError "source:line: ..."
std::vector<SlamSample> parse_slam_csv(const std::string& text, const std::string& source);

}  // namespace paddock::runner
