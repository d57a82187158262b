#pragma once
// one OSMesa context (software OpenGL, no display, no GPU) and the RGBA
// framebuffer it draws into.
#include <cstdint>
#include <memory>
#include <vector>

struct osmesa_context;  // OSMesaContext of <GL/osmesa.h>, kept out of this header

namespace paddock::render {

// a width x height px framebuffer with an 8-bit stencil (no depth buffer), made
// current on the calling thread by the constructor. One context per thread at
// a time: OpenGL binds the current context to a thread.
//
// Determinism: OSMesa runs on llvmpipe, which bins the triangles into tiles and
// may raster the tiles on several threads; every tile replays the same command
// list in order with fixed-point edge functions, so the pixels do not depend on
// the thread count or the scheduling (the render tests pin this).
class GlContext {
 public:
  // throws RenderError when OSMesa cannot make the context or the size is
  // beyond the implementation's limit (max_size())
  GlContext(int width, int height);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  // binds this context to the calling thread (the constructor already did)
  void make_current();
  // finishes the drawing and returns OSMesa's colour buffer: RGBA bytes,
  // width * 4 per row, the BOTTOM row first (OpenGL's order); valid until the
  // next drawing call or the context's end
  const std::uint8_t* finish();
  // the framebuffer as RGBA bytes, the top row first (a copy)
  std::vector<std::uint8_t> read_rgba();

  // the largest width or height a framebuffer may have (px)
  static constexpr int max_size() { return 16384; }

 private:
  osmesa_context* ctx_ = nullptr;
  std::unique_ptr<std::uint8_t[]> buffer_;  // OSMesa's colour buffer, the bottom row first
  int width_ = 0;
  int height_ = 0;
};

}  // namespace paddock::render
