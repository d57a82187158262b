// camera images: YUYV to RGB against BT.601's limited-range equations in
// floating point, JPEG both ways (a round trip within JPEG's loss), and bytes
// that are no image refused with libjpeg's reason
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "autonomy/hal/image.h"

namespace paddock::hal {
namespace {

TEST(Image, YuyvIsBt601LimitedRange) {
  std::mt19937 rng(5);
  const int w = 64, h = 8;
  const std::size_t stride = 2 * w + 16;  // rows padded, as drivers may
  std::vector<std::uint8_t> yuyv(stride * h);
  for (auto& b : yuyv) b = static_cast<std::uint8_t>(rng());
  CameraFrame f;
  yuyv_to_rgb(yuyv.data(), yuyv.size(), w, h, stride, f);
  ASSERT_EQ(f.width, w);
  ASSERT_EQ(f.rgb.size(), static_cast<std::size_t>(w * h * 3));
  int worst = 0;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const std::uint8_t* p = &yuyv[stride * j + 4 * (i / 2)];
      const double y = 255.0 / 219.0 * (p[2 * (i % 2)] - 16), cb = 255.0 / 224.0 * (p[1] - 128),
                   cr = 255.0 / 224.0 * (p[3] - 128);
      // R = Y + 1.402 Cr, G = Y - 0.344136 Cb - 0.714136 Cr, B = Y + 1.772 Cb (full-range Y, Cb, Cr)
      const double rgb[3] = {y + 1.402 * cr, y - 0.344136 * cb - 0.714136 * cr, y + 1.772 * cb};
      for (int c = 0; c < 3; ++c) {
        const int want = static_cast<int>(std::lround(std::clamp(rgb[c], 0.0, 255.0)));
        worst = std::max(worst, std::abs(want - f.rgb[(static_cast<std::size_t>(j) * w + i) * 3 + c]));
      }
    }
  }
  EXPECT_LE(worst, 1);
  // black and white at the range's ends
  const std::uint8_t ends[8] = {16, 128, 16, 128, 235, 128, 235, 128};
  yuyv_to_rgb(ends, sizeof ends, 4, 1, 8, f);
  EXPECT_EQ(f.rgb[0], 0);
  EXPECT_EQ(f.rgb[5], 0);
  EXPECT_EQ(f.rgb[6], 255);
  EXPECT_EQ(f.rgb[11], 255);
  EXPECT_THROW(yuyv_to_rgb(ends, sizeof ends, 4, 2, 8, f), std::invalid_argument);  // a row short
  EXPECT_THROW(yuyv_to_rgb(ends, sizeof ends, 3, 1, 8, f), std::invalid_argument);  // an odd width
}

// a picture with edges and gradients, like a camera's
CameraFrame scene(int w, int h) {
  CameraFrame f;
  f.width = w;
  f.height = h;
  f.rgb.resize(static_cast<std::size_t>(w * h * 3));
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      std::uint8_t* p = &f.rgb[(static_cast<std::size_t>(j) * w + i) * 3];
      const bool sky = j < h / 3;
      const bool cone = std::abs(i - w / 2) < (j - h / 3) / 3 && j > h / 3 && j < 2 * h / 3;
      p[0] = static_cast<std::uint8_t>(cone ? 250 : sky ? 120 : 60 + j * 100 / h);
      p[1] = static_cast<std::uint8_t>(cone ? 200 : sky ? 170 : 70 + i * 60 / w);
      p[2] = static_cast<std::uint8_t>(cone ? 20 : sky ? 235 : 60);
    }
  return f;
}

TEST(Image, JpegComesBackWithinItsLoss) {
  const CameraFrame f = scene(800, 500);
  const std::vector<std::uint8_t> jpeg = encode_jpeg(f, 90);
  EXPECT_LT(jpeg.size(), f.rgb.size() / 10);  // it compresses
  const CameraFrame g = decode_jpeg(jpeg.data(), jpeg.size(), 77);
  EXPECT_EQ(g.stamp, 77);
  ASSERT_EQ(g.width, 800);
  ASSERT_EQ(g.height, 500);
  double se = 0.0;
  for (std::size_t k = 0; k < f.rgb.size(); ++k) se += std::pow(double(f.rgb[k]) - g.rgb[k], 2);
  const double psnr = 10.0 * std::log10(255.0 * 255.0 / (se / static_cast<double>(f.rgb.size())));
  EXPECT_GT(psnr, 35.0);
  // a lower quality is smaller and still close
  EXPECT_LT(encode_jpeg(f, 40).size(), jpeg.size());
}

TEST(Image, BytesThatAreNoJpegAreRefused) {
  const std::vector<std::uint8_t> garbage = {1, 2, 3, 4, 5, 6, 7, 8};
  try {
    decode_jpeg(garbage.data(), garbage.size(), 0);
    ADD_FAILURE() << "garbage decoded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no JPEG image"), std::string::npos) << e.what();
  }
  const std::vector<std::uint8_t> jpeg = encode_jpeg(scene(64, 48), 80);
  EXPECT_THROW(decode_jpeg(jpeg.data(), jpeg.size() / 2, 0), std::invalid_argument);  // cut
  EXPECT_THROW(decode_jpeg(jpeg.data(), 0, 0), std::invalid_argument);
  CameraFrame bad;
  bad.width = 4;
  bad.height = 4;
  EXPECT_THROW(encode_jpeg(bad, 80), std::invalid_argument);
}

}  // namespace
}  // namespace paddock::hal
