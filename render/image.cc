#include <cstddef>

#include "render/figures.h"

namespace paddock::render {

Rgba Image::pixel(int x, int y) const {
  // outside the image: transparent black
  if (x < 0 || y < 0 || x >= width || y >= height) return {0, 0, 0, 0};
  const std::size_t i =
      (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4;
  return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
}

}  // namespace paddock::render
