#include "prizma/relight/terminal_preview.h"

#include <algorithm>
#include <cmath>

#include "prizma/relight/terminal_image.h"

namespace prizma::relight {

void print_terminal_thumbnail(std::ostream& out, const std::vector<float>& rgb, int width, int height,
                              int max_columns, int max_lines) {
  if (width <= 0 || height <= 0 || max_columns <= 0) return;
  // Thumbnail size: at most max_columns wide, aspect kept (each character cell is two pixels tall).
  int cols = std::min(width, max_columns);
  int rows = std::max(1, static_cast<int>(std::lround(static_cast<double>(height) * cols / width)));
  if (max_lines > 0 && rows > 2 * max_lines) {
    rows = 2 * max_lines;
    cols = std::clamp(static_cast<int>(std::lround(static_cast<double>(width) * rows / height)), 1, cols);
  }
  rows += rows % 2;
  const Rgb8Image px = resample_rgb8(rgb, width, height, cols, rows);
  auto at = [&](int x, int y, int c) { return static_cast<int>(px.pixels[3 * (static_cast<std::size_t>(y) * cols + x) + c]); };
  for (int ty = 0; ty < rows; ty += 2) {
    for (int tx = 0; tx < cols; ++tx) {
      // Upper half block: foreground = upper pixel, background = lower pixel.
      out << "\x1b[38;2;" << at(tx, ty, 0) << ';' << at(tx, ty, 1) << ';' << at(tx, ty, 2) << 'm' << "\x1b[48;2;"
          << at(tx, ty + 1, 0) << ';' << at(tx, ty + 1, 1) << ';' << at(tx, ty + 1, 2) << "m\u2580";
    }
    out << "\x1b[0m\n";
  }
}

}  // namespace prizma::relight
