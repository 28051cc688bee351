#pragma once
// Helpers of the numerical stress tests: scenes built in code, the bounded/full switch, and the checks
// every stress case runs (finite and non-negative, agreement within error bars with a Bonferroni
// threshold, variance of the mean shrinking like 1/N).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "prizma/render/render.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::stress {

namespace pr = prizma::render;
namespace ps = prizma::spectral;

// PRIZMA_STRESS_FULL=1 runs the long version (512³ volumes, more samples).
inline bool full_run() {
  const char* v = std::getenv("PRIZMA_STRESS_FULL");
  return v != nullptr && std::string(v) == "1";
}

// A constant-spectrum material.
inline pr::Material grey_material(double albedo, double sigma_t, double g) {
  pr::Material m;
  m.name = "grey";
  m.albedo = ps::Spectrum::constant(albedo);
  m.sigma_t_per_unit = ps::Spectrum::constant(sigma_t);
  m.anisotropy = ps::Spectrum::constant(g);
  return m;
}

// σt(λ) = lo·(hi/lo)^((λ − 380)/400): log-linear from lo at 380 nm to hi at 780 nm, tabulated every
// 5 nm (the renderer interpolates linearly between table points; references use the same table).
inline ps::Spectrum log_ramp(double lo, double hi) {
  std::vector<double> l, v;
  for (double x = 380; x <= 780.0 + 1e-9; x += 5) {
    l.push_back(x);
    v.push_back(lo * std::pow(hi / lo, (x - 380.0) / 400.0));
  }
  return ps::Spectrum(l, v);
}

// Bin average of exp(−σt(λ)·length) over each bin, by the midpoint rule on 0.01 nm steps (σt is the
// piecewise-linear table the renderer interpolates; its integrand is smooth between table points).
inline std::vector<double> bin_average_transmittance(const ps::Spectrum& sigma_t, const ps::BinLayout& bins, double length) {
  std::vector<double> out;
  for (int i = 0; i < bins.size(); ++i) {
    const int steps = std::max(1, static_cast<int>(bins.width_nm(i) / 0.01));
    const double h = bins.width_nm(i) / steps;
    double sum = 0.0;
    for (int k = 0; k < steps; ++k) sum += std::exp(-sigma_t.eval(bins.lo_nm(i) + (k + 0.5) * h) * length);
    out.push_back(sum / steps);
  }
  return out;
}

// A medium of dims voxels over the box [lo, hi], every voxel holding material 0 at density 1, unless
// `fill` says otherwise (voxel centres in [−1, 1]³ → density; 0 = empty).
inline pr::Medium box_medium(std::array<int, 3> dims, const pr::Material& mat,
                             Eigen::Vector3d lo = Eigen::Vector3d(-0.5, -0.5, -0.5),
                             Eigen::Vector3d hi = Eigen::Vector3d(0.5, 0.5, 0.5),
                             const std::function<float(double, double, double)>& fill = {}) {
  pr::Medium m;
  m.dims = dims;
  m.bounds_min = lo;
  m.bounds_max = hi;
  m.materials = {mat};
  m.material.assign(m.voxel_count(), 0);
  m.density.assign(m.voxel_count(), 1.0f);
  if (fill) {
    std::size_t v = 0;
    for (int z = 0; z < dims[2]; ++z)
      for (int y = 0; y < dims[1]; ++y)
        for (int x = 0; x < dims[0]; ++x, ++v) {
          const float d = fill((x + 0.5) / dims[0] * 2 - 1, (y + 0.5) / dims[1] * 2 - 1, (z + 0.5) / dims[2] * 2 - 1);
          m.density[v] = d;
          if (d <= 0.0f) m.material[v] = pr::Medium::kEmpty;
        }
  }
  return m;
}

// The slab scene: an orthographic camera looking down −z at the box, every pixel's ray crossing the
// full depth (ortho height 0.8 inside the box's unit side). Lights: the uniform environment and, when
// `key` is set, a directional light from (1, 1, 1).
inline pr::Scene slab_scene(pr::Medium medium, bool key, int size = 8, int bins = 4) {
  pr::Scene s;
  s.medium = std::move(medium);
  pr::Light env;
  env.name = "env";
  s.lights.push_back(env);
  if (key) {
    pr::Light k;
    k.name = "key";
    k.direction = Eigen::Vector3d(1, 1, 1);
    s.lights.push_back(k);
  }
  s.camera.type = pr::CameraType::Orthographic;
  s.camera.position = Eigen::Vector3d(0, 0, 2);
  s.camera.look_at = Eigen::Vector3d(0, 0, 0);
  s.camera.ortho_height = 0.8;
  s.camera.width = size;
  s.camera.height = size;
  s.settings.bins = ps::BinLayout::linear(380, 780, bins);
  s.settings.write_variance = true;
  s.settings.threads = 0;
  s.hash = "stress";
  return s;
}

inline ps::SpectralImage render_range(pr::Scene s, std::int64_t begin, std::int64_t end, std::uint64_t seed,
                                      pr::WavelengthSampling w = pr::WavelengthSampling::SpectralTracking,
                                      bool grid = true, pr::RenderStats* stats = nullptr) {
  s.settings.sample_begin = begin;
  s.settings.sample_end = end;
  s.settings.seed = seed;
  s.settings.wavelength_sampling = w;
  s.settings.use_majorant_grid = grid;
  return pr::render(s, {}, stats);
}

// Two-sided normal quantile z with P(|Z| > z) = p, by bisection on erfc.
inline double two_sided_z(double p) {
  double lo = 0.0, hi = 40.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > p) lo = mid;
    else hi = mid;
  }
  return hi;
}

// Family-wise false-alarm probability of every agreement check (Bonferroni over its comparisons).
constexpr double kFamilyAlpha = 1e-4;

// Every value finite and ≥ 0 (variances too).
inline void expect_finite_non_negative(const ps::SpectralImage& img, const std::string& what) {
  std::size_t bad = 0;
  float worst = 0.0f;
  for (const auto& layer : img.lights) {
    for (float v : layer.data)
      if (!std::isfinite(v) || v < 0.0f) {
        ++bad;
        worst = v;
      }
    for (float v : layer.variance)
      if (!std::isfinite(v) || v < 0.0f) ++bad;
  }
  EXPECT_EQ(bad, 0u) << what << ": non-finite or negative values (e.g. " << worst << ")";
}

// Per light and bin, the image means over groups of `bin_group` adjacent bins (pixels are
// independent, so Var = Σ var / P²) of two renders agree within the Bonferroni threshold. For values
// that one render resolves too poorly for a per-pixel test: the one-wavelength method with many bins
// (each bin sees 1/bins of its samples), or rare contributions that it did not see in some pixels.
// Groups of adjacent bins give that method bin_group times the samples: its per-bin estimate from
// a few rare, large samples is skewed (usually low, with a sample variance low with it), and a test
// of skewed means against their own variance estimates fails far more often than its nominal rate.
inline void expect_image_means_agree(const ps::SpectralImage& a, const ps::SpectralImage& b, const std::string& what,
                                     int bin_group = 1) {
  const int nb = a.bins.size();
  const std::size_t pixels = a.pixel_count();
  const int groups = (nb + bin_group - 1) / bin_group;
  const std::size_t comparisons = a.lights.size() * static_cast<std::size_t>(groups);
  const double z_max = std::max(4.0, two_sided_z(kFamilyAlpha / static_cast<double>(comparisons)));
  std::size_t failures = 0;
  double worst = 0.0;
  std::string detail;
  for (std::size_t l = 0; l < a.lights.size(); ++l)
    for (int i0 = 0; i0 < nb; i0 += bin_group) {
      const int i1 = std::min(nb, i0 + bin_group);
      double ma = 0, mb = 0, va = 0, vb = 0;
      for (std::size_t p = 0; p < pixels; ++p)
        for (int i = i0; i < i1; ++i) {
          const std::size_t k = p * nb + i;
          ma += a.lights[l].data[k];
          mb += b.lights[l].data[k];
          va += a.lights[l].variance[k];
          vb += b.lights[l].variance[k];
        }
      // One render's samples were all 0 in every pixel (a contribution too rare for all of them, e.g.
      // a transmittance of 1e-6): its error is unknown, so there is nothing to compare (the exact
      // checks cover such values where a closed form exists). All equal but not 0: that render is
      // exact there (a furnace), compared with the other's variance alone.
      if ((va > 0) != (vb > 0) && (va > 0 ? mb : ma) == 0.0) continue;
      const double var = va + vb;
      const double z = var > 0 ? std::abs(ma - mb) / std::sqrt(var) : (std::abs(ma - mb) <= 1e-6 * pixels ? 0 : 1e30);
      worst = std::max(worst, z);
      if (z > z_max) {
        ++failures;
        if (failures <= 8)
          detail += " [light " + a.lights[l].name + " bins " + std::to_string(i0) + "–" + std::to_string(i1 - 1) +
                    ": " + std::to_string(ma / pixels) + " vs " + std::to_string(mb / pixels) + ", z " +
                    std::to_string(z) + "]";
      }
    }
  EXPECT_EQ(failures, 0u) << what << ": " << failures << " of " << comparisons << " image means differ by more than "
                          << z_max << " standard errors (worst " << worst << ")" << detail;
}

// Per pixel, light and bin: |a − b| ≤ z·sqrt(var_a + var_b), z the Bonferroni threshold for family-wise
// false-alarm probability kFamilyAlpha over all comparisons (at least 4 standard errors). Where both
// variances are 0 the values must be equal to float precision. Where only one is 0, that render saw no
// variation in the value (typically: none of its samples reached a rare contribution), so its error
// is unknown and may be far larger than the other's: such values are not compared per pixel (taking
// the other render's variance for it made a precise render fail against one that saw nothing, the
// more often the more precise it was), and the image means per light and bin are compared as well
// (expect_image_means_agree), where every pixel's samples count. Returns the largest per-pixel |z|.
inline double expect_agree(const ps::SpectralImage& a, const ps::SpectralImage& b, const std::string& what) {
  std::size_t comparisons = 0;
  for (const auto& layer : a.lights) comparisons += layer.data.size();
  const double z_max = std::max(4.0, two_sided_z(kFamilyAlpha / static_cast<double>(comparisons)));
  double worst = 0.0;
  std::string worst_at;
  std::size_t failures = 0, unresolved = 0;
  const int nb = a.bins.size();
  for (std::size_t l = 0; l < a.lights.size(); ++l) {
    const auto& la = a.lights[l];
    const auto& lb = b.lights[l];
    for (std::size_t k = 0; k < la.data.size(); ++k) {
      const double d = std::abs(static_cast<double>(la.data[k]) - lb.data[k]);
      const double va = la.variance[k], vb = lb.variance[k];
      double z;
      if (va > 0 && vb > 0) {
        z = d / std::sqrt(va + vb);
      } else if (va > 0 || vb > 0) {
        ++unresolved;
        continue;
      } else {
        z = d <= 1e-6 * std::max(1.0, std::abs(static_cast<double>(la.data[k]))) ? 0.0 : 1e30;
      }
      if (z > worst) {
        worst = z;
        worst_at = "light " + la.name + " pixel " + std::to_string(k / nb) + " bin " + std::to_string(k % nb) +
                   ": " + std::to_string(la.data[k]) + " vs " + std::to_string(lb.data[k]) +
                   " (sd " + std::to_string(std::sqrt(va + vb)) + ")";
      }
      if (z > z_max) ++failures;
    }
  }
  EXPECT_EQ(failures, 0u) << what << ": " << failures << " of " << comparisons << " values differ by more than "
                          << z_max << " standard errors; worst " << worst << " at " << worst_at;
  if (unresolved > 0)
    expect_image_means_agree(a, b, what + " (image means; " + std::to_string(unresolved) +
                                       " values with variance 0 in one render)");
  return worst;
}

// Each pixel and bin against an exact value: |x − exact| ≤ z·sd (Bonferroni as above); where the
// estimate's variance is 0 it must equal the exact value to `tol`.
// `sd_floor(bin)` (optional) is a lower bound of the standard error known from the model (e.g. the
// Bernoulli error of an analog estimator), used where the sample variance can be 0 by chance.
inline void expect_exact(const ps::SpectralImage& img, int light,
                         const std::function<double(int bin)>& exact, const std::string& what,
                         const std::function<double(int bin)>& sd_floor = {}, double tol = 1e-5) {
  const auto& layer = img.lights[static_cast<std::size_t>(light)];
  const int nb = img.bins.size();
  const double z_max = std::max(4.0, two_sided_z(kFamilyAlpha / static_cast<double>(layer.data.size())));
  std::size_t failures = 0;
  double worst = 0.0;
  std::string worst_at;
  for (std::size_t k = 0; k < layer.data.size(); ++k) {
    const int bin = static_cast<int>(k % nb);
    const double e = exact(bin);
    const double d = std::abs(layer.data[k] - e);
    double sd = std::sqrt(static_cast<double>(layer.variance[k]));
    if (sd_floor) sd = std::max(sd, sd_floor(bin));
    const double z = sd > 0 ? d / sd : (d <= tol * std::max(1.0, e) ? 0.0 : 1e30);
    if (z > worst) {
      worst = z;
      worst_at = "pixel " + std::to_string(k / nb) + " bin " + std::to_string(bin) + ": " +
                 std::to_string(layer.data[k]) + " vs exact " + std::to_string(e) + " (sd " + std::to_string(sd) + ")";
    }
    if (z > z_max) ++failures;
  }
  EXPECT_EQ(failures, 0u) << what << ": " << failures << " values beyond " << z_max
                          << " standard errors of the exact value; worst " << worst << " at " << worst_at;
}

// Σ variance of the mean over the image at N samples and at 4N samples (the latter including the
// first N): their ratio must be near 4. Tolerance [2, 16]: wide because the variance estimate is itself
// a noisy (and for heavy-tailed paths, skewed) statistic. An infinite or exploding variance makes the
// sample variance grow with N, giving ratios near 1 or below; the upper bound only catches a broken
// variance layer (one large sample in the first N is diluted at 4N, so ratios up to ~10 occur).
inline void expect_variance_shrinks(const ps::SpectralImage& n1, const ps::SpectralImage& n4, const std::string& what) {
  double v1 = 0, v4 = 0;
  for (const auto& l : n1.lights)
    for (float v : l.variance) v1 += v;
  for (const auto& l : n4.lights)
    for (float v : l.variance) v4 += v;
  // No variation seen in the first N samples (a deterministic estimate such as the grey furnace, or a
  // rare event not yet reached): nothing to compare.
  if (v1 == 0.0) return;
  const double ratio = v1 / v4;
  EXPECT_GT(ratio, 2.0) << what << ": variance of the mean did not shrink from N to 4N (ratio " << ratio << ")";
  EXPECT_LT(ratio, 16.0) << what << ": variance of the mean shrank implausibly fast from N to 4N (ratio " << ratio
                        << ")";
}

}  // namespace prizma::stress
