// bench_bin_study: how many bins does relighting need? For each light, relit images with n bins are
// compared (CIEDE2000 per pixel) with a reference in which the light is folded into the rendering
// (render::render_folded: each path's radiance multiplied by E(λ) at its own wavelength) over fine bins
// (320 × 1.25 nm), converted to XYZ by integrating bins × CMF. The n-bin transport is the average of
// the fine transport over each coarse bin (its exact expectation), from the same seed and so the same
// paths as the reference: path noise cancels and the difference is the binning error. The noise of a
// render at this sample count (a second seed) is reported for scale.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>

#include "bench_common.h"

namespace pb = prizma::bench;
namespace pr = prizma::render;
namespace ps = prizma::spectral;

namespace {

// The n-bin image whose bin j is the mean of the fine bins inside it (fine bins of equal width).
ps::SpectralImage aggregate_bins(const ps::SpectralImage& fine, int n) {
  const int nf = fine.bins.size();
  const int k = nf / n;
  ps::SpectralImage out = fine;
  out.bins = ps::BinLayout::linear(fine.bins.min_nm(), fine.bins.max_nm(), n);
  for (std::size_t l = 0; l < fine.lights.size(); ++l) {
    const auto& src = fine.lights[l].data;
    auto& dst = out.lights[l].data;
    dst.assign(fine.pixel_count() * static_cast<std::size_t>(n), 0.0f);
    out.lights[l].variance.clear();
    for (std::size_t p = 0; p < fine.pixel_count(); ++p)
      for (int j = 0; j < n; ++j) {
        double sum = 0.0;
        for (int i = j * k; i < (j + 1) * k; ++i) sum += src[p * nf + i];
        dst[p * n + j] = static_cast<float>(sum / k);
      }
  }
  return out;
}

}  // namespace

// long on purpose: a bench's main: options, setup, timed runs and its one table, read top to bottom.
int main(int argc, char** argv) {
  std::vector<std::string> scenes{"cube", "metamers"};
  std::vector<std::string> lights{"D65", "A", "F11", "LED-B3", "gaussian:550:10"};
  std::vector<int> bin_counts{4, 8, 16, 32, 64};
  int fine_bins = 320;
  int size = 48;
  std::int64_t spp = 32;
  int threads = 2;
  std::string cache = "build-bench/cache";
  std::string out = "docs/results/bin_study.csv";
  CLI::App app{"Relight error versus bin count against a folded-light fine-bin reference"};
  app.add_option("--scenes", scenes, "cube, metamers, mri, grey");
  app.add_option("--lights", lights, "light spectrum specs");
  app.add_option("--bins", bin_counts, "bin counts over 380–780 nm");
  app.add_option("--fine-bins", fine_bins, "bins of the fine render and the folded reference over 380–780 nm "
                                           "(every bin count must divide it)");
  app.add_option("--size", size, "image width and height");
  app.add_option("--spp", spp, "samples per pixel of every render (same seed)");
  app.add_option("--threads", threads, "render threads");
  app.add_option("--cache", cache, "folder for renders (outside git)");
  app.add_option("--out", out, "CSV output");
  CLI11_PARSE(app, argc, argv);
  for (int n : bin_counts)
    if (n < 1 || fine_bins % n != 0) {
      std::cerr << "bench_bin_study: error: --bins: " << n << " does not divide --fine-bins " << fine_bins << "\n";
      return 2;
    }

  std::ostringstream csv;
  csv << std::setprecision(6);
  csv << "scene,light,kind,bins,mean_de00,p95_de00,max_de00,spp,fine_bins\n";
  try {
    for (const std::string& name : scenes) {
      pr::Scene scene;
      std::string why;
      if (!pb::load_bench_scene(name, scene, why)) {
        std::cerr << "skipping scene " << name << ": " << why << "\n";
        continue;
      }
      scene.camera.width = size;
      scene.camera.height = size;
      scene.settings.threads = threads;
      scene.settings.sample_begin = 0;
      scene.settings.sample_end = spp;
      scene.settings.seed = 1;
      scene.settings.wavelength_sampling = pr::WavelengthSampling::SpectralTracking;
      scene.settings.use_majorant_grid = true;
      scene.settings.write_variance = false;
      scene.settings.target_error = 0.0;

      // One fine render of the transport (unit white lights). The n-bin transport is the average of
      // the fine bins inside each coarse bin: exactly the expectation of an n-bin render (λ uniform in
      // a bin = equal-weight mix of its equal-width sub-bins), computed from the same paths as the
      // references, so the comparison sees the binning error and not the path noise.
      pr::Scene fine_scene = scene;
      fine_scene.settings.bins = ps::BinLayout::linear(380, 780, fine_bins);
      double sec = 0;
      const auto fine = pb::cached_render(fine_scene, cache, "fine-" + name, &sec);
      std::cerr << name << ": fine transport, " << fine_bins << " bins "
                << (sec > 0 ? std::to_string(sec) + " s" : "cached") << "\n";
      std::vector<ps::SpectralImage> tests;
      for (int n : bin_counts) tests.push_back(aggregate_bins(fine, n));

      for (std::size_t li = 0; li < lights.size(); ++li) {
        const std::string& light = lights[li];
        // Reference: the same render with the light folded in (same seed, so the same paths: folding
        // multiplies each path's radiance by E(λ) after tracing and draws no random numbers).
        pr::Scene r = fine_scene;
        for (auto& l : r.lights) l.spectrum_spec = light;
        const auto ref = pb::cached_render(r, cache, "fold-" + name, &sec, /*folded=*/true);
        std::cerr << name << ": folded reference " << light << " " << (sec > 0 ? std::to_string(sec) + " s" : "cached")
                  << "\n";
        Eigen::Vector3d white;
        const auto fine_xyz = pb::relight_all(fine, light, &white);
        const auto ref_xyz = pb::folded_to_xyz(ref, light);
        auto row = [&](const std::string& kind, int bins, const pb::DeltaEStats& de) {
          csv << name << ',' << light << ',' << kind << ',' << bins << ',' << de.mean << ',' << de.p95 << ',' << de.max
              << ',' << spp << ',' << fine_bins << '\n';
          std::cerr << "  " << std::setw(16) << std::left << light << std::right << " " << std::setw(12) << kind
                    << std::setw(5) << bins << " bins: mean dE00 " << std::fixed << std::setprecision(4) << de.mean
                    << "  p95 " << de.p95 << "  max " << de.max << std::defaultfloat << "\n";
        };
        for (std::size_t k = 0; k < bin_counts.size(); ++k) {
          const auto relit = pb::relight_all(tests[k], light);
          row("binning", bin_counts[k], pb::delta_e_stats(relit, ref_xyz, white));
          // Against the fine relight of the same paths: no fold noise (a folded path samples E at one
          // wavelength per bin, which is noisy for spiky and narrow lights), only the binning error.
          row("binning_vs_fine", bin_counts[k], pb::delta_e_stats(relit, fine_xyz, white));
        }
        // The relight of the fine transport itself: the residual of the method at the fine resolution.
        row("fine_relight", fine_bins, pb::delta_e_stats(fine_xyz, ref_xyz, white));
        // Context for the first light: the path noise at this sample count (another seed).
        if (li == 0) {
          pr::Scene r2 = r;
          r2.settings.seed = 2;
          const auto ref2 = pb::cached_render(r2, cache, "fold-" + name, &sec, /*folded=*/true);
          row("noise_floor", fine_bins, pb::delta_e_stats(pb::folded_to_xyz(ref2, light), ref_xyz, white));
        }
      }
    }
  } catch (const ps::InputError& e) {
    std::cerr << "bench_bin_study: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bench_bin_study: error: " << e.what() << "\n";
    return 1;
  }
  pb::write_text(out, csv.str());
  std::cerr << "wrote " << out << "\n";
  return 0;
}
