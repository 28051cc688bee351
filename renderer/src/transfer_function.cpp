// Transfer functions: material rules, VPT transfer-function images, and the Medium built from a
// volume.
#include "prizma/render/transfer_function.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "checked_picture.h"
#include "prizma/spectral/error.h"

namespace prizma::render {

using spectral::InputError;
using spectral::Spectrum;

namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// Smallest and largest value a spectrum takes (piecewise linear: the table's extremes).
void spectrum_extremes(const Spectrum& s, double& lo, double& hi) {
  lo = s.min_value();
  hi = s.max_value();
}

constexpr double kMaxAbsG = 0.999;
// Transfer-function images: at most this many pixels (a row per value level, a column per
// wavelength sample; 2048 × 2048 is far more than any real one), and at most this many decoded
// bytes per byte of file (deflate's limit is 1032:1, LZW's about 2000:1), so a tiny file that
// claims a huge image is refused before anything is allocated.
constexpr long long kMaxTfPixels = 1LL << 22;
constexpr long long kMaxTfExpansion = 4096;

}  // namespace

double DensityRamp::eval(double value) const {
  if (values.empty()) return 1.0;
  if (value <= values.front()) return densities.front();
  if (value >= values.back()) return densities.back();
  const auto it = std::upper_bound(values.begin(), values.end(), value);
  const std::size_t i = static_cast<std::size_t>(it - values.begin());
  const double t = (value - values[i - 1]) / (values[i] - values[i - 1]);
  return densities[i - 1] + t * (densities[i] - densities[i - 1]);
}

double DensityRamp::max_over(double lo, double hi) const {
  double m = std::max(eval(lo), eval(hi));
  for (std::size_t k = 0; k < values.size(); ++k)
    if (values[k] > lo && values[k] < hi) m = std::max(m, densities[k]);
  return m;
}

double DensityRamp::min_over(double lo, double hi) const {
  double m = std::min(eval(lo), eval(hi));
  for (std::size_t k = 0; k < values.size(); ++k)
    if (values[k] > lo && values[k] < hi) m = std::min(m, densities[k]);
  return m;
}

double ValueNormalisation::to_unit(double v) const {
  const double t = (v - min) / (max - min);
  return std::clamp(t, 0.0, 1.0);
}

ValueNormalisation auto_normalisation(const Volume& vol) {
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  for (float v : vol.values) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(lo <= hi)) throw InputError(vol.source, "volume has no finite value");
  ValueNormalisation n;
  n.min = lo;
  n.max = hi > lo ? hi : lo + 1.0;
  return n;
}

void validate_material(const Material& m, const std::string& input) {
  double lo = 0.0;
  double hi = 0.0;
  spectrum_extremes(m.albedo, lo, hi);
  if (!(lo >= 0.0 && hi <= 1.0)) {
    throw InputError(input + ".albedo", "must be in [0, 1] at every wavelength (got values in [" + num(lo) + ", " +
                                            num(hi) + "])");
  }
  spectrum_extremes(m.sigma_t_per_unit, lo, hi);
  if (!(lo >= 0.0) || !std::isfinite(hi)) {
    throw InputError(input + ".extinction", "must be ≥ 0 and finite at every wavelength (got minimum " + num(lo) + ")");
  }
  spectrum_extremes(m.anisotropy, lo, hi);
  if (!(lo > -1.0 && hi < 1.0)) {
    throw InputError(input + ".anisotropy", "must be in (-1, 1) at every wavelength (got values in [" + num(lo) +
                                                ", " + num(hi) + "])");
  }
}

// long on purpose: the image checks and the row-runs → rules conversion, in the order an image is trusted.
TransferFunction read_transfer_function_image(const std::filesystem::path& image, double extinction_scale,
                                              double lambda_lo_nm, double lambda_hi_nm,
                                              const ValueNormalisation& norm, const std::string& input) {
  if (!(extinction_scale > 0.0) || !std::isfinite(extinction_scale)) {
    throw InputError(input, "extinction_scale must be > 0 (got " + num(extinction_scale) + ")");
  }
  if (!(lambda_lo_nm < lambda_hi_nm) || !std::isfinite(lambda_lo_nm) || !std::isfinite(lambda_hi_nm)) {
    throw InputError(input, "wavelength range must be increasing (got [" + num(lambda_lo_nm) + ", " +
                                num(lambda_hi_nm) + "])");
  }
  const CheckedPicture picture = read_picture_checked(
      image, {"a transfer-function image", "a transfer function", "libpng", kMaxTfPixels, kMaxTfExpansion, 3}, input);
  const int w = picture.width, h = picture.height, nc = picture.channels;
  const std::vector<float>& px = picture.pixels;

  // Wavelengths of the pixel centres.
  std::vector<double> lambda(w);
  for (int x = 0; x < w; ++x) lambda[x] = lambda_lo_nm + (x + 0.5) / w * (lambda_hi_nm - lambda_lo_nm);

  TransferFunction tf;
  std::map<std::vector<float>, int> row_material;  // distinct row contents → material index
  std::vector<int> row_index(h, -1);
  for (int y = 0; y < h; ++y) {
    std::vector<float> row(static_cast<std::size_t>(w) * 3);
    bool any_extinction = false;
    for (int x = 0; x < w; ++x) {
      const float* p = &px[(static_cast<std::size_t>(y) * w + x) * nc];
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(p[c]) || p[c] < 0.0f || (c != 1 && p[c] > 1.0f)) {
          throw InputError(input, "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") channel " + "RGB"[c] +
                                      " = " + num(p[c]) + " is outside [0, 1]");
        }
        row[static_cast<std::size_t>(x) * 3 + c] = p[c];
      }
      any_extinction |= p[1] > 0.0f;
    }
    if (!any_extinction) continue;  // empty space
    auto [it, inserted] = row_material.try_emplace(row, static_cast<int>(tf.materials.size()));
    if (inserted) {
      if (tf.materials.size() >= 65534) throw InputError(input, "more than 65534 distinct rows");
      std::vector<double> albedo(w), sigma(w), g(w);
      for (int x = 0; x < w; ++x) {
        albedo[x] = row[x * 3 + 0];
        sigma[x] = row[x * 3 + 1] * extinction_scale;
        g[x] = std::clamp(2.0 * row[x * 3 + 2] - 1.0, -kMaxAbsG, kMaxAbsG);
      }
      Material m;
      m.name = "row" + std::to_string(y);
      if (w == 1) {
        m.albedo = Spectrum::constant(albedo[0]);
        m.sigma_t_per_unit = Spectrum::constant(sigma[0]);
        m.anisotropy = Spectrum::constant(g[0]);
      } else {
        m.albedo = Spectrum(lambda, albedo, input);
        m.sigma_t_per_unit = Spectrum(lambda, sigma, input);
        m.anisotropy = Spectrum(lambda, g, input);
      }
      tf.materials.push_back(std::move(m));
    }
    row_index[y] = it->second;
  }

  // Runs of rows with the same material become one rule. Row y holds the normalised values t with
  // round(t·(h − 1)) = y, i.e. t in [(y − 0.5)/(h − 1), (y + 0.5)/(h − 1)].
  const double inf = std::numeric_limits<double>::infinity();
  auto row_lo = [&](int y) { return y == 0 ? -inf : norm.from_unit((y - 0.5) / (h - 1)); };
  auto row_hi = [&](int y) { return y == h - 1 ? inf : norm.from_unit((y + 0.5) / (h - 1)); };
  for (int y = 0; y < h;) {
    int end = y + 1;
    while (end < h && row_index[end] == row_index[y]) ++end;
    if (row_index[y] >= 0) {
      MaterialRule r;
      r.material = row_index[y];
      r.value_lo = h == 1 ? -inf : row_lo(y);
      r.value_hi = h == 1 ? inf : row_hi(end - 1);
      tf.rules.push_back(r);
    }
    y = end;
  }
  return tf;
}

Medium build_medium(const Volume& vol, const TransferFunction& tf, const std::string& input,
                    Interpolation interpolation) {
  if (tf.materials.size() > 65534) {
    throw InputError(input, "at most 65534 materials are supported (got " + std::to_string(tf.materials.size()) + ")");
  }
  for (const MaterialRule& r : tf.rules) {
    if (r.material < 0 || static_cast<std::size_t>(r.material) >= tf.materials.size()) {
      throw InputError(input, "rule names material " + std::to_string(r.material) + ", which does not exist");
    }
  }
  const std::size_t count = vol.voxel_count();
  if (vol.values.size() != count || count == 0) {
    throw InputError(input, "volume has " + std::to_string(vol.values.size()) + " values for " +
                                std::to_string(count) + " voxels");
  }

  Medium m;
  m.dims = vol.dims;
  m.materials = tf.materials;
  m.interpolation = interpolation;
  if (interpolation == Interpolation::Trilinear) {
    m.value = vol.values;
    m.rules = tf.rules;
  }
  if (!vol.block_range.empty()) {  // a sparse source's block ranges: the majorant grid classifies them
    m.block_range = vol.block_range;
    m.rules = tf.rules;
  }

  // World box: dims × spacing, largest side 1, centred at the origin.
  double extent[3];
  double largest = 0.0;
  for (int a = 0; a < 3; ++a) {
    extent[a] = vol.dims[a] * vol.spacing[a];
    largest = std::max(largest, extent[a]);
  }
  if (!(largest > 0.0) || !std::isfinite(largest)) throw InputError(input, "volume has no extent");
  for (int a = 0; a < 3; ++a) {
    m.bounds_min[a] = -0.5 * extent[a] / largest;
    m.bounds_max[a] = 0.5 * extent[a] / largest;
  }

  // Per voxel: first matching rule. A voxel with its predecessor's value takes its result (label and
  // segmented volumes are runs of a few values; the rules and the density ramp need not run again).
  m.material.assign(count, Medium::kEmpty);
  m.density.assign(count, 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
    float last_value = std::numeric_limits<float>::quiet_NaN();  // equal to no value
    std::uint16_t last_material = Medium::kEmpty;
    float last_density = 0.0f;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const float value = vol.values[i];
      if (value != last_value) {
        last_value = value;
        last_material = Medium::kEmpty;
        last_density = 0.0f;
        const double v = value;
        if (!std::isfinite(v)) continue;
        for (const MaterialRule& rule : tf.rules) {
          if (v >= rule.value_lo && v <= rule.value_hi) {
            const double d = rule.density.eval(v);
            if (d > 0.0) {
              last_material = static_cast<std::uint16_t>(rule.material);
              last_density = static_cast<float>(d);
            }
            break;
          }
        }
      }
      m.material[i] = last_material;
      m.density[i] = last_density;
    }
  });
  return m;
}

}  // namespace prizma::render
