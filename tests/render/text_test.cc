// text with FreeType: errors for missing fonts, measuring, anchors, rotation,
// kerning, UTF-8, and ink only inside the box it reports.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "render/text.h"

namespace paddock::render {
namespace {

const std::vector<std::uint8_t>& font_bytes() {
  static const std::vector<std::uint8_t> bytes = [] {
    std::ifstream in("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  return bytes;
}

Image blank(int w, int h) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(static_cast<std::size_t>(w) * h * 4, 255);
  return img;
}

// the box of the non-white pixels
Box ink(const Image& img) {
  Box b{img.width, img.height, 0, 0};
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      if (img.pixel(x, y) == Rgba{255, 255, 255, 255}) continue;
      b.left = std::min(b.left, x), b.top = std::min(b.top, y);
      b.right = std::max(b.right, x + 1), b.bottom = std::max(b.bottom, y + 1);
    }
  }
  return b;
}

TEST(Font, MissingEmptyOrJunkFontsAreClearErrors) {
  try {
    Font f(nullptr, 150.0);
    FAIL();
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("font"), std::string::npos);
  }
  const std::vector<std::uint8_t> empty, junk(500, 7);
  try {
    Font f(&empty, 150.0);
    FAIL();
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos);
  }
  try {
    Font f(&junk, 150.0);
    FAIL();
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("not a TrueType"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Font(&font_bytes(), 0.0), RenderError);
}

TEST(Font, SizesInPointsAtTheDpi) {
  ASSERT_FALSE(font_bytes().empty()) << "fonts-dejavu-core is not installed";
  const Font f72(&font_bytes(), 72.0), f144(&font_bytes(), 144.0);
  EXPECT_DOUBLE_EQ(f144.px(10.0), 20.0);
  const LineMetrics m = f144.metrics(10.0);
  EXPECT_GT(m.ascent, m.cap_height);
  EXPECT_GT(m.cap_height, 10.0);  // DejaVu's H is 0.73 em: 14.6 px at 20 px per em
  EXPECT_LT(m.cap_height, 18.0);
  EXPECT_GT(m.descent, 0.0);
  EXPECT_EQ(f144.width("", 10.0), 0);
  EXPECT_GT(f144.width("ab", 10.0), f144.width("a", 10.0));
  EXPECT_NEAR(f144.width("speed [m/s]", 10.0), 2.0 * f72.width("speed [m/s]", 10.0), 3.0);
}

TEST(Font, KerningWhenTheFaceHasIt) {
  const Font f(&font_bytes(), 150.0);
  if (!f.has_kerning()) GTEST_SKIP() << "this DejaVu build has no kerning table";
  EXPECT_LT(f.width("AV", 20.0), f.width("A", 20.0) + f.width("V", 20.0));
}

TEST(Font, InkStaysInTheReportedBox) {
  const Font f(&font_bytes(), 150.0);
  for (bool vertical : {false, true}) {
    for (HAlign h : {HAlign::Left, HAlign::Center, HAlign::Right}) {
      for (VAlign v : {VAlign::Top, VAlign::Middle, VAlign::Baseline, VAlign::Bottom}) {
        Image img = blank(800, 800);
        TextStyle s;
        s.size = 12.0;
        s.h = h, s.v = v, s.vertical = vertical;
        const std::string text = "Lap time (g) 1.25 s";
        const Box box = f.draw(img, text, {400.0, 400.0}, s);
        EXPECT_EQ(box.left, f.bounds(text, {400.0, 400.0}, s).left);
        const Box got = ink(img);
        EXPECT_GE(got.left, box.left);
        EXPECT_GE(got.top, box.top);
        EXPECT_LE(got.right, box.right);
        EXPECT_LE(got.bottom, box.bottom);
        EXPECT_LE(box.right - got.right + got.left - box.left, 2);  // and the box is tight
        if (vertical) {
          EXPECT_GT(box.bottom - box.top, 3 * (box.right - box.left));
        } else {
          EXPECT_GT(box.right - box.left, 3 * (box.bottom - box.top));
        }
      }
    }
  }
}

TEST(Font, AnchorsPlaceTheText) {
  const Font f(&font_bytes(), 150.0);
  TextStyle s;
  s.size = 20.0;
  const Vec2 at{300.0, 200.0};
  // "H" sits on the baseline and is cap_height tall; middle centres the caps
  s.v = VAlign::Baseline;
  Box b = f.bounds("H", at, s);
  EXPECT_NEAR(b.bottom, 200, 1);
  EXPECT_NEAR(b.bottom - b.top, f.metrics(20.0).cap_height, 1.5);
  s.v = VAlign::Middle;
  b = f.bounds("H", at, s);
  EXPECT_NEAR(0.5 * (b.top + b.bottom), 200.0, 1.0);
  s.v = VAlign::Top;
  EXPECT_GE(f.bounds("Hg", at, s).top, 200);
  s.v = VAlign::Bottom;
  EXPECT_LE(f.bounds("Hg", at, s).bottom, 201);
  // left starts at the point, right ends there, centre straddles it
  s.v = VAlign::Baseline;
  s.h = HAlign::Left;
  EXPECT_NEAR(f.bounds("HHH", at, s).left, 300, 5);  // H's side bearing: 0.1 em
  s.h = HAlign::Right;
  EXPECT_NEAR(f.bounds("HHH", at, s).right, 300, 5);
  s.h = HAlign::Center;
  b = f.bounds("HHH", at, s);
  EXPECT_NEAR(0.5 * (b.left + b.right), 300.0, 1.5);
}

TEST(Font, RotatedTextReadsUpwards) {
  const Font f(&font_bytes(), 150.0);
  Image img = blank(200, 200);
  TextStyle s;
  s.size = 40.0;
  s.vertical = true;
  s.h = HAlign::Center, s.v = VAlign::Middle;
  // an "L" turned a quarter counter-clockwise: its stem lies along the bottom,
  // its foot stands up on the right, the top left is empty
  const Box b = f.draw(img, "L", {100.0, 100.0}, s);
  const auto dark = [&](int x, int y) { return img.pixel(x, y).r < 100; };
  const int w = b.right - b.left, h = b.bottom - b.top;
  ASSERT_GT(w, 20);
  ASSERT_GT(h, 20);
  for (int x = b.left + 1; x < b.right - 1; ++x) EXPECT_TRUE(dark(x, b.bottom - 2)) << x;
  for (int y = b.top + 1; y < b.bottom - 1; ++y) EXPECT_TRUE(dark(b.right - 2, y)) << y;
  EXPECT_FALSE(dark(b.left + w / 4, b.top + h / 4));
}

TEST(Font, Utf8AndSameBytesEveryTime) {
  EXPECT_EQ(decode_utf8("a\xC2\xB0\xE2\x88\x92"), (std::vector<char32_t>{U'a', 0xB0, 0x2212}));
  EXPECT_EQ(decode_utf8("\xFF" "b"), (std::vector<char32_t>{0xFFFD, U'b'}));
  EXPECT_EQ(decode_utf8("\xE2\x88"), (std::vector<char32_t>{0xFFFD, 0xFFFD}));
  const Font f(&font_bytes(), 150.0);
  Image a = blank(300, 100), b = blank(300, 100);
  TextStyle s;
  s.size = 11.0;
  f.draw(a, "heading error [\xC2\xB0] \xE2\x88\x92" "3", {10.0, 60.0}, s);
  f.draw(b, "heading error [\xC2\xB0] \xE2\x88\x92" "3", {10.0, 60.0}, s);
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_NE(a.rgba, blank(300, 100).rgba);
}

}  // namespace
}  // namespace paddock::render
