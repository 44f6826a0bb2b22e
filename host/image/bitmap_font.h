// bitmap_font.h: a small hand-made 5x7 bitmap font for labels on figures (ΔE heat-map legends, the
// JND percentage on JND maps). Covers digits, upper-case letters (lower case draws as upper case),
// '%', '.', '-', ':', ' ' and a few extras ('+', '/', '(', ')', '=', '_', '?', '[', ']', ','); any other character
// draws as '?'.
#pragma once

#include <cstdint>
#include <string>

namespace narval {

constexpr int kFontWidth = 5;    // glyph columns
constexpr int kFontHeight = 7;   // glyph rows
constexpr int kFontAdvance = 6;  // columns from one character to the next (one blank column between)

// The glyph of `c`: kFontHeight rows, top first; in each row bit 4 is the leftmost column and bit 0
// the rightmost. Lower case maps to upper case; a character without a glyph gets '?'s. Never null.
const uint8_t* fontGlyph(char c);
// Whether `c` has a glyph of its own (after mapping lower case to upper case).
bool fontHasGlyph(char c);
// Width in pixels of `text` drawn at `scale` pixels per font pixel: the last character's trailing
// blank column is not counted (0 for an empty string).
int fontTextWidth(const std::string& text, int scale);

}  // namespace narval
