#pragma once
// Tiny hand-built scenes for the renderer's tests: a box medium seen by an orthographic camera
// looking down −z, so every pixel's ray crosses the box along z over its full depth.
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "prizma/render/render.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::render::testing {

inline constexpr double kSe = 3.0;  // tolerance of the statistical tests in standard errors (fixed seeds)

// Every light layer (and variance layer) of a and b the same to the bit.
inline bool same_bits(const spectral::SpectralImage& a, const spectral::SpectralImage& b) {
  if (a.lights.size() != b.lights.size()) return false;
  for (std::size_t l = 0; l < a.lights.size(); ++l) {
    const auto& x = a.lights[l].data;
    const auto& y = b.lights[l].data;
    if (x.size() != y.size() || std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) != 0) return false;
    if (a.lights[l].variance != b.lights[l].variance) return false;
  }
  return true;
}

inline Material make_material(spectral::Spectrum albedo, spectral::Spectrum sigma_t, spectral::Spectrum g) {
  Material m;
  m.name = "m";
  m.albedo = std::move(albedo);
  m.sigma_t_per_unit = std::move(sigma_t);
  m.anisotropy = std::move(g);
  return m;
}

inline Material grey_material(double albedo, double sigma_t, double g = 0.0) {
  return make_material(spectral::Spectrum::constant(albedo), spectral::Spectrum::constant(sigma_t),
                       spectral::Spectrum::constant(g));
}

inline Light environment_light(std::string name = "env") {
  Light l;
  l.name = std::move(name);
  l.direction = Eigen::Vector3d::Zero();
  l.spectrum_spec = "E";
  return l;
}

inline Light directional_light(std::string name, Eigen::Vector3d dir, double angular_size_deg = 0.0) {
  Light l;
  l.name = std::move(name);
  l.direction = dir;
  l.angular_size_deg = angular_size_deg;
  l.spectrum_spec = "E";
  return l;
}

// A unit box [−0.5, 0.5]³ of n³ voxels, all of material 0 at density 1, one environment light, an
// orthographic camera of ortho_height 0.8 (every ray crosses the box over depth 1), 8×8 pixels.
inline Scene box_scene(const Material& material, int n = 4, int pixels = 8, std::int64_t spp = 64) {
  Scene s;
  s.medium.dims = {n, n, n};
  s.medium.material.assign(s.medium.voxel_count(), 0);
  s.medium.density.assign(s.medium.voxel_count(), 1.0f);
  s.medium.materials = {material};
  s.lights = {environment_light()};
  s.camera.type = CameraType::Orthographic;
  s.camera.position = {0, 0, 2};
  s.camera.look_at = {0, 0, 0};
  s.camera.up = {0, 1, 0};
  s.camera.ortho_height = 0.8;
  s.camera.width = pixels;
  s.camera.height = pixels;
  s.settings.bins = spectral::BinLayout::linear(400, 700, 6);
  s.settings.sample_begin = 0;
  s.settings.sample_end = spp;
  s.settings.seed = 7;
  s.settings.write_variance = true;
  s.hash = "test";
  return s;
}

// A box seen straight down (emergent μ = 1) through a small central window (ortho height 0.1), so
// that every light path toward a light within 25° of the zenith leaves through the top face, lit by
// `light` only.
inline Scene window_scene(const Material& m, const Light& light, int pixels, std::int64_t spp) {
  Scene s = box_scene(m, 4, pixels, spp);
  s.camera.ortho_height = 0.1;
  s.lights = {light};
  return s;
}

// Fills the density with a fixed pseudo-random field in [lo, hi] (heterogeneous medium).
inline void randomise_density(Scene& s, float lo, float hi, unsigned seed = 3) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  for (float& d : s.medium.density) d = dist(gen);
}

// The chromatic white furnace: albedo 1, σt from 6 to 1 per unit and HG g from g400 to g700 over
// 400–700 nm, a 6³ random density field in [0.2, 2], unit environment: every bin's expectation is 1.
inline Scene chromatic_furnace(double g400, double g700, int pixels, std::int64_t spp) {
  Scene s = box_scene(make_material(spectral::Spectrum::constant(1.0), spectral::Spectrum({400.0, 700.0}, {6.0, 1.0}),
                                    spectral::Spectrum({400.0, 700.0}, {g400, g700})),
                      6, pixels, spp);
  randomise_density(s, 0.2f, 2.0f);
  return s;
}

// A small chromatic heterogeneous box (wavelength-dependent albedo and extinction, random density)
// under one directional light: the determinism and resume tests' scene.
inline Scene chromatic_scene(std::int64_t spp) {
  Scene s = box_scene(make_material(spectral::Spectrum({400.0, 700.0}, {0.95, 0.7}),
                                    spectral::Spectrum({400.0, 700.0}, {4.0, 1.0}), spectral::Spectrum::constant(0.5)),
                      8, 12, spp);
  randomise_density(s, 0.0f, 2.0f);
  s.lights.push_back(directional_light("sun", {0.5, 1, 0.2}));
  return s;
}

// Per bin: the mean over all pixels of a layer and its standard error from the variance layer
// (pixels are independent, so var(mean over P pixels) = Σ var_p / P²).
struct BinEstimate {
  std::vector<double> mean, se;
};
inline BinEstimate pixel_average(const spectral::SpectralImage& img, int light) {
  const int nb = img.bins.size();
  const auto& layer = img.lights[light];
  BinEstimate e{std::vector<double>(nb, 0.0), std::vector<double>(nb, 0.0)};
  const double p = static_cast<double>(img.pixel_count());
  for (std::size_t px = 0; px < img.pixel_count(); ++px)
    for (int i = 0; i < nb; ++i) {
      e.mean[i] += layer.data[px * nb + i] / p;
      if (!layer.variance.empty()) e.se[i] += layer.variance[px * nb + i] / (p * p);
    }
  for (double& v : e.se) v = std::sqrt(v);
  return e;
}

// Bin average over [lo, hi] of e^{−D σ(λ)} for σ linear in λ: (e^{−D σ(lo)} − e^{−D σ(hi)}) / (D (σ(hi) − σ(lo))).
inline double bin_transmittance(double sigma_lo, double sigma_hi, double depth) {
  const double a = depth * sigma_lo, b = depth * sigma_hi;
  return std::abs(b - a) < 1e-12 ? std::exp(-a) : (std::exp(-a) - std::exp(-b)) / (b - a);
}

// The window [−0.4, 0.4]² of a 4³ box_scene seen from above, over its columns [−0.5 + k/4,
// −0.25 + k/4] (widths 0.15, 0.25, 0.25, 0.15): Σ over the columns of their area fraction times
// f(D), D = the column's mean density.
template <class F>
double column_window_average(const Scene& s, F f) {
  const double width[4] = {0.15, 0.25, 0.25, 0.15};
  double sum = 0.0;
  for (int cy = 0; cy < 4; ++cy)
    for (int cx = 0; cx < 4; ++cx) {
      double depth = 0.0;
      for (int cz = 0; cz < 4; ++cz) depth += s.medium.density[(static_cast<std::size_t>(cz) * 4 + cy) * 4 + cx] / 4.0;
      sum += width[cx] * width[cy] / 0.64 * f(depth);
    }
  return sum;
}

}  // namespace prizma::render::testing
