#pragma once
// Shared pieces of the accuracy benchmarks (bench_error_vs_time, bench_bin_study): the benchmark
// scenes, a reference-render cache, and the error metrics (relative RMSE of the transport, CIEDE2000
// of a relit image).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/render/render.h"
#include "prizma/render/scene.h"
#include "prizma/render/transfer_function.h"
#include "prizma/render/volume.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::bench {

namespace fs = std::filesystem;

// The repository's data/ folder (compile definition from bench/CMakeLists.txt).
inline fs::path source_data_dir() { return fs::path(PRIZMA_BENCH_DATA_DIR); }

// Bin average of a spectrum over [lo, hi] as a constant spectrum: the "grey" version of a material.
inline spectral::Spectrum grey_of(const spectral::Spectrum& s, double lo_nm, double hi_nm) {
  if (s.is_constant()) return s;
  return spectral::Spectrum::constant(s.integrate(lo_nm, hi_nm) / (hi_nm - lo_nm));
}

// The scene with every material's spectra replaced by their averages over the bins: the same geometry
// and mean optical thickness, wavelength-independent (the renderer traces it once for all bins).
// With bin >= 0, the averages over that one bin instead: the medium lane `bin` sees, traced alone (what
// a renderer that gave each bin its own paths would trace for it).
inline render::Scene make_grey(render::Scene scene, int bin = -1) {
  const spectral::BinLayout& b = scene.settings.bins;
  const double lo = bin < 0 ? b.min_nm() : b.lo_nm(bin), hi = bin < 0 ? b.max_nm() : b.hi_nm(bin);
  for (auto& m : scene.medium.materials) {
    m.albedo = grey_of(m.albedo, lo, hi);
    m.sigma_t_per_unit = grey_of(m.sigma_t_per_unit, lo, hi);
    m.anisotropy = grey_of(m.anisotropy, lo, hi);
  }
  scene.hash += bin < 0 ? "-grey" : "-grey-bin" + std::to_string(bin);
  return scene;
}

// Fallback chromatic cube when data/scenes/cube_sphere.json is missing: VPT's sphere_in_cube volume,
// a thin bluish-scattering cube around a dense reddish sphere, one key light and the environment.
inline render::Scene builtin_cube_sphere(int resolution) {
  render::Volume vol = render::make_procedural_volume("cube_sphere", resolution);
  render::TransferFunction tf;
  render::Material cube;
  cube.name = "cube";
  cube.albedo = spectral::Spectrum({380, 480, 580, 780}, {0.95, 0.9, 0.6, 0.3});
  cube.sigma_t_per_unit = spectral::Spectrum({380, 500, 600, 780}, {8.0, 4.0, 2.0, 1.0});
  cube.anisotropy = spectral::Spectrum::constant(0.3);
  render::Material sphere;
  sphere.name = "sphere";
  sphere.albedo = spectral::Spectrum({380, 550, 600, 780}, {0.2, 0.3, 0.9, 0.95});
  sphere.sigma_t_per_unit = spectral::Spectrum({380, 550, 780}, {40.0, 20.0, 10.0});
  sphere.anisotropy = spectral::Spectrum::constant(0.0);
  tf.materials = {cube, sphere};
  render::MaterialRule r1;
  r1.value_lo = 50;
  r1.value_hi = 150;
  r1.material = 0;
  render::MaterialRule r2;
  r2.value_lo = 200;
  r2.value_hi = 300;
  r2.material = 1;
  tf.rules = {r1, r2};
  render::Scene scene;
  scene.medium = render::build_medium(vol, tf, "builtin cube_sphere");
  render::Light key;
  key.name = "key";
  key.direction = Eigen::Vector3d(1, 1, 1);
  render::Light env;
  env.name = "env";
  scene.lights = {key, env};
  scene.hash = "builtin-cube-sphere-" + std::to_string(resolution);
  return scene;
}

// A benchmark scene by name: "grey" (the cube with grey materials), "cube", "metamers", "mri",
// "peer" (bench_peer.json, the pbrt-v4 anchor's Rayleigh medium), any other data/scenes/NAME.json
// ("fluorescent_dye", "cloud_vdb", "sky_haze"), and NAME-grey for any of them: its materials replaced
// by their bin averages (make_grey). Returns false (and says why) when a file is missing or fails.
inline bool load_bench_scene(const std::string& name, render::Scene& out, std::string& why) {
  constexpr std::string_view kGrey = "-grey";
  if (name.size() > kGrey.size() && name.ends_with(kGrey)) {
    if (!load_bench_scene(name.substr(0, name.size() - kGrey.size()), out, why)) return false;
    out = make_grey(out);
    return true;
  }
  const fs::path dir = source_data_dir() / "scenes";
  auto from_file = [&](const std::string& file) {
    const fs::path p = dir / file;
    if (!fs::exists(p)) {
      why = p.string() + " not found";
      return false;
    }
    try {
      out = render::load_scene(p);
    } catch (const std::exception& e) {
      why = e.what();
      return false;
    }
    return true;
  };
  if (name == "cube" || name == "grey") {
    if (!from_file("cube_sphere.json")) {
      std::cerr << "note: " << why << "; using the built-in chromatic cube\n";
      out = builtin_cube_sphere(128);
    }
    if (name == "grey") out = make_grey(out);
    return true;
  }
  if (name == "peer") return from_file("bench_peer.json");
  if (!name.empty() && name.find('/') == std::string::npos && fs::exists(dir / (name + ".json")))
    return from_file(name + ".json");
  why = "unknown scene \"" + name + "\" (known: grey, cube, peer, a data/scenes/NAME.json, NAME-grey)";
  return false;
}

// Writes a text file atomically, creating its folder.
inline void write_text(const fs::path& path, const std::string& text) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  spectral::write_file_atomically(path, text);
}

// FNV-1a of a string, hex: cache keys.
inline std::string hash_hex(const std::string& s) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  std::ostringstream o;
  o << std::hex << h;
  return o.str();
}

// Renders (or reads from the cache folder) an image keyed on the scene hash and every setting that
// changes the result.
// folded: render::render_folded (a reference with the lights folded in), else render::render.
inline spectral::SpectralImage cached_render(const render::Scene& scene, const fs::path& cache_dir,
                                             const std::string& tag, double* seconds = nullptr, bool folded = false) {
  const auto& st = scene.settings;
  std::ostringstream key;
  key << scene.hash << '|' << scene.camera.width << 'x' << scene.camera.height << '|' << st.bins.to_string() << '|'
      << st.sample_begin << ':' << st.sample_end << '|' << st.seed << '|'
      << render::wavelength_sampling_name(st.wavelength_sampling) << '|' << folded << '|'
      << st.write_variance << '|' << st.max_bounces << '|' << render::event_probabilities_name(st.event_probabilities);
  if (st.sampler != render::Sampler::Independent) key << '|' << render::sampler_name(st.sampler);  // older keys unchanged
  // A render with guide layers is another file (bench_denoise_error --features denoises the cached bias
  // render with them: one cached without would silently be denoised on the luminance alone).
  if (st.write_guides) key << "|guides";  // older keys unchanged
  // Spectral MIS's lane groups as resolved (auto became 3 groups on the cube and bench_peer): other bits,
  // and 1.9-3.7x less variance per sample, which bench_denoise_error's reference-noise floor assumes
  // the reference shares with the raw renders.
  if (const int groups = render::resolve_mis_lane_groups(scene); groups > 1) key << "|groups" << groups;  // older keys unchanged
  for (const auto& l : scene.lights) key << '|' << l.name << ':' << l.spectrum_spec;
  const fs::path file = cache_dir / (tag + "-" + hash_hex(key.str()) + ".exr");
  if (fs::exists(file)) {
    try {
      if (seconds) *seconds = 0.0;
      return spectral::read_spectral_exr(file);
    } catch (const std::exception& e) {
      std::cerr << "note: cache file " << file << " unreadable (" << e.what() << "), rendering again\n";
    }
  }
  render::RenderStats stats;
  spectral::SpectralImage img = folded ? render::render_folded(scene, {}, &stats) : render::render(scene, {}, &stats);
  if (seconds) *seconds = stats.wall_seconds;
  fs::create_directories(cache_dir);
  spectral::write_spectral_exr(file, img);
  return img;
}

// Pixels whose camera rays (nearly) all miss the medium: every value of the reference exactly 0 or 1
// (the unit environment seen directly, no directional light). 1 = background.
inline std::vector<char> background_mask(const spectral::SpectralImage& ref) {
  std::vector<char> mask(ref.pixel_count(), 1);
  const std::size_t nb = static_cast<std::size_t>(ref.bins.size());
  for (const auto& layer : ref.lights)
    for (std::size_t p = 0; p < ref.pixel_count(); ++p)
      for (std::size_t i = 0; i < nb; ++i) {
        const float v = layer.data[p * nb + i];
        if (v != 0.0f && v != 1.0f) mask[p] = 0;
      }
  return mask;
}

// Relative RMSE of the transport over every pixel, light and bin: sqrt(Σ(x − r)² / Σ r²). With
// `ref_variance_sum` > 0 (Σ of the reference's variance of the mean), the reference's own noise is
// subtracted from the numerator (E[(x − r)²] = (x − E r)² + Var r).
// `skip` (optional, per pixel): pixels left out (e.g. the background).
inline double relative_rmse(const spectral::SpectralImage& x, const spectral::SpectralImage& ref,
                            double* corrected = nullptr, const std::vector<char>* skip = nullptr) {
  double num = 0.0, den = 0.0, var = 0.0;
  const std::size_t nb = static_cast<std::size_t>(ref.bins.size());
  for (std::size_t l = 0; l < ref.lights.size(); ++l) {
    const auto& a = x.lights[l].data;
    const auto& r = ref.lights[l].data;
    const auto& rv = ref.lights[l].variance;
    for (std::size_t k = 0; k < r.size(); ++k) {
      if (skip && (*skip)[k / nb]) continue;
      const double d = static_cast<double>(a[k]) - r[k];
      num += d * d;
      den += static_cast<double>(r[k]) * r[k];
      if (!rv.empty()) var += rv[k];
    }
  }
  if (corrected) *corrected = std::sqrt(std::max(0.0, num - var) / den);
  return std::sqrt(num / den);
}

// Relights every layer of `img` with the same light spec (relative to white).
inline spectral::XyzImage relight_all(const spectral::SpectralImage& img, const std::string& light,
                                     Eigen::Vector3d* white = nullptr) {
  std::vector<spectral::LightSpectrum> specs;
  for (std::size_t l = 0; l < img.lights.size(); ++l) specs.push_back(spectral::parse_light_spectrum(light));
  const spectral::RelightMatrix m(img.bins, specs, spectral::RelightOptions{});
  if (white) *white = m.mix_white_xyz();
  return spectral::relight_image(img, m);
}

struct DeltaEStats {
  double mean = 0.0;
  double max = 0.0;
  double p95 = 0.0;
};

// CIEDE2000 between two XYZ images, per pixel, in CIELAB relative to `white`.
inline DeltaEStats delta_e_stats(const spectral::XyzImage& a, const spectral::XyzImage& b,
                                 const Eigen::Vector3d& white) {
  std::vector<double> de(a.pixel_count());
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    const Eigen::Vector3d xa(a.xyz[3 * p], a.xyz[3 * p + 1], a.xyz[3 * p + 2]);
    const Eigen::Vector3d xb(b.xyz[3 * p], b.xyz[3 * p + 1], b.xyz[3 * p + 2]);
    de[p] = spectral::delta_e2000(spectral::xyz_to_lab(xa, white), spectral::xyz_to_lab(xb, white));
  }
  DeltaEStats s;
  for (double v : de) {
    s.mean += v;
    s.max = std::max(s.max, v);
  }
  s.mean /= static_cast<double>(de.size());
  std::sort(de.begin(), de.end());
  s.p95 = de[std::min(de.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(de.size())))];
  return s;
}

// Folded-light images store bin averages of T·E: XYZ = k Σ_i T̄E_i ∫_{bin i} cmf dλ with
// k = 1/∫_{bins} E ȳ dλ (the same white normalisation as the relighter).
inline spectral::XyzImage folded_to_xyz(const spectral::SpectralImage& img, const std::string& light) {
  const spectral::LightSpectrum ls = spectral::parse_light_spectrum(light);
  const auto& cmf = spectral::ColorMatching::get(spectral::Observer::Cie1931_2deg);
  const int nb = img.bins.size();
  Eigen::Matrix<double, 3, Eigen::Dynamic> w(3, nb);
  for (int i = 0; i < nb; ++i)
    for (int c = 0; c < 3; ++c) w(c, i) = cmf.channel(c).integrate(img.bins.lo_nm(i), img.bins.hi_nm(i));
  const double k = 1.0 / ls.spectrum.integrate_product(cmf.y(), img.bins.min_nm(), img.bins.max_nm());
  spectral::XyzImage out;
  out.width = img.width;
  out.height = img.height;
  out.xyz.assign(3 * img.pixel_count(), 0.0f);
  for (std::size_t p = 0; p < img.pixel_count(); ++p) {
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
    for (const auto& layer : img.lights)
      for (int i = 0; i < nb; ++i) xyz += w.col(i) * static_cast<double>(layer.data[p * nb + i]);
    xyz *= k * ls.scale;
    for (int c = 0; c < 3; ++c) out.xyz[3 * p + c] = static_cast<float>(xyz[c]);
  }
  return out;
}

}  // namespace prizma::bench
