// Writes the spectral files of the live-page tests (tests/e2e/browser.cmake) and benchmarks:
//   make_fixture DIR                 DIR/two.exr: 64×48, 16 bins 400–700 nm, lights "side" (default
//                                    D65) and "back" (default A): the 24 ColorChecker patches, side
//                                    rising left to right up to 1.4 (so bright patches clip), back a
//                                    vertical ramp; DIR/one.exr: 64×48, 1 bin, one light;
//                                    DIR/wide.exr: 256×192, as two.exr (the page's layout check)
//   make_fixture --size W H FILE     W×H, 16 bins, the same two lights (bench/live-page)
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum_spec.h"

namespace {

using namespace prizma::spectral;

SpectralImage two_lights(int width, int height, int bins) {
  SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = BinLayout::linear(400.0, 700.0, bins);
  std::vector<std::vector<double>> patches;
  for (int p = 1; p <= 24; ++p) patches.push_back(parse_spectrum("cc:" + std::to_string(p)).bin_averages(img.bins));
  for (const char* name : {"side", "back"}) {
    TransportLayer layer;
    layer.name = name;
    layer.data.assign(img.pixel_count() * static_cast<std::size_t>(bins), 0.0f);
    img.lights.push_back(std::move(layer));
  }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int patch = (y * 4 / height) * 6 + x * 6 / width;
      const double u = (x + 0.5) / width, v = (y + 0.5) / height;
      const double side = 0.05 + 1.35 * u, back = 0.9 * v * v;
      for (int i = 0; i < bins; ++i) {
        const double r = patches[static_cast<std::size_t>(patch)][static_cast<std::size_t>(i)];
        const std::size_t k = (static_cast<std::size_t>(y) * width + x) * bins + i;
        img.lights[0].data[k] = static_cast<float>(r * side);
        img.lights[1].data[k] = static_cast<float>(r * r * back);
      }
    }
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"side","direction":[-1,0,1],"angularSizeDeg":0,"spectrum":"D65"},)"
                         R"({"name":"back","direction":[1,0,0.2],"angularSizeDeg":0,"spectrum":"A"}])", "test");
  return img;
}

SpectralImage one_bin(int width, int height) {
  SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = BinLayout::linear(400.0, 700.0, 1);
  TransportLayer layer;
  layer.name = "key";
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) layer.data.push_back(static_cast<float>(1.2 * (x + 0.5) / width * (0.3 + 0.7 * y / height)));
  img.lights.push_back(std::move(layer));
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"key","direction":[0,0,1],"angularSizeDeg":0,"spectrum":"D65"}])", "test");
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  try {
    if (argc == 5 && std::string(argv[1]) == "--size") {
      write_spectral_exr(argv[4], two_lights(std::stoi(argv[2]), std::stoi(argv[3]), 16));
      return 0;
    }
    if (argc != 2) {
      std::cerr << "usage: make_fixture DIR | make_fixture --size W H FILE\n";
      return 2;
    }
    const fs::path dir = argv[1];
    fs::create_directories(dir);
    write_spectral_exr(dir / "two.exr", two_lights(64, 48, 16));
    write_spectral_exr(dir / "one.exr", one_bin(64, 48));
    write_spectral_exr(dir / "wide.exr", two_lights(256, 192, 16));
  } catch (const std::exception& e) {
    std::cerr << "make_fixture: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
