// bench_denoise_error: issue 23's measurements of the denoiser. For each scene, raw renders at a few
// sample counts and their denoised versions are relit under several lights and compared with a
// cached high-sample reference (another seed): relMSE of the relit XYZ, the equal-error time ratio
// (raw time needed to reach the denoised error, the raw error falling as 1/time, over raw time +
// denoise time), and the bias of a high-sample denoised render as CIEDE2000 p99. Writes one CSV row
// per (scene, spp, light) and prints a summary; bench/denoise-error drives it and plots.
//
//   bench_denoise_error [--scenes cube_sphere,mri_head,cloud_vdb,bench_peer] [--size 256]
//       [--spp 16,64,256] [--bias-spp 4096] [--ref-spp 16384] [--threads 2]
//       [--lights D65,F11,gaussian:450:10] [--cache build-bench/cache] [--out FILE.csv]
//       [--images DIR] [--guides luminance,features,monte-carlo] [--features] [--references-only]
//       [--window R] [--patch F] [--strength K] [--strength-wide K] [--feature-k K] [--centre-threshold T]
//
// Several guide choices (comma-separated) denoise the same raw renders, one CSV row each.
//
// relMSE = mean over pixels and X, Y, Z of (x − r)² / (r² + ε), ε = 0.01 (Rousselle et al. 2011,
// Bitterli et al. 2016; white has Y = 1). The reference's own noise adds E[(r − E r)²/(r² + ε)] to
// every method alike; it is estimated as relMSE_raw(n)·n / N_ref (the raw error is variance, falling
// as 1/spp) and subtracted ("corrected" columns; the ratios use them).
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "bench_common.h"
#include "prizma/denoise/denoise.h"
#include "prizma/spectral/guide_names.h"

namespace pb = prizma::bench;
namespace pd = prizma::denoise;
namespace pr = prizma::render;
namespace ps = prizma::spectral;
namespace fs = std::filesystem;

namespace {

constexpr double kRelMseEpsilon = 0.01;

struct Options {
  std::vector<std::string> scenes{"cube_sphere", "mri_head", "cloud_vdb", "bench_peer"};
  int size = 256;
  std::vector<std::int64_t> spp{16, 64, 256};
  std::int64_t bias_spp = 4096;
  std::int64_t ref_spp = 16384;
  int threads = 2;
  std::vector<std::string> lights{"D65", "F11", "gaussian:450:10"};
  std::string cache = "build-bench/cache";
  std::string out = "build-bench/results/denoise_error.csv";
  std::string images;
  std::vector<std::string> guides{"luminance"};
  pd::DenoiseOptions denoise;
  std::uint64_t seed = 1;
  bool references_only = false;
};

// The guides the weights are computed from. "luminance": the white luminance of the transport;
// "features": that and the guide layers the renders then write (--features), as the tools take them
// (image_guides: the first-hit layers); "monte-carlo": the luminance and the Monte Carlo layers
// (depth, scatter) only, as the tools took them before the first-hit layers existed.
pd::DenoiseGuides make_guides(const ps::SpectralImage& img, const std::string& kind) {
  if (kind == "luminance") return pd::luminance_guides(img);
  if (kind == "features") return pd::image_guides(img);
  if (kind == "monte-carlo") {
    ps::SpectralImage mc = img;
    std::erase_if(mc.guides, [](const ps::GuideLayer& l) { return ps::exact_guide(l.name); });
    return pd::image_guides(mc);
  }
  throw ps::InputError("--guides", "unknown guides \"" + kind + "\" (known: luminance, features, monte-carlo)");
}

double rel_mse(const std::vector<float>& x, const std::vector<float>& r) {
  double s = 0.0;
  for (std::size_t k = 0; k < r.size(); ++k) {
    const double d = static_cast<double>(x[k]) - r[k];
    s += d * d / (static_cast<double>(r[k]) * r[k] + kRelMseEpsilon);
  }
  return s / static_cast<double>(r.size());
}

// CIEDE2000 between two relit images at the 99th percentile of the pixels.
double delta_e_p99(const prizma::spectral::XyzImage& a, const prizma::spectral::XyzImage& b,
                   const Eigen::Vector3d& white) {
  std::vector<double> de(a.pixel_count());
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    const Eigen::Vector3d xa(a.xyz[3 * p], a.xyz[3 * p + 1], a.xyz[3 * p + 2]);
    const Eigen::Vector3d xb(b.xyz[3 * p], b.xyz[3 * p + 1], b.xyz[3 * p + 2]);
    de[p] = ps::delta_e2000(ps::xyz_to_lab(xa, white), ps::xyz_to_lab(xb, white));
  }
  const std::size_t k = std::min(de.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(de.size())));
  std::nth_element(de.begin(), de.begin() + static_cast<std::ptrdiff_t>(k), de.end());
  return de[k];
}

pr::Scene load(const std::string& name, const Options& o) {
  const fs::path path = pb::source_data_dir() / "scenes" / (name + ".json");
  pr::Scene s = pr::load_scene(path, {{"camera.width", std::to_string(o.size)}, {"camera.height", std::to_string(o.size)}});
  s.settings.threads = o.threads;
  s.settings.write_variance = true;
  // Changes no bit of the transport (the render's time includes the first-hit march).
  s.settings.write_guides = std::any_of(o.guides.begin(), o.guides.end(), [](const std::string& g) { return g != "luminance"; });
  return s;
}

pr::Scene with_samples(pr::Scene s, std::int64_t spp, std::uint64_t seed) {
  s.settings.sample_begin = 0;
  s.settings.sample_end = spp;
  s.settings.seed = seed;
  return s;
}

struct Denoised {
  ps::SpectralImage image;
  double seconds = 0.0;
};

Denoised run_denoiser(const ps::SpectralImage& raw, const std::string& guides, const pd::DenoiseOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  Denoised d;
  d.image = pd::denoise(raw, pd::compute_weights(make_guides(raw, guides), options));
  d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return d;
}

void save(const Options& o, const std::string& name, const ps::SpectralImage& img) {
  if (o.images.empty()) return;
  fs::create_directories(o.images);
  ps::write_spectral_exr(fs::path(o.images) / (name + ".exr"), img);
}

// One scene: the reference, the timed raw renders and their denoised versions, the bias render.
void measure_scene(const std::string& name, const Options& o, std::ostringstream& csv) {
  const pr::Scene scene = load(name, o);
  std::cerr << name << ": reference " << o.ref_spp << " spp (cached in " << o.cache << ")\n";
  // The reference needs no guide layers: rendered without them, one cached reference serves every guide choice.
  pr::Scene ref_scene = with_samples(scene, o.ref_spp, o.seed + 1000003);
  ref_scene.settings.write_guides = false;
  const ps::SpectralImage ref = pb::cached_render(ref_scene, o.cache, name + "-ref");
  std::vector<prizma::spectral::XyzImage> ref_xyz;
  std::vector<Eigen::Vector3d> white(o.lights.size());
  for (std::size_t k = 0; k < o.lights.size(); ++k) ref_xyz.push_back(pb::relight_all(ref, o.lights[k], &white[k]));
  save(o, name + "-ref", ref);

  std::vector<std::int64_t> counts = o.references_only ? std::vector<std::int64_t>{} : o.spp;
  if (o.bias_spp > 0) counts.push_back(o.bias_spp);
  for (const std::int64_t n : counts) {
    const bool bias_run = o.bias_spp > 0 && n == o.bias_spp;
    pr::RenderStats stats;
    double raw_seconds = 0.0;
    const pr::Scene s = with_samples(scene, n, o.seed);
    const ps::SpectralImage raw = bias_run ? pb::cached_render(s, o.cache, name + "-bias", &raw_seconds)
                                           : pr::render(s, {}, &stats);
    if (!bias_run) raw_seconds = stats.wall_seconds;
    save(o, name + "-" + std::to_string(n) + "spp-raw", raw);
    for (const std::string& guides : o.guides) {
    const Denoised den = run_denoiser(raw, guides, o.denoise);
    save(o, name + "-" + std::to_string(n) + "spp-denoised" + (guides == "luminance" ? "" : "-" + guides), den.image);
    for (std::size_t k = 0; k < o.lights.size(); ++k) {
      const auto xr = pb::relight_all(raw, o.lights[k]), xd = pb::relight_all(den.image, o.lights[k]);
      const double er = rel_mse(xr.xyz, ref_xyz[k].xyz), ed = rel_mse(xd.xyz, ref_xyz[k].xyz);
      const double floor = er * static_cast<double>(n) / static_cast<double>(o.ref_spp);
      const double erc = er - floor, edc = ed - floor;
      // Raw time to reach the denoised error (relMSE ∝ 1/time through this point) over the denoised cost.
      const double ratio = edc > 0.0 ? erc * raw_seconds / (edc * (raw_seconds + den.seconds)) : INFINITY;
      const double de_raw = delta_e_p99(xr, ref_xyz[k], white[k]), de_den = delta_e_p99(xd, ref_xyz[k], white[k]);
      csv << name << ',' << n << ',' << o.lights[k] << ',' << raw_seconds << ',' << den.seconds << ',' << er << ','
          << ed << ',' << floor << ',' << erc << ',' << edc << ',' << (bias_run ? 0.0 : ratio) << ',' << de_raw << ','
          << de_den << ',' << o.ref_spp << ',' << o.size << ',' << guides << '\n';
      std::cerr << "  " << std::setw(5) << n << " spp  " << std::setw(10) << std::left << guides << std::right
                << std::setw(16) << std::left << o.lights[k] << std::right
                << std::fixed << std::setprecision(3) << " raw " << raw_seconds << " s + denoise " << den.seconds
                << " s  relMSE raw " << std::scientific << std::setprecision(3) << erc << " denoised " << edc
                << std::fixed << std::setprecision(2);
      if (bias_run)
        std::cerr << "  dE00 p99 raw " << de_raw << " denoised " << de_den << "\n";
      else
        std::cerr << "  equal-error ratio " << ratio << "x  reduction " << (edc > 0.0 ? erc / edc : INFINITY)
                  << "x  dE00 p99 " << de_den << "\n";
    }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Error of denoised renders against a high-sample reference, and the equal-error time ratio"};
  app.add_option("--scenes", o.scenes, "scene files in data/scenes/ (without .json)")->delimiter(',');
  app.add_option("--size", o.size, "image width and height in pixels");
  app.add_option("--spp", o.spp, "sample counts of the timed renders")->delimiter(',');
  app.add_option("--bias-spp", o.bias_spp, "sample count of the bias render (cached; 0 = none)");
  app.add_option("--ref-spp", o.ref_spp, "reference samples per pixel (cached)");
  app.add_option("--threads", o.threads, "render and denoise threads");
  app.add_option("--lights", o.lights, "light spectra every layer is relit with, one measurement each")->delimiter(',');
  app.add_option("--cache", o.cache, "folder of cached references and bias renders (outside git)");
  app.add_option("--out", o.out, "CSV output");
  app.add_option("--images", o.images, "folder to write the raw, denoised and reference EXR files into");
  app.add_option("--guides", o.guides,
                 "guides of the weights, one or more: luminance, features (the renders' first-hit guide layers "
                 "too), monte-carlo (their depth and scatter layers instead)")
      ->delimiter(',');
  app.add_flag_callback("--features", [&o] { o.guides = {"features"}; }, "the same as --guides features");
  app.add_option("--window", o.denoise.window_radius_px, "denoiser window radius");
  app.add_option("--patch", o.denoise.patch_radius_px, "denoiser patch radius");
  app.add_option("--strength", o.denoise.patch_k, "denoiser patch k");
  app.add_option("--strength-wide", o.denoise.patch_k_wide, "denoiser second patch k (0: none)");
  app.add_option("--feature-k", o.denoise.feature_k, "denoiser feature k");
  app.add_option("--centre-threshold", o.denoise.centre_threshold_se, "denoiser centre test threshold");
  app.add_option("--seed", o.seed, "seed of the measured renders (the reference uses seed + 1000003)");
  app.add_flag("--references-only", o.references_only, "only render (and cache) the references and bias renders");
  CLI11_PARSE(app, argc, argv);
  std::ostringstream csv;
  csv << "scene,spp,light,raw_seconds,denoise_seconds,relmse_raw,relmse_denoised,reference_floor,"
         "relmse_raw_corrected,relmse_denoised_corrected,equal_error_ratio,de00_p99_raw,de00_p99_denoised,ref_spp,"
         "size,guides\n";
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(o.threads));
  try {
    for (const std::string& name : o.scenes) measure_scene(name, o, csv);
  } catch (const ps::InputError& e) {
    std::cerr << "bench_denoise_error: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bench_denoise_error: error: " << e.what() << "\n";
    return 1;
  }
  pb::write_text(o.out, csv.str());
  std::cerr << "wrote " << o.out << "\n";
  return 0;
}
