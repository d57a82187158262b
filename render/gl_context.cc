#include "render/gl_context.h"

#include <GL/gl.h>
#include <GL/osmesa.h>

#include <cstring>
#include <string>

#include "render/figures.h"

namespace paddock::render {

GlContext::GlContext(int width, int height) : width_(width), height_(height) {
  if (width < 1 || height < 1 || width > max_size() || height > max_size()) {
    throw RenderError("cannot render a " + std::to_string(width) + " x " + std::to_string(height) +
                      " px framebuffer: each side must be in [1, " + std::to_string(max_size()) + "]");
  }
  // RGBA colour, no depth, 8 stencil bits (even-odd polygon fill), no accumulation buffer
  ctx_ = OSMesaCreateContextExt(OSMESA_RGBA, 0, 8, 0, nullptr);
  if (ctx_ == nullptr) throw RenderError("OSMesaCreateContextExt failed: no software OpenGL context");
  // no need to zero it: the canvas clears the framebuffer first
  buffer_.reset(new std::uint8_t[static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4]);
  try {
    make_current();
  } catch (...) {
    OSMesaDestroyContext(ctx_);
    throw;
  }
  // rows of the colour buffer bottom-up as in OpenGL (the default; read_rgba flips)
  OSMesaPixelStore(OSMESA_Y_UP, 1);
  GLint dims[2] = {0, 0};
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
  if (dims[0] < width || dims[1] < height) {
    OSMesaDestroyContext(ctx_);
    throw RenderError("cannot render a " + std::to_string(width) + " x " + std::to_string(height) +
                      " px framebuffer: OpenGL's viewport limit is " + std::to_string(dims[0]) + " x " +
                      std::to_string(dims[1]));
  }
}

GlContext::~GlContext() {
  // unbind first when current, then free (the buffer is ours and outlives the context)
  if (OSMesaGetCurrentContext() == ctx_) OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
  OSMesaDestroyContext(ctx_);
}

void GlContext::make_current() {
  if (!OSMesaMakeCurrent(ctx_, buffer_.get(), GL_UNSIGNED_BYTE, width_, height_)) {
    throw RenderError("OSMesaMakeCurrent failed for a " + std::to_string(width_) + " x " +
                      std::to_string(height_) + " px framebuffer");
  }
}

const std::uint8_t* GlContext::finish() {
  // OSMesa (gallium) renders into its own surface and copies it to our buffer
  // when the context flushes: glFinish makes the buffer whole
  glFinish();
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) throw RenderError("OpenGL error " + std::to_string(err) + " while drawing");
  return buffer_.get();
}

std::vector<std::uint8_t> GlContext::read_rgba() {
  const std::uint8_t* buf = finish();
  const std::size_t row = static_cast<std::size_t>(width_) * 4;
  std::vector<std::uint8_t> out(row * static_cast<std::size_t>(height_));
  for (int y = 0; y < height_; ++y) {
    std::memcpy(out.data() + static_cast<std::size_t>(y) * row,
                buf + static_cast<std::size_t>(height_ - 1 - y) * row, row);
  }
  return out;
}

}  // namespace paddock::render
