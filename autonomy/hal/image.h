#pragma once
// camera images as a car's camera driver gives them and a log keeps them:
// YUYV (4:2:2, what a UVC camera streams uncompressed) to RGB, and JPEG (the
// MJPEG stream of a UVC camera; the compressed images of a log, Foxglove's
// foxglove.CompressedImage) both ways, with libjpeg-turbo.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "autonomy/hal/messages.h"

namespace paddock::hal {

// a YUYV image (Y0 U Y1 V per two pixels, `stride` bytes a row) as RGB, with
// BT.601's limited-range matrix (V4L2's default for YUYV: Y in [16, 235],
// Cb, Cr in [16, 240]); width must be even. Throws std::invalid_argument
// when the sizes do not fit `size` bytes
void yuyv_to_rgb(const std::uint8_t* yuyv, std::size_t size, int width, int height, std::size_t stride,
                 CameraFrame& out);

// the frame as a baseline JPEG (4:2:0, quality 1..100)
std::vector<std::uint8_t> encode_jpeg(const CameraFrame& frame, int quality);

// a JPEG image as an RGB frame stamped `stamp`; throws std::invalid_argument
// with libjpeg's reason for bytes that are no JPEG (or a cut one)
CameraFrame decode_jpeg(const std::uint8_t* data, std::size_t size, TimeNs stamp);

}  // namespace paddock::hal
