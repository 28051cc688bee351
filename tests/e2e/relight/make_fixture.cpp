// Writes the inputs of the prizma-relight end-to-end tests into the folder given as argv[1]:
//   scene.exr      16×12, 16 bins over 400–700 nm, lights "key" (default D65) and "back" (default A):
//                  left half a grey T = 0.5 under key, right half a green-peaked reflectance under back
//   batch.json     three outputs (see below)
//   rgb.exr        a plain RGB EXR (no spectral channels)
//   fake.exr       a text file with an .exr name
//   existing.png   a file a failing run must leave untouched ("keep me")
//   colorchecker.exr  the example chart of docs/relight.md (relight/examples/colorchecker_chart.h;
//                     bins from 380 nm, below the CIE 2012 tables)
//   reference400.exr  a plain reflective file as the JCGT reference writer makes one: T.400nm …
//                     T.700nm, 100 nm apart, no prizma: attributes (its inferred first edge, 350 nm,
//                     is clamped to the tables' 360 nm)
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "colorchecker_chart.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum_spec.h"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace prizma::spectral;
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
  prizma::relight::write_colorchecker_chart(dir / "colorchecker.exr");

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
