// prizma_make_colorchecker OUT.exr: writes the example chart of docs/relight.md (colorchecker_chart.h).
// A build step (relight/CMakeLists.txt), not an installed tool: the chart is installed as data.
#include <exception>
#include <iostream>

#include "colorchecker_chart.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: prizma_make_colorchecker OUT.exr\n";
    return 2;
  }
  try {
    prizma::relight::write_colorchecker_chart(argv[1]);
  } catch (const std::exception& e) {
    std::cerr << "prizma_make_colorchecker: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
