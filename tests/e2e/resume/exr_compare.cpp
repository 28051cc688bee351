// prizma-test-exr-compare A.exr B.exr [--max-ulps N] [--max-var-rel X] [--same-range]: compares two
// spectral EXR files of the same render (e.g. a resumed or merged render against one uninterrupted
// render) within the merge tolerance of docs/distributed.md. Prints the worst differences; exit 0
// when within, 1 when not, 2 for files that cannot be compared.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"

namespace {

std::int64_t ulps(float a, float b) {
  if (std::signbit(a) != std::signbit(b)) return a == b ? 0 : std::numeric_limits<std::int64_t>::max();
  return std::abs(static_cast<std::int64_t>(std::bit_cast<std::int32_t>(a)) -
                  static_cast<std::int64_t>(std::bit_cast<std::int32_t>(b)));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: prizma-test-exr-compare A.exr B.exr [--max-ulps N] [--max-var-rel X]\n";
    return 2;
  }
  std::int64_t max_ulps = 2;
  double max_var_rel = 1e-5;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--max-ulps") max_ulps = std::atoll(argv[i + 1]);
    else if (key == "--max-var-rel") max_var_rel = std::atof(argv[i + 1]);
    else {
      std::cerr << "unknown option " << key << "\n";
      return 2;
    }
  }
  try {
    const auto a = prizma::spectral::read_spectral_exr(argv[1]);
    const auto b = prizma::spectral::read_spectral_exr(argv[2]);
    if (a.width != b.width || a.height != b.height || !(a.bins == b.bins) || a.lights.size() != b.lights.size() ||
        a.info.samples != b.info.samples || a.info.sample_range != b.info.sample_range ||
        a.info.scene_hash != b.info.scene_hash || a.info.seed != b.info.seed) {
      std::cerr << "FAIL: not renders of the same scene and samples (size, bins, lights, samples "
                << a.info.sample_range << " vs " << b.info.sample_range << ", hash, seed)\n";
      return 1;
    }
    std::int64_t worst = 0;
    double worst_var = 0.0;
    for (std::size_t l = 0; l < a.lights.size(); ++l) {
      const auto& x = a.lights[l];
      const auto& y = b.lights[l];
      if (x.name != y.name || x.data.size() != y.data.size() || x.variance.size() != y.variance.size()) {
        std::cerr << "FAIL: light layers differ\n";
        return 1;
      }
      for (std::size_t k = 0; k < x.data.size(); ++k) worst = std::max(worst, ulps(x.data[k], y.data[k]));
      for (std::size_t k = 0; k < x.variance.size(); ++k) {
        const double v = x.variance[k], w = y.variance[k];
        if (v != w) worst_var = std::max(worst_var, std::abs(v - w) / std::max(std::abs(v), std::abs(w)));
      }
    }
    std::cout << "samples " << a.info.sample_range << ": means differ by at most " << worst
              << " ulp, variances by at most " << worst_var << " relative\n";
    if (worst > max_ulps || worst_var > max_var_rel) {
      std::cerr << "FAIL: beyond the merge tolerance (" << max_ulps << " ulp, variance " << max_var_rel << ")\n";
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
