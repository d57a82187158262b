#include "render/page.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "render/gl_context.h"

namespace paddock::render {

namespace {

const FigureStyle& checked(const FigureStyle& s) {
  if (s.width < 1 || s.height < 1 || s.width > GlContext::max_size() || s.height > GlContext::max_size()) {
    throw RenderError("bad figure size " + std::to_string(s.width) + " x " + std::to_string(s.height) +
                      " px: each side must be in [1, " + std::to_string(GlContext::max_size()) + "]");
  }
  return s;
}

}  // namespace

int effective_supersample(const FigureStyle& style) {
  int ss = std::clamp(style.supersample, 1, 4);
  while (ss > 1 && (style.width * ss > 8192 || style.height * ss > 8192)) --ss;
  return ss;
}

Page::Page(const FigureStyle& style)
    : style_(checked(style)),
      font_(style.font, style.dpi),
      canvas_(style.width, style.height, effective_supersample(style), style.background) {}

int Page::px_int(double pt) const { return std::max(1, static_cast<int>(std::lround(px(pt)))); }

Box Page::text(const std::string& utf8, Vec2 at, const TextStyle& style) {
  texts_.push_back({utf8, at, style});
  return font_.bounds(utf8, at, style);
}

Figure Page::finish(std::vector<AxesFrame> axes) {
  Figure fig;
  fig.image = canvas_.finish();
  for (const QueuedText& t : texts_) font_.draw(fig.image, t.text, t.at, t.style);
  fig.axes = std::move(axes);
  fig.boxes = boxes_;
  return fig;
}

}  // namespace paddock::render
