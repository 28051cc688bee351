#include "colorchecker_chart.h"

#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::relight {

void write_colorchecker_chart(const std::filesystem::path& path) {
  using namespace prizma::spectral;
  constexpr int kPatch = 24, kGap = 4;  // pixels: a patch, the surround between patches
  SpectralImage img;
  img.width = 6 * (kPatch + kGap) + kGap;
  img.height = 4 * (kPatch + kGap) + kGap;
  img.bins = BinLayout::linear(380.0, 700.0, 32);
  const int n = img.bins.size();
  std::vector<std::vector<double>> patches;
  for (int p = 1; p <= 24; ++p) patches.push_back(parse_spectrum("cc:" + std::to_string(p)).bin_averages(img.bins));
  for (const char* name : {"key", "back"}) {
    TransportLayer layer;
    layer.name = name;
    layer.data.assign(img.pixel_count() * static_cast<std::size_t>(n), 0.0f);
    img.lights.push_back(std::move(layer));
  }
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const int col = (x - kGap) / (kPatch + kGap), row = (y - kGap) / (kPatch + kGap);
      const bool inside = x >= kGap && y >= kGap && (x - kGap) % (kPatch + kGap) < kPatch &&
                          (y - kGap) % (kPatch + kGap) < kPatch;
      // Key falls off to the right, back rises toward the right edge (a rim light).
      const double u = static_cast<double>(x) / img.width;
      const double key = 1.0 - 0.35 * u, back = 0.8 * u * u;
      for (int i = 0; i < n; ++i) {
        const double r = inside ? patches[static_cast<std::size_t>(row * 6 + col)][static_cast<std::size_t>(i)] : 0.02;
        const std::size_t k = (static_cast<std::size_t>(y) * img.width + x) * n + i;
        img.lights[0].data[k] = static_cast<float>(r * key);
        img.lights[1].data[k] = static_cast<float>(r * back);
      }
    }
  img.info.light_records = parse_light_records(R"([{"name":"key","direction":[-1,0,1],"angularSizeDeg":0,"spectrum":"D65"},)"
                                               R"({"name":"back","direction":[1,0,0.2],"angularSizeDeg":0,"spectrum":"off"}])",
                                               "colorchecker chart");
  write_spectral_exr(path, img);
}

}  // namespace prizma::relight
