#include "autonomy/hal/image.h"

#include <csetjmp>
#include <cstdlib>
#include <memory>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <jpeglib.h>

namespace paddock::hal {
namespace {

std::uint8_t clamp_byte(int v) { return static_cast<std::uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v); }

// libjpeg reports a fatal error through error_exit, which must not return:
// it jumps back to the call (no C++ exception crosses the C library)
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void on_error(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegError*>(c->err);
  (*c->err->format_message)(c, e->message);
  std::longjmp(e->jump, 1);
}

}  // namespace

void yuyv_to_rgb(const std::uint8_t* yuyv, std::size_t size, int width, int height, std::size_t stride,
                 CameraFrame& out) {
  if (width <= 0 || height <= 0 || width % 2 != 0 || stride < 2 * static_cast<std::size_t>(width) ||
      size < stride * static_cast<std::size_t>(height - 1) + 2 * static_cast<std::size_t>(width))
    throw std::invalid_argument("YUYV: " + std::to_string(size) + " bytes are no " + std::to_string(width) + "x" +
                                std::to_string(height) + " image with rows of " + std::to_string(stride) + " bytes");
  out.width = width;
  out.height = height;
  out.rgb.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  std::uint8_t* o = out.rgb.data();
  for (int j = 0; j < height; ++j) {
    const std::uint8_t* row = yuyv + stride * static_cast<std::size_t>(j);
    for (int i = 0; i < width; i += 2, row += 4) {
      // BT.601 limited range, in 8.8 fixed point: R = 1.164 (Y-16) + 1.596 (Cr-128) ...
      const int d = row[1] - 128, e = row[3] - 128;
      const int r = 409 * e + 128, g = -100 * d - 208 * e + 128, b = 516 * d + 128;
      for (int k = 0; k < 2; ++k) {
        const int c = 298 * (row[2 * k] - 16);
        *o++ = clamp_byte((c + r) >> 8);
        *o++ = clamp_byte((c + g) >> 8);
        *o++ = clamp_byte((c + b) >> 8);
      }
    }
  }
}

std::vector<std::uint8_t> encode_jpeg(const CameraFrame& frame, int quality) {
  if (frame.width <= 0 || frame.height <= 0 ||
      frame.rgb.size() != static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) * 3)
    throw std::invalid_argument("encode_jpeg: the frame's pixels do not fit its size");
  jpeg_compress_struct c{};
  JpegError err{};
  c.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = on_error;
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&c);
    std::free(buffer);
    throw std::runtime_error(std::string("encode_jpeg: ") + err.message);
  }
  jpeg_create_compress(&c);
  jpeg_mem_dest(&c, &buffer, &size);
  c.image_width = static_cast<JDIMENSION>(frame.width);
  c.image_height = static_cast<JDIMENSION>(frame.height);
  c.input_components = 3;
  c.in_color_space = JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, quality < 1 ? 1 : quality > 100 ? 100 : quality, TRUE);
  c.dct_method = JDCT_IFAST;  // libjpeg-turbo's SIMD DCT: the log's cost, at no visible loss
  jpeg_start_compress(&c, TRUE);
  const auto row_bytes = static_cast<std::size_t>(frame.width) * 3;
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(frame.rgb.data() + row_bytes * c.next_scanline);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  std::vector<std::uint8_t> out(buffer, buffer + size);
  jpeg_destroy_compress(&c);
  std::free(buffer);
  return out;
}

CameraFrame decode_jpeg(const std::uint8_t* data, std::size_t size, TimeNs stamp) {
  jpeg_decompress_struct d{};
  JpegError err{};
  d.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = on_error;
  // a warning (a cut file: "Premature end of JPEG file") is an error here
  err.mgr.emit_message = [](j_common_ptr c, int level) {
    if (level < 0) on_error(c);
  };
  // what the decoder fills lives on the heap: after a longjmp, automatic
  // objects changed since the setjmp are indeterminate; the pointer is not
  const auto out = std::make_unique<CameraFrame>();
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&d);
    throw std::invalid_argument(std::string("no JPEG image: ") + err.message);
  }
  jpeg_create_decompress(&d);
  jpeg_mem_src(&d, data, static_cast<unsigned long>(size));
  jpeg_read_header(&d, TRUE);
  d.out_color_space = JCS_RGB;
  jpeg_start_decompress(&d);
  out->stamp = stamp;
  out->width = static_cast<int>(d.output_width);
  out->height = static_cast<int>(d.output_height);
  out->rgb.resize(static_cast<std::size_t>(out->width) * static_cast<std::size_t>(out->height) * 3);
  const auto row_bytes = static_cast<std::size_t>(out->width) * 3;
  while (d.output_scanline < d.output_height) {
    JSAMPROW row = out->rgb.data() + row_bytes * d.output_scanline;
    jpeg_read_scanlines(&d, &row, 1);
  }
  jpeg_finish_decompress(&d);
  jpeg_destroy_decompress(&d);
  return std::move(*out);
}

}  // namespace paddock::hal
