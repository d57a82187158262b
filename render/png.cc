// PNG encoding and decoding with libpng through memory callbacks. libpng
// reports errors by longjmp: each entry point keeps everything it touches after
// setjmp in a context struct of its caller's frame (never in locals of the
// function that calls setjmp), and turns the jump into a RenderError.
#include <png.h>

#include <csetjmp>
#include <cstring>
#include <string>

#include "render/figures.h"

namespace paddock::render {

namespace {

struct PngIo {
  char message[256] = {0};                   // libpng's error text
  std::vector<std::uint8_t>* out = nullptr;  // encoding: appended to
  const std::vector<std::uint8_t>* in = nullptr;  // decoding: read from ...
  std::size_t pos = 0;                             // ... here
  std::vector<png_bytep> rows;
  Image* image = nullptr;
};

void on_error(png_structp png, png_const_charp msg) {
  auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
  std::strncpy(io->message, msg ? msg : "unknown libpng error", sizeof(io->message) - 1);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}

void on_write(png_structp png, png_bytep data, png_size_t n) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  io->out->insert(io->out->end(), data, data + n);
}

void on_flush(png_structp) {}

void on_read(png_structp png, png_bytep data, png_size_t n) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  if (io->in->size() - io->pos < n) png_error(png, "the PNG data ends early (truncated file)");
  std::memcpy(data, io->in->data() + io->pos, n);
  io->pos += n;
}

// returns false on a libpng error (the message in io)
bool encode_core(png_structp png, png_infop info, PngIo* io, bool opaque) {
  if (setjmp(png_jmpbuf(png))) return false;
  const Image& img = *io->image;
  png_set_write_fn(png, io, on_write, on_flush);
  // an opaque image is stored as RGB (smaller); decode_png adds the alpha back
  png_set_IHDR(png, info, static_cast<png_uint_32>(img.width), static_cast<png_uint_32>(img.height), 8,
               opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  if (opaque) png_set_filler(png, 0, PNG_FILLER_AFTER);  // rows in memory are RGBA: drop the A
  png_write_image(png, io->rows.data());
  png_write_end(png, nullptr);
  return true;
}

bool decode_core(png_structp png, png_infop info, PngIo* io) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, io, on_read);
  png_read_info(png, info);
  // any PNG to 8-bit RGBA: palette and low bit depths expanded, 16 bits stripped, grey to RGB, opaque alpha added
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xFF, PNG_FILLER_AFTER);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (png_get_rowbytes(png, info) != static_cast<png_size_t>(w) * 4) png_error(png, "unexpected row layout");
  io->image->width = static_cast<int>(w);
  io->image->height = static_cast<int>(h);
  io->image->rgba.assign(static_cast<std::size_t>(w) * h * 4, 0);
  io->rows.resize(h);
  for (png_uint_32 y = 0; y < h; ++y) io->rows[y] = io->image->rgba.data() + static_cast<std::size_t>(y) * w * 4;
  png_read_image(png, io->rows.data());
  png_read_end(png, nullptr);
  return true;
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4) {
    throw RenderError("encode_png: the image is " + std::to_string(image.width) + " x " +
                      std::to_string(image.height) + " px with " + std::to_string(image.rgba.size()) +
                      " bytes; expected a non-empty image of width * height * 4 bytes");
  }
  bool opaque = true;
  for (std::size_t i = 3; i < image.rgba.size() && opaque; i += 4) opaque = image.rgba[i] == 255;
  std::vector<std::uint8_t> out;
  PngIo io;
  io.out = &out;
  io.image = const_cast<Image*>(&image);
  io.rows.resize(static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y) {
    io.rows[static_cast<std::size_t>(y)] =
        const_cast<png_bytep>(image.rgba.data()) + static_cast<std::size_t>(y) * image.width * 4;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &io, on_error, on_warning);
  if (png == nullptr) throw RenderError("encode_png: libpng could not start (png_create_write_struct)");
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    throw RenderError("encode_png: libpng could not start (png_create_info_struct)");
  }
  const bool ok = encode_core(png, info, &io, opaque);
  png_destroy_write_struct(&png, &info);
  if (!ok) throw RenderError(std::string("encode_png: libpng: ") + io.message);
  return out;
}

Image decode_png(const std::vector<std::uint8_t>& data) {
  if (data.size() < 8 || png_sig_cmp(data.data(), 0, 8) != 0) {
    throw RenderError("decode_png: not a PNG file (" + std::to_string(data.size()) +
                      " bytes without the PNG signature)");
  }
  Image image;
  PngIo io;
  io.in = &data;
  io.image = &image;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &io, on_error, on_warning);
  if (png == nullptr) throw RenderError("decode_png: libpng could not start (png_create_read_struct)");
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    throw RenderError("decode_png: libpng could not start (png_create_info_struct)");
  }
  const bool ok = decode_core(png, info, &io);
  png_destroy_read_struct(&png, &info, nullptr);
  if (!ok) throw RenderError(std::string("decode_png: libpng: ") + io.message);
  return image;
}

}  // namespace paddock::render
