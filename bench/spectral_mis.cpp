// bench_spectral_mis: spectral MIS against spectral tracking (issue 24), and each chromatic scene
// against its bin-averaged grey version, by efficiency = 1 / (relative variance · CPU seconds).
// The relative variance is the renders' own: Σ var / Σ mean² over every light and bin of the volume
// pixels (background pixels, exactly 0 or 1 everywhere, left out), var the variance of the pixel
// mean that --variance writes. No reference is needed, so a run takes minutes, not hours; the
// equal-error figures with references are bench/error-vs-time's. (With spectral MIS the hero lanes
// of a pixel are stratified, so its sample variance overstates its true variance a little: the
// ratios here are conservative for spectral MIS.) Renders are interleaved (repeat outer, scene and
// method inner), so a change of load falls on all alike; CPU time is the process's (all threads).
//
//   bench_spectral_mis [--scenes cube grey peer peer-grey ...] [--methods spectral-tracking spectral-mis]
//                      [--spp 64] [--size 32] [--repeats 3] [--threads 2]
// Prints per scene and method the median efficiency, MIS ÷ tracking, chromatic ÷ grey cost pairs
// (X with X-grey, cube with grey) and the load at the start and the end.
#include <sys/resource.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench_common.h"
#include "bench_image.h"
#include "prizma/render/render.h"
#include "prizma/spectral/error.h"

namespace pb = prizma::bench;
namespace pr = prizma::render;
namespace ps = prizma::spectral;

namespace {

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Σ var / Σ mean² over the volume pixels' values (the pixel means' variance, relative).
double relative_variance(const ps::SpectralImage& img) {
  const std::vector<char> background = pb::background_mask(img);
  const std::size_t nb = static_cast<std::size_t>(img.bins.size());
  double var = 0.0, sq = 0.0;
  for (const auto& layer : img.lights)
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      if (background[p]) continue;
      for (std::size_t i = 0; i < nb; ++i) {
        var += layer.variance[p * nb + i];
        sq += static_cast<double>(layer.data[p * nb + i]) * layer.data[p * nb + i];
      }
    }
  return sq > 0.0 ? var / sq : 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

// long on purpose: a bench's main: options, setup, timed runs and its one table, read top to bottom.
int main(int argc, char** argv) {
  std::vector<std::string> scenes{"grey", "cube", "peer", "peer-grey", "metamers", "mri", "sky_haze", "cloud_vdb"};
  std::vector<std::string> methods{"spectral-tracking", "spectral-mis"};
  std::int64_t spp = 64;
  int size = 32, repeats = 3, threads = 2;
  CLI::App app{"Spectral MIS against spectral tracking, and chromatic against grey, by efficiency"};
  app.add_option("--scenes", scenes, "bench scenes: grey, cube, peer, a data/scenes/NAME, NAME-grey");
  app.add_option("--methods", methods, "spectral-tracking, spectral-mis, auto, single");
  app.add_option("--spp", spp, "samples per pixel of each render");
  app.add_option("--size", size, "image width and height in pixels");
  app.add_option("--repeats", repeats, "renders per scene and method (seeds 1, 2, …; the median is kept)");
  app.add_option("--threads", threads, "render threads");
  CLI11_PARSE(app, argc, argv);

  std::map<std::string, std::map<std::string, std::vector<double>>> eff, relvar, cpu;
  std::map<std::string, pr::Scene> loaded;
  try {
    for (const std::string& name : scenes) {
      std::string why;
      pr::Scene s;
      if (!pb::load_bench_scene(name, s, why)) {
        std::cerr << "skipping scene " << name << ": " << why << "\n";
        continue;
      }
      s.camera.width = s.camera.height = size;
      s.settings.threads = threads;
      s.settings.target_error = 0.0;
      s.settings.sample_begin = 0;
      s.settings.sample_end = spp;
      s.settings.write_variance = true;
      loaded.emplace(name, std::move(s));
    }
    std::cout << "bench_spectral_mis: " << size << "×" << size << ", " << spp << " spp, " << threads
              << " threads, " << repeats << " repeats; load at start " << pb::load_average() << "\n";
    for (int r = 0; r < repeats; ++r)
      for (auto& [name, scene] : loaded)
        for (const std::string& m : methods) {
          pr::Scene s = scene;
          s.settings.wavelength_sampling = pr::parse_wavelength_sampling(m, "--methods");
          s.settings.seed = static_cast<std::uint64_t>(r + 1);
          try {
            (void)pr::resolve_wavelength_sampling(s);
          } catch (const ps::InputError& e) {  // spectral-mis with a fluorescent material
            if (r == 0) std::cout << "  " << name << " " << m << ": refused (" << e.what() << ")\n";
            continue;
          }
          const double c0 = cpu_seconds();
          const ps::SpectralImage img = pr::render(s);
          const double c = cpu_seconds() - c0, v = relative_variance(img);
          cpu[name][m].push_back(c);
          relvar[name][m].push_back(v);
          eff[name][m].push_back(v > 0.0 && c > 0.0 ? 1.0 / (v * c) : 0.0);
        }
  } catch (const ps::InputError& e) {
    std::cerr << "bench_spectral_mis: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bench_spectral_mis: error: " << e.what() << "\n";
    return 1;
  }
  std::cout << std::setprecision(4);
  for (const auto& [name, per] : eff) {
    std::cout << name << ":\n";
    for (const auto& [m, e] : per)
      std::cout << "  " << std::setw(18) << std::left << m << std::right << " rel. variance " << median(relvar[name][m])
                << "  CPU " << median(cpu[name][m]) << " s  efficiency " << median(e) << "\n";
    if (per.count("spectral-tracking") && per.count("spectral-mis"))
      std::cout << "  spectral-mis ÷ spectral-tracking efficiency: "
                << median(per.at("spectral-mis")) / median(per.at("spectral-tracking")) << "×\n";
  }
  // Chromatic ÷ grey cost at equal error: the grey version's efficiency over the chromatic one's.
  for (const auto& [name, per] : eff) {
    const std::string grey = name == "cube" ? "grey" : name + "-grey";
    if (!eff.count(grey)) continue;
    // A grey medium is one lane whatever the method: its first method's renders stand for all.
    const auto& [gm, ge] = *eff.at(grey).begin();
    for (const auto& [m, e] : per)
      std::cout << name << " (" << m << ") ÷ " << grey << " (" << gm << ") cost at equal error: "
                << median(ge) / median(e) << "×\n";
  }
  std::cout << "load at end " << pb::load_average() << "\n";
  return 0;
}
