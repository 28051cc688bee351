// Emission (issue 13 part 4): an emitting medium's radiance goes to its own light layer, stored at
// unit white like every layer; checked against the closed form of an absorbing, emitting slab and
// against Kirchhoff's energy balance for a scattering one; the scene file's fields and errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "prizma/render/render.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;
using testing::box_scene;
using testing::make_material;
using testing::pixel_average;

constexpr double kSe = 3.0;  // tolerance in standard errors (fixed seeds)

Light emission_light(std::string name = "emission") {
  Light l;
  l.name = std::move(name);
  l.emission = true;
  l.spectrum_spec = "E";
  return l;
}

// Bin average of f over [lo, hi] by composite Simpson (f smooth; 2000 panels: error ≪ 1e-9).
template <class F>
double bin_average(F f, double lo, double hi) {
  const int n = 2000;
  const double h = (hi - lo) / n;
  double s = f(lo) + f(hi);
  for (int k = 1; k < n; ++k) s += f(lo + k * h) * (k % 2 ? 4.0 : 2.0);
  return s * h / 3.0 / (hi - lo);
}

TEST(RenderEmission, AbsorbingEmittingSlabGivesLeTimesOneMinusTransmittance) {
  // Albedo 0, σt(λ) from 0.5 to 3 per unit and Le(λ) from 2 to 0.5 over 400–700 nm, depth 1: the
  // radiance leaving the slab along a ray is ∫₀¹ σt Le e^{−σt s} ds = Le (1 − e^{−τ}), τ = σt·1
  // (the emission term is σa·Le and σa = σt here); each bin holds its average over λ. The
  // environment layer is Beer–Lambert's e^{−τ} on the same paths.
  auto sigma = [](double l) { return 0.5 + 2.5 * (l - 400.0) / 300.0; };
  auto le = [](double l) { return 2.0 - 1.5 * (l - 400.0) / 300.0; };
  Material m = make_material(Spectrum::constant(0.0), Spectrum({400.0, 700.0}, {0.5, 3.0}), Spectrum::constant(0.0));
  m.emission = Spectrum({400.0, 700.0}, {2.0, 0.5});
  Scene s = box_scene(m, 4, 8, 256);
  s.lights.push_back(emission_light());
  for (std::uint64_t seed : {1, 2, 3}) {
    s.settings.seed = seed;
    RenderStats stats;
    const auto img = render(s, {}, &stats);
    ASSERT_EQ(img.lights.size(), 2u);
    EXPECT_EQ(img.lights[1].name, "emission");
    EXPECT_FALSE(stats.wavelength_independent);
    const auto env = pixel_average(img, 0), em = pixel_average(img, 1);
    for (int b = 0; b < 6; ++b) {
      const double lo = 400.0 + 50.0 * b, hi = lo + 50.0;
      const double expected = bin_average([&](double l) { return le(l) * (1.0 - std::exp(-sigma(l))); }, lo, hi);
      EXPECT_NEAR(em.mean[b], expected, kSe * em.se[b]) << "seed " << seed << " bin " << b << ": " << em.mean[b]
                                                        << " ± " << em.se[b] << ", expected " << expected;
      EXPECT_LT(em.se[b], 0.02 * expected);
      const double t = bin_average([&](double l) { return std::exp(-sigma(l)); }, lo, hi);
      EXPECT_NEAR(env.mean[b], t, kSe * env.se[b]) << "seed " << seed << " bin " << b;
    }
  }
  // The same scene in VPT's one-wavelength mode agrees (one lane, analog tracking).
  s.settings.wavelength_sampling = WavelengthSampling::Single;
  s.settings.sample_end = 1024;
  const auto em = pixel_average(render(s), 1);
  for (int b = 0; b < 6; ++b) {
    const double lo = 400.0 + 50.0 * b, hi = lo + 50.0;
    const double expected = bin_average([&](double l) { return le(l) * (1.0 - std::exp(-sigma(l))); }, lo, hi);
    EXPECT_NEAR(em.mean[b], expected, kSe * em.se[b]) << "single, bin " << b;
  }
}

TEST(RenderEmission, ScatteringMediumInEquilibriumWithItsEnvironment) {
  // Kirchhoff's energy balance: a medium emitting Le = 1 inside a unit environment is in radiative
  // equilibrium, L = 1 everywhere, whatever its albedo, phase function and density (L = 1 solves the
  // transfer equation: −σt·1 + σa·1 + σs·∫p·1 = 0). So environment + emission layers = 1 in every
  // bin, here for a heterogeneous, chromatic, anisotropic, scattering medium and a camera that sees
  // the box's edges too. Standard error of the sum ≤ the sum of the two layers' (Cauchy–Schwarz).
  Material m = make_material(Spectrum({400.0, 550.0, 700.0}, {0.95, 0.3, 0.7}), Spectrum({400.0, 700.0}, {6.0, 1.5}),
                             Spectrum({400.0, 700.0}, {0.6, -0.2}));
  m.emission = Spectrum::constant(1.0);
  Scene s = box_scene(m, 6, 8, 128);
  s.camera.ortho_height = 1.2;
  testing::randomise_density(s, 0.0f, 2.0f);
  s.lights.push_back(emission_light("glow"));
  for (std::uint64_t seed : {1, 2}) {
    s.settings.seed = seed;
    const auto img = render(s);
    const auto env = pixel_average(img, 0), em = pixel_average(img, 1);
    for (int b = 0; b < 6; ++b) {
      EXPECT_NEAR(env.mean[b] + em.mean[b], 1.0, kSe * (env.se[b] + em.se[b]))
          << "seed " << seed << " bin " << b << ": environment " << env.mean[b] << " + emission " << em.mean[b];
      EXPECT_GT(em.mean[b], 0.1);  // both layers matter
      EXPECT_GT(env.mean[b], 0.1);
    }
  }
}

TEST(RenderEmission, EmittingMaterialWithoutEmissionLightIsAnInputError) {
  Material m = testing::grey_material(0.0, 1.0);
  m.emission = Spectrum::constant(1.0);
  Scene s = box_scene(m, 2, 2, 2);
  EXPECT_THROW(render(s), spectral::InputError);
}

// Scene files: the emission field, the layer's name, and their errors.
class EmissionScene : public ::testing::Test {
 protected:
  std::filesystem::path write(const std::string& materials, const std::string& extra = "") {
    const std::string text = R"({"volume": {"type": "procedural", "name": "homogeneous_box", "resolution": 4},
      "materials": [)" + materials + R"(],
      "lights": [{"name": "env", "direction": [0, 0, 0]}], "bins": "linear:400:700:3")" + extra + "}";
    return dir.write("s.json", text);
  }
  testing::ScratchDir dir;
};

TEST_F(EmissionScene, EmittingMaterialAddsTheEmissionLayer) {
  Scene s = load_scene(write(R"({"albedo": 0.5, "extinction": 2, "emission": "blackbody:1800K"})"));
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[1].name, "emission");
  EXPECT_TRUE(s.lights[1].emission);
  EXPECT_GT(s.medium.materials[0].emission.max_value(), 0.0);
  s = load_scene(write(R"({"albedo": 0.5, "extinction": 2, "emission": {"spectrum": 1, "scale": 3}})",
                       R"(, "emission_light": "flame")"));
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[1].name, "flame");
  EXPECT_DOUBLE_EQ(s.medium.materials[0].emission.eval(500.0), 3.0);
  // No emitting material: no layer, even when the name is given (the file is as before).
  s = load_scene(write(R"({"albedo": 0.5, "extinction": 2, "emission": 0})", R"(, "emission_light": "flame")"));
  EXPECT_EQ(s.lights.size(), 1u);
}

TEST_F(EmissionScene, BadEmissionFieldsAreInputErrors) {
  auto message = [&](const std::string& materials, const std::string& extra = "") {
    try {
      load_scene(write(materials, extra));
    } catch (const spectral::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"albedo": 0.5, "extinction": 2, "emission": -1})").find("materials[0].emission: must be ≥ 0"),
            std::string::npos);
  EXPECT_NE(message(R"({"albedo": 0.5, "extinction": 2, "emission": "D66"})").find("materials[0].emission"),
            std::string::npos);
  EXPECT_NE(message(R"({"albedo": 0.5, "extinction": 2, "emission": 1})", R"(, "emission_light": "env")")
                .find("emission_light: the emission layer \"env\" has the name of a light"),
            std::string::npos);
  EXPECT_NE(message(R"({"albedo": 0.5, "extinction": 2, "emission": 1})", R"(, "emission_light": "a b")")
                .find("emission_light: may hold only letters"),
            std::string::npos);
  EXPECT_NE(message(R"({"albedo": 0.5, "extinction": 2})", R"(, "emission_light": 3)").find("emission_light: must be a string"),
            std::string::npos);
}

// issue 21: emission 3e38 loaded, every path's w·σa·density·Le overflowed to inf and then NaN, and
// the samples were counted as 0 (a warning, and no light). Le is bounded like extinction, at 10⁶;
// at both bounds (σt = 10⁶, Le = 10⁶, albedo 0) every pixel is Le·(1 − e^{−10⁶}) = 10⁶, finite.
TEST_F(EmissionScene, EmissionIsBoundedAndTheBoundRendersFinite) {
  auto message = [&](const std::string& materials) {
    try {
      load_scene(write(materials));
    } catch (const spectral::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (const char* emission : {"3e38", "1.000001e6", "\"D65*1e39\""}) {
    const std::string m = message(std::string(R"({"albedo": 0.5, "extinction": 2, "emission": )") + emission + "}");
    EXPECT_NE(m.find("materials[0].emission: must be at most 1000000 at every wavelength (got "), std::string::npos)
        << emission << ": " << m;
  }
  Scene s = load_scene(write(R"({"albedo": 0, "extinction": 1e6, "emission": 1e6})",
                             R"(, "camera": {"type": "orthographic", "ortho_height": 0.8, "width": 4, "height": 4},
                                  "samples": 4)"));
  RenderStats stats;
  const auto img = render(s, {}, &stats);
  EXPECT_EQ(stats.nan_or_inf_count, 0);
  const auto em = pixel_average(img, 1);
  for (int b = 0; b < 3; ++b) EXPECT_NEAR(em.mean[b], 1e6, 1.0) << "bin " << b;
}

}  // namespace
}  // namespace prizma::render
