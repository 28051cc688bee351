// Stress tests of relighting and storage: light scales from 1e-6 to 1e6, float32 storage of extreme
// values, half storage only on request (refused beyond 65504, or clamped with a warning).
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <unistd.h>

#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/error.h"
#include "stress/stress_support.h"

namespace prizma::stress {
namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("prizma-stress-" + name + "-" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

pr::Scene small_chromatic_scene() {
  pr::Material m;
  m.name = "chromatic";
  m.albedo = ps::Spectrum({380, 500, 600, 780}, {0.95, 0.8, 0.5, 0.3});
  m.sigma_t_per_unit = log_ramp(0.5, 5.0);
  m.anisotropy = ps::Spectrum::constant(0.3);
  pr::Scene s = slab_scene(box_medium({8, 8, 8}, m), true, 8, 16);
  s.settings.sample_end = 16;
  return s;
}

TEST(StressRelight, LightScales1em6To1e6AreLinearAndFinite) {
  const ps::SpectralImage img = pr::render(small_chromatic_scene());
  for (const std::string base : {"D65", "F11", "LED-B3", "gaussian:550:10"}) {
    auto relit = [&](const std::string& scale) {
      std::vector<spectral::LightSpectrum> specs;
      for (std::size_t l = 0; l < img.lights.size(); ++l)
        specs.push_back(spectral::parse_light_spectrum(scale.empty() ? base : base + "*" + scale));
      return spectral::relight_image(img, spectral::RelightMatrix(img.bins, specs, spectral::RelightOptions{}));
    };
    const spectral::XyzImage ref = relit("");
    for (const std::string scale : {"1e-6", "1e-3", "1e3", "1e6"}) {
      const double k = std::stod(scale);
      const spectral::XyzImage x = relit(scale);
      std::size_t bad = 0, nonlinear = 0;
      for (std::size_t i = 0; i < x.xyz.size(); ++i) {
        if (!std::isfinite(x.xyz[i]) || x.xyz[i] < 0.0f) ++bad;
        // float32 evaluation: relative 1e-5 of the value (a few ulp of the matrix product).
        if (std::abs(x.xyz[i] - k * ref.xyz[i]) > 1e-5 * k * std::abs(ref.xyz[i]) + 1e-30) ++nonlinear;
      }
      EXPECT_EQ(bad, 0u) << base << "*" << scale << ": non-finite or negative XYZ";
      EXPECT_EQ(nonlinear, 0u) << base << "*" << scale << ": XYZ not " << scale << " times the unit-scale XYZ";
    }
  }
}

ps::SpectralImage extreme_image() {
  ps::SpectralImage img;
  img.width = 3;
  img.height = 2;
  img.bins = ps::BinLayout::linear(380, 780, 4);
  ps::TransportLayer layer;
  layer.name = "key";
  // Tiny, ordinary and huge values, all representable in float32.
  layer.data = {1e-30f, 1e-6f, 0.5f, 1.0f, 7e4f, 1e6f, 3e30f, 0.0f, 1e-38f, 65504.0f, 65505.0f, 2.0f,
                1e-7f,  1e-3f, 1e2f, 1e4f, 1e5f, 1e7f, 1e9f, 1e12f, 123.456f, 6e-8f, 3.0f, 1e-20f};
  img.lights.push_back(layer);
  img.info.samples = 1;
  img.info.sample_range = "0:1";
  return img;
}

TEST(StressStorage, Float32IsDefaultAndKeepsExtremeValuesExactly) {
  const fs::path dir = scratch_dir("float");
  const ps::SpectralImage img = extreme_image();
  ps::write_spectral_exr(dir / "x.exr", img);
  const ps::SpectralImage back = ps::read_spectral_exr(dir / "x.exr");
  ASSERT_EQ(back.lights.size(), 1u);
  ASSERT_EQ(back.lights[0].data.size(), img.lights[0].data.size());
  for (std::size_t k = 0; k < img.lights[0].data.size(); ++k)
    EXPECT_EQ(back.lights[0].data[k], img.lights[0].data[k]) << "value " << k;
  fs::remove_all(dir);
}

TEST(StressStorage, HalfRefusesValuesBeyondItsRange) {
  const fs::path dir = scratch_dir("half");
  ps::ExrWriteOptions opts;
  opts.pixel_type = ps::ExrPixelType::Half;
  const fs::path path = dir / "h.exr";
  try {
    ps::write_spectral_exr(path, extreme_image(), opts);
    FAIL() << "half output of 1e6 was accepted";
  } catch (const ps::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("65504"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path)) << "a refused write left a file";
  fs::remove_all(dir);
}

TEST(StressStorage, HalfClampsWithAWarningOnRequest) {
  const fs::path dir = scratch_dir("halfclamp");
  ps::ExrWriteOptions opts;
  opts.pixel_type = ps::ExrPixelType::Half;
  opts.clamp_half = true;
  const ps::SpectralImage img = extreme_image();
  testing::internal::CaptureStderr();
  ps::write_spectral_exr(dir / "h.exr", img, opts);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("warning"), std::string::npos) << "no warning for clamped values: " << err;
  const ps::SpectralImage back = ps::read_spectral_exr(dir / "h.exr");
  for (std::size_t k = 0; k < img.lights[0].data.size(); ++k) {
    const float v = img.lights[0].data[k], b = back.lights[0].data[k];
    EXPECT_TRUE(std::isfinite(b)) << k;
    EXPECT_GE(b, 0.0f) << k;
    if (v > 65504.0f) {
      EXPECT_EQ(b, 65504.0f) << "value " << k << " = " << v << " not clamped";
    } else if (v >= 6.2e-5f) {
      // Within half's normal range: relative precision 2^-11.
      EXPECT_NEAR(b, v, v * 4.9e-4f) << "value " << k;
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace prizma::stress
