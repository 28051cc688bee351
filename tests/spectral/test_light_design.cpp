// Light design: a hiding light must make two materials match, a revealing light must separate them
// more than the reference light and the hiding light, all checked here independently (product
// spectra tabulated every 1 nm, ColorMatching, Lab relative to the light's white, CIEDE2000).
#include <gtest/gtest.h>

#include <vector>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/light_design.h"
#include "prizma/spectral/metamer_design.h"
#include "prizma/spectral/spectrum_spec.h"
#include "spectral/independent_colour.h"

namespace prizma::spectral {
namespace {

using test::independent_delta_e;
using test::independent_xyz;

// A pair that matches under A and differs under D65: the hiding light exists (A is one).
struct Pair {
  Spectrum a;
  Spectrum b;
};
const Pair& metameric_pair() {
  static const Pair pair = [] {
    const Spectrum a = parse_spectrum("cc:4");
    MetamerOptions options;
    options.iterations = 40;
    return Pair{a, design_metamer(a, parse_spectrum("A"), parse_spectrum("D65"), options).reflectance};
  }();
  return pair;
}

TEST(LightDesign, HideMakesThePairMatchAtReferenceLuminance) {
  const Pair& pair = metameric_pair();
  const Spectrum d65 = parse_spectrum("D65");
  const double reference_de = independent_delta_e(pair.a, pair.b, d65);
  ASSERT_GT(reference_de, 2.0) << "the test pair should differ under D65";
  const LightDesignResult hide = design_light(pair.a, pair.b, LightGoal::Hide, d65);
  EXPECT_LT(independent_delta_e(pair.a, pair.b, hide.light), 0.5);
  EXPECT_GE(hide.light.min_value(), 0.0);
  // Same luminance as the reference: ∫E·ȳ over 380–780 nm within 0.1 %.
  const double y_hide = independent_xyz(Spectrum::constant(1.0), hide.light, true).y();
  const double y_ref = independent_xyz(Spectrum::constant(1.0), d65, true).y();
  EXPECT_NEAR(y_hide / y_ref, 1.0, 1e-3);
  EXPECT_NEAR(hide.delta_e_reference, reference_de, 0.05);
}

TEST(LightDesign, RevealSeparatesMoreThanReferenceAndHide) {
  const Pair& pair = metameric_pair();
  const Spectrum d65 = parse_spectrum("D65");
  const LightDesignResult reveal = design_light(pair.a, pair.b, LightGoal::Reveal, d65);
  const LightDesignResult hide = design_light(pair.a, pair.b, LightGoal::Hide, d65);
  const double de_reveal = independent_delta_e(pair.a, pair.b, reveal.light);
  EXPECT_GT(de_reveal, independent_delta_e(pair.a, pair.b, d65) + 1.0);
  EXPECT_GT(de_reveal, independent_delta_e(pair.a, pair.b, hide.light) + 1.0);
  EXPECT_NEAR(reveal.delta_e, de_reveal, 0.05);
  EXPECT_GE(reveal.light.min_value(), 0.0);
}

TEST(LightDesign, PrimaryMixBeatsTheEqualMix) {
  // Three LED-like gaussians: the revealing mix separates at least as well as the equal mix and
  // better than the hiding mix; the weights are non-negative.
  const Pair& pair = metameric_pair();
  const std::vector<Spectrum> primaries{parse_spectrum("gaussian:450:30"), parse_spectrum("gaussian:540:30"),
                                        parse_spectrum("gaussian:610:30")};
  const Spectrum d65 = parse_spectrum("D65");
  const LightDesignResult reveal = design_light(pair.a, pair.b, LightGoal::Reveal, d65, primaries);
  const LightDesignResult hide = design_light(pair.a, pair.b, LightGoal::Hide, d65, primaries);
  ASSERT_EQ(reveal.weights.size(), 3u);
  for (double w : reveal.weights) EXPECT_GE(w, 0.0);
  std::vector<double> lambda, equal;
  for (int nm = 380; nm <= 780; ++nm) {
    lambda.push_back(nm);
    equal.push_back(primaries[0].eval(nm) + primaries[1].eval(nm) + primaries[2].eval(nm));
  }
  const double de_equal = independent_delta_e(pair.a, pair.b, Spectrum(lambda, equal));
  const double de_reveal = independent_delta_e(pair.a, pair.b, reveal.light);
  EXPECT_GE(de_reveal, de_equal - 1e-6);
  EXPECT_GT(de_reveal, independent_delta_e(pair.a, pair.b, hide.light) + 1.0);
  EXPECT_LE(independent_delta_e(pair.a, pair.b, hide.light), de_equal + 1e-6);
}

TEST(LightDesign, IdenticalAlbedosCannotBeRevealed) {
  const Spectrum a = parse_spectrum("cc:7");
  try {
    design_light(a, a, LightGoal::Reveal, parse_spectrum("D65"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "albedo-b");
  }
}

TEST(LightDesign, RejectsNegativePrimaryAndDarkReference) {
  const Spectrum a = parse_spectrum("cc:7");
  const Spectrum b = parse_spectrum("cc:16");
  try {
    design_light(a, b, LightGoal::Reveal, parse_spectrum("D65"), {parse_spectrum("D65"), parse_spectrum("gaussian:550:20*-1")});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "primaries[1]");
  }
  try {
    design_light(a, b, LightGoal::Hide, Spectrum::constant(0.0));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "reference light");
  }
}

}  // namespace
}  // namespace prizma::spectral
