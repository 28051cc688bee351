// bench_bin_study: how many bins does relighting need? For each light, relit renders with n bins are
// compared (CIEDE2000 per pixel) with a reference in which the light is folded into the rendering
// (fold_light_spectra: each path's radiance multiplied by E(λ) at its own wavelengths) over fine bins,
// converted to XYZ by integrating bins × CMF. Both use the same seed and sample count, so much of the
// path noise is shared; the noise floor (two references with different seeds) is reported too.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>

#include "bench_common.h"

namespace pb = prizma::bench;
namespace pr = prizma::render;
namespace ps = prizma::spectral;

int main(int argc, char** argv) {
  std::vector<std::string> scenes{"cube", "metamers"};
  std::vector<std::string> lights{"D65", "A", "F11", "LED-B3", "gaussian:550:10"};
  std::vector<int> bin_counts{4, 8, 16, 32, 64};
  int ref_bins = 200;
  int size = 48;
  std::int64_t spp = 256;
  int threads = 2;
  std::string cache = "build-bench/cache";
  std::string out = "docs/results/bin_study.csv";
  CLI::App app{"Relight error versus bin count against a folded-light fine-bin reference"};
  app.add_option("--scenes", scenes, "cube, metamers, mri, grey");
  app.add_option("--lights", lights, "light spectrum specs");
  app.add_option("--bins", bin_counts, "bin counts over 380–780 nm");
  app.add_option("--ref-bins", ref_bins, "bins of the folded reference over 380–780 nm");
  app.add_option("--size", size, "image width and height");
  app.add_option("--spp", spp, "samples per pixel of every render (same seed)");
  app.add_option("--threads", threads, "render threads");
  app.add_option("--cache", cache, "folder for renders (outside git)");
  app.add_option("--out", out, "CSV output");
  CLI11_PARSE(app, argc, argv);

  std::ostringstream csv;
  csv << std::setprecision(6);
  csv << "scene,light,kind,bins,mean_de00,p95_de00,max_de00,spp,ref_bins\n";
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

      // Transport renders at each bin count (unit white lights; relit below).
      std::vector<ps::SpectralImage> tests;
      for (int n : bin_counts) {
        pr::Scene s = scene;
        s.settings.bins = ps::BinLayout::linear(380, 780, n);
        double sec = 0;
        tests.push_back(pb::cached_render(s, cache, "bins-" + name, &sec));
        std::cerr << name << ": " << n << " bins " << (sec > 0 ? std::to_string(sec) + " s" : "cached") << "\n";
      }
      for (std::size_t li = 0; li < lights.size(); ++li) {
        const std::string& light = lights[li];
        pr::Scene r = scene;
        r.settings.bins = ps::BinLayout::linear(380, 780, ref_bins);
        r.settings.fold_light_spectra = true;
        for (auto& l : r.lights) l.spectrum_spec = light;
        double sec = 0;
        const auto ref = pb::cached_render(r, cache, "fold-" + name, &sec);
        std::cerr << name << ": folded reference " << light << " " << (sec > 0 ? std::to_string(sec) + " s" : "cached")
                  << "\n";
        Eigen::Vector3d white;
        pb::relight_all(tests.front(), light, &white);
        const auto ref_xyz = pb::folded_to_xyz(ref, light);
        for (std::size_t k = 0; k < bin_counts.size(); ++k) {
          const auto de = pb::delta_e_stats(pb::relight_all(tests[k], light), ref_xyz, white);
          csv << name << ',' << light << ",binning," << bin_counts[k] << ',' << de.mean << ',' << de.p95 << ','
              << de.max << ',' << spp << ',' << ref_bins << '\n';
          std::cerr << "  " << std::setw(16) << std::left << light << std::right << std::setw(4) << bin_counts[k]
                    << " bins: mean dE00 " << std::fixed << std::setprecision(4) << de.mean << "  p95 " << de.p95
                    << "  max " << de.max << std::defaultfloat << "\n";
        }
        // Noise floor for the first light: the same folded reference with another seed.
        if (li == 0) {
          pr::Scene r2 = r;
          r2.settings.seed = 2;
          const auto ref2 = pb::cached_render(r2, cache, "fold-" + name, &sec);
          const auto de = pb::delta_e_stats(pb::folded_to_xyz(ref2, light), ref_xyz, white);
          csv << name << ',' << light << ",noise_floor," << ref_bins << ',' << de.mean << ',' << de.p95 << ','
              << de.max << ',' << spp << ',' << ref_bins << '\n';
          std::cerr << "  noise floor (two seeds, " << light << "): mean dE00 " << de.mean << "  max " << de.max << "\n";
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
