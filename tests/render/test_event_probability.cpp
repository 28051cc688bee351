// Spectral tracking's event-probability schemes (renderer/include/prizma/render/event_probability.h):
// the names, the auto rule, the per-collision coefficients, and for every scheme the closed forms
// (Beer–Lambert, white furnace, single scattering, Chandrasekhar's half-space with a saturated albedo)
// at fixed seeds within 3 standard errors, plus one pinned value.
#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <vector>

#include "prizma/render/event_probability.h"
#include "prizma/render/render.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"
#include "transfer_references.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;
using testing::box_scene;
using testing::grey_material;
using testing::make_material;
using testing::hg;
using testing::HFunction;
using testing::integrate;
using testing::kPi;
using testing::kSe;
using testing::pixel_average;
using testing::window_scene;

constexpr EventProbabilities kSchemes[] = {EventProbabilities::Max, EventProbabilities::Average,
                                           EventProbabilities::Mixed, EventProbabilities::Implicit};

TEST(EventProbability, NamesRoundTripAndBadNamesAreRefused) {
  for (EventProbabilities e : {EventProbabilities::Auto, EventProbabilities::Max, EventProbabilities::Average,
                               EventProbabilities::Mixed, EventProbabilities::Implicit})
    EXPECT_EQ(parse_event_probabilities(event_probabilities_name(e)), e);
  try {
    parse_event_probabilities("maximum", "scene.json: event_probabilities");
    FAIL() << "no error";
  } catch (const spectral::InputError& err) {
    EXPECT_EQ(err.input(), "scene.json: event_probabilities");
    EXPECT_NE(err.reason().find("\"auto\", \"max\", \"average\", \"mixed\" or \"implicit\""), std::string::npos) << err.reason();
    EXPECT_NE(err.reason().find("maximum"), std::string::npos) << err.reason();
  }
}

TEST(EventProbability, CoefficientsOfEachScheme) {
  const float w[3] = {1.0f, 0.5f, 2.0f};
  const float sa[3] = {1.0f, 4.0f, 0.0f}, ss[3] = {2.0f, 2.0f, 1.0f}, sn[3] = {3.0f, 0.0f, 0.5f};
  // w·σ: absorb {1, 2, 0}, scatter {2, 1, 2}, null {3, 0, 1}.
  const auto mx = event_coefficients(EventProbabilities::Max, 3, w, sa, ss, sn);
  EXPECT_EQ(mx.absorb, 2.0f);
  EXPECT_EQ(mx.scatter, 2.0f);
  EXPECT_EQ(mx.null, 3.0f);
  const auto av = event_coefficients(EventProbabilities::Average, 3, w, sa, ss, sn);
  EXPECT_EQ(av.absorb, 3.0f);
  EXPECT_EQ(av.scatter, 5.0f);
  EXPECT_EQ(av.null, 4.0f);
  const auto mi = event_coefficients(EventProbabilities::Mixed, 3, w, sa, ss, sn);
  EXPECT_FLOAT_EQ(mi.absorb, 3.0f);
  EXPECT_FLOAT_EQ(mi.scatter, 2.0f + 5.0f / 3.0f);
  EXPECT_FLOAT_EQ(mi.null, 3.0f + 4.0f / 3.0f);
  const auto im = event_coefficients(EventProbabilities::Implicit, 3, w, sa, ss, sn);
  EXPECT_EQ(im.absorb, 0.0f);  // no absorption event with several lanes
  EXPECT_EQ(im.scatter, 5.0f);
  EXPECT_EQ(im.null, 4.0f);
  EXPECT_EQ(event_coefficients(EventProbabilities::Implicit, 1, w, sa, ss, sn).absorb, 1.0f);  // one lane: analog
  const float fo[3] = {1.0f, 1.0f, 1.0f};
  EXPECT_EQ(event_coefficient(EventProbabilities::Max, 3, w, 2.0f, fo), 4.0f);
  EXPECT_EQ(event_coefficient(EventProbabilities::Average, 3, w, 2.0f, fo), 7.0f);
  EXPECT_FLOAT_EQ(event_coefficient(EventProbabilities::Mixed, 3, w, 2.0f, fo), 4.0f + 7.0f / 3.0f);
}

TEST(EventProbability, AutoRuleReadsTheSpectra) {
  const auto bins = spectral::BinLayout::linear(400, 700, 12);
  auto choose = [&](const Material& m) { return choose_event_probabilities(EventProbabilities::Auto, m, bins); };
  // Grey and scattering: implicit (one lane anyway when every material is grey).
  auto c = choose(grey_material(0.8, 5.0));
  EXPECT_EQ(c.scheme, EventProbabilities::Implicit);
  EXPECT_DOUBLE_EQ(c.extinction_ratio, 1.0);
  EXPECT_DOUBLE_EQ(c.albedo_spread, 0.0);
  EXPECT_DOUBLE_EQ(c.albedo_max, 0.8);
  // Chromatic extinction (the Rayleigh-like cube): implicit.
  c = choose(make_material(Spectrum::constant(0.99), Spectrum({400.0, 700.0}, {9.0, 1.0}), Spectrum::constant(0.0)));
  EXPECT_EQ(c.scheme, EventProbabilities::Implicit);
  EXPECT_GT(c.extinction_ratio, 5.0);
  // Saturated albedo (the metamer spheres): implicit.
  c = choose(make_material(Spectrum({400.0, 550.0, 700.0}, {0.05, 0.9, 0.1}), Spectrum::constant(40.0),
                           Spectrum::constant(0.0)));
  EXPECT_EQ(c.scheme, EventProbabilities::Implicit);
  EXPECT_GT(c.albedo_spread, 0.5);
  // Absorbing more than scattering in every bin: max (absorption ends the path).
  c = choose(make_material(Spectrum({400.0, 700.0}, {0.0, 0.4}), Spectrum({400.0, 700.0}, {3.0, 1.0}),
                           Spectrum::constant(0.0)));
  EXPECT_EQ(c.scheme, EventProbabilities::Max);
  EXPECT_LT(c.albedo_max, kAbsorbingAlbedo);
  EXPECT_EQ(choose(grey_material(0.0, 2.0)).scheme, EventProbabilities::Max);
  // A forced scheme is kept, the measurements still made; one entry per material.
  const auto all = choose_event_probabilities(EventProbabilities::Mixed,
                                              {grey_material(0.5, 2.0), grey_material(0.5, 3.0)}, bins);
  ASSERT_EQ(all.size(), 2u);
  for (const auto& e : all) EXPECT_EQ(e.scheme, EventProbabilities::Mixed);
}

TEST(EventProbability, OneLaneIsTheSameForEveryScheme) {
  // A grey medium is traced with one lane: analog delta tracking whatever the scheme, bit for bit.
  Scene s = box_scene(grey_material(0.7, 3.0, 0.4), 6, 8, 16);
  testing::randomise_density(s, 0.0f, 2.0f);
  s.lights.push_back(testing::directional_light("sun", {0.3, 1, 0.2}));
  s.settings.event_probabilities = EventProbabilities::Max;
  const auto ref = render(s);
  for (EventProbabilities e : {EventProbabilities::Auto, EventProbabilities::Average, EventProbabilities::Mixed,
                               EventProbabilities::Implicit}) {
    s.settings.event_probabilities = e;
    s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;  // the schemes are spectral tracking's
    const auto img = render(s);
    for (std::size_t l = 0; l < ref.lights.size(); ++l) EXPECT_EQ(img.lights[l].data, ref.lights[l].data);
  }
}

TEST(EventProbability, AutoRendersAsTheSchemeItChooses) {
  Scene s = testing::chromatic_scene(8);
  s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  const auto chosen = choose_event_probabilities(EventProbabilities::Auto, s.medium.materials[0], s.settings.bins).scheme;
  const auto a = render(s);
  s.settings.event_probabilities = chosen;
  const auto b = render(s);
  s.settings.event_probabilities = chosen == EventProbabilities::Max ? EventProbabilities::Average : EventProbabilities::Max;
  EXPECT_EQ(chosen, EventProbabilities::Implicit);
  const auto other = render(s);
  EXPECT_EQ(a.lights[0].data, b.lights[0].data);
  EXPECT_NE(a.lights[0].data, other.lights[0].data);  // the setting reaches the tracer
}

TEST(EventProbability, BeerLambertPerBinForEveryScheme) {
  // Absorbing box, σt from 0.5 to 3 over the bins, depth 1: bin average (e^{−a} − e^{−b}) / (b − a).
  for (EventProbabilities e : kSchemes) {
    Scene s = box_scene(make_material(Spectrum::constant(0.0), Spectrum({400.0, 700.0}, {0.5, 3.0}),
                                      Spectrum::constant(0.0)),
                        4, 8, 256);
    s.settings.event_probabilities = e;
    s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;  // the schemes are spectral tracking's
    const auto m = pixel_average(render(s), 0);
    for (int i = 0; i < 6; ++i) {
      const double a = 0.5 + 2.5 * (i / 6.0), b = 0.5 + 2.5 * ((i + 1) / 6.0);
      EXPECT_NEAR(m.mean[i], (std::exp(-a) - std::exp(-b)) / (b - a), kSe * m.se[i] + 1e-7)
          << event_probabilities_name(e) << " bin " << i;
    }
  }
}

TEST(EventProbability, ChromaticFurnaceIsOneForEveryScheme) {
  // Albedo 1, σt and g depending on λ, heterogeneous density: 1 in every bin.
  for (EventProbabilities e : kSchemes) {
    Scene s = testing::chromatic_furnace(0.6, 0.3, 8, 64);
    s.settings.event_probabilities = e;
    s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;  // the schemes are spectral tracking's
    const auto m = pixel_average(render(s), 0);
    for (int i = 0; i < 6; ++i)
      EXPECT_NEAR(m.mean[i], 1.0, kSe * m.se[i] + 1e-6) << event_probabilities_name(e) << " bin " << i;
  }
}

// Per bin, the pixel average of single scattering (max_bounces = 1) of a delta light theta0 from
// the zenith in the window, 16×16 pixels at spp samples, by scheme e.
testing::BinEstimate single_scattering(const Material& m, double theta0, std::uint64_t seed, EventProbabilities e,
                                       std::int64_t spp = 128) {
  Scene s = window_scene(m, testing::directional_light("sun", {std::sin(theta0), 0.0, std::cos(theta0)}), 16, spp);
  s.settings.max_bounces = 1;
  s.settings.seed = seed;
  s.settings.event_probabilities = e;
  s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;  // the schemes are spectral tracking's
  return pixel_average(render(s), 0);
}

TEST(EventProbability, SingleScatteringWithChromaticAlbedoForEveryScheme) {
  // Single scattering (max_bounces = 1) in a slab of depth 1, σt from 0.5 to 0.05 per unit and the
  // albedo from 0.2 to 0.9 over 400–700 nm, HG g = 0.5, a delta light 20° from the zenith:
  // ω p(−μ0) (1 − e^{−τ(1 + 1/μ0)}) / (1 + 1/μ0) per wavelength, averaged over each bin.
  const double g = 0.5, theta0 = 20.0 * kPi / 180.0, mu0 = std::cos(theta0), k = 1.0 + 1.0 / mu0;
  for (EventProbabilities e : kSchemes) {
    const auto m = single_scattering(make_material(Spectrum({400.0, 700.0}, {0.2, 0.9}),
                                                   Spectrum({400.0, 700.0}, {0.5, 0.05}), Spectrum::constant(g)),
                                     theta0, 11, e);
    for (int b = 0; b < 6; ++b) {
      const double lo = 400.0 + 50.0 * b, hi = lo + 50.0;
      const double expected = integrate([&](double l) {
                                const double t = (l - 400.0) / 300.0;
                                const double w = 0.2 + 0.7 * t, tau = 0.5 - 0.45 * t;
                                return w * hg(-mu0, g) * (1.0 - std::exp(-tau * k)) / k;
                              }, lo, hi, 16) / (hi - lo);
      EXPECT_NEAR(m.mean[b], expected, kSe * m.se[b]) << event_probabilities_name(e) << " bin " << b;
      EXPECT_LT(m.se[b], 0.03 * expected) << event_probabilities_name(e) << " bin " << b;
    }
  }
}

TEST(EventProbability, SaturatedHalfSpaceMatchesChandrasekharForEveryScheme) {
  // All orders of scattering with a saturated albedo (0.3 at 400 nm to 0.95 at 700 nm) and a
  // chromatic extinction (600 to 300 per unit, a half-space in every bin): the diffuse reflection
  // ω μ0 H_ω(1) H_ω(μ0) / (4π (1 + μ0)) per wavelength, averaged over each bin.
  const double theta0 = 60.0 * kPi / 180.0, mu0 = std::cos(theta0);
  std::vector<double> expected(6);
  for (int b = 0; b < 6; ++b) {
    const double lo = 400.0 + 50.0 * b, hi = lo + 50.0;
    expected[b] = integrate([&](double l) {
                    const double w = 0.3 + 0.65 * (l - 400.0) / 300.0;
                    const HFunction h(w);
                    return w * mu0 * h(1.0) * h(mu0) / (4.0 * kPi * (1.0 + mu0));
                  }, lo, hi, 6) / (hi - lo);
  }
  for (EventProbabilities e : kSchemes) {
    Scene s = window_scene(make_material(Spectrum({400.0, 700.0}, {0.3, 0.95}), Spectrum({400.0, 700.0}, {600.0, 300.0}),
                                         Spectrum::constant(0.0)),
                           testing::directional_light("sun", {std::sin(theta0), 0.0, mu0}), 16, 128);
    s.settings.seed = 13;
    s.settings.event_probabilities = e;
    s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;  // the schemes are spectral tracking's
    const auto m = pixel_average(render(s), 0);
    for (int b = 0; b < 6; ++b) {
      EXPECT_NEAR(m.mean[b], expected[b], kSe * m.se[b])
          << event_probabilities_name(e) << " bin " << b << ": " << m.mean[b] << " ± " << m.se[b];
      EXPECT_LT(m.se[b], 0.03 * expected[b]) << event_probabilities_name(e) << " bin " << b;
    }
  }
}

}  // namespace
}  // namespace prizma::render

namespace prizma::render {
namespace {

TEST(EventProbability, PinnedValueOfTheImplicitScheme) {
  // One absolute value of the implicit scheme at a fixed seed, so that a change of the scheme's
  // arithmetic or of its random numbers shows: the mean over pixels of bin 0 of the environment and
  // sun layers of the determinism tests' chromatic box, 8 spp.
  Scene implicit = testing::chromatic_scene(8);
  implicit.settings.event_probabilities = EventProbabilities::Implicit;
  implicit.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  const auto img = render(implicit);
  const auto env = pixel_average(img, 0), sun = pixel_average(img, 1);
  EXPECT_NEAR(env.mean[0], 0.803799102, 1e-6) << std::setprecision(9) << env.mean[0];
  EXPECT_NEAR(sun.mean[0], 0.0485953252, 1e-6) << std::setprecision(9) << sun.mean[0];
  // And the closed-form scale it must sit in: within 3 standard errors of the max scheme's render.
  Scene s = testing::chromatic_scene(8);
  s.settings.event_probabilities = EventProbabilities::Max;
  s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  const auto mx = pixel_average(render(s), 0);
  EXPECT_NEAR(env.mean[0], mx.mean[0], 3.0 * std::hypot(env.se[0], mx.se[0]));
}

}  // namespace
}  // namespace prizma::render

namespace prizma::render {
namespace {

TEST(EventProbability, SingleScatteringWithExtinctionVaryingBy1e4ForEveryScheme) {
  // The spectrum of StressExtinction.VaryingBy1e4AcrossBins, where the sum schemes once failed the
  // comparison with one wavelength per path: σt log-linear from 0.01 (400 nm) to 100 per unit
  // (700 nm), tabulated every 5 nm, albedo 0.8, HG g = 0.3, single scattering (max_bounces = 1) of a
  // delta light 20° from the zenith in a slab of depth 1. Per wavelength
  // ω p(−μ0) (1 − e^{−τ(1 + 1/μ0)}) / (1 + 1/μ0), averaged over each bin (Gauss–Legendre on each
  // 5 nm piece of the table). Optical depths 0.01 to 100: the blue bins see a few collisions per
  // hundred paths, which the path takes because of the red lanes. 512 spp: the max and mixed
  // schemes' per-path values are heavy-tailed here (docs/results.md), and at 128 spp mixed's mean
  // of bin 4 sat 3.1 of its standard errors low.
  const double g = 0.3, albedo = 0.8, theta0 = 20.0 * kPi / 180.0, mu0 = std::cos(theta0), k = 1.0 + 1.0 / mu0;
  std::vector<double> l, v;
  for (double x = 400.0; x <= 700.0 + 1e-9; x += 5.0) {
    l.push_back(x);
    v.push_back(0.01 * std::pow(1e4, (x - 400.0) / 300.0));
  }
  const Spectrum sigma_t(l, v);
  std::vector<double> expected(6);
  for (int b = 0; b < 6; ++b) {
    double sum = 0.0;
    for (double lo = 400.0 + 50.0 * b; lo < 400.0 + 50.0 * (b + 1) - 1e-9; lo += 5.0)
      sum += integrate([&](double x) { return albedo * hg(-mu0, g) * (1.0 - std::exp(-sigma_t.eval(x) * k)) / k; },
                       lo, lo + 5.0, 8);
    expected[b] = sum / 50.0;
  }
  for (EventProbabilities e : kSchemes) {
    const auto m =
        single_scattering(make_material(Spectrum::constant(albedo), sigma_t, Spectrum::constant(g)), theta0, 17, e, 512);
    for (int b = 0; b < 6; ++b) {
      EXPECT_NEAR(m.mean[b], expected[b], kSe * m.se[b])
          << event_probabilities_name(e) << " bin " << b << ": " << m.mean[b] << " ± " << m.se[b] << " vs " << expected[b];
      EXPECT_LT(m.se[b], 0.1 * expected[b]) << event_probabilities_name(e) << " bin " << b;
    }
  }
}

}  // namespace
}  // namespace prizma::render
