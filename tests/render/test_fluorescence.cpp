// Fluorescence (issue 16): the scene field, and absolute checks of the bispectral transport against
// closed forms (docs/fluorescence.md). Every expected value is computed here from the spectra, never
// from another render. The dye absorbs only in 400–500 nm and emits only in 550–700 nm, so light is
// re-emitted at most once and the single-event forms below are exact at any optical depth.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "prizma/render/fluorescence.h"
#include "prizma/render/render.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/spectrum_spec.h"
#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"
#include "transfer_references.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;
using testing::box_scene;
using testing::grey_material;
using testing::kSe;

// σf per unit: 2 at 400 nm falling to 0 at 500 nm (zero outside the table).
Spectrum dye_absorption(double scale) { return Spectrum({400.0, 450.0, 500.0}, {2.0 * scale, 1.0 * scale, 0.0}); }
// Emission, any scale (the renderer normalises it): zero below 550 nm.
Spectrum dye_emission() { return Spectrum({550.0, 600.0, 650.0, 700.0}, {0.0, 2.0, 2.0, 1.0}); }

Material dye_material(double sigma_t, double sigma_f_scale, double q) {
  Material m = grey_material(0.0, sigma_t);  // σt: a non-fluorescent absorber (albedo 0)
  m.fluorescent = true;
  m.fluorescence.absorption = dye_absorption(sigma_f_scale);
  m.fluorescence.emission = dye_emission();
  m.fluorescence.quantum_yield = q;
  return m;
}

// Simpson's rule with many panels (the integrands are smooth inside a bin).
double integrate(const std::function<double(double)>& f, double a, double b, int n = 2000) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += f(a + i * h) * (i % 2 ? 4.0 : 2.0);
  return s * h / 3.0;
}

// Means over the pixels of value(px, k) for k < count, and their standard errors from the spread
// over pixels (the box is homogeneous and every pixel's ray crosses it fully: the pixels are i.i.d.).
struct PairEstimate {
  std::vector<double> mean, se;
};
PairEstimate pixel_spread(std::size_t count, std::size_t pixels,
                          const std::function<double(std::size_t px, std::size_t k)>& value) {
  PairEstimate e{std::vector<double>(count, 0.0), std::vector<double>(count, 0.0)};
  const auto p = static_cast<double>(pixels);
  for (std::size_t k = 0; k < count; ++k) {
    double s = 0.0, s2 = 0.0;
    for (std::size_t px = 0; px < pixels; ++px) {
      const double v = value(px, k);
      s += v;
      s2 += v * v;
    }
    const double mean = s / p;
    e.mean[k] = mean;
    e.se[k] = std::sqrt(std::max(0.0, (s2 / p - mean * mean) * p / (p - 1.0)) / p);
  }
  return e;
}

// Each bispectral pair of a light.
PairEstimate pair_average(const spectral::SpectralImage& img, int light) {
  const std::size_t np = img.reradiation.size();
  const auto& r = img.lights[static_cast<std::size_t>(light)].reradiation;
  return pixel_spread(np, img.pixel_count(), [&](std::size_t px, std::size_t k) { return r[px * np + k]; });
}

// (q/4π)·⟨ρ(λ)/λ⟩_out·∫_in λ·f(σf(λ)) dλ: the single-event bispectral term, ρ the normalised
// emission, f the geometry's absorbed (and transmitted) fraction as a function of σf.
double closed_form(const spectral::BinLayout& bins, const spectral::BinPair& pr, double q, double sigma_f_scale,
                   const std::function<double(double)>& f) {
  const Spectrum rho = dye_emission().scaled(1.0 / fluorescence_emission_area(dye_emission()));
  const Spectrum sf = dye_absorption(sigma_f_scale);
  const double out_avg =
      integrate([&](double l) { return rho.eval(l) / l; }, bins.lo_nm(pr.out), bins.hi_nm(pr.out)) / bins.width_nm(pr.out);
  const double in_int = integrate([&](double l) { return l * f(sf.eval(l)); }, bins.lo_nm(pr.in), bins.hi_nm(pr.in));
  return q / (4.0 * std::numbers::pi) * out_avg * in_int;
}

Scene dye_box(const Material& m, Eigen::Vector3d light_dir, std::int64_t spp) {
  Scene s = box_scene(m, 4, 8, spp);
  s.lights = {testing::directional_light("uv", light_dir)};
  return s;
}

TEST(Fluorescence, LayoutHoldsOnlyTheBinsTheDyeCanFill) {
  const auto bins = spectral::BinLayout::linear(400, 700, 6);  // 50 nm bins
  Scene s = dye_box(dye_material(0.0, 1.0, 1.0), {0, 0, 1}, 1);
  const FluorescenceLayout fl = fluorescence_layout(s.medium, bins);
  EXPECT_TRUE(fl.any);
  EXPECT_TRUE(fl.diagonal.empty());
  const std::vector<spectral::BinPair> want = {{0, 3}, {0, 4}, {0, 5}, {1, 3}, {1, 4}, {1, 5}};
  EXPECT_EQ(fl.pairs, want);
  s.medium.materials[0].fluorescence.quantum_yield = 0.0;  // q = 0: nothing is re-emitted
  EXPECT_FALSE(fluorescence_layout(s.medium, bins).any);
}

// q = 1 furnace of photons: a box whose only absorber is the dye, lit from the side the camera
// looks from. Every absorbed photon is re-emitted (isotropically, at λout drawn from ρ) and the
// red leaves unattenuated, so per output bin M[out][in] = (1/4π)·⟨ρ/λ⟩_out·∫_in λ(1 − e^{−σf}) dλ:
// the photons absorbed over the depth (1 − e^{−σf}), each carrying energy λin/λout times its own.
TEST(Fluorescence, QuantumYieldOneConservesPhotonsPerOutputBin) {
  Scene s = dye_box(dye_material(0.0, 1.0, 1.0), {0, 0, 1}, 256);
  const spectral::SpectralImage img = render(s);
  ASSERT_EQ(img.reradiation.size(), 6u);
  const PairEstimate e = pair_average(img, 0);
  for (std::size_t k = 0; k < img.reradiation.size(); ++k) {
    const double want = closed_form(img.bins, img.reradiation[k], 1.0, 1.0, [](double sf) { return 1.0 - std::exp(-sf); });
    EXPECT_GT(want, 0.0);
    EXPECT_NEAR(e.mean[k], want, kSe * e.se[k] + 1e-6) << "pair " << k << " se " << e.se[k];
    EXPECT_LT(e.se[k], 0.03 * want);  // the test can tell a wrong factor (λin/λout is ~0.7–0.8)
  }
  // No scattering: the diagonal (the T layer) holds nothing under the directional light.
  for (float v : img.lights[0].data) EXPECT_EQ(v, 0.0f);
}

// An optically thin dye slab (σf ≤ 0.2) in an absorbing medium (σt = 0.3), lit from below and seen
// from above, q = 0.6: light reaches height h with e^{−(σt+σf)h}, the re-emitted red leaves with
// e^{−σt(1−h)}, so ∫₀¹ σf e^{…} dh = e^{−σt}(1 − e^{−σf}).
TEST(Fluorescence, ThinSlabUnderDirectionalLightMatchesTheSingleEventForm) {
  const double st = 0.3, scale = 0.1, q = 0.6;
  Scene s = dye_box(dye_material(st, scale, q), {0, 0, -1}, 512);
  const spectral::SpectralImage img = render(s);
  ASSERT_EQ(img.reradiation.size(), 6u);
  const PairEstimate e = pair_average(img, 0);
  for (std::size_t k = 0; k < img.reradiation.size(); ++k) {
    const double want =
        closed_form(img.bins, img.reradiation[k], q, scale, [&](double sf) { return std::exp(-st) * (1.0 - std::exp(-sf)); });
    EXPECT_NEAR(e.mean[k], want, kSe * e.se[k] + 1e-7) << "pair " << k << " se " << e.se[k];
    EXPECT_LT(e.se[k], 0.1 * want);
  }
}

// q = 0: the dye only absorbs; the environment seen through the box is Beer–Lambert with σt + σf
// (bin averages of e^{−(σt+σf(λ))}), and no bispectral term is written.
TEST(Fluorescence, QuantumYieldZeroIsBeerLambertWithSigmaTPlusSigmaF) {
  const double st = 0.5;
  Scene s = box_scene(dye_material(st, 1.0, 0.0), 4, 8, 256);
  const spectral::SpectralImage img = render(s);
  EXPECT_TRUE(img.reradiation.empty());
  EXPECT_TRUE(img.lights[0].reradiation.empty());
  const auto e = testing::pixel_average(img, 0);
  const Spectrum sf = dye_absorption(1.0);
  for (int i = 0; i < img.bins.size(); ++i) {
    const double want = integrate([&](double l) { return std::exp(-(st + sf.eval(l))); }, img.bins.lo_nm(i), img.bins.hi_nm(i)) /
                        img.bins.width_nm(i);
    EXPECT_NEAR(e.mean[i], want, kSe * e.se[i] + 1e-6) << "bin " << i;
  }
  // The estimate must be able to tell σt alone from σt + σf in the dye's bins.
  EXPECT_LT(e.mean[0], std::exp(-st) - 10.0 * e.se[0]);
}

// Renders s as it is (bispectral) and with its light spectra folded in (the same random numbers),
// and checks that relighting the first with those spectra, T·ē + M·ē per light summed over the
// lights, equals the second bin for bin (up to float rounding). Returns both renders.
struct BispectralAndFolded {
  spectral::SpectralImage bispectral, folded;
};
BispectralAndFolded expect_relit_equals_folded(Scene s) {
  BispectralAndFolded r;
  r.bispectral = render(s);
  r.folded = render_folded(s);
  const spectral::SpectralImage& bi = r.bispectral;
  EXPECT_FALSE(bi.reradiation.empty());
  EXPECT_TRUE(r.folded.reradiation.empty());
  const int nb = bi.bins.size();
  std::vector<double> relit(bi.pixel_count() * nb, 0.0), want(bi.pixel_count() * nb, 0.0);
  for (std::size_t l = 0; l < s.lights.size(); ++l) {
    spectral::SpecContext ctx;
    const std::vector<double> e = spectral::parse_spectrum(s.lights[l].spectrum_spec, ctx).bin_averages(bi.bins);
    for (std::size_t k = 0; k < relit.size(); ++k) {
      relit[k] += bi.lights[l].data[k] * e[k % nb];
      want[k] += r.folded.lights[l].data[k];
    }
    spectral::add_reradiated(bi, static_cast<int>(l), e, relit);
  }
  for (std::size_t k = 0; k < relit.size(); ++k)
    EXPECT_NEAR(relit[k], want[k], 2e-4 * (1.0 + std::abs(want[k]))) << "pixel " << k / nb << " bin " << k % nb;
  return r;
}

// Relighting the bispectral file under E (diagonal T·ē plus Σ_in M[out][in]·ē_in) equals rendering
// with E folded into the paths. Both lights are constant inside every bin (box spectra on the bin
// edges), where relighting is exact; the two renders share their random numbers.
TEST(Fluorescence, RelightingTheBispectralImageEqualsFoldingTheLightIn) {
  Material m = dye_material(0.2, 1.0, 0.8);
  m.albedo = Spectrum::constant(0.5);  // scattering too: diagonal and chains through scattering
  Scene s = box_scene(m, 4, 8, 64);
  s.lights[0].spectrum_spec = "box:450:650";                        // environment
  s.lights.push_back(testing::directional_light("uv", {0.3, 0.2, 1}));
  s.lights[1].spectrum_spec = "box:400:500*2";
  const BispectralAndFolded r = expect_relit_equals_folded(s);
  const spectral::SpectralImage& bi = r.bispectral;
  const spectral::SpectralImage& folded = r.folded;
  const int nb = bi.bins.size();
  double reradiated = 0.0;
  for (float v : bi.lights[1].reradiation) reradiated += v;
  EXPECT_GT(reradiated, 0.0);
  // The violet light shows red only through fluorescence: its relit red bins are not zero.
  double red = 0.0;
  for (std::size_t px = 0; px < bi.pixel_count(); ++px) red += folded.lights[1].data[px * nb + 4];
  EXPECT_GT(red, 0.0);
}

// --wavelength-sampling single: one wavelength per path, changed at the re-emission (λin drawn ∝
// σf·λ), the pair (camera bin, λin's bin) filled. The same closed forms as above, and the
// spectral-tracking render of the same scene, within 3 combined standard errors (fixed seeds). The
// single render gets 6× the samples (each path estimates one out bin of six).
void expect_single_matches(Scene s, std::int64_t spp, double q, double sigma_f_scale,
                           const std::function<double(double)>& f) {
  const spectral::SpectralImage spectral_img = render(s);
  s.settings.wavelength_sampling = WavelengthSampling::Single;
  s.settings.sample_end = 6 * spp;
  const spectral::SpectralImage single_img = render(s);
  ASSERT_EQ(single_img.reradiation, spectral_img.reradiation);
  const PairEstimate a = pair_average(single_img, 0), b = pair_average(spectral_img, 0);
  for (std::size_t k = 0; k < single_img.reradiation.size(); ++k) {
    const double want = closed_form(single_img.bins, single_img.reradiation[k], q, sigma_f_scale, f);
    EXPECT_NEAR(a.mean[k], want, kSe * a.se[k] + 1e-7) << "pair " << k << " se " << a.se[k];
    EXPECT_NEAR(a.mean[k], b.mean[k], kSe * std::hypot(a.se[k], b.se[k]) + 1e-7) << "pair " << k;
    EXPECT_LT(a.se[k], 0.1 * want);  // precise enough to tell a wrong factor
  }
  // The diagonal as well (the part of the paths before any re-emission).
  const auto da = testing::pixel_average(single_img, 0), db = testing::pixel_average(spectral_img, 0);
  for (int i = 0; i < single_img.bins.size(); ++i)
    EXPECT_NEAR(da.mean[i], db.mean[i], kSe * std::hypot(da.se[i], db.se[i]) + 1e-7) << "bin " << i;
}

TEST(Fluorescence, SingleWavelengthSamplingConservesPhotonsLikeSpectralTracking) {
  expect_single_matches(dye_box(dye_material(0.0, 1.0, 1.0), {0, 0, 1}, 256), 256, 1.0, 1.0,
                        [](double sf) { return 1.0 - std::exp(-sf); });
}

TEST(Fluorescence, SingleWavelengthSamplingMatchesTheThinSlabForm) {
  const double st = 0.3, scale = 0.1, q = 0.6;
  expect_single_matches(dye_box(dye_material(st, scale, q), {0, 0, -1}, 512), 512, q, scale,
                        [&](double sf) { return std::exp(-st) * (1.0 - std::exp(-sf)); });
}

// Scattering, a diagonal term (absorption and emission overlap in one bin) and folded lights: the
// single render relit equals the single render with the light folded in, and the spectral one.
TEST(Fluorescence, SingleWavelengthSamplingRelitEqualsSpectralTracking) {
  Material m = dye_material(0.2, 1.0, 0.8);
  m.albedo = Spectrum::constant(0.5);
  m.fluorescence.emission = Spectrum({430.0, 500.0, 650.0, 700.0}, {0.0, 1.0, 2.0, 1.0});  // overlaps σf in 450–500
  Scene s = box_scene(m, 4, 8, 1024);
  s.lights.push_back(testing::directional_light("uv", {0.3, 0.2, 1}));
  const spectral::SpectralImage spectral_img = render(s);
  s.settings.wavelength_sampling = WavelengthSampling::Single;
  s.settings.sample_end = 6 * 1024;
  const spectral::SpectralImage single_img = render(s);
  ASSERT_EQ(single_img.reradiation, spectral_img.reradiation);
  ASSERT_FALSE(fluorescence_layout(s.medium, s.settings.bins).diagonal.empty());
  for (int l = 0; l < 2; ++l) {
    const PairEstimate a = pair_average(single_img, l), b = pair_average(spectral_img, l);
    for (std::size_t k = 0; k < single_img.reradiation.size(); ++k)
      EXPECT_NEAR(a.mean[k], b.mean[k], kSe * std::hypot(a.se[k], b.se[k]) + 1e-7) << "light " << l << " pair " << k;
    const auto da = testing::pixel_average(single_img, l), db = testing::pixel_average(spectral_img, l);
    for (int i = 0; i < single_img.bins.size(); ++i)
      EXPECT_NEAR(da.mean[i], db.mean[i], kSe * std::hypot(da.se[i], db.se[i]) + 1e-7) << "light " << l << " bin " << i;
  }
  // Folded (the same random numbers): T·ē + M·ē of the single render equals its folded render.
  s.lights[0].spectrum_spec = "box:450:650";
  s.lights[1].spectrum_spec = "box:400:500*2";
  expect_relit_equals_folded(s);
}

// A dye whose absorption and emission overlap (issue 27): light re-emitted in the overlap can be
// absorbed and re-emitted again, so paths chain events and the one-wavelength method must put what
// a path sees after each event in the bin of that event's excitation wavelength. σf absorbs over
// 400–700 nm (0.4–0.8 per unit: every bin excites, so a 1 % error per excitation bin is resolved
// without many more paths for one weak bin), ρ emits in 450–700 nm (five bins both excite and emit);
// the medium's other extinction makes σt(λ) + σf(λ) = σ for every λ (both tables linear between the
// same knots), so that the geometry of a chain does not depend on its wavelengths.
constexpr double kOverlapSigma = 1.2;  // σt + σf per unit, every wavelength
Spectrum overlap_absorption() {
  return Spectrum({400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0}, {0.6, 0.8, 0.8, 0.7, 0.6, 0.5, 0.4});
}
Spectrum overlap_emission() { return Spectrum({450.0, 500.0, 600.0, 700.0}, {0.0, 1.0, 2.0, 1.0}); }

// A slab 1 unit thick (z ∈ [−0.5, 0.5]) and ±20 units wide (24 mean free paths: an infinite slab
// to e^{−24}), lit from below by a unit directional light at normal incidence and seen straight
// down, absorbing only (albedo 0), the dye with q = 1, at most two events per path (max_bounces).
Scene overlap_slab(std::int64_t spp) {
  const Spectrum sf = overlap_absorption();
  std::vector<double> rest;
  for (double v : sf.values()) rest.push_back(kOverlapSigma - v);
  Material m = testing::make_material(Spectrum::constant(0.0), Spectrum(sf.wavelengths_nm(), rest), Spectrum::constant(0.0));
  m.fluorescent = true;
  m.fluorescence.absorption = sf;
  m.fluorescence.emission = overlap_emission();
  m.fluorescence.quantum_yield = 1.0;
  Scene s = box_scene(m, 1, 8, spp);
  s.medium.bounds_min = {-20.0, -20.0, -0.5};
  s.medium.bounds_max = {20.0, 20.0, 0.5};
  s.lights = {testing::directional_light("uv", {0, 0, -1})};
  s.settings.max_bounces = 2;
  s.settings.seed = 27;
  return s;
}

// The slab's transport per pair, at most two events, by the transfer equation in energy radiance
// (docs/fluorescence.md, "Physics") with the grey σ: every factor separates,
//   M[out][in] = A_out · B_in · e^{−σL}/(4π) · (L + C·J),
//   A_out = (1/Δ_out) ∫_out q·ρ(λ)/λ dλ,   B_in = ∫_in σf(λ)·λ dλ,   C = q ∫ ρ·σf dλ over the bins,
// one event: ∫₀ᴸ e^{−σ(L−z)} (1/4π) e^{−σz} dz = L e^{−σL}/(4π) (camera ray down to z, light up to z);
// two events: the second source at z2 (lit with e^{−σ z2}) seen from z1 along direction cosine μ at
// distance s (z2 = z1 + μs) with e^{−σs}: the exponents add to σ(L + (1 + μ)s), so
//   J = ½ ∫_{−1}^{1} dμ ∫₀ᴸ dz1 ∫₀^{s_max} e^{−σ(1+μ)s} ds = ½ ∫_{−1}^{1} (L²/|μ|)·h(σ(1+μ)L/|μ|) dμ,
//   h(x) = (x − 1 + e^{−x})/x²   (s_max = (L − z1)/μ upward, z1/|μ| downward; the z1 integral done).
double overlap_pair(int out, int in, const spectral::BinLayout& bins) {
  const double q = 1.0, sigma = kOverlapSigma, thickness = 1.0;
  const Spectrum rho = overlap_emission().scaled(1.0 / fluorescence_emission_area(overlap_emission()));
  const Spectrum sf = overlap_absorption();
  const double a =
      integrate([&](double l) { return q * rho.eval(l) / l; }, bins.lo_nm(out), bins.hi_nm(out)) / bins.width_nm(out);
  const double b = integrate([&](double l) { return sf.eval(l) * l; }, bins.lo_nm(in), bins.hi_nm(in));
  const double c = q * integrate([&](double l) { return rho.eval(l) * sf.eval(l); }, bins.min_nm(), bins.max_nm());
  auto h = [](double x) { return x < 1e-2 ? 0.5 - x / 6.0 + x * x / 24.0 - x * x * x / 120.0 : (x - 1.0 + std::exp(-x)) / (x * x); };
  auto g = [&](double mu) {
    const double m = std::abs(mu);
    return thickness * thickness / m * h(sigma * (1.0 + mu) * thickness / m);
  };
  // The kink of |μ| at 0: each half by Gauss–Legendre.
  const double j = 0.5 * (testing::integrate(g, -1.0, 0.0) + testing::integrate(g, 0.0, 1.0));
  return a * b * std::exp(-sigma * thickness) / (4.0 * std::numbers::pi) * (thickness + c * j);
}

// Per excitation bin of in_bins, Σ_out M[out][in] (the diagonal term from the T layer) of light 0.
PairEstimate excitation_sums(const spectral::SpectralImage& img, const std::vector<int>& in_bins) {
  const int nb = img.bins.size();
  const std::size_t np = img.reradiation.size();
  const auto& layer = img.lights[0];
  return pixel_spread(in_bins.size(), img.pixel_count(), [&](std::size_t px, std::size_t t) {
    double v = layer.data[px * nb + in_bins[t]];
    for (std::size_t k = 0; k < np; ++k)
      if (img.reradiation[k].in == in_bins[t]) v += layer.reradiation[px * np + k];
    return v;
  });
}

// Both modes, per excitation bin against the closed form at 3 standard errors, each standard error
// below 1/3 % of the value (so a 1 % error is 3 SE); every pair and diagonal term at 3 SE too. Before
// issue 27's fix the single render missed by up to 78 SE (1.25 in bin 0, 0.89 in bin 3).
void expect_overlap_slab(WavelengthSampling mode, std::int64_t spp) {
  Scene s = overlap_slab(spp);
  s.settings.wavelength_sampling = mode;
  const spectral::SpectralImage img = render(s);
  const std::string name = wavelength_sampling_name(mode);
  const spectral::BinLayout& bins = img.bins;
  const std::vector<int> in_bins = {0, 1, 2, 3, 4, 5};
  const PairEstimate e = excitation_sums(img, in_bins);
  for (std::size_t t = 0; t < in_bins.size(); ++t) {
    double want = 0.0;
    for (int out = 0; out < bins.size(); ++out) want += overlap_pair(out, in_bins[t], bins);
    EXPECT_NEAR(e.mean[t], want, kSe * e.se[t]) << name << " excitation bin " << in_bins[t] << ": " << e.mean[t] / want;
    EXPECT_LT(e.se[t], 0.01 / kSe * want) << name << " excitation bin " << in_bins[t];
  }
  const PairEstimate pairs = pair_average(img, 0);
  for (std::size_t k = 0; k < img.reradiation.size(); ++k) {
    const spectral::BinPair pr = img.reradiation[k];
    const double want = overlap_pair(pr.out, pr.in, bins);
    EXPECT_NEAR(pairs.mean[k], want, kSe * pairs.se[k]) << name << " pair in " << pr.in << " out " << pr.out;
  }
  const auto diag = testing::pixel_average(img, 0);
  for (int i : fluorescence_layout(s.medium, bins).diagonal)
    EXPECT_NEAR(diag.mean[i], overlap_pair(i, i, bins), kSe * diag.se[i]) << name << " diagonal " << i;
}

TEST(Fluorescence, OverlappingDyeSlabMatchesTheTwoEventFormPerExcitationBin) {
  expect_overlap_slab(WavelengthSampling::SpectralTracking, 8192);
  expect_overlap_slab(WavelengthSampling::Single, 81920);
}

// The scene field: the happy path and one-line errors naming the field.
nlohmann::json dye_scene(const nlohmann::json& fluorescence) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "volume": {"type": "procedural", "name": "cube_sphere", "resolution": 8},
    "materials": [{"name": "dye", "range": [0, 255], "albedo": 0.5, "extinction": 1}],
    "camera": {"width": 4, "height": 4},
    "lights": [{"name": "uv", "direction": [0, 0, 1]}],
    "bins": "linear:400:700:6", "samples": 1
  })");
  j["materials"][0]["fluorescence"] = fluorescence;
  return j;
}

void expect_field_error(const nlohmann::json& fl, const std::string& field, const std::string& reason) {
  testing::ScratchDir dir;
  const auto path = dir.write("scene.json", dye_scene(fl).dump());
  try {
    load_scene(path);
    FAIL() << "no error; expected " << field;
  } catch (const spectral::InputError& e) {
    EXPECT_EQ(e.input(), path.string() + ": materials[0].fluorescence" + field) << e.what();
    EXPECT_NE(e.reason().find(reason), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

TEST(Fluorescence, SceneFieldIsReadAndChecked) {
  testing::ScratchDir dir;
  const nlohmann::json good = {{"absorption", "box:400:450*3"}, {"emission", "gaussian:600:40"}, {"quantum_yield", 0.9}};
  const Scene s = load_scene(dir.write("scene.json", dye_scene(good).dump()));
  ASSERT_TRUE(s.medium.materials[0].fluorescent);
  EXPECT_DOUBLE_EQ(s.medium.materials[0].fluorescence.quantum_yield, 0.9);
  EXPECT_NEAR(s.medium.materials[0].fluorescence.absorption.eval(420.0), 3.0, 1e-12);
  // Without the field the hash is that of the same scene before fluorescence existed.
  nlohmann::json plain = dye_scene(good);
  plain["materials"][0].erase("fluorescence");
  EXPECT_FALSE(load_scene(dir.write("plain.json", plain.dump())).medium.materials[0].fluorescent);

  expect_field_error(1, "", "must be an object");
  expect_field_error({{"absorption", 1}, {"emission", 1}}, ".quantum_yield", "is required");
  expect_field_error({{"absorption", 1}, {"emission", 1}, {"quantum_yield", 1.5}}, ".quantum_yield", "must be in [0, 1]");
  expect_field_error({{"absorption", -1}, {"emission", 1}, {"quantum_yield", 1}}, ".absorption", "must be ≥ 0");
  expect_field_error({{"absorption", 1}, {"emission", 0}, {"quantum_yield", 1}}, ".emission", "has no area");
  expect_field_error({{"absorption", 1}, {"emission", "box:900:950"}, {"quantum_yield", 1}}, ".emission", "");
  expect_field_error({{"absorption", 1}, {"emission", 1}, {"quantum_yield", 1}, {"colour", 1}}, ".colour", "unknown field");
}

}  // namespace
}  // namespace prizma::render
