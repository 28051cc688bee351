// render(): set-up, then passes of samples over the image into the Film (each pixel's samples
// accumulated in sample order in double, so the result does not depend on threads or tiling).
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
#include "prizma/render/event_probability.h"
#include "prizma/render/film.h"
#include "prizma/render/fluorescence.h"
#include "prizma/render/hit_guides.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/rng.h"
#include "prizma/render/sample_range.h"
#include "prizma/render/wavelength_map.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"
#include "prizma/spectral/version.h"

namespace prizma::render {
namespace {

using spectral::InputError;

// Automatic pass size: about this many paths per pass.
constexpr std::int64_t kPathsPerPass = std::int64_t{1} << 20;

// The guide layers of --features (docs/spectral-exr.md, "Guide layers"), per sample from the path's
// result: the depth of the first scattering as a fraction of the bounds' diagonal (1: none), and
// whether it scattered (the pixel's mean: the fraction of paths that scatter).
const std::vector<std::string> kGuideNames = {"depth", "scatter"};
void guide_sample(const PathResult& r, double* g) {
  g[0] = r.scattered ? static_cast<double>(r.first_scatter_depth) : 1.0;
  g[1] = r.scattered ? 1.0 : 0.0;
}

struct ThreadState {
  PathScratch path;
  std::vector<double> value;     // [light][bin] of one sample
  std::vector<double> value_fl;  // [light][bispectral pair] of one sample (fluorescent scenes)
  std::int64_t paths = 0;
  std::int64_t nan_or_inf = 0;
  std::int64_t converged = 0;
};

// Lights at unit white, as the file stores them (production): nothing folded in.
struct UnitLights {
  static constexpr bool kFolds = false;
  double at(int, double) const { return 1.0; }
};
// render_folded() (tests and benchmarks): each light's contribution at λ multiplied by
// its default spectrum at λ (the light "baked in", as VPT does). A separate instantiation of the
// sample loop, so the production loop has no branch for it.
struct FoldedLights {
  static constexpr bool kFolds = true;
  std::vector<spectral::Spectrum> spectra;  // per light
  double at(int light, double lambda_nm) const { return spectra[light].eval(lambda_nm); }
};

// What every sample of one render shares.
struct RenderContext {
  const RenderSettings& settings;
  const CameraModel& camera;
  const PathTracer& tracer;
  const WavelengthMap& map;
  const FluorescenceLayout& fluor;
  // Where each light's per-lane radiance comes from: the environment (−1), the medium's emission
  // (−2) or a directional light (its index in the tracer's directional results).
  std::vector<int> source;
  bool fluorescent = false;  // fluor.any in all-bins or single mode: paths may fluoresce
  // Single mode: pair_index[out·nb + in] is the bispectral pair of (out, in), −1 if none.
  std::vector<int> pair_index;
  Film& film;
  const std::atomic<bool>* cancel = nullptr;
  std::atomic<bool>& pass_cut;
};

// The samples of one pixel, for one way of treating the lights' spectra (Fold).
template <class Fold>
class PixelRenderer {
 public:
  PixelRenderer(const RenderContext& c, const Fold& fold) : m_c(c), m_fold(fold) {}

  void render(ThreadState& ts, int x, int y, std::int64_t s0, std::int64_t s1) const {
    const RenderSettings& st = m_c.settings;
    const int width = m_c.camera.width();
    const int nl = static_cast<int>(m_c.source.size());
    const int nb = st.bins.size();
    const std::size_t pix = static_cast<std::size_t>(y) * width + x;
    if (m_c.film.converged(pix)) return;
    PathScratch& ps = ts.path;
    double* v = ts.value.data();
    const std::size_t per_pixel = ts.value.size();
    for (std::int64_t s = s0; s < s1; ++s) {
      if (cancelled()) return;
      Rng rng(st.seed, pix, static_cast<std::uint64_t>(s), st.sampler);
      const double px = x + rng.uniform_double();
      const double py = y + rng.uniform_double();
      const Ray ray = m_c.camera.generate(px, py);
      const SampleIndex at{.seed = st.seed, .pixel = pix, .sample = s};
      // One path per lane group (one path without groups), all from the same camera ray and the same
      // random numbers (common random numbers: the groups' paths coincide as far as their lanes'
      // media agree, so their errors stay alike across the bins, as one path's are).
      bool finite = true;
      double guides[2];
      const int groups = m_c.map.groups();
      for (int k = 0; k < groups; ++k) {
        Rng path_rng = rng;
        const WavelengthDraw draw = m_c.map.draw(path_rng, ps.in.lambda_nm.data(), at, k);
        if (draw.hero >= 0) ps.in.hero_lane = draw.hero;
        ps.lanes = draw.lanes;  // a lane group's: fewer than prepared
        m_c.tracer.trace(ray, path_rng, ps);
        ++ts.paths;

        // Lanes → (light, bin) values of this sample (with lane groups: the group's bins).
        const auto [b0, b1] = m_c.map.bin_range(draw);
        for (int l = 0; l < nl; ++l) {
          double* out = v + static_cast<std::size_t>(l) * nb;
          m_c.map.to_bins(lane_values(ps.out, l, false, draw.lanes), draw, out);
          if constexpr (Fold::kFolds) {
            if (m_c.map.mode() == LaneMode::Single) {
              out[draw.bin] *= m_fold.at(l, m_c.map.lambda_at(draw, draw.bin));
            } else {
              for (int i = b0; i < b1; ++i) out[i] *= m_fold.at(l, m_c.map.lambda_at(draw, i));
            }
          }
          for (int i = b0; i < b1; ++i) finite = finite && std::isfinite(out[i]);
        }
        if (m_c.fluorescent) finite = add_fluorescent_sample(ps, draw.bin, v, ts.value_fl.data()) && finite;
        // The guides from the first group's path (the others' first scattering differs only by their
        // lanes' extinction).
        if (k == 0) guide_sample(ps.out, guides);
      }
      if (!finite) {
        // Never let a NaN/Inf reach the image: count it, take the sample as 0.
        ++ts.nan_or_inf;
        std::fill(v, v + per_pixel, 0.0);
        std::fill(ts.value_fl.begin(), ts.value_fl.end(), 0.0);
      }
      if (m_c.film.add_sample(pix, v, ts.value_fl.data(), guides)) {
        ++ts.converged;
        return;
      }
    }
  }

 private:
  // Cancellation is polled at every sample: a pass cut short is abandoned (the film goes back to
  // its state before it), so the image still holds whole passes only.
  bool cancelled() const {
    if (m_c.cancel == nullptr || !m_c.cancel->load(std::memory_order_relaxed)) return false;
    m_c.pass_cut.store(true, std::memory_order_relaxed);
    return true;
  }

  // Light l's per-lane radiance in a path's result: the diagonal part, or (fl) the in side of the
  // rank-one term of a path that fluoresced.
  // `lanes`: the path's lane count, the rows' stride (the map's with fluorescence: no lane groups).
  const float* lane_values(const PathResult& r, int l, bool fl, int lanes) const {
    const int src = m_c.source[l];
    if (src == -2) return fl ? r.fl_emission.data() : r.emission.data();
    if (src < 0) return fl ? r.fl_environment.data() : r.environment.data();
    const auto row = static_cast<std::size_t>(src) * static_cast<std::size_t>(lanes);
    return (fl ? r.fl_directional.data() : r.directional.data()) + row;
  }

  // A fluorescent path's rank-one term, M[out][in] = a[out]·(in side)[in] per light: off-diagonal
  // pairs into vf, diagonal ones into the sample's transport v. Folded lights (test mode) weigh the
  // in side by the light at λin and everything goes to the diagonal (the radiance at out).
  // False when a value is not finite.
  bool add_fluorescent_sample(const PathScratch& ps, int bin, double* v, double* vf) const {
    const std::size_t per_pixel_fl = m_c.film.bispectral_per_pixel();
    std::fill(vf, vf + per_pixel_fl, 0.0);
    if (!ps.out.fl_active) return true;
    const int nl = static_cast<int>(m_c.source.size());
    const int nb = m_c.settings.bins.size();
    const std::size_t np = m_c.fluor.pairs.size();
    bool ok = true;
    const float* a = ps.out.fl_a.data();
    if (m_c.map.mode() == LaneMode::Single) {
      // One lane: out = the camera bin (drawn with probability 1/n: weight n), in = the bin of the
      // wavelength each segment carried (σf > 0 there, so the pair is in the layout): the segments
      // that later events closed, then the open one, at the path's last wavelength.
      const std::size_t size = PathResult::fl_segment_size(m_c.tracer.directional_lights().size());
      const std::vector<float>& seg = ps.out.fl_segments;
      for (std::size_t r = 0; r + size <= seg.size(); r += size)
        ok = add_single_segment(seg[r + PathResult::kSegmentLambda], a[0], bin,
                                [&](int l) { return seg[r + segment_offset(l)]; }, v, vf) && ok;
      return add_single_segment(ps.cache.lambda_nm[0], a[0], bin,
                                [&](int l) { return lane_values(ps.out, l, true, m_c.map.lanes())[0]; }, v, vf) && ok;
    }
    for (int l = 0; l < nl; ++l) {
      const float* src = lane_values(ps.out, l, true, m_c.map.lanes());
      double* out = v + static_cast<std::size_t>(l) * nb;
      // λin: the path's last wavelengths (a fluorescent event draws them anew; with two or more
      // events chained the folded light is taken at the last segment's, an approximation of the
      // test mode only).
      auto fold_at = [&](int i) { return m_fold.at(l, ps.cache.lambda_nm[i]); };
      for (std::size_t k = 0; k < np; ++k) {
        const spectral::BinPair pr = m_c.fluor.pairs[k];
        const double val = static_cast<double>(a[pr.out]) * src[pr.in] * fold_at(pr.in);
        ok = ok && std::isfinite(val);
        if constexpr (Fold::kFolds)
          out[pr.out] += val;
        else
          vf[static_cast<std::size_t>(l) * np + k] = val;
      }
      for (int i : m_c.fluor.diagonal) {
        out[i] += static_cast<double>(a[i]) * src[i] * fold_at(i);
        ok = ok && std::isfinite(out[i]);
      }
    }
    return ok;
  }

  // Single mode: one segment's term a·(in side at λin)·n into the pair (camera bin, bin of λin), per
  // light l (in_side(l)); added to the pair's value of the sample (a path can visit a bin twice).
  template <class InSide>
  bool add_single_segment(double lambda_in, float a, int bin, const InSide& in_side, double* v, double* vf) const {
    const int nl = static_cast<int>(m_c.source.size());
    const int nb = m_c.settings.bins.size();
    const std::size_t np = m_c.fluor.pairs.size();
    const int in = m_c.settings.bins.find(lambda_in);
    const int k = in < 0 ? -1 : in == bin ? -2 : m_c.pair_index[static_cast<std::size_t>(bin) * nb + in];
    bool ok = true;
    for (int l = 0; l < nl; ++l) {
      const double val = static_cast<double>(a) * in_side(l) * nb * m_fold.at(l, lambda_in);
      ok = ok && std::isfinite(val);
      if (k == -2 || (k >= 0 && Fold::kFolds))
        v[static_cast<std::size_t>(l) * nb + bin] += val;
      else if (k >= 0)
        vf[static_cast<std::size_t>(l) * np + static_cast<std::size_t>(k)] += val;
    }
    return ok;
  }

  // Light l's place in a closed segment's record (PathResult::fl_segments).
  std::size_t segment_offset(int l) const {
    const int src = m_c.source[l];
    if (src == -2) return PathResult::kSegmentEmission;
    if (src < 0) return PathResult::kSegmentEnvironment;
    return PathResult::kSegmentDirectional + static_cast<std::size_t>(src);
  }

  const RenderContext& m_c;
  const Fold& m_fold;
};

// Renders the passes [sample_begin, sample_end) into the film; returns the samples per pixel
// completed (whole passes only) and sets interrupted when the cancel flag stopped it early.
template <class Fold>
std::int64_t run_passes(const RenderContext& c, const Fold& fold, tbb::enumerable_thread_specific<ThreadState>& states,
                        const RenderCallbacks& callbacks, std::chrono::steady_clock::time_point start,
                        bool& interrupted) {
  const RenderSettings& st = c.settings;
  const PixelRenderer<Fold> pixel(c, fold);
  const int width = c.camera.width(), height = c.camera.height();
  const std::int64_t total = st.sample_end - st.sample_begin;
  std::int64_t per_pass = callbacks.samples_per_pass;
  if (per_pass <= 0) per_pass = std::max<std::int64_t>(1, kPathsPerPass / static_cast<std::int64_t>(c.film.pixels()));
  per_pass = std::min(per_pass, total);

  std::optional<tbb::task_arena> arena;
  if (st.threads > 0) arena.emplace(st.threads);
  auto run_pass = [&](std::int64_t s0, std::int64_t s1) {
    // Runs of pixels, not rows: a 24×24 image has 24 rows, each 1/24 of the pass, too few for two
    // threads to finish a pass together; each pixel's samples are still taken by one task, in order.
    const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels, 4), [&](const tbb::blocked_range<std::size_t>& r) {
      ThreadState& ts = states.local();
      for (std::size_t p = r.begin(); p != r.end() && !c.pass_cut.load(std::memory_order_relaxed); ++p)
        pixel.render(ts, static_cast<int>(p % static_cast<std::size_t>(width)), static_cast<int>(p / static_cast<std::size_t>(width)), s0, s1);
    });
  };

  std::int64_t done = 0;
  interrupted = false;
  while (done < total) {
    if (callbacks.cancel && callbacks.cancel->load()) {
      interrupted = true;
      break;
    }
    const std::int64_t s0 = st.sample_begin + done;
    const std::int64_t s1 = std::min(st.sample_end, s0 + per_pass);
    if (callbacks.cancel) c.film.save();  // only a render that can be cancelled keeps a copy
    if (arena)
      arena->execute([&] { run_pass(s0, s1); });
    else
      run_pass(s0, s1);
    if (c.pass_cut.load()) {
      c.film.restore();
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
  return done;
}

}  // namespace

std::string wavelength_sampling_name(WavelengthSampling w) {
  switch (w) {
    case WavelengthSampling::Auto: return "auto";
    case WavelengthSampling::Single: return "single";
    case WavelengthSampling::SpectralMis: return "spectral-mis";
    case WavelengthSampling::SpectralTracking: break;
  }
  return "spectral-tracking";
}

WavelengthSampling parse_wavelength_sampling(std::string_view name, std::string_view input) {
  for (WavelengthSampling w : {WavelengthSampling::Auto, WavelengthSampling::SpectralTracking,
                               WavelengthSampling::SpectralMis, WavelengthSampling::Single})
    if (name == wavelength_sampling_name(w)) return w;
  throw InputError(std::string(input), "unknown wavelength sampling \"" + std::string(name) +
                                           "\" (known: auto, spectral-tracking, spectral-mis, single)");
}

WavelengthSampling resolve_wavelength_sampling(const Scene& scene) {
  const WavelengthSampling w = scene.settings.wavelength_sampling;
  const auto fluorescent = std::find_if(scene.medium.materials.begin(), scene.medium.materials.end(),
                                        [](const Material& m) { return m.fluorescent; });
  const bool any_fluorescent = fluorescent != scene.medium.materials.end();
  if (w == WavelengthSampling::SpectralMis && any_fluorescent)
    throw InputError("wavelength_sampling", "spectral-mis does not support fluorescent materials (material \"" +
                                                fluorescent->name + "\" fluoresces): use spectral-tracking or auto");
  if (w != WavelengthSampling::Auto) return w;
  if (any_fluorescent) return WavelengthSampling::SpectralTracking;
  // The rule and the measurements behind it: docs/renderer.md, "Which scenes take spectral MIS".
  for (const MaterialEvents& e :
       choose_event_probabilities(scene.settings.event_probabilities, scene.medium.materials, scene.settings.bins))
    if (e.extinction_ratio > kMisExtinctionRatio) return WavelengthSampling::SpectralMis;
  return WavelengthSampling::SpectralTracking;
}

int resolve_mis_lane_groups(const Scene& scene) {
  const spectral::BinLayout& bins = scene.settings.bins;
  const int nb = bins.size();
  if (nb < 2 || resolve_wavelength_sampling(scene) != WavelengthSampling::SpectralMis) return 1;
  if (scene.settings.mis_lane_groups > 0) return std::min(scene.settings.mis_lane_groups, nb);
  // The chromatic materials' bin-average extinction, then the fewest runs that keep each within the
  // ratio. The measurements behind the rule: docs/renderer.md, "Lane groups".
  std::vector<std::vector<double>> sigma;
  for (const Material& m : scene.medium.materials)
    if (!m.sigma_t_per_unit.is_constant()) sigma.push_back(m.sigma_t_per_unit.bin_averages(bins));
  const int most = std::max(1, nb / kMisGroupMinBins);
  for (int g = 1; g < most; ++g) {
    bool within = true;
    for (int k = 0; k < g && within; ++k) {
      const int b0 = WavelengthMap::run_begin(k, nb, g), b1 = WavelengthMap::run_begin(k + 1, nb, g);
      for (const std::vector<double>& v : sigma) {
        const auto [lo, hi] = std::minmax_element(v.begin() + b0, v.begin() + b1);
        if (!(*hi <= kMisGroupExtinctionRatio * *lo)) within = false;
      }
    }
    if (within) return g;
  }
  return most;
}

int recorded_mis_lane_groups(const spectral::SpectralExrInfo& info) { return std::max(1, info.mis_lane_groups); }

std::string sampler_name(Sampler s) { return s == Sampler::Sobol ? "sobol" : "independent"; }

Sampler parse_sampler(std::string_view name, std::string_view input) {
  if (name == "independent") return Sampler::Independent;
  if (name == "sobol") return Sampler::Sobol;
  throw InputError(std::string(input), "unknown sampler \"" + std::string(name) + "\" (known: independent, sobol)");
}

namespace {

// render() and render_folded(): `fold` chooses the lights' treatment (the sample loop is instantiated
// for each, so the production loop has no branch for the test mode).
// long on purpose: the one sample loop set-up per mode (single, tracking, MIS, fluorescence, folded), instantiated once each.
spectral::SpectralImage render_scene(const Scene& scene, const RenderCallbacks& callbacks, RenderStats* stats_out,
                                     bool fold) {
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
  const WavelengthSampling sampling = resolve_wavelength_sampling(scene);
  const PathTracer tracer(scene, bins.min_nm(), bins.max_nm(), st.use_majorant_grid);
  const int nl = static_cast<int>(scene.lights.size());

  LaneMode mode = LaneMode::AllBins;
  if (sampling == WavelengthSampling::Single)
    mode = LaneMode::Single;
  else if (tracer.wavelength_independent())
    mode = LaneMode::Replicated;
  const WavelengthMap map(mode, bins, sampling == WavelengthSampling::SpectralMis, resolve_mis_lane_groups(scene));
  // Fluorescence (docs/fluorescence.md): the bispectral pairs the scene can fill; nothing of it
  // runs for a scene without fluorescence.
  const FluorescenceLayout fluor = fluorescence_layout(scene.medium, bins);
  // Single: the path's one wavelength changes at a fluorescent event (PathTracer::fluoresce); the
  // pair (camera bin, bin of the last wavelength) gets the term.
  const bool fluorescent = fluor.any && mode != LaneMode::Replicated;
  std::vector<int> pair_index;
  if (fluor.any && mode == LaneMode::Single) {
    pair_index.assign(static_cast<std::size_t>(nb) * nb, -1);
    for (std::size_t k = 0; k < fluor.pairs.size(); ++k)
      pair_index[static_cast<std::size_t>(fluor.pairs[k].out) * nb + fluor.pairs[k].in] = static_cast<int>(k);
  }

  std::vector<int> source(nl, -1);
  for (std::size_t k = 0; k < tracer.directional_lights().size(); ++k)
    source[tracer.directional_lights()[k]] = static_cast<int>(k);
  if (tracer.emission_light() >= 0) source[tracer.emission_light()] = -2;

  // Test/benchmark mode: lights folded in with their default spectra.
  FoldedLights folded;
  if (fold) {
    spectral::SpecContext ctx;
    if (!scene.source.empty()) ctx.base_dir = scene.source.parent_path();
    for (int l = 0; l < nl; ++l) {
      ctx.input = "lights[" + std::to_string(l) + "].spectrum";
      folded.spectra.push_back(spectral::parse_spectrum(scene.lights[l].spectrum_spec, ctx));
    }
  }

  Film::Layout layout;
  layout.width = camera.width();
  layout.height = camera.height();
  layout.lights = nl;
  layout.bins = bins;
  if (fluorescent && !fold) layout.bispectral = fluor.pairs;  // folded: all on the diagonal
  layout.variance = st.write_variance;
  layout.target_error = st.target_error;
  if (st.write_guides) layout.guides = kGuideNames;
  Film film(std::move(layout));

  tbb::enumerable_thread_specific<ThreadState> states([&] {
    ThreadState t;
    tracer.prepare(t.path, map.lanes());
    t.value.assign(film.values_per_pixel(), 0.0);
    if (fluorescent) t.value_fl.assign(film.bispectral_per_pixel(), 0.0);
    if (fluorescent && mode == LaneMode::AllBins) {
      for (int i = 0; i < nb; ++i) {
        t.path.in.lo_nm[i] = static_cast<float>(bins.lo_nm(i));
        t.path.in.width_nm[i] = static_cast<float>(bins.width_nm(i));
      }
    }
    return t;
  });

  std::atomic<bool> pass_cut{false};
  const RenderContext context{st,   camera, tracer, map, fluor, source, fluorescent, std::move(pair_index),
                              film, callbacks.cancel, pass_cut};
  bool interrupted = false;
  const std::int64_t done = fold ? run_passes(context, folded, states, callbacks, start, interrupted)
                            : run_passes(context, UnitLights{}, states, callbacks, start, interrupted);
  if (done == 0) throw spectral::RuntimeError("render interrupted before the first pass completed");

  std::vector<std::string> names;
  for (const Light& light : scene.lights) names.push_back(light.name);
  spectral::SpectralImage img = film.image(names);
  // --features: the Monte Carlo guides (the film's), then the deterministic first-hit ones.
  if (st.write_guides)
    for (spectral::GuideLayer& g : hit_guides(scene, camera, tracer)) img.guides.push_back(std::move(g));
  img.info.is_prizma = true;
  img.info.light_records = light_records(scene.lights);
  img.info.samples = done;
  img.info.sample_range = SampleRange{st.sample_begin, st.sample_begin + done}.to_string();
  img.info.seed = st.seed;
  img.info.scene_hash = scene.hash;
  img.info.version = spectral::prizma_version();
  img.info.wavelength_sampling = wavelength_sampling_name(sampling);
  if (sampling == WavelengthSampling::SpectralMis) img.info.mis_lane_groups = map.groups();

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

}  // namespace

spectral::SpectralImage render(const Scene& scene, const RenderCallbacks& callbacks, RenderStats* stats) {
  return render_scene(scene, callbacks, stats, /*fold=*/false);
}

spectral::SpectralImage render_folded(const Scene& scene, const RenderCallbacks& callbacks, RenderStats* stats) {
  return render_scene(scene, callbacks, stats, /*fold=*/true);
}

}  // namespace prizma::render
