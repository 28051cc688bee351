// Writes the inputs of the prizma-relight end-to-end tests into the folder given as argv[1]:
//   scene.exr      16×12, 16 bins over 400–700 nm, lights "key" (default D65) and "back" (default A):
//                  left half a grey T = 0.5 under key, right half a green-peaked reflectance under back
//   batch.json     three outputs (see below)
//   rgb.exr        a plain RGB EXR (no spectral channels)
//   fake.exr       a text file with an .exr name
//   existing.png   a file a failing run must leave untouched ("keep me")
//   colorchecker.exr  the image below (bins from 380 nm, below the CIE 2012 tables)
//   reference400.exr  a plain reflective file as the JCGT reference writer makes one: T.400nm …
//                     T.700nm, 100 nm apart, no prizma: attributes (its inferred first edge, 350 nm,
//                     is clamped to the tables' 360 nm)
// With "--colorchecker FILE.exr" it writes instead the image of docs/relight.md: the 24 ColorChecker
// patches (reflectance bin averages, 32 bins over 380–700 nm), lit by "key" from the left and "back"
// from the right.
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum_spec.h"

namespace {

int write_colorchecker(const std::filesystem::path& path) {
  using namespace prizma::spectral;
  constexpr int kPatch = 24, kGap = 4;
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
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"key","direction":[-1,0,1],"angularSizeDeg":0,"spectrum":"D65"},)"
                         R"({"name":"back","direction":[1,0,0.2],"angularSizeDeg":0,"spectrum":"off"}])", "test");
  write_spectral_exr(path, img);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace prizma::spectral;
  if (argc == 3 && std::string(argv[1]) == "--colorchecker") return write_colorchecker(argv[2]);
  if (argc != 2) {
    std::cerr << "usage: make_fixture DIR\n";
    return 2;
  }
  const fs::path dir = argv[1];
  fs::remove_all(dir);
  fs::create_directories(dir);

  SpectralImage img;
  img.width = 16;
  img.height = 12;
  img.bins = BinLayout::linear(400.0, 700.0, 16);
  for (const char* name : {"key", "back"}) {
    TransportLayer layer;
    layer.name = name;
    layer.data.assign(img.pixel_count() * 16, 0.0f);
    img.lights.push_back(std::move(layer));
  }
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int i = 0; i < 16; ++i) {
        const std::size_t k = (static_cast<std::size_t>(y) * 16 + x) * 16 + i;
        if (x < 8) img.lights[0].data[k] = 0.5f;
        else img.lights[1].data[k] = static_cast<float>(0.1 + 0.8 * std::exp(-0.5 * std::pow((img.bins.centre_nm(i) - 540.0) / 40.0, 2)));
      }
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"key","direction":[0,0,1],"angularSizeDeg":0,"spectrum":"D65"},)"
                         R"({"name":"back","direction":[0,1,0],"angularSizeDeg":0,"spectrum":"A"}])", "test");
  write_spectral_exr(dir / "scene.exr", img);

  std::ofstream(dir / "batch.json") << R"({
  "defaults": {"lights": {"back": "off"}},
  "outputs": [
    {"file": "batch_d65.png", "lights": {"key": "D65"}},
    {"file": "batch_a16.png", "lights": {"key": "A"}, "bitDepth": 16},
    {"file": "batch_xyz.exr", "lights": "F11", "exposure": -1}
  ]
})";
  std::ofstream(dir / "fake.exr") << "not an EXR file\n";
  std::ofstream(dir / "existing.png") << "keep me";
  if (const int rc = write_colorchecker((dir / "colorchecker.exr").string()); rc != 0) return rc;

  const float rgb[3 * 4] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1.0f, 0.5f, 0.0f};
  auto out = OIIO::ImageOutput::create((dir / "rgb.exr").string());
  OIIO::ImageSpec spec(2, 2, 3, OIIO::TypeDesc::FLOAT);
  if (!out || !out->open((dir / "rgb.exr").string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, rgb) ||
      !out->close()) {
    std::cerr << "make_fixture: cannot write rgb.exr\n";
    return 1;
  }
  {
    const float t[4 * 4] = {0.2f, 0.4f, 0.6f, 0.8f, 0.2f, 0.4f, 0.6f, 0.8f, 0.2f, 0.4f, 0.6f, 0.8f, 0.2f, 0.4f, 0.6f, 0.8f};
    auto ref = OIIO::ImageOutput::create((dir / "reference400.exr").string());
    OIIO::ImageSpec rs(2, 2, 4, OIIO::TypeDesc::FLOAT);
    rs.channelnames = {"T.400nm", "T.500nm", "T.600nm", "T.700nm"};
    rs.attribute("spectralLayoutVersion", "1.0");
    if (!ref || !ref->open((dir / "reference400.exr").string(), rs) || !ref->write_image(OIIO::TypeDesc::FLOAT, t) ||
        !ref->close()) {
      std::cerr << "make_fixture: cannot write reference400.exr\n";
      return 1;
    }
  }
  return 0;
}
