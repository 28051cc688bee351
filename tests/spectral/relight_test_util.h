#pragma once
// Helpers of the relight tests: synthetic spectral images and an independent "by hand" evaluation of
// the relight integrals straight from the CIE CSV tables (no libspectral code on that path).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"
#include "spectral/scratch_files.h"

namespace prizma::spectral::test {

// A table read from data/spectra/<file>: first column nm, other columns values.
struct Table {
  std::vector<double> nm;
  std::vector<std::vector<double>> columns;

  // Linear interpolation, 0 outside the table.
  double eval(int column, double lambda_nm) const {
    if (lambda_nm < nm.front() || lambda_nm > nm.back()) return 0.0;
    const auto it = std::upper_bound(nm.begin(), nm.end(), lambda_nm);
    std::size_t i = static_cast<std::size_t>(it - nm.begin());
    i = i == 0 ? 0 : std::min(i - 1, nm.size() - 2);
    const double t = (lambda_nm - nm[i]) / (nm[i + 1] - nm[i]);
    return columns[column][i] * (1.0 - t) + columns[column][i + 1] * t;
  }
};

inline Table read_table(const std::string& name) {
  std::ifstream in(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "spectra" / name);
  Table t;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || !(std::isdigit(static_cast<unsigned char>(line[0])))) continue;  // header
    std::stringstream s(line);
    std::string cell;
    std::getline(s, cell, ',');
    t.nm.push_back(std::stod(cell));
    for (std::size_t c = 0; std::getline(s, cell, ','); ++c) {
      if (t.columns.size() <= c) t.columns.emplace_back();
      t.columns[c].push_back(std::stod(cell));
    }
  }
  return t;
}

// ∫_{lo}^{hi} light(λ)·cmf_c(λ) dλ by the trapezoid rule on a 0.05 nm grid (cmf linearly
// interpolated from the 1 nm CIE 1931 table, as the standard tabulates it).
inline double hand_weight(const Table& cmf, int c, const std::function<double(double)>& light, double lo, double hi) {
  const int steps = static_cast<int>(std::lround((hi - lo) / 0.05));
  const double h = (hi - lo) / steps;
  double sum = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const double lambda = lo + k * h;
    const double f = light(lambda) * cmf.eval(c, lambda);
    sum += (k == 0 || k == steps) ? 0.5 * f : f;
  }
  return sum * h;
}

// An image whose layer l at pixel p holds value(l, p, i) in bin i.
inline spectral::SpectralImage make_image(int width, int height, const spectral::BinLayout& bins,
                                          const std::vector<std::string>& names,
                                          const std::function<float(int, int, int)>& value) {
  spectral::SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = bins;
  const int n = bins.size();
  for (std::size_t l = 0; l < names.size(); ++l) {
    spectral::TransportLayer layer;
    layer.name = names[l];
    layer.data.resize(static_cast<std::size_t>(width) * height * n);
    for (int p = 0; p < width * height; ++p)
      for (int i = 0; i < n; ++i)
        layer.data[static_cast<std::size_t>(p) * n + i] = value(static_cast<int>(l), p, i);
    img.lights.push_back(std::move(layer));
  }
  return img;
}

// The fluorescent (bispectral) test image: 4×2 pixels, 6 bins over 400–700 nm (centres 425 … 675),
// lights "uv" and "sky" with diagonal values 0.05·(1 + l + p % 3 + i), and pairs from the two blue
// bins into the three red ones, {0,3}, {0,4}, {0,5}, {1,3}, {1,4}, {1,5}, with values
// 0.02·(1 + (k·7 + 3l) % 11) (k = pixel·6 + pair).
inline spectral::SpectralImage fluorescent_image() {
  auto img = make_image(4, 2, spectral::BinLayout::linear(400, 700, 6), {"uv", "sky"},
                        [](int l, int p, int i) { return 0.05f * static_cast<float>(1 + l + p % 3 + i); });
  img.reradiation = {{0, 3}, {0, 4}, {0, 5}, {1, 3}, {1, 4}, {1, 5}};
  for (std::size_t l = 0; l < 2; ++l)
    for (std::size_t k = 0; k < img.pixel_count() * 6; ++k)
      img.lights[l].reradiation.push_back(0.02f * static_cast<float>(1 + (k * 7 + l * 3) % 11));
  return img;
}

// A fresh scratch folder per test (scratch_files.h).
inline std::filesystem::path scratch_dir(const std::string& name) { return scratch_dir("relight", name); }

}  // namespace prizma::spectral::test
