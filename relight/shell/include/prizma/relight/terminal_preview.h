#pragma once
// A true-colour terminal thumbnail: ANSI 24-bit colours on "▀" half blocks, two image rows per line.
#include <ostream>
#include <vector>

namespace prizma::relight {

// `rgb` holds display-encoded interleaved RGB in [0, 1] (values outside are clamped), width·height
// pixels. The thumbnail is box-filtered down to at most max_columns characters wide and, when
// max_lines > 0, at most max_lines lines tall, the aspect ratio kept; it is never enlarged.
void print_terminal_thumbnail(std::ostream& out, const std::vector<float>& rgb, int width, int height,
                              int max_columns = 64, int max_lines = 0);

}  // namespace prizma::relight
