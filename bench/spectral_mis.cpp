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
// (X with X-grey, cube with grey) and the load at the start and the end. With --per-bin K it also
// renders every K-th bin's medium alone (the scene's materials averaged over that bin, traced as a
// grey medium) and splits each chromatic ÷ grey cost into the estimator's factor (chromatic ÷ the
// lanes traced alone: what sharing one path among the lanes costs) and the scene's own (the lanes
// traced alone ÷ the grey version: what the grey estimator itself pays at each bin's coefficients).
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

struct VarianceSums {
  double var = 0.0, sq = 0.0;  // Σ var and Σ mean² over the volume pixels' values
  double relative() const { return sq > 0.0 ? var / sq : 0.0; }
};

// The sums over every light and bin of the volume pixels (background pixels, exactly 0 or 1
// everywhere, left out), or over bin `only_bin` alone.
VarianceSums variance_sums(const ps::SpectralImage& img, int only_bin = -1) {
  const std::vector<char> background = pb::background_mask(img);
  const std::size_t nb = static_cast<std::size_t>(img.bins.size());
  VarianceSums out;
  for (const auto& layer : img.lights)
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      if (background[p]) continue;
      for (std::size_t i = 0; i < nb; ++i) {
        if (only_bin >= 0 && i != static_cast<std::size_t>(only_bin)) continue;
        out.var += layer.variance[p * nb + i];
        out.sq += static_cast<double>(layer.data[p * nb + i]) * layer.data[p * nb + i];
      }
    }
  return out;
}

// Σ var / Σ mean² over the volume pixels' values (the pixel means' variance, relative).
double relative_variance(const ps::SpectralImage& img) { return variance_sums(img).relative(); }

// Real and null collisions per path that entered the volume.
double collisions_per_path(const pr::RenderStats& st) {
  return st.paths_in_volume > 0 ? static_cast<double>(st.collisions) / static_cast<double>(st.paths_in_volume) : 0.0;
}

// The chromatic scene's grey partner in the bench's naming (cube → grey, X → X-grey).
std::string grey_partner(const std::string& name) { return name == "cube" ? "grey" : name + "-grey"; }

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
  int size = 32, repeats = 3, threads = 2, per_bin = 0;
  CLI::App app{"Spectral MIS against spectral tracking, and chromatic against grey, by efficiency"};
  app.add_option("--scenes", scenes, "bench scenes: grey, cube, peer, a data/scenes/NAME, NAME-grey");
  app.add_option("--methods", methods,
                 "spectral-tracking, spectral-mis (lane groups by the auto rule), spectral-mis:G (G lane groups; "
                 "1: none), auto, single");
  app.add_option("--spp", spp, "samples per pixel of each render");
  app.add_option("--size", size, "image width and height in pixels");
  app.add_option("--repeats", repeats, "renders per scene and method (seeds 1, 2, …; the median is kept)");
  app.add_option("--threads", threads, "render threads");
  app.add_option("--per-bin", per_bin,
                 "also render, for each chromatic scene with its grey version in --scenes, every K-th bin's "
                 "grey medium alone (0: none) and split chromatic ÷ grey into the estimator's factor and the "
                 "scene's own")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  // paths: paths per camera sample (the lane groups' paths: RenderStats::paths over the samples).
  std::map<std::string, std::map<std::string, std::vector<double>>> eff, relvar, cpu, coll, paths;
  // --per-bin: per chromatic scene, per repeat, the lanes traced alone: the relative variance over
  // the rendered bins (Σ var / Σ mean²) and the mean CPU seconds of one bin's render.
  std::map<std::string, std::vector<double>> alone_relvar, alone_cpu, alone_coll;
  std::map<std::string, int> alone_bins;
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
    for (int r = 0; r < repeats; ++r) {
      for (auto& [name, scene] : loaded)
        for (const std::string& m : methods) {
          pr::Scene s = scene;
          // "spectral-mis:G": spectral MIS in G lane groups (1: every bin on one path; 0: the auto rule).
          const std::size_t colon = m.find(':');
          s.settings.wavelength_sampling = pr::parse_wavelength_sampling(m.substr(0, colon), "--methods");
          if (colon != std::string::npos) s.settings.mis_lane_groups = std::stoi(m.substr(colon + 1));
          s.settings.seed = static_cast<std::uint64_t>(r + 1);
          try {
            (void)pr::resolve_wavelength_sampling(s);
          } catch (const ps::InputError& e) {  // spectral-mis with a fluorescent material
            if (r == 0) std::cout << "  " << name << " " << m << ": refused (" << e.what() << ")\n";
            continue;
          }
          const double c0 = cpu_seconds();
          pr::RenderStats st;
          const ps::SpectralImage img = pr::render(s, {}, &st);
          const double c = cpu_seconds() - c0, v = relative_variance(img);
          cpu[name][m].push_back(c);
          coll[name][m].push_back(collisions_per_path(st));
          paths[name][m].push_back(static_cast<double>(st.paths) / (static_cast<double>(size) * size * spp));
          relvar[name][m].push_back(v);
          eff[name][m].push_back(v > 0.0 && c > 0.0 ? 1.0 / (v * c) : 0.0);
        }
      // Each lane's medium traced alone (the scene's materials averaged over one bin): what the grey
      // estimator pays at that bin's coefficients, in the same interleaving as the renders above.
      for (auto& [name, scene] : loaded) {
        if (per_bin == 0 || !loaded.count(grey_partner(name))) continue;
        VarianceSums sums;
        double c_sum = 0.0, coll_sum = 0.0;
        int& bins = alone_bins[name];
        bins = 0;
        for (int b = 0; b < scene.settings.bins.size(); b += per_bin, ++bins) {
          pr::Scene s = pb::make_grey(scene, b);
          s.settings.seed = static_cast<std::uint64_t>(r + 1);
          const double c0 = cpu_seconds();
          pr::RenderStats st;
          const ps::SpectralImage img = pr::render(s, {}, &st);
          c_sum += cpu_seconds() - c0;
          coll_sum += collisions_per_path(st);
          const VarianceSums v = variance_sums(img, b);
          sums.var += v.var;
          sums.sq += v.sq;
        }
        alone_relvar[name].push_back(sums.relative());
        alone_cpu[name].push_back(c_sum / bins);
        alone_coll[name].push_back(coll_sum / bins);
      }
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
                << "  CPU " << median(cpu[name][m]) << " s  efficiency " << median(e) << "  collisions per path "
                << median(coll[name][m]) << "\n";
    if (per.count("spectral-tracking") && per.count("spectral-mis"))
      std::cout << "  spectral-mis ÷ spectral-tracking efficiency: "
                << median(per.at("spectral-mis")) / median(per.at("spectral-tracking")) << "×\n";
  }
  // Chromatic ÷ grey cost at equal error: the grey version's efficiency over the chromatic one's.
  for (const auto& [name, per] : eff) {
    const std::string grey = grey_partner(name);
    if (!eff.count(grey)) continue;
    // A grey medium is one lane whatever the method: its first method's renders stand for all.
    const auto& [gm, ge] = *eff.at(grey).begin();
    const double vg = median(relvar.at(grey).at(gm)), cg = median(cpu.at(grey).at(gm));
    const double pg = median(paths.at(grey).at(gm));
    for (const auto& [m, e] : per) {
      // The cost split per path (a sample traces one path per lane group): the relative variance
      // of one path's estimate (the mean's × the paths per sample) and the CPU seconds of one path,
      // each against the grey version's.
      const double pm = median(paths.at(name).at(m));
      std::cout << name << " (" << m << ") ÷ " << grey << " (" << gm << ") cost at equal error: "
                << median(ge) / median(e) << "×; per path: variance " << median(relvar.at(name).at(m)) * pm / (vg * pg)
                << "× · CPU " << median(cpu.at(name).at(m)) / pm / (cg / pg) << "× (" << pm << " paths per sample)\n";
    }
    if (!alone_relvar.count(name)) continue;
    // cost ratio = (CPU ratio)·(variance ratio), split at the lanes traced alone: the estimator's
    // factor (sharing one path among the lanes, and their arithmetic) times the scene's own (what
    // the grey estimator itself pays at each bin's coefficients against the bin average's).
    const double va = median(alone_relvar.at(name)), ca = median(alone_cpu.at(name));
    std::cout << "  " << name << "'s lanes traced alone (" << alone_bins.at(name)
              << " bins, each its grey medium): rel. variance " << va << ", CPU " << ca << " s per bin, collisions per path "
              << median(alone_coll.at(name)) << "\n";
    std::cout << "  scene factor (alone ÷ " << grey << "): CPU " << ca / cg << "× · variance " << va / vg << "× = "
              << ca * va / (cg * vg) << "×\n";
    for (const auto& [m, e] : per) {
      const double vm = median(relvar.at(name).at(m)), cm = median(cpu.at(name).at(m));
      std::cout << "  estimator factor (" << m << " ÷ alone): CPU " << cm / ca << "× · variance " << vm / va
                << "× = " << cm * vm / (ca * va) << "×\n";
    }
  }
  std::cout << "load at end " << pb::load_average() << "\n";
  return 0;
}
