// render(): passes of samples over the image, each pixel's samples accumulated in sample order in
// double, so the result does not depend on threads or tiling.
#include "prizma/render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>

#include "prizma/render/camera.h"
#include "prizma/render/fluorescence.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/rng.h"
#include "prizma/render/sample_range.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"
#include "prizma/spectral/tool_main.h"

namespace prizma::render {
namespace {

using spectral::InputError;

// Adaptive sampling looks at a pixel's error only after this many samples.
constexpr std::int64_t kMinAdaptiveSamples = 16;
// Automatic pass size: about this many paths per pass.
constexpr std::int64_t kPathsPerPass = std::int64_t{1} << 20;

enum class LaneMode { AllBins, Replicated, Single };

struct ThreadState {
  PathScratch path;
  std::vector<double> value;  // [light][bin] of one sample
  std::vector<double> value_fl;  // [light][bispectral pair] of one sample (fluorescent scenes)
  std::int64_t paths = 0;
  std::int64_t nan_or_inf = 0;
  std::int64_t converged = 0;
};

}  // namespace

std::string wavelength_sampling_name(WavelengthSampling w) {
  return w == WavelengthSampling::Single ? "single" : "spectral-tracking";
}

WavelengthSampling parse_wavelength_sampling(std::string_view name, std::string_view input) {
  if (name == "spectral-tracking") return WavelengthSampling::SpectralTracking;
  if (name == "single") return WavelengthSampling::Single;
  throw InputError(std::string(input),
                   "unknown wavelength sampling \"" + std::string(name) + "\" (known: spectral-tracking, single)");
}

spectral::SpectralImage render(const Scene& scene, const RenderCallbacks& callbacks, RenderStats* stats_out) {
  const auto start = std::chrono::steady_clock::now();
  const RenderSettings& st = scene.settings;
  const spectral::BinLayout& bins = st.bins;
  const int nb = bins.size();
  if (nb < 1) throw InputError("bins", "no bins");
  if (st.sample_begin < 0 || st.sample_end <= st.sample_begin)
    throw InputError("samples", "empty or negative sample range " + std::to_string(st.sample_begin) + ":" +
                                    std::to_string(st.sample_end));
  if (scene.lights.empty()) throw InputError("lights", "the scene has no lights");
  if (!(st.target_error >= 0.0) || !std::isfinite(st.target_error))
    throw InputError("target_error", "must be ≥ 0, got " + std::to_string(st.target_error));

  const CameraModel camera(scene.camera);
  const PathTracer tracer(scene, bins.min_nm(), bins.max_nm(), st.use_majorant_grid);
  const int width = camera.width(), height = camera.height();
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  const int nl = static_cast<int>(scene.lights.size());

  LaneMode mode = LaneMode::AllBins;
  if (st.wavelength_sampling == WavelengthSampling::Single)
    mode = LaneMode::Single;
  else if (tracer.wavelength_independent())
    mode = LaneMode::Replicated;
  const int lanes = mode == LaneMode::AllBins ? nb : 1;
  // Fluorescence (docs/fluorescence.md): the bispectral pairs the scene can fill; nothing of it
  // runs for a scene without fluorescence.
  const FluorescenceLayout fluor = fluorescence_layout(scene.medium, bins);
  if (fluor.any && mode == LaneMode::Single)
    throw InputError("wavelength_sampling", "fluorescence is rendered with spectral-tracking only (all bins per path); "
                                            "single does not change a path's wavelength yet");

  // Where each light's per-lane radiance comes from: the environment (−1), the medium's emission
  // (−2) or a directional light.
  std::vector<int> source(nl, -1);
  for (std::size_t k = 0; k < tracer.directional_lights().size(); ++k)
    source[tracer.directional_lights()[k]] = static_cast<int>(k);
  if (tracer.emission_light() >= 0) source[tracer.emission_light()] = -2;

  // Test/benchmark mode: lights folded in with their default spectra.
  std::vector<spectral::Spectrum> fold;
  if (st.fold_light_spectra) {
    spectral::SpecContext ctx;
    if (!scene.source.empty()) ctx.base_dir = scene.source.parent_path();
    for (int l = 0; l < nl; ++l) {
      ctx.input = "lights[" + std::to_string(l) + "].spectrum";
      fold.push_back(spectral::parse_spectrum(scene.lights[l].spectrum_spec, ctx));
    }
  }

  // Accumulators: per pixel, light and bin, in double.
  const std::size_t per_pixel = static_cast<std::size_t>(nl) * nb;
  const bool adaptive = st.target_error > 0.0;
  const bool keep_squares = st.write_variance;
  std::vector<double> sum(pixels * per_pixel, 0.0);
  std::vector<double> sum_sq(keep_squares ? pixels * per_pixel : 0, 0.0);
  std::vector<double> total_sum(adaptive ? pixels : 0, 0.0), total_sq(adaptive ? pixels : 0, 0.0);
  std::vector<std::int64_t> count(pixels, 0);
  std::vector<char> converged(pixels, 0);
  const bool fluorescent = fluor.any && mode == LaneMode::AllBins;
  const std::size_t np = fluor.pairs.size();
  const std::size_t per_pixel_fl = fluorescent && st.fold_light_spectra ? 0 : static_cast<std::size_t>(nl) * np;
  std::vector<double> sum_fl(fluorescent ? pixels * per_pixel_fl : 0, 0.0);

  tbb::enumerable_thread_specific<ThreadState> states([&] {
    ThreadState t;
    tracer.prepare(t.path, lanes);
    t.value.assign(per_pixel, 0.0);
    if (fluorescent) {
      t.value_fl.assign(per_pixel_fl, 0.0);
      for (int i = 0; i < nb; ++i) {
        t.path.lo_nm[i] = static_cast<float>(bins.lo_nm(i));
        t.path.width_nm[i] = static_cast<float>(bins.width_nm(i));
      }
    }
    return t;
  });

  const std::int64_t total = st.sample_end - st.sample_begin;
  std::int64_t per_pass = callbacks.samples_per_pass;
  if (per_pass <= 0) per_pass = std::max<std::int64_t>(1, kPathsPerPass / static_cast<std::int64_t>(pixels));
  per_pass = std::min(per_pass, total);

  // Cancellation is polled at every sample: a pass cut short is abandoned (the accumulators go
  // back to their state before it), so the image still holds whole passes only.
  std::atomic<bool> pass_cut{false};
  auto cancelled = [&] {
    if (callbacks.cancel == nullptr || !callbacks.cancel->load(std::memory_order_relaxed)) return false;
    pass_cut.store(true, std::memory_order_relaxed);
    return true;
  };
  // A fluorescent path's rank-one term, M[out][in] = a[out]·(in side)[in] per light: off-diagonal
  // pairs into vf, diagonal ones into the sample's transport (ts.value). Folded lights (test mode)
  // weigh the in side by the light at λin and everything goes to the diagonal (the radiance at out).
  // False when a value is not finite.
  auto add_fluorescent_sample = [&](const PathScratch& ps, double* v, double* vf) -> bool {
    std::fill(vf, vf + per_pixel_fl, 0.0);
    if (!ps.fl_active) return true;
    bool ok = true;
    const float* a = ps.fl_a.data();
    for (int l = 0; l < nl; ++l) {
      const float* src = source[l] == -2 ? ps.fl_emission.data()
                         : source[l] < 0 ? ps.fl_environment.data()
                                         : ps.fl_directional.data() + static_cast<std::size_t>(source[l]) * lanes;
      double* out = v + static_cast<std::size_t>(l) * nb;
      // λin: the path's last wavelengths (a fluorescent event draws them anew; with two or more
      // events chained the folded light is taken at the last segment's, an approximation of the
      // test mode only).
      auto fold_at = [&](int i) { return fold.empty() ? 1.0 : fold[l].eval(ps.lambda_nm[i]); };
      for (std::size_t k = 0; k < np; ++k) {
        const spectral::BinPair pr = fluor.pairs[k];
        const double val = static_cast<double>(a[pr.out]) * src[pr.in] * fold_at(pr.in);
        ok = ok && std::isfinite(val);
        if (fold.empty())
          vf[static_cast<std::size_t>(l) * np + k] = val;
        else
          out[pr.out] += val;
      }
      for (int i : fluor.diagonal) {
        out[i] += static_cast<double>(a[i]) * src[i] * fold_at(i);
        ok = ok && std::isfinite(out[i]);
      }
    }
    return ok;
  };
  auto render_pixel = [&](ThreadState& ts, int x, int y, std::int64_t s0, std::int64_t s1) {
    const std::size_t pix = static_cast<std::size_t>(y) * width + x;
    if (converged[pix]) return;
    double* acc = sum.data() + pix * per_pixel;
    double* acc_sq = keep_squares ? sum_sq.data() + pix * per_pixel : nullptr;
    PathScratch& ps = ts.path;
    double* v = ts.value.data();
    for (std::int64_t s = s0; s < s1; ++s) {
      if (cancelled()) return;
      Rng rng(st.seed, pix, static_cast<std::uint64_t>(s));
      const double px = x + rng.uniform_double();
      const double py = y + rng.uniform_double();
      const Ray ray = camera.generate(px, py);
      // Wavelengths: one jitter u shared by all bins, λ_i = lo_i + u·Δλ_i; Single picks one bin.
      const double u = rng.uniform_double();
      int bin = 0;
      if (mode == LaneMode::Single) {
        bin = std::min(nb - 1, static_cast<int>(rng.uniform_double() * nb));
        ps.lambda_nm[0] = static_cast<float>(bins.lo_nm(bin) + u * bins.width_nm(bin));
      } else if (mode == LaneMode::AllBins) {
        for (int i = 0; i < nb; ++i) ps.lambda_nm[i] = static_cast<float>(bins.lo_nm(i) + u * bins.width_nm(i));
      } else {
        ps.lambda_nm[0] = static_cast<float>(bins.centre_nm(0));
      }
      tracer.trace(ray, rng, ps);
      ++ts.paths;

      // Lanes → (light, bin) values of this sample.
      bool finite = true;
      for (int l = 0; l < nl; ++l) {
        const float* src = source[l] == -2 ? ps.emission.data()
                           : source[l] < 0 ? ps.environment.data()
                                           : ps.directional.data() + static_cast<std::size_t>(source[l]) * lanes;
        double* out = v + static_cast<std::size_t>(l) * nb;
        switch (mode) {
          case LaneMode::AllBins:
            for (int i = 0; i < nb; ++i) out[i] = src[i];
            break;
          case LaneMode::Replicated:
            for (int i = 0; i < nb; ++i) out[i] = src[0];
            break;
          case LaneMode::Single:
            for (int i = 0; i < nb; ++i) out[i] = 0.0;
            out[bin] = static_cast<double>(src[0]) * nb;  // one bin of n drawn: weight n
            break;
        }
        if (!fold.empty()) {
          if (mode == LaneMode::Single) {
            out[bin] *= fold[l].eval(bins.lo_nm(bin) + u * bins.width_nm(bin));
          } else {
            for (int i = 0; i < nb; ++i) out[i] *= fold[l].eval(bins.lo_nm(i) + u * bins.width_nm(i));
          }
        }
        for (int i = 0; i < nb; ++i) finite = finite && std::isfinite(out[i]);
      }
      if (fluorescent) finite = add_fluorescent_sample(ps, v, ts.value_fl.data()) && finite;
      if (!finite) {
        // Never let a NaN/Inf reach the image: count it, take the sample as 0.
        ++ts.nan_or_inf;
        std::fill(v, v + per_pixel, 0.0);
        std::fill(ts.value_fl.begin(), ts.value_fl.end(), 0.0);
      }
      if (per_pixel_fl > 0) {
        double* acc_fl = sum_fl.data() + pix * per_pixel_fl;
        for (std::size_t k = 0; k < per_pixel_fl; ++k) acc_fl[k] += ts.value_fl[k];
      }
      double sample_total = 0.0;
      for (std::size_t k = 0; k < per_pixel; ++k) {
        acc[k] += v[k];
        sample_total += v[k];
      }
      if (acc_sq)
        for (std::size_t k = 0; k < per_pixel; ++k) acc_sq[k] += v[k] * v[k];
      const std::int64_t nsamp = ++count[pix];
      if (adaptive) {
        total_sum[pix] += sample_total;
        total_sq[pix] += sample_total * sample_total;
        if (nsamp >= kMinAdaptiveSamples) {
          const double n = static_cast<double>(nsamp);
          const double mean = total_sum[pix] / n;
          const double var = std::max(0.0, (total_sq[pix] / n - mean * mean) * n / (n - 1.0));
          if (std::sqrt(var / n) <= st.target_error * std::abs(mean)) {
            converged[pix] = 1;
            ++ts.converged;
            return;
          }
        }
      }
    }
  };

  std::optional<tbb::task_arena> arena;
  if (st.threads > 0) arena.emplace(st.threads);
  auto run_pass = [&](std::int64_t s0, std::int64_t s1) {
    // Runs of pixels, not rows: a 24×24 image has 24 rows, each 1/24 of the pass, too few for two
    // threads to finish a pass together; each pixel's samples are still taken by one task, in order.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels, 4), [&](const tbb::blocked_range<std::size_t>& r) {
      ThreadState& ts = states.local();
      for (std::size_t p = r.begin(); p != r.end() && !pass_cut.load(std::memory_order_relaxed); ++p)
        render_pixel(ts, static_cast<int>(p % static_cast<std::size_t>(width)), static_cast<int>(p / static_cast<std::size_t>(width)), s0, s1);
    });
  };

  std::int64_t done = 0;
  bool interrupted = false;
  // The accumulators before the current pass, kept only when the render can be cancelled.
  struct Snapshot {
    std::vector<double> sum, sum_sq, total_sum, total_sq, sum_fl;
    std::vector<std::int64_t> count;
    std::vector<char> converged;
  } before;
  while (done < total) {
    if (callbacks.cancel && callbacks.cancel->load()) {
      interrupted = true;
      break;
    }
    const std::int64_t s0 = st.sample_begin + done;
    const std::int64_t s1 = std::min(st.sample_end, s0 + per_pass);
    if (callbacks.cancel) {
      before.sum.assign(sum.begin(), sum.end());
      before.sum_fl.assign(sum_fl.begin(), sum_fl.end());
      before.sum_sq.assign(sum_sq.begin(), sum_sq.end());
      before.total_sum.assign(total_sum.begin(), total_sum.end());
      before.total_sq.assign(total_sq.begin(), total_sq.end());
      before.count.assign(count.begin(), count.end());
      before.converged.assign(converged.begin(), converged.end());
    }
    if (arena)
      arena->execute([&] { run_pass(s0, s1); });
    else
      run_pass(s0, s1);
    if (pass_cut.load()) {
      sum.swap(before.sum);
      sum_fl.swap(before.sum_fl);
      sum_sq.swap(before.sum_sq);
      total_sum.swap(before.total_sum);
      total_sq.swap(before.total_sq);
      count.swap(before.count);
      converged.swap(before.converged);
      interrupted = true;
      break;
    }
    done = s1 - st.sample_begin;
    if (callbacks.progress) {
      RenderProgress p;
      p.samples_done = done;
      p.samples_total = total;
      for (const auto& t : states) p.paths += t.paths;
      p.elapsed_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      callbacks.progress(p);
    }
  }
  if (done < total && !interrupted) interrupted = true;
  if (done == 0) throw spectral::RuntimeError("render interrupted before the first pass completed");

  // The image: per-pixel means (and variances of the mean) as float.
  spectral::SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = bins;
  img.lights.resize(nl);
  for (int l = 0; l < nl; ++l) {
    auto& layer = img.lights[l];
    layer.name = scene.lights[l].name;
    layer.data.assign(pixels * nb, 0.0f);
    if (keep_squares) layer.variance.assign(pixels * nb, 0.0f);
  }
  for (std::size_t pix = 0; pix < pixels; ++pix) {
    const double n = static_cast<double>(count[pix]);
    for (int l = 0; l < nl; ++l) {
      auto& layer = img.lights[l];
      for (int i = 0; i < nb; ++i) {
        const std::size_t k = pix * per_pixel + static_cast<std::size_t>(l) * nb + i;
        const double mean = n > 0 ? sum[k] / n : 0.0;
        layer.data[pix * nb + i] = static_cast<float>(mean);
        if (keep_squares && n > 1) {
          const double var = std::max(0.0, (sum_sq[k] / n - mean * mean) * n / (n - 1.0));
          layer.variance[pix * nb + i] = static_cast<float>(var / n);
        }
      }
    }
  }
  if (per_pixel_fl > 0) {
    // The bispectral terms (docs/spectral-exr.md, "Bispectral channels"): per light, pairs contiguous.
    img.reradiation = fluor.pairs;
    for (int l = 0; l < nl; ++l) {
      auto& r = img.lights[l].reradiation;
      r.assign(pixels * np, 0.0f);
      for (std::size_t pix = 0; pix < pixels; ++pix) {
        const double n = static_cast<double>(count[pix]);
        for (std::size_t k = 0; k < np; ++k)
          r[pix * np + k] = n > 0 ? static_cast<float>(sum_fl[pix * per_pixel_fl + static_cast<std::size_t>(l) * np + k] / n) : 0.0f;
      }
    }
  }
  img.info.is_prizma = true;
  img.info.lights_json = lights_to_json(scene.lights);
  img.info.samples = done;
  img.info.sample_range = SampleRange{st.sample_begin, st.sample_begin + done}.to_string();
  img.info.seed = static_cast<std::int64_t>(st.seed);
  img.info.scene_hash = scene.hash;
  img.info.version = spectral::prizma_version();
  img.info.wavelength_sampling = wavelength_sampling_name(st.wavelength_sampling);

  if (stats_out) {
    RenderStats s;
    for (const auto& t : states) {
      s.paths += t.paths;
      s.nan_or_inf_count += t.nan_or_inf;
      s.pixels_converged += t.converged;
      s.paths_in_volume += t.path.counters.paths_in_volume;
      s.collisions += t.path.counters.collisions;
      s.shadow_steps += t.path.counters.shadow_steps;
      s.majorant_cells += t.path.counters.majorant_cells;
    }
    s.samples_completed = done;
    s.interrupted = interrupted;
    s.wavelength_independent = mode == LaneMode::Replicated;
    s.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    *stats_out = s;
  }
  return img;
}

}  // namespace prizma::render
