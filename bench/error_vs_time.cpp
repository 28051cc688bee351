// bench_error_vs_time: error of the transport and of a D65 relight against a high-sample reference, as
// a function of render time, for each wavelength-sampling method with and without the majorant grid.
// Writes one CSV row per (scene, method, sample count). Driven by bench/error-vs-time, which plots.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <thread>

#include "bench_common.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"

namespace pb = prizma::bench;
namespace pr = prizma::render;
namespace ps = prizma::spectral;

namespace {

struct Method {
  std::string name;
  pr::WavelengthSampling sampling;
  bool grid;
  pr::EventProbabilities events = pr::EventProbabilities::Auto;
  pr::Sampler sampler = pr::Sampler::Independent;
  int mis_lane_groups = 0;  // spectral MIS's lane groups (0: the auto rule, the default; 1: none)
};

struct Options {
  std::vector<std::string> scenes{"grey", "cube", "metamers", "mri"};
  std::vector<std::string> methods{"single", "single-nogrid", "spectral", "spectral-nogrid"};
  int size = 64;
  std::int64_t ref_spp = 8192;
  std::int64_t max_spp = 256;
  int threads = 2;
  std::string cache = "build-bench/cache";
  std::string out = "docs/results/error_vs_time.csv";
  std::uint64_t seed = 1;
  bool references_only = false;
  std::string bins;  // a bin layout for every scene instead of its own (empty: the scene's)
};

}  // namespace

// long on purpose: a bench's main: options, setup, timed runs and its one table, read top to bottom.
int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Error versus time of each wavelength-sampling method against a high-sample reference"};
  app.add_option("--scenes", o.scenes, "grey, cube, metamers, mri, peer, any data/scenes/NAME, NAME-grey (bin-averaged)");
  app.add_option("--methods", o.methods,
                 "single, single-nogrid, spectral (auto event probabilities), spectral-nogrid, spectral-max, "
                 "spectral-average, spectral-mixed, spectral-implicit, spectral-sobol, single-sobol (the Sobol' sampler), "
                 "spectral-tracking (= spectral), spectral-mis, spectral-mis-G (spectral MIS in G lane groups; 0: the auto "
                 "rule, = spectral-mis; 1: none)");
  app.add_option("--size", o.size, "image width and height in pixels");
  app.add_option("--ref-spp", o.ref_spp, "reference samples per pixel (spectral tracking, grid)");
  app.add_option("--max-spp", o.max_spp, "largest sample count of the measured renders (powers of 2 up to it)");
  app.add_option("--threads", o.threads, "render threads");
  app.add_option("--cache", o.cache, "folder for reference renders (outside git)");
  app.add_option("--out", o.out, "CSV output");
  app.add_option("--seed", o.seed, "seed of the measured renders (the reference uses seed + 1000003)");
  app.add_flag("--references-only", o.references_only, "only render (and cache) the references");
  app.add_option("--bins", o.bins, "bin layout for every scene (e.g. linear:600:700:12), instead of its own");
  CLI11_PARSE(app, argc, argv);

  const std::vector<Method> known = {
      {"single", pr::WavelengthSampling::Single, true},
      {"single-nogrid", pr::WavelengthSampling::Single, false},
      {"spectral", pr::WavelengthSampling::SpectralTracking, true},
      {"spectral-nogrid", pr::WavelengthSampling::SpectralTracking, false},
      {"spectral-max", pr::WavelengthSampling::SpectralTracking, true, pr::EventProbabilities::Max},
      {"spectral-average", pr::WavelengthSampling::SpectralTracking, true, pr::EventProbabilities::Average},
      {"spectral-mixed", pr::WavelengthSampling::SpectralTracking, true, pr::EventProbabilities::Mixed},
      {"spectral-implicit", pr::WavelengthSampling::SpectralTracking, true, pr::EventProbabilities::Implicit},
      {"spectral-sobol", pr::WavelengthSampling::SpectralTracking, true, pr::EventProbabilities::Auto, pr::Sampler::Sobol},
      {"single-sobol", pr::WavelengthSampling::Single, true, pr::EventProbabilities::Auto, pr::Sampler::Sobol},
      {"spectral-tracking", pr::WavelengthSampling::SpectralTracking, true},
      {"spectral-mis", pr::WavelengthSampling::SpectralMis, true},
  };
  std::vector<Method> methods;
  for (const std::string& name : o.methods) {
    // "spectral-mis-G": spectral MIS in G lane groups (1: every bin on one path, as spectral-mis; 0: auto).
    constexpr std::string_view kGroups = "spectral-mis-";
    if (name.starts_with(kGroups) && name.size() > kGroups.size() &&
        name.find_first_not_of("0123456789", kGroups.size()) == std::string::npos) {
      methods.push_back({name, pr::WavelengthSampling::SpectralMis, true, pr::EventProbabilities::Auto,
                         pr::Sampler::Independent, std::stoi(name.substr(kGroups.size()))});
      continue;
    }
    const auto it = std::find_if(known.begin(), known.end(), [&](const Method& m) { return m.name == name; });
    if (it == known.end()) {
      std::cerr << "bench_error_vs_time: error: --methods: unknown method \"" << name << "\"\n";
      return 2;
    }
    methods.push_back(*it);
  }

  std::ostringstream csv;
  csv << "scene,method,spp,seconds,paths,collisions,shadow_steps,rel_rmse,rel_rmse_corrected,mean_de00,"
         "ref_spp,ref_rel_noise,wavelength_independent,rel_rmse_volume_corrected\n";
  csv << std::setprecision(6);
  try {
    for (const std::string& name : o.scenes) {
      pr::Scene scene;
      std::string why;
      if (!pb::load_bench_scene(name, scene, why)) {
        std::cerr << "skipping scene " << name << ": " << why << "\n";
        continue;
      }
      if (!o.bins.empty()) scene.settings.bins = ps::BinLayout::parse(o.bins, "--bins");  // in the cache key
      scene.camera.width = o.size;
      scene.camera.height = o.size;
      scene.settings.threads = o.threads;
      scene.settings.target_error = 0.0;
      scene.settings.max_bounces = -1;

      // Reference: spectral tracking with the grid, independent seed, variance kept.
      pr::Scene ref_scene = scene;
      ref_scene.settings.wavelength_sampling = pr::WavelengthSampling::SpectralTracking;
      ref_scene.settings.use_majorant_grid = true;
      ref_scene.settings.event_probabilities = pr::EventProbabilities::Max;  // fixed: the cache stays valid
      ref_scene.settings.sample_begin = 0;
      ref_scene.settings.sample_end = o.ref_spp;
      ref_scene.settings.seed = o.seed + 1000003;
      ref_scene.settings.write_variance = true;
      double ref_seconds = 0.0;
      std::cerr << name << ": reference " << o.ref_spp << " spp ..." << std::flush;
      const ps::SpectralImage ref = pb::cached_render(ref_scene, o.cache, "ref-" + name, &ref_seconds);
      std::cerr << (ref_seconds > 0 ? " rendered in " + std::to_string(ref_seconds) + " s" : " from cache") << "\n";
      if (o.references_only) continue;
      // The reference's own relative noise: sqrt(Σ var / Σ r²).
      double ref_var = 0.0, ref_sq = 0.0;
      for (const auto& layer : ref.lights)
        for (std::size_t k = 0; k < layer.data.size(); ++k) {
          ref_var += layer.variance.empty() ? 0.0 : layer.variance[k];
          ref_sq += static_cast<double>(layer.data[k]) * layer.data[k];
        }
      const double ref_noise = std::sqrt(ref_var / ref_sq);
      Eigen::Vector3d white;
      const auto ref_xyz = pb::relight_all(ref, "D65", &white);
      const std::vector<char> background = pb::background_mask(ref);

      // Sample counts outer, methods inner: the methods are interleaved, so a change of the machine's
      // load during the run falls on all of them alike.
      for (std::int64_t n = 1; n <= o.max_spp; n *= 2) {
        for (const Method& m : methods) {
          pr::Scene s = scene;
          s.settings.wavelength_sampling = m.sampling;
          s.settings.use_majorant_grid = m.grid;
          s.settings.event_probabilities = m.events;
          s.settings.sampler = m.sampler;
          s.settings.mis_lane_groups = m.mis_lane_groups;
          s.settings.seed = o.seed;
          s.settings.write_variance = false;
          // Each sample count is a fresh render of samples [0, n): its wall time includes the set-up
          // (majorant grid, material tables) once, as a user's render would.
          s.settings.sample_begin = 0;
          s.settings.sample_end = n;
          pr::RenderStats st;
          const auto img = pr::render(s, {}, &st);
          const double seconds = st.wall_seconds;
          double corrected = 0.0;
          const double err = pb::relative_rmse(img, ref, &corrected);
          double vol_corrected = 0.0;
          pb::relative_rmse(img, ref, &vol_corrected, &background);
          const auto de = pb::delta_e_stats(pb::relight_all(img, "D65"), ref_xyz, white);
          csv << name << ',' << m.name << ',' << n << ',' << seconds << ',' << st.paths << ',' << st.collisions << ','
              << st.shadow_steps << ',' << err << ',' << corrected << ',' << de.mean << ',' << o.ref_spp << ','
              << ref_noise << ',' << (st.wavelength_independent ? 1 : 0) << ',' << vol_corrected << '\n';
          std::cerr << "  " << std::setw(16) << std::left << m.name << std::right << " spp " << std::setw(5) << n
                    << "  " << std::fixed << std::setprecision(3) << std::setw(8) << seconds << " s  rel.RMSE "
                    << std::setprecision(4) << err << "  dE00 " << de.mean << std::defaultfloat << "\n";
        }
      }
    }
  } catch (const ps::InputError& e) {
    std::cerr << "bench_error_vs_time: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bench_error_vs_time: error: " << e.what() << "\n";
    return 1;
  }
  pb::write_text(o.out, csv.str());
  std::cerr << "wrote " << o.out << "\n";
  return 0;
}
