// A 5 x 7 bitmap font for the plots of tissue-host compare (printable ASCII), so that a PNG can
// carry its tick labels, axis titles and legend without a font library. Cells are 5 x 9: seven
// rows down to the baseline and two below it for the descenders of g, j, p, q and y.
#pragma once

#include <array>
#include <cstdint>

namespace tissue::host {

inline constexpr int GLYPH_WIDTH = 5;
inline constexpr int GLYPH_HEIGHT = 9;

/// Rows top to bottom; bit 4 is the leftmost column. Characters outside ' '..'~' draw as '?'.
[[nodiscard]] const std::array<std::uint8_t, GLYPH_HEIGHT>& glyph(char c);

}  // namespace tissue::host
