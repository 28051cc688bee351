#include "prizma/relight/terminal_preview.h"

#include <algorithm>
#include <cmath>

namespace prizma::relight {

void print_terminal_thumbnail(std::ostream& out, const std::vector<float>& rgb, int width, int height,
                              int max_columns) {
  if (width <= 0 || height <= 0 || max_columns <= 0) return;
  // Thumbnail size: at most max_columns wide, aspect kept (each character cell is two pixels tall).
  const int cols = std::min(width, max_columns);
  int rows = std::max(1, static_cast<int>(std::lround(static_cast<double>(height) * cols / width)));
  rows += rows % 2;
  // Box filter: the mean of the source pixels that fall into each thumbnail pixel.
  auto sample = [&](int tx, int ty, int c) {
    const int x0 = tx * width / cols, x1 = std::max(x0 + 1, (tx + 1) * width / cols);
    const int y0 = ty * height / rows, y1 = std::max(y0 + 1, (ty + 1) * height / rows);
    double sum = 0.0;
    int count = 0;
    for (int y = y0; y < std::min(y1, height); ++y)
      for (int x = x0; x < std::min(x1, width); ++x, ++count) {
        const float v = rgb[3 * (static_cast<std::size_t>(y) * width + x) + c];
        sum += std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
      }
    return count ? static_cast<int>(std::lround(255.0 * sum / count)) : 0;
  };
  for (int ty = 0; ty < rows; ty += 2) {
    for (int tx = 0; tx < cols; ++tx) {
      // Upper half block: foreground = upper pixel, background = lower pixel.
      out << "\x1b[38;2;" << sample(tx, ty, 0) << ';' << sample(tx, ty, 1) << ';' << sample(tx, ty, 2) << 'm'
          << "\x1b[48;2;" << sample(tx, ty + 1, 0) << ';' << sample(tx, ty + 1, 1) << ';'
          << sample(tx, ty + 1, 2) << "m\u2580";
    }
    out << "\x1b[0m\n";
  }
}

}  // namespace prizma::relight
