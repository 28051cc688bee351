// Spectral MIS (WavelengthSampling::SpectralMis, renderer/src/tracer/spectral_mis.inl): its pieces
// (the fast exponential, the hero lanes, the grid's per-lane majorant bounds), closed forms at fixed
// seeds within kSe standard errors (Beer–Lambert with σt spread 100× across the bins, homogeneous
// and heterogeneous; the chromatic white furnace; the half-space with spectral albedo, anisotropy and
// extinction; an absorbing, emitting slab), bounded tails over many seeds, determinism over thread
// counts and shards, and the auto rule with what it leaves to spectral tracking.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstring>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "prizma/render/fast_exp.h"
#include "prizma/render/majorant_grid.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/render.h"
#include "prizma/render/transfer_function.h"
#include "prizma/render/wavelength_map.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"
#include "transfer_references.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;
using testing::box_scene;
using testing::hg;
using testing::kSe;
using testing::make_material;
using testing::pixel_average;
using testing::same_bits;

// Spectral MIS in `groups` lane groups (1: every bin on every path; the closed forms run with 1 and 3,
// the six bins in three runs of two, each its own path per sample).
Scene with_mis(Scene s, int groups = 1) {
  s.settings.wavelength_sampling = WavelengthSampling::SpectralMis;
  s.settings.mis_lane_groups = groups;
  return s;
}
constexpr int kGroupings[] = {1, 3};

using testing::bin_transmittance;

TEST(SpectralMis, FastExpIsWithinThreeTenthsOfAMillionth) {
  double worst = 0.0;
  for (double x = -87.0; x <= 88.0; x += 0.001) {
    const auto xf = static_cast<float>(x);
    const double exact = std::exp(static_cast<double>(xf));
    worst = std::max(worst, std::abs(exp_approx(xf) - exact) / exact);
  }
  EXPECT_LT(worst, 3e-7);
  EXPECT_EQ(exp_approx(0.0f), 1.0f);
  EXPECT_EQ(exp_approx(-1000.0f), exp_approx(-87.0f));  // clamped, never 0 or a denormal
  EXPECT_EQ(exp_approx(std::numeric_limits<float>::quiet_NaN()), exp_approx(-87.0f));
  EXPECT_TRUE(std::isfinite(exp_approx(1000.0f)));
}

TEST(SpectralMis, HeroLanesTakeEveryBinOncePerCycleAndSpreadOverFewerSamples) {
  for (int n : {1, 2, 6, 12, 16, 32, 33}) {
    const WavelengthMap map(LaneMode::AllBins, spectral::BinLayout::linear(400, 700, n));
    for (std::uint64_t pixel : {0u, 7u, 123456u}) {
      // Every n consecutive samples (from any start) take each lane once.
      for (std::int64_t start : {0, 5, 1000003}) {
        std::set<int> seen;
        for (std::int64_t s = start; s < start + n; ++s) {
          const int j = map.hero_lane(9, pixel, s);
          ASSERT_GE(j, 0);
          ASSERT_LT(j, n);
          seen.insert(j);
        }
        EXPECT_EQ(static_cast<int>(seen.size()), n) << n << " bins, pixel " << pixel << ", from " << start;
      }
      // Half a cycle leaves no gap of more than 3 bins (plain turns would leave half the spectrum;
      // 16 of 32 bins take every other one).
      if (n >= 12) {
        std::vector<int> half;
        for (std::int64_t s = 0; s < n / 2; ++s) half.push_back(map.hero_lane(9, pixel, s));
        std::sort(half.begin(), half.end());
        int gap = half.front() + n - half.back();
        for (std::size_t k = 1; k < half.size(); ++k) gap = std::max(gap, half[k] - half[k - 1]);
        EXPECT_LE(gap, n == 32 || n == 16 ? 2 : 3) << n << " bins";
      }
    }
    // The offset depends on the seed and the pixel.
    if (n >= 12) {
      std::set<int> first;
      for (std::uint64_t pixel = 0; pixel < 64; ++pixel) first.insert(map.hero_lane(9, pixel, 0));
      EXPECT_GT(first.size(), 6u);
      EXPECT_NE(map.hero_lane(9, 3, 0) + 100 * map.hero_lane(9, 4, 0), map.hero_lane(10, 3, 0) + 100 * map.hero_lane(10, 4, 0));
    }
  }
}

TEST(SpectralMis, TheWavelengthDrawCarriesTheHeroLaneOnlyUnderSpectralMis) {
  // WavelengthMap::draw is the one sampler: the lanes' wavelengths and, in all-bins mode with a hero,
  // hero_lane(seed, pixel, sample); −1 in every other mode. The hero takes no random number: the
  // wavelengths are those of the draw without it.
  const spectral::BinLayout bins = spectral::BinLayout::linear(400, 700, 12);
  const WavelengthMap hero(LaneMode::AllBins, bins, true), plain(LaneMode::AllBins, bins);
  const WavelengthMap single(LaneMode::Single, bins, true), replicated(LaneMode::Replicated, bins, true);
  EXPECT_TRUE(hero.has_hero());
  EXPECT_FALSE(plain.has_hero());
  EXPECT_FALSE(single.has_hero());
  EXPECT_FALSE(replicated.has_hero());
  std::vector<float> a(12), b(12);
  for (std::int64_t s = 0; s < 30; ++s) {
    const SampleIndex at{.seed = 9, .pixel = 77, .sample = s};
    Rng ra(9, 77, static_cast<std::uint64_t>(s)), rb(9, 77, static_cast<std::uint64_t>(s));
    const WavelengthDraw dh = hero.draw(ra, a.data(), at), dp = plain.draw(rb, b.data(), at);
    EXPECT_EQ(dh.hero, hero.hero_lane(9, 77, s));
    EXPECT_EQ(dp.hero, -1);
    EXPECT_EQ(dh.u, dp.u);
    EXPECT_EQ(a, b);
    EXPECT_EQ(single.draw(ra, a.data(), at).hero, -1);
    EXPECT_EQ(replicated.draw(ra, a.data(), at).hero, -1);
  }
}

TEST(SpectralMis, SpectralBoundsHoldEveryPointOfTheirCells) {
  // The per-lane majorant d_max·σt_m(λ) of a cell with a spectral bound must bound d·σt_m(λ) at
  // every point of it, with the point's material m: a random trilinear volume with overlapping rules
  // (as Interpolation.MajorantBoundsSigmaTAtEveryPoint), and the same classified nearest.
  // Half the volume (x < 12) takes values 150–255, which only the third rule meets, with NaN voxels
  // (empty points) among them: cells of one material; the other half random values of all rules and
  // 0 (empty).
  const int n = 24;
  Volume vol;
  vol.dims = {n, n - 3, n + 5};
  vol.source = "random";
  std::mt19937 gen(23);
  std::uniform_real_distribution<float> val(0.0f, 255.0f), high(150.0f, 255.0f);
  for (std::size_t k = 0; k < vol.voxel_count(); ++k) {
    const bool one_material = static_cast<int>(k % n) < n / 2;
    vol.values.push_back(k % 37 == 0 ? std::numeric_limits<float>::quiet_NaN()
                         : one_material ? high(gen)
                         : k % 13 == 0 ? 0.0f : val(gen));
  }
  TransferFunction tf;
  tf.materials = {testing::grey_material(0.5, 3.0), testing::grey_material(0.9, 40.0), testing::grey_material(0.2, 7.0)};
  MaterialRule ra, rb, rc;
  ra.value_lo = 10.0;
  ra.value_hi = 60.0;
  ra.material = 0;
  ra.density.values = {10.0, 30.0, 60.0};
  ra.density.densities = {0.0, 2.5, 0.5};
  rb.value_lo = 100.0;
  rb.value_hi = 120.0;
  rb.material = 1;
  rc.value_lo = 50.0;
  rc.value_hi = 255.0;
  rc.material = 2;
  rc.density.values = {150.0, 255.0};
  rc.density.densities = {1.0, 3.0};
  tf.rules = {ra, rb, rc};
  for (Interpolation interp : {Interpolation::Trilinear, Interpolation::Nearest}) {
    Scene s = box_scene(testing::grey_material(0.5, 1.0));
    s.medium = build_medium(vol, tf, "test", interp);
    const std::vector<float> sigma_max = {3.0f, 40.0f, 7.0f};
    const PathTracer tracer(s, 400, 700, true);
    for (int cell_voxels : {4, MajorantGrid::kCellVoxels}) {
      const MajorantGrid own(s.medium, sigma_max, cell_voxels);
      const MajorantGrid& grid = cell_voxels == MajorantGrid::kCellVoxels ? tracer.grid() : own;
      std::uniform_real_distribution<double> u(0.0, 1.0);
      int bounded = 0, unbounded = 0;
      for (int k = 0; k < 100000; ++k) {
        Eigen::Vector3d p;
        std::array<int, 3> cell{};
        for (int a = 0; a < 3; ++a) {
          p[a] = s.medium.bounds_min[a] + u(gen) * (s.medium.bounds_max[a] - s.medium.bounds_min[a]);
          cell[a] = std::clamp(static_cast<int>(std::floor((p[a] - grid.bounds_min()[a]) / grid.cell_size()[a])), 0,
                               grid.cells()[a] - 1);
        }
        std::uint16_t m;
        float d;
        tracer.lookup(p, m, d);
        const CellSpectralBound& b = grid.spectral_bound(cell);
        if (b.material == CellSpectralBound::kNone) {
          ++unbounded;
          continue;
        }
        ++bounded;
        if (m == Medium::kEmpty || !(d > 0.0f)) continue;
        ASSERT_EQ(m, b.material) << "point " << p.transpose();
        ASSERT_LE(d, b.density_max) << "point " << p.transpose();
        ASSERT_LE(d * sigma_max[m], grid.majorant(cell[0], cell[1], cell[2]));
      }
      EXPECT_GT(bounded, 5000) << (interp == Interpolation::Nearest ? "nearest" : "trilinear") << ", " << cell_voxels;
      EXPECT_GT(unbounded, 5000);  // the volume has cells of two materials
    }
  }
}

TEST(SpectralMis, BeerLambertPerBinWithExtinctionSpread100Times) {
  // Absorbing box of depth 1, σt linear from 0.05 (400 nm) to 5 (700 nm) per unit: every pixel's
  // environment layer is the bin average of e^{−σt}. Homogeneous (each lane's majorant exact: no
  // null collisions), then a random density in [0.2, 2] on 4³ nearest voxels (majorant d_max·σt:
  // null collisions; per column of voxels the depth D = Σ d/4, the window covering parts of 4×4
  // columns), and with one global cell.
  const double s400 = 0.05, s700 = 5.0;
  for (const int groups : kGroupings)
  for (int variant = 0; variant < 3; ++variant) {
    Scene s = with_mis(box_scene(make_material(Spectrum::constant(0.0), Spectrum({400.0, 700.0}, {s400, s700}),
                                               Spectrum::constant(0.0)),
                                 4, 8, 256),
                       groups);
    if (variant > 0) testing::randomise_density(s, 0.2f, 2.0f);
    s.settings.use_majorant_grid = variant != 2;
    const auto m = pixel_average(render(s), 0);
    for (int b = 0; b < 6; ++b) {
      const double lo = s400 + (s700 - s400) * b / 6.0, hi = s400 + (s700 - s400) * (b + 1) / 6.0;
      const double expected =
          testing::column_window_average(s, [&](double depth) { return bin_transmittance(lo, hi, depth); });
      EXPECT_NEAR(m.mean[b], expected, kSe * m.se[b]) << groups << " groups, variant " << variant << " bin " << b << ": "
                                                      << m.mean[b] << " ± " << m.se[b] << ", expected " << expected;
      EXPECT_LT(m.se[b], 0.08 * expected) << groups << " groups, variant " << variant << " bin " << b;
    }
  }
}

TEST(SpectralMis, ChromaticFurnaceIsOne) {
  // Albedo 1, σt from 6 to 1 per unit and g from 0.6 to 0.3 (then constant) over 400–700 nm, random
  // density: exactly 1 in every bin. The hero's phase lobe and free flights, every lane weighted.
  for (const int groups : kGroupings)
  for (const auto& [g400, g700] : {std::pair{0.6, 0.3}, std::pair{0.4, 0.4}}) {
    const auto m = pixel_average(render(with_mis(testing::chromatic_furnace(g400, g700, 8, 64), groups)), 0);
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(m.mean[i], 1.0, kSe * m.se[i] + 1e-6) << groups << " groups, g " << g400 << "–" << g700 << " bin " << i;
      EXPECT_LT(m.se[i], 0.03) << groups << " groups, g " << g400 << "–" << g700 << " bin " << i;
    }
  }
}

TEST(SpectralMis, HalfSpaceWithSpectralAlbedoAnisotropyAndExtinction) {
  // All orders of scattering in a half-space (depth 1 of σt ≥ 300 per unit, the window ≥ 130 mean
  // free paths from the sides), each bin its own albedo (0.3 … 0.95) and HG g (−0.4 … 0.6) from
  // step tables, and σt from 1500 down to 300 over the bins (5×: the lanes' paths differ, the
  // reflection does not depend on σt), a delta light at 60°: per bin Ambartsumian's S(1, μ0)/(4π)
  // (HalfSpaceReflection). Both event rules of the hero: implicit capture (auto: albedo ≥ 0.5
  // somewhere) and analog (max).
  const std::vector<double> albedo = {0.3, 0.5, 0.7, 0.85, 0.9, 0.95}, g = {-0.4, -0.2, 0.0, 0.2, 0.4, 0.6};
  auto table = [](const std::vector<double>& v) {
    std::vector<double> l, y;
    for (int b = 0; b < 6; ++b) {
      l.push_back(400.0 + 50.0 * b);
      y.push_back(v[b]);
      l.push_back(b == 5 ? 700.0 : 449.999 + 50.0 * b);
      y.push_back(v[b]);
    }
    return Spectrum(l, y);
  };
  const double theta0 = 60.0 * std::numbers::pi / 180.0, mu0 = std::cos(theta0);
  std::vector<double> expected(6);
  for (int b = 0; b < 6; ++b) {
    const double gb = g[b];
    expected[b] = testing::HalfSpaceReflection(albedo[b], [gb](double c) { return hg(c, gb); }, mu0).radiance();
  }
  for (const int groups : kGroupings)
  for (EventProbabilities e : {EventProbabilities::Auto, EventProbabilities::Max}) {
    Scene s = with_mis(testing::window_scene(make_material(table(albedo), Spectrum({400.0, 700.0}, {1500.0, 300.0}), table(g)),
                                             testing::directional_light("sun", {std::sin(theta0), 0.0, mu0}), 16, 128),
                       groups);
    s.settings.seed = 21;
    s.settings.event_probabilities = e;
    const auto m = pixel_average(render(s), 0);
    for (int b = 0; b < 6; ++b) {
      EXPECT_NEAR(m.mean[b], expected[b], kSe * m.se[b]) << groups << " groups, " << event_probabilities_name(e) << " bin "
                                                         << b << ": " << m.mean[b] << " ± " << m.se[b] << " vs " << expected[b];
      EXPECT_LT(m.se[b], 0.03 * expected[b]) << groups << " groups, " << event_probabilities_name(e) << " bin " << b;
    }
  }
}

TEST(SpectralMis, AbsorbingEmittingSlabGivesLeTimesOneMinusTransmittance) {
  // The emission layer under spectral MIS: albedo 0, σt from 0.2 to 4 per unit (20×), Le = 2, depth
  // 1: per bin 2·(1 − the bin average of e^{−σt}); the environment layer that average.
  Material mat = make_material(Spectrum::constant(0.0), Spectrum({400.0, 700.0}, {0.2, 4.0}), Spectrum::constant(0.0));
  mat.emission = Spectrum::constant(2.0);
  for (const int groups : kGroupings) {
  Scene s = with_mis(box_scene(mat, 4, 8, 256), groups);
  Light em;
  em.name = "emission";
  em.emission = true;
  em.spectrum_spec = "E";
  s.lights.push_back(em);
  const auto img = render(s);
  const auto env = pixel_average(img, 0), glow = pixel_average(img, 1);
  for (int b = 0; b < 6; ++b) {
    const double t = bin_transmittance(0.2 + 3.8 * b / 6.0, 0.2 + 3.8 * (b + 1) / 6.0, 1.0);
    EXPECT_NEAR(glow.mean[b], 2.0 * (1.0 - t), kSe * glow.se[b]) << groups << " groups, bin " << b;
    EXPECT_LT(glow.se[b], 0.02 * 2.0 * (1.0 - t)) << groups << " groups, bin " << b;
    EXPECT_NEAR(env.mean[b], t, kSe * env.se[b]) << groups << " groups, bin " << b;
  }
  }
}

TEST(SpectralMis, TailsStayBoundedOverManySeeds) {
  // The heavy-tail check: a scattering, absorbing box with σt spread 20× over the bins, chromatic
  // albedo and g, random density, a directional light and the environment, rendered with 40 seeds of
  // 16 spp. The balance heuristic bounds every lane's path weight by n (6) times its own analog
  // weight, so: no render's largest pixel is far above the seeds' median largest pixel (a hero's
  // weight f_i/p_j without the heuristic puts single pixels orders of magnitude above it), every
  // render's standard error stays near the median one, the spread of the renders' means is what
  // their standard errors say (a tail the renders miss shows as a spread above them; the reported
  // errors are conservative, the hero lanes being stratified), and each render's mean lies within
  // 5 of its own standard errors of the seeds' mean. (tests/stress: the long form, 400 seeds.) With
  // and without lane groups.
  for (const int groups : kGroupings) {
  SCOPED_TRACE(std::to_string(groups) + " lane groups");
  Scene s = with_mis(box_scene(make_material(Spectrum({400.0, 700.0}, {0.95, 0.4}), Spectrum({400.0, 700.0}, {8.0, 0.4}),
                                             Spectrum({400.0, 700.0}, {0.7, -0.2})),
                               8, 8, 16),
                     groups);
  testing::randomise_density(s, 0.0f, 2.0f);
  s.lights.push_back(testing::directional_light("sun", {0.4, 1.0, 0.3}));
  const int seeds = 40;
  std::vector<std::vector<double>> mean(seeds), se(seeds);
  std::vector<double> peak(seeds, 0.0);
  for (int k = 0; k < seeds; ++k) {
    s.settings.seed = 100 + k;
    const auto img = render(s);
    for (int light = 0; light < 2; ++light) {
      const auto e = pixel_average(img, light);
      mean[k].insert(mean[k].end(), e.mean.begin(), e.mean.end());
      se[k].insert(se[k].end(), e.se.begin(), e.se.end());
      for (float v : img.lights[light].data) peak[k] = std::max(peak[k], static_cast<double>(v));
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  for (std::size_t i = 0; i < mean[0].size(); ++i) {
    double m = 0.0, sq = 0.0;
    std::vector<double> ses;
    for (int k = 0; k < seeds; ++k) {
      m += mean[k][i] / seeds;
      ses.push_back(se[k][i]);
    }
    for (int k = 0; k < seeds; ++k) sq += (mean[k][i] - m) * (mean[k][i] - m) / (seeds - 1);
    const double median_se = median(ses);
    EXPECT_LT(*std::max_element(ses.begin(), ses.end()), 2.5 * median_se) << "value " << i;
    EXPECT_LT(std::sqrt(sq), 1.5 * median_se) << "value " << i;
    for (int k = 0; k < seeds; ++k) EXPECT_NEAR(mean[k][i], m, 5.0 * se[k][i]) << "seed " << 100 + k << " value " << i;
  }
  EXPECT_LT(*std::max_element(peak.begin(), peak.end()), 2.0 * median(peak));
  }
}

TEST(SpectralMis, ThreadCountAndShardsDoNotChangeABit) {
  for (const int groups : kGroupings) {
  SCOPED_TRACE(std::to_string(groups) + " lane groups");
  Scene s = with_mis(testing::chromatic_scene(16), groups);
  s.settings.threads = 1;
  const auto one = render(s);
  s.settings.threads = 2;
  EXPECT_TRUE(same_bits(one, render(s)));
  s.settings.threads = 0;
  RenderCallbacks cb;
  cb.samples_per_pass = 3;
  EXPECT_TRUE(same_bits(one, render(s, cb)));
  // Shards of the sample range merge into the full render, bit for bit (each sample's hero lane
  // depends on the sample index, not on where its range starts).
  std::vector<spectral::SpectralImage> shards;
  for (const auto& [b, e] : {std::pair{0, 5}, std::pair{5, 13}, std::pair{13, 16}}) {
    s.settings.sample_begin = b;
    s.settings.sample_end = e;
    shards.push_back(render(s));
    EXPECT_EQ(shards.back().info.wavelength_sampling, "spectral-mis");
  }
  const auto merged = merge_shards(shards);
  for (std::size_t l = 0; l < one.lights.size(); ++l)
    for (std::size_t k = 0; k < one.lights[l].data.size(); ++k)
      ASSERT_FLOAT_EQ(merged.lights[l].data[k], one.lights[l].data[k]) << "light " << l << " value " << k;
  // The comparison can fail: spectral tracking renders other bits.
  s.settings.sample_begin = 0;
  s.settings.sample_end = 16;
  s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  EXPECT_FALSE(same_bits(one, render(s)));
  }
}

TEST(SpectralMis, GreyMediaRenderTheSameBitsWhateverTheSetting) {
  // A wavelength-independent medium is one lane, replicated: no hero, the same bits as before.
  Scene s = box_scene(testing::grey_material(0.7, 3.0, 0.4), 6, 8, 16);
  testing::randomise_density(s, 0.0f, 2.0f);
  s.lights.push_back(testing::directional_light("sun", {0.3, 1, 0.2}));
  s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  const auto tracking = render(s);
  for (WavelengthSampling w : {WavelengthSampling::Auto, WavelengthSampling::SpectralMis}) {
    s.settings.wavelength_sampling = w;
    RenderStats stats;
    EXPECT_TRUE(same_bits(tracking, render(s, {}, &stats))) << wavelength_sampling_name(w);
    EXPECT_TRUE(stats.wavelength_independent);
  }
}

TEST(SpectralMis, AutoTakesItWhereTheExtinctionVariesAndNotForFluorescence) {
  Scene chromatic = testing::chromatic_scene(2);  // σt from 4 to 1 over the bins
  EXPECT_EQ(resolve_wavelength_sampling(chromatic), WavelengthSampling::SpectralMis);
  EXPECT_EQ(render(chromatic).info.wavelength_sampling, "spectral-mis");
  // σt the same in every bin, the albedo not (the metamer pair, the MRI): spectral tracking.
  Scene albedo_only = box_scene(make_material(Spectrum({400.0, 700.0}, {0.9, 0.2}), Spectrum::constant(3.0),
                                              Spectrum::constant(0.0)));
  EXPECT_EQ(resolve_wavelength_sampling(albedo_only), WavelengthSampling::SpectralTracking);
  // A forced setting is kept.
  chromatic.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  EXPECT_EQ(resolve_wavelength_sampling(chromatic), WavelengthSampling::SpectralTracking);
  // Fluorescence stays on spectral tracking; spectral-mis asked for is refused, naming the material.
  Scene dye = testing::chromatic_scene(2);
  dye.medium.materials[0].name = "dye";
  dye.medium.materials[0].fluorescent = true;
  EXPECT_EQ(resolve_wavelength_sampling(dye), WavelengthSampling::SpectralTracking);
  dye.settings.wavelength_sampling = WavelengthSampling::SpectralMis;
  try {
    resolve_wavelength_sampling(dye);
    FAIL() << "no error";
  } catch (const spectral::InputError& e) {
    EXPECT_EQ(e.input(), "wavelength_sampling");
    EXPECT_NE(e.reason().find("\"dye\""), std::string::npos) << e.reason();
    EXPECT_NE(e.reason().find("spectral-tracking"), std::string::npos) << e.reason();
  }
  EXPECT_THROW(render(dye), spectral::InputError);
  EXPECT_EQ(parse_wavelength_sampling("spectral-mis"), WavelengthSampling::SpectralMis);
  EXPECT_EQ(parse_wavelength_sampling("auto"), WavelengthSampling::Auto);
  EXPECT_THROW(parse_wavelength_sampling("hero"), spectral::InputError);
}

}  // namespace
}  // namespace prizma::render
