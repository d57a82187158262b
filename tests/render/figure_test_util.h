#pragma once
// what the figure tests share: the DejaVu font, a style of a given size, and
// the PNG round trip a user's file goes through (set PADDOCK_RENDER_OUT=DIR to
// keep the figures for a look)
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "render/figures.h"

namespace paddock::render::testing {

inline const std::vector<std::uint8_t>& font() {
  static const std::vector<std::uint8_t> bytes = [] {
    std::ifstream in("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  return bytes;
}

inline FigureStyle style(int w, int h) {
  FigureStyle s;
  s.width = w;
  s.height = h;
  s.font = &font();
  return s;
}

// the figure as a PNG file's bytes and back (what a user opens)
inline Image round_trip(const Figure& fig, const std::string& name) {
  const std::vector<std::uint8_t> png = encode_png(fig.image);
  if (const char* dir = std::getenv("PADDOCK_RENDER_OUT")) {
    std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary)
        .write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  }
  return decode_png(png);
}

}  // namespace paddock::render::testing
