// Compressed transport: relighting from k coefficients equals the exact relight of the reconstructed
// spectra (and of the exact ones at k = n), is independent of the thread count, and the baked 8-bit
// display encoder writes what write_output_image writes into an 8-bit PNG.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "prizma/relight/compressed_relight.h"
#include "prizma/relight/output_image.h"
#include "prizma/relight/relight_image.h"
#include "prizma/spectral/error.h"
#include "relight_test_util.h"

namespace prizma::relight {
namespace {

namespace fs = std::filesystem;

// Two layers of smooth spectra varying over the image, plus ±0.0005 noise (fixed seed).
spectral::SpectralImage smooth_image(int width, int height, int bins) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.0005f, 0.0005f);
  const spectral::BinLayout layout = spectral::BinLayout::linear(400.0, 700.0, bins);
  return test::make_image(width, height, layout, {"key", "back"}, [&](int l, int p, int i) {
    const double x = static_cast<double>(p % width) / width, y = static_cast<double>(p / width) / height;
    const double lambda = layout.centre_nm(i);
    const double mu = 450.0 + 200.0 * x + 30.0 * l;
    const double v = 0.1 + 0.6 * y * std::exp(-0.5 * std::pow((lambda - mu) / 40.0, 2)) + 0.2 * (1.0 - y) * (lambda / 700.0);
    return static_cast<float>(v) + u(rng);
  });
}

std::vector<LightSpec> two_lights() { return {parse_light_spec("D65"), parse_light_spec("A*0.7")}; }

double max_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, double(std::abs(a[i] - b[i])));
  return d;
}

TEST(CompressedRelight, EqualsExactRelightWhenKIsN) {
  const auto img = smooth_image(40, 30, 16);
  spectral::BasisCriterion all;
  all.max_delta_e = -1.0;  // no k < n passes: k = n
  const CompressedTransport t = compress_transport(img, all);
  for (const auto& layer : t.lights) EXPECT_EQ(layer.k, 16);
  const RelightMatrix m(img.bins, two_lights(), {});
  EXPECT_LT(max_abs_diff(relight_compressed(t, m).xyz, relight_image(img, m).xyz), 2e-5);
}

TEST(CompressedRelight, EqualsExactRelightOfTheReconstructedSpectra) {
  const auto img = smooth_image(40, 30, 16);
  const CompressedTransport t = compress_transport(img);
  spectral::SpectralImage back = img;
  for (std::size_t l = 0; l < t.lights.size(); ++l) {
    const CompressedLayer& c = t.lights[l];
    EXPECT_GE(c.k, 1);
    EXPECT_LT(c.k, 16) << "smooth spectra compress";
    ASSERT_EQ(c.errors.size(), 4u);
    for (const auto& e : c.errors) EXPECT_LE(e.percentile, 0.5) << c.name << " " << e.light;
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      const Eigen::VectorXf s = c.basis * Eigen::Map<const Eigen::VectorXf>(c.coefficients.data() + p * c.k, c.k);
      for (int i = 0; i < 16; ++i) back.lights[l].data[p * 16 + static_cast<std::size_t>(i)] = s[i];
    }
  }
  RelightOptions opts;
  opts.exposure_ev = 0.5;
  opts.adapt_to_d65 = true;
  const RelightMatrix m(img.bins, two_lights(), opts);
  EXPECT_LT(max_abs_diff(relight_compressed(t, m).xyz, relight_image(back, m).xyz), 2e-5);
  // A light that is off contributes nothing.
  const RelightMatrix off(img.bins, {parse_light_spec("off"), parse_light_spec("F11")}, {});
  spectral::SpectralImage only_back = back;
  for (float& v : only_back.lights[0].data) v = 0.0f;
  EXPECT_LT(max_abs_diff(relight_compressed(t, off).xyz, relight_image(only_back, off).xyz), 2e-5);
}

TEST(CompressedRelight, IndependentOfTheThreadCount) {
  const auto img = smooth_image(64, 48, 16);
  const CompressedTransport t = compress_transport(img);
  const RelightMatrix m(img.bins, two_lights(), {});
  std::vector<float> one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = relight_compressed(t, m).xyz;
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = relight_compressed(t, m).xyz;
  }
  EXPECT_EQ(one, two);
}

TEST(CompressedRelight, RefusesAMatrixOfOtherShape) {
  const auto img = smooth_image(8, 8, 16);
  const CompressedTransport t = compress_transport(img);
  const RelightMatrix m(img.bins, {parse_light_spec("D65")}, {});
  EXPECT_THROW(relight_compressed(t, m), spectral::RuntimeError);
}

TEST(DisplayEncoder8, BakedSrgbWritesWhatAnEightBitPngHolds) {
  const auto img = smooth_image(96, 64, 16);
  const RelightMatrix m(img.bins, two_lights(), {});
  XyzImage xyz = relight_image(img, m);
  // Dark, bright, out-of-gamut and non-finite colours too.
  for (std::size_t i = 0; i < 600; ++i) xyz.xyz[i] *= std::pow(10.0f, -3.0f + 0.01f * static_cast<float>(i));
  xyz.xyz[3 * 700] = -0.2f;
  xyz.xyz[3 * 701 + 1] = std::numeric_limits<float>::quiet_NaN();
  xyz.xyz[3 * 702 + 2] = std::numeric_limits<float>::infinity();
  OutputOptions opts;
  const spectral::DisplayTransform display(opts.display);
  const DisplayEncoder8 encoder(display);
  EXPECT_TRUE(encoder.baked());
  std::vector<std::uint8_t> fast(xyz.xyz.size());
  encoder.encode(xyz.xyz.data(), xyz.pixel_count(), fast.data());

  const fs::path dir = test::scratch_dir("encoder8");
  write_output_image(dir / "a.png", xyz, opts, {});
  auto in = OIIO::ImageInput::open((dir / "a.png").string());
  ASSERT_TRUE(in);
  std::vector<std::uint8_t> png(fast.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, png.data()));
  in->close();
  std::size_t differ = 0;
  int worst = 0;
  for (std::size_t i = 0; i < png.size(); ++i) {
    const int d = std::abs(int{png[i]} - int{fast[i]});
    worst = std::max(worst, d);
    differ += d != 0;
  }
  EXPECT_LE(worst, 1);
  EXPECT_LE(differ, png.size() / 1000) << differ << " of " << png.size() << " values differ by 1";
  fs::remove_all(dir);
}

TEST(DisplayEncoder8, AColourSpaceConversionIsAMatrixAndBakesToo) {
  // A colour-space conversion of the shipped config (Linear sRGB) is a matrix alone: baked, with the
  // transform's own codes.
  spectral::DisplayOptions o;
  o.colour_space = "Linear sRGB";
  const spectral::DisplayTransform display(o);
  const DisplayEncoder8 encoder(display);
  EXPECT_TRUE(encoder.baked());
  std::vector<float> xyz = {0.2f, 0.3f, 0.4f, 0.9f, 0.95f, 1.0f, 0.0f, 0.0f, 0.0f};
  std::vector<float> ref = xyz;
  display.apply(ref.data(), 3);
  std::vector<std::uint8_t> out(9);
  encoder.encode(xyz.data(), 3, out.data());
  for (std::size_t i = 0; i < 9; ++i) {
    EXPECT_NEAR(int{out[i]}, std::floor(std::clamp(ref[i], 0.0f, 1.0f) * 255.0f + 0.5f), 1.0) << i;
  }
}

}  // namespace
}  // namespace prizma::relight
