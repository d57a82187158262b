#pragma once
// colours: mixing helpers and the colour maps (viridis is declared in figures.h)
#include <cstdint>

#include "render/figures.h"

namespace paddock::render {

// a + (b - a) t per channel, alpha too (t in [0, 1])
Rgba lerp(Rgba a, Rgba b, double t);
// towards white / black by t in [0, 1], alpha kept
Rgba lighten(Rgba c, double t);
Rgba darken(Rgba c, double t);
Rgba with_alpha(Rgba c, std::uint8_t a);

// a palette for series (matplotlib's "tab10" first colours)
inline constexpr Rgba kTabBlue{31, 119, 180, 255};
inline constexpr Rgba kTabOrange{255, 127, 14, 255};
inline constexpr Rgba kTabGreen{44, 160, 44, 255};
inline constexpr Rgba kTabRed{214, 39, 40, 255};
inline constexpr Rgba kTabPurple{148, 103, 189, 255};
inline constexpr Rgba kBlack{0, 0, 0, 255};

}  // namespace paddock::render
