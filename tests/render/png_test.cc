// PNG through libpng in memory: exact round trips, clear errors.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "render/figures.h"

namespace paddock::render {
namespace {

Image noise(int w, int h, bool opaque, unsigned seed) {
  std::mt19937 rng(seed);
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
  for (std::size_t i = 0; i < img.rgba.size(); ++i) {
    img.rgba[i] = static_cast<std::uint8_t>(opaque && i % 4 == 3 ? 255 : rng() & 0xFF);
  }
  return img;
}

TEST(Png, RoundTripIsExact) {
  for (bool opaque : {false, true}) {
    const Image img = noise(123, 77, opaque, 7);
    const std::vector<std::uint8_t> png = encode_png(img);
    ASSERT_GT(png.size(), 8u);
    EXPECT_EQ(png[1], 'P');
    const Image back = decode_png(png);
    EXPECT_EQ(back.width, img.width);
    EXPECT_EQ(back.height, img.height);
    EXPECT_EQ(back.rgba, img.rgba);
    EXPECT_EQ(back.pixel(5, 6), img.pixel(5, 6));
  }
  // a single pixel
  Image one;
  one.width = one.height = 1;
  one.rgba = {1, 2, 3, 4};
  EXPECT_EQ(decode_png(encode_png(one)).rgba, one.rgba);
}

TEST(Png, OpaqueImagesAreStoredSmaller) {
  Image img = noise(64, 64, true, 3);
  const std::size_t rgb = encode_png(img).size();
  img.rgba[3] = 254;  // one translucent pixel: stored as RGBA
  EXPECT_LT(rgb, encode_png(img).size());
}

TEST(Png, GarbageIsAnError) {
  EXPECT_THROW(decode_png({}), RenderError);
  EXPECT_THROW(decode_png(std::vector<std::uint8_t>(100, 0x42)), RenderError);
  // a real PNG cut short, and one with a damaged data stream
  const std::vector<std::uint8_t> png = encode_png(noise(50, 40, false, 1));
  EXPECT_THROW(decode_png(std::vector<std::uint8_t>(png.begin(), png.begin() + static_cast<long>(png.size() / 2))),
               RenderError);
  std::vector<std::uint8_t> bad = png;
  for (std::size_t i = 60; i < bad.size() - 20; i += 7) bad[i] ^= 0x5A;
  EXPECT_THROW(decode_png(bad), RenderError);
  try {
    decode_png(std::vector<std::uint8_t>(100, 0x42));
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("PNG"), std::string::npos) << e.what();
  }
}

TEST(Png, BadImagesAreAnError) {
  Image img;
  EXPECT_THROW(encode_png(img), RenderError);
  img.width = 4;
  img.height = 4;
  img.rgba.resize(10);
  EXPECT_THROW(encode_png(img), RenderError);
}

TEST(Image, PixelOutsideIsTransparent) {
  Image img = noise(3, 2, true, 5);
  EXPECT_EQ(img.pixel(-1, 0), (Rgba{0, 0, 0, 0}));
  EXPECT_EQ(img.pixel(3, 0), (Rgba{0, 0, 0, 0}));
  EXPECT_EQ(img.pixel(0, 2), (Rgba{0, 0, 0, 0}));
  EXPECT_EQ(img.pixel(2, 1).a, 255);
}

}  // namespace
}  // namespace paddock::render
