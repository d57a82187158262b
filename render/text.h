#pragma once
// real text from a TrueType font with FreeType: sizes in points at a dpi,
// kerning, horizontal or rotated by 90 degrees, anchored, measured, and
// composited onto an image with alpha blending.
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/geometry.h"
#include "render/figures.h"

struct FT_LibraryRec_;  // FreeType's handles, kept out of this header
struct FT_FaceRec_;

namespace paddock::render {

enum class HAlign { Left, Center, Right };        // along the text: its start, middle, end (advance)
enum class VAlign { Top, Middle, Baseline, Bottom };  // across it: ascender, half the cap height, baseline, descender

struct TextStyle {
  double size = 10.0;        // pt
  Rgba color{0, 0, 0, 255};
  HAlign h = HAlign::Left;
  VAlign v = VAlign::Baseline;
  bool vertical = false;     // rotated 90 degrees counter-clockwise: reads bottom to top (y-axis labels)
};

// a font's line at one size (px)
struct LineMetrics {
  double ascent = 0.0;      // above the baseline, > 0
  double descent = 0.0;     // below the baseline, > 0
  double cap_height = 0.0;  // of "H"
  double height() const { return ascent + descent; }
};

// one face of a TrueType (or OpenType) font read from memory. The bytes are
// not copied: they must outlive the Font. Not thread-safe (a glyph cache).
class Font {
 public:
  // throws RenderError when the bytes are missing, empty or not a scalable font
  Font(const std::vector<std::uint8_t>* ttf, double dpi);
  ~Font();
  Font(const Font&) = delete;
  Font& operator=(const Font&) = delete;

  double dpi() const { return dpi_; }
  // whether the face has kerning pairs (applied by width, bounds and draw)
  bool has_kerning() const;
  // px of a length in points at this dpi
  double px(double pt) const { return pt * dpi_ / 72.0; }

  LineMetrics metrics(double size_pt) const;
  // the advance width of a UTF-8 string (px), kerning included
  int width(const std::string& utf8, double size_pt) const;
  // the ink box the text covers when drawn at `at` (the anchor point) in `style`
  Box bounds(const std::string& utf8, Vec2 at, const TextStyle& style) const;
  // composites the text onto image and returns its ink box (clipped to nothing outside the image)
  Box draw(Image& image, const std::string& utf8, Vec2 at, const TextStyle& style) const;

 private:
  struct Glyph {
    int left = 0, top = 0, w = 0, h = 0;  // bitmap offset from the pen (top: up from the baseline), size
    long advance = 0;                     // 26.6 px
    std::vector<std::uint8_t> coverage;   // w * h, row-major, top row first
  };
  struct Placed {
    int x = 0;  // the glyph's origin (px from the pen start)
    const Glyph* glyph = nullptr;
  };
  struct Run {
    std::vector<Placed> glyphs;
    int advance = 0;                          // px
    int ink_l = 0, ink_t = 0, ink_r = 0, ink_b = 0;  // ink box, pen-start/baseline frame, y down
    bool has_ink = false;
  };
  void set_size(long size26) const;
  long size26(double size_pt) const;
  const Glyph& glyph(unsigned index, long size26) const;
  Run layout(const std::string& utf8, double size_pt) const;
  // the integer origin of the run and its ink box in the image
  void place(const Run& run, Vec2 at, const TextStyle& style, int& ox, int& oy, Box& ink) const;

  double dpi_ = 72.0;
  FT_LibraryRec_* lib_ = nullptr;
  FT_FaceRec_* face_ = nullptr;
  mutable long current_size_ = -1;
  mutable std::map<std::pair<long, unsigned>, Glyph> glyphs_;
  mutable std::map<long, LineMetrics> metrics_;
};

// the code points of a UTF-8 string (a malformed sequence gives U+FFFD)
std::vector<char32_t> decode_utf8(const std::string& s);

}  // namespace paddock::render
