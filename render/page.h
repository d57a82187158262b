#pragma once
// one figure being drawn: the style, the font, the GL canvas for the shapes, and
// the text queued to be composited on top once the shapes are done.
#include <map>
#include <string>
#include <vector>

#include "render/canvas.h"
#include "render/figures.h"
#include "render/text.h"

namespace paddock::render {

class Page {
 public:
  // throws RenderError for a missing or bad font, a bad size or dpi, or no OpenGL
  explicit Page(const FigureStyle& style);

  const FigureStyle& style() const { return style_; }
  int width() const { return style_.width; }
  int height() const { return style_.height; }
  Canvas& canvas() { return canvas_; }
  const Font& font() const { return font_; }
  // px of a length in points
  double px(double pt) const { return font_.px(pt); }
  // a length in points as whole pixels (at least 1): crisp lines
  int px_int(double pt) const;

  // queues text to be drawn over the shapes; returns the ink box it will cover
  Box text(const std::string& utf8, Vec2 at, const TextStyle& style);
  // the named parts of Figure::boxes
  std::map<std::string, Box>& boxes() { return boxes_; }

  // the shapes downsampled, the text on top
  Figure finish(std::vector<AxesFrame> axes);

 private:
  struct QueuedText {
    std::string text;
    Vec2 at;
    TextStyle style;
  };
  FigureStyle style_;
  Font font_;
  Canvas canvas_;
  std::vector<QueuedText> texts_;
  std::map<std::string, Box> boxes_;
};

// the supersampling factor used for a style: FigureStyle::supersample clamped
// to [1, 4] and lowered until the framebuffer fits 8192 px a side
int effective_supersample(const FigureStyle& style);

}  // namespace paddock::render
