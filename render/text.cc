#include "render/text.h"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace paddock::render {

namespace {

std::string ft_error(FT_Error e) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "FreeType error 0x%02x", static_cast<unsigned>(e));
  return buf;
}

}  // namespace

std::vector<char32_t> decode_utf8(const std::string& s) {
  std::vector<char32_t> out;
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b0 = static_cast<unsigned char>(s[i]);
    int len = 0;
    char32_t cp = 0;
    if (b0 < 0x80) {
      len = 1, cp = b0;
    } else if ((b0 & 0xE0) == 0xC0) {
      len = 2, cp = b0 & 0x1Fu;
    } else if ((b0 & 0xF0) == 0xE0) {
      len = 3, cp = b0 & 0x0Fu;
    } else if ((b0 & 0xF8) == 0xF0) {
      len = 4, cp = b0 & 0x07u;
    }
    bool ok = len > 0 && i + static_cast<std::size_t>(len) <= s.size();
    for (int k = 1; ok && k < len; ++k) {
      const auto b = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      ok = (b & 0xC0) == 0x80;
      cp = (cp << 6) | (b & 0x3Fu);
    }
    if (!ok) {
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    out.push_back(cp);
    i += static_cast<std::size_t>(len);
  }
  return out;
}

Font::Font(const std::vector<std::uint8_t>* ttf, double dpi) : dpi_(dpi) {
  if (ttf == nullptr) {
    throw RenderError("no font: FigureStyle::font is null; read a TrueType file (for example "
                      "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf of fonts-dejavu-core) and pass its bytes");
  }
  if (ttf->empty()) {
    throw RenderError("the font is empty (0 bytes): FigureStyle::font must hold the bytes of a TrueType file");
  }
  if (!(dpi > 0.0) || !std::isfinite(dpi)) {
    throw RenderError("the dpi must be a positive number, got " + std::to_string(dpi));
  }
  FT_Library lib = nullptr;
  if (const FT_Error e = FT_Init_FreeType(&lib)) throw RenderError("FreeType failed to start: " + ft_error(e));
  lib_ = lib;
  FT_Face face = nullptr;
  if (const FT_Error e = FT_New_Memory_Face(lib, ttf->data(), static_cast<FT_Long>(ttf->size()), 0, &face)) {
    FT_Done_FreeType(lib);
    throw RenderError("the font (" + std::to_string(ttf->size()) +
                      " bytes) is not a TrueType or OpenType font FreeType can read: " + ft_error(e));
  }
  if (!FT_IS_SCALABLE(face)) {
    FT_Done_Face(face);
    FT_Done_FreeType(lib);
    throw RenderError("the font is not scalable (a bitmap font): give a TrueType font");
  }
  face_ = face;
}

Font::~Font() {
  FT_Done_Face(face_);
  FT_Done_FreeType(lib_);
}

bool Font::has_kerning() const { return FT_HAS_KERNING(face_); }

long Font::size26(double size_pt) const {
  // the em size in 26.6 px; at least 1 px
  return std::max(64L, std::lround(size_pt * dpi_ / 72.0 * 64.0));
}

void Font::set_size(long s26) const {
  if (s26 == current_size_) return;
  // a char size in 26.6 points at 72 dpi is that many 26.6 pixels
  if (const FT_Error e = FT_Set_Char_Size(face_, 0, s26, 72, 72)) {
    throw RenderError("FreeType cannot set the size " + std::to_string(static_cast<double>(s26) / 64.0) + " px: " + ft_error(e));
  }
  current_size_ = s26;
}

LineMetrics Font::metrics(double size_pt) const {
  const long s26 = size26(size_pt);
  if (auto it = metrics_.find(s26); it != metrics_.end()) return it->second;
  set_size(s26);
  LineMetrics m;
  m.ascent = static_cast<double>(face_->size->metrics.ascender) / 64.0;
  m.descent = -static_cast<double>(face_->size->metrics.descender) / 64.0;
  const FT_UInt h = FT_Get_Char_Index(face_, 'H');
  if (h != 0 && FT_Load_Glyph(face_, h, FT_LOAD_DEFAULT | FT_LOAD_TARGET_LIGHT) == 0) {
    m.cap_height = static_cast<double>(face_->glyph->metrics.horiBearingY) / 64.0;
  } else {
    m.cap_height = 0.7 * m.ascent;
  }
  metrics_[s26] = m;
  return m;
}

const Font::Glyph& Font::glyph(unsigned index, long s26) const {
  const auto key = std::make_pair(s26, index);
  if (auto it = glyphs_.find(key); it != glyphs_.end()) return it->second;
  set_size(s26);
  Glyph g;
  // light hinting: vertical only, so the shapes keep their design widths
  if (FT_Load_Glyph(face_, index, FT_LOAD_RENDER | FT_LOAD_TARGET_LIGHT) == 0) {
    const FT_GlyphSlot slot = face_->glyph;
    const FT_Bitmap& bm = slot->bitmap;
    g.left = slot->bitmap_left;
    g.top = slot->bitmap_top;
    g.advance = slot->advance.x;
    if (bm.pixel_mode == FT_PIXEL_MODE_GRAY && bm.buffer != nullptr) {
      g.w = static_cast<int>(bm.width);
      g.h = static_cast<int>(bm.rows);
      g.coverage.resize(static_cast<std::size_t>(g.w) * static_cast<std::size_t>(g.h));
      const int levels = bm.num_grays > 1 ? bm.num_grays - 1 : 255;
      for (int r = 0; r < g.h; ++r) {
        const unsigned char* src = bm.buffer + static_cast<long>(r) * bm.pitch;
        for (int c = 0; c < g.w; ++c) {
          g.coverage[static_cast<std::size_t>(r * g.w + c)] = static_cast<std::uint8_t>(src[c] * 255 / levels);
        }
      }
    }
  }
  return glyphs_.emplace(key, std::move(g)).first->second;
}

Font::Run Font::layout(const std::string& utf8, double size_pt) const {
  const long s26 = size26(size_pt);
  Run run;
  long pen = 0;  // 26.6 px
  FT_UInt prev = 0;
  const bool kerning = FT_HAS_KERNING(face_);
  for (const char32_t cp : decode_utf8(utf8)) {
    const FT_UInt index = FT_Get_Char_Index(face_, cp);
    if (kerning && prev != 0 && index != 0) {
      set_size(s26);
      FT_Vector k{0, 0};
      if (FT_Get_Kerning(face_, prev, index, FT_KERNING_DEFAULT, &k) == 0) pen += k.x;
    }
    const Glyph& g = glyph(index, s26);
    const int x = static_cast<int>((pen + 32) >> 6);
    run.glyphs.push_back({x, &g});
    if (g.w > 0 && g.h > 0) {
      const int l = x + g.left, t = -g.top, r = l + g.w, b = t + g.h;
      if (!run.has_ink) {
        run.ink_l = l, run.ink_t = t, run.ink_r = r, run.ink_b = b;
        run.has_ink = true;
      } else {
        run.ink_l = std::min(run.ink_l, l), run.ink_t = std::min(run.ink_t, t);
        run.ink_r = std::max(run.ink_r, r), run.ink_b = std::max(run.ink_b, b);
      }
    }
    pen += g.advance;
    prev = index;
  }
  run.advance = static_cast<int>((pen + 32) >> 6);
  return run;
}

int Font::width(const std::string& utf8, double size_pt) const { return layout(utf8, size_pt).advance; }

void Font::place(const Run& run, Vec2 at, const TextStyle& style, int& ox, int& oy, Box& ink) const {
  const LineMetrics m = metrics(style.size);
  // the anchor in the text's own frame (x along the text from the pen start, y down from the baseline)
  const double ax = style.h == HAlign::Left ? 0.0 : style.h == HAlign::Center ? 0.5 * run.advance : run.advance;
  const double ay = style.v == VAlign::Top        ? -m.ascent
                    : style.v == VAlign::Middle   ? -0.5 * m.cap_height
                    : style.v == VAlign::Baseline ? 0.0
                                                  : m.descent;
  if (!style.vertical) {
    // text (u, v) -> image (at.x + u - ax, at.y + v - ay)
    ox = static_cast<int>(std::lround(at.x - ax));
    oy = static_cast<int>(std::lround(at.y - ay));
    ink = run.has_ink ? Box{ox + run.ink_l, oy + run.ink_t, ox + run.ink_r, oy + run.ink_b} : Box{ox, oy, ox, oy};
  } else {
    // rotated counter-clockwise: text (u, v) -> image (at.x + v - ay, at.y - (u - ax))
    ox = static_cast<int>(std::lround(at.x - ay));
    oy = static_cast<int>(std::lround(at.y + ax));
    ink = run.has_ink ? Box{ox + run.ink_t, oy - run.ink_r, ox + run.ink_b, oy - run.ink_l} : Box{ox, oy, ox, oy};
  }
}

Box Font::bounds(const std::string& utf8, Vec2 at, const TextStyle& style) const {
  int ox = 0, oy = 0;
  Box ink;
  place(layout(utf8, style.size), at, style, ox, oy, ink);
  return ink;
}

Box Font::draw(Image& image, const std::string& utf8, Vec2 at, const TextStyle& style) const {
  const Run run = layout(utf8, style.size);
  int ox = 0, oy = 0;
  Box ink;
  place(run, at, style, ox, oy, ink);
  const Rgba c = style.color;
  const auto blend = [&](int x, int y, std::uint8_t cov) {
    if (cov == 0 || x < 0 || y < 0 || x >= image.width || y >= image.height) return;
    const unsigned a = (cov * c.a + 127u) / 255u;
    std::uint8_t* p = image.rgba.data() + (static_cast<std::size_t>(y) * image.width + x) * 4;
    p[0] = static_cast<std::uint8_t>((c.r * a + p[0] * (255u - a) + 127u) / 255u);
    p[1] = static_cast<std::uint8_t>((c.g * a + p[1] * (255u - a) + 127u) / 255u);
    p[2] = static_cast<std::uint8_t>((c.b * a + p[2] * (255u - a) + 127u) / 255u);
    p[3] = static_cast<std::uint8_t>(a + (p[3] * (255u - a) + 127u) / 255u);
  };
  for (const Placed& pg : run.glyphs) {
    const Glyph& g = *pg.glyph;
    for (int r = 0; r < g.h; ++r) {
      for (int col = 0; col < g.w; ++col) {
        const std::uint8_t cov = g.coverage[static_cast<std::size_t>(r * g.w + col)];
        // the pixel's position in the text frame
        const int u = pg.x + g.left + col, v = -g.top + r;
        if (!style.vertical) {
          blend(ox + u, oy + v, cov);
        } else {
          blend(ox + v, oy - u - 1, cov);
        }
      }
    }
  }
  return ink;
}

}  // namespace paddock::render
