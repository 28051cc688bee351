#pragma once
// Film: the accumulators of a render. Per pixel, light and bin the sum of the samples in double (and
// of their squares with --variance, and per pixel the sums of the sample totals for the error
// target), added in sample order by the one thread that renders the pixel, so the image never
// depends on threads or tiling; image() turns the sums into means (and variances of the mean).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {

class Film {
 public:
  struct Layout {
    int width = 0, height = 0;
    int lights = 0;
    spectral::BinLayout bins;
    std::vector<spectral::BinPair> bispectral;  // the off-diagonal terms stored per light (fluorescence)
    bool variance = false;                      // keep the squares (variance layers)
    double target_error = 0.0;                  // > 0: a pixel stops once its relative error is ≤ this
    std::vector<std::string> guides;            // --features: the guide planes' names (sums and squares kept)
  };
  explicit Film(Layout spec);

  const Layout& layout() const { return m_layout; }
  std::size_t pixels() const { return m_live.count.size(); }
  // Values of one sample: [light][bin], and [light][bispectral pair].
  std::size_t values_per_pixel() const { return m_per_pixel; }
  std::size_t bispectral_per_pixel() const { return m_per_pixel_fl; }
  bool converged(std::size_t pixel) const { return m_live.converged[pixel] != 0; }

  // Adds one sample of `pixel`: v[values_per_pixel()], vf[bispectral_per_pixel()] and g[guides]
  // (finite; g may be null without guides).
  // Returns true when the error target is met with this sample: the pixel is then converged and
  // takes no more (checked from the 16th sample on; never without a target).
  bool add_sample(std::size_t pixel, const double* v, const double* vf, const double* g = nullptr);

  // Keeps a copy of every sum; restore() goes back to it (a pass cut short by a cancel).
  void save();
  void restore();

  // The means as float layers named `names` (one per light), the variances of the mean when kept
  // (0 for a pixel with one sample), the bispectral terms and the guide layers with their variance
  // of the mean. Info is left empty.
  spectral::SpectralImage image(const std::vector<std::string>& names) const;

 private:
  struct Sums {
    std::vector<double> sum, sum_sq;          // [pixel][light][bin]
    std::vector<double> total_sum, total_sq;  // [pixel] sample totals (error target only)
    std::vector<double> sum_fl;               // [pixel][light][bispectral pair]
    std::vector<double> sum_g, sum_g_sq;      // [pixel][guide]
    std::vector<std::int64_t> count;          // [pixel]
    std::vector<char> converged;              // [pixel]
  };

  Layout m_layout;
  std::size_t m_per_pixel = 0, m_per_pixel_fl = 0;
  Sums m_live, m_saved;
};

}  // namespace prizma::render
