// Compressed transport: relighting from k coefficients equals the exact relight of the reconstructed
// spectra (and of the exact ones at k = n), is independent of the thread count, and the baked 8-bit
// display encoder writes what spectral::write_output_image writes into an 8-bit PNG.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <Imath/half.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "prizma/relight/compressed_relight.h"
#include "prizma/spectral/output_image.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/relight/relight_session.h"
#include "prizma/relight/kernel_levels.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/simd_choice.h"
#include "spectral/relight_test_util.h"

namespace prizma::relight {
namespace {

namespace fs = std::filesystem;

// Two layers of smooth spectra varying over the image, plus ±0.0005 noise (fixed seed).
spectral::SpectralImage smooth_image(int width, int height, int bins) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.0005f, 0.0005f);
  const spectral::BinLayout layout = spectral::BinLayout::linear(400.0, 700.0, bins);
  return spectral::test::make_image(width, height, layout, {"key", "back"}, [&](int l, int p, int i) {
    const double x = static_cast<double>(p % width) / width, y = static_cast<double>(p / width) / height;
    const double lambda = layout.centre_nm(i);
    const double mu = 450.0 + 200.0 * x + 30.0 * l;
    const double v = 0.1 + 0.6 * y * std::exp(-0.5 * std::pow((lambda - mu) / 40.0, 2)) + 0.2 * (1.0 - y) * (lambda / 700.0);
    return static_cast<float>(v) + u(rng);
  });
}

std::vector<LightSpec> two_lights() { return {parse_light_spec("D65"), parse_light_spec("A*0.7")}; }

// How two 8-bit images differ: the values that differ and the largest difference.
struct CodeDiff {
  std::size_t differ = 0;
  int worst = 0;
};
CodeDiff code_diff(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  CodeDiff out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const int d = std::abs(int{a[i]} - int{b[i]});
    out.worst = std::max(out.worst, d);
    out.differ += d != 0;
  }
  return out;
}

double max_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, double(std::abs(a[i] - b[i])));
  return d;
}

// The image with each layer's spectra replaced by the compressed transport's reconstruction B·c.
spectral::SpectralImage reconstructed(const spectral::SpectralImage& img, const CompressedTransport& t) {
  spectral::SpectralImage back = img;
  const std::size_t n = static_cast<std::size_t>(img.bins.size());
  for (std::size_t l = 0; l < t.lights.size(); ++l) {
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      const Eigen::VectorXf s = reconstructed_spectrum(t.lights[l], p);
      std::copy(s.data(), s.data() + n, back.lights[l].data.begin() + static_cast<std::ptrdiff_t>(p * n));
    }
  }
  return back;
}

// At k = n the only loss is half rounding: with an orthonormal basis each bin's error is at most
// ‖δc‖ ≤ 2⁻¹¹·‖c‖ = 2⁻¹¹·‖t_p‖ (half's unit roundoff, round to nearest), plus float rounding.
TEST(CompressedRelight, AtKEqualToNOnlyHalfRoundingIsLost) {
  const auto img = smooth_image(40, 30, 16);
  spectral::BasisCriterion all;
  all.max_delta_e = -1.0;  // no k < n passes: k = n
  const CompressedTransport t = compress_transport(img, all);
  const spectral::SpectralImage back = reconstructed(img, t);
  double worst = 0.0, worst_float = 0.0;
  for (std::size_t l = 0; l < t.lights.size(); ++l) {
    EXPECT_EQ(t.lights[l].k, 16);
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      const Eigen::Map<const Eigen::VectorXf> exact(img.lights[l].data.data() + 16 * p, 16);
      const Eigen::Map<const Eigen::VectorXf> mine(back.lights[l].data.data() + 16 * p, 16);
      worst = std::max(worst, double((exact - mine).cwiseAbs().maxCoeff() / exact.norm()));
      worst_float = std::max(worst_float, double((exact - mine).cwiseAbs().maxCoeff()));
    }
  }
  EXPECT_LE(worst, std::ldexp(1.0, -11) + 1e-6);
  EXPECT_GT(worst_float, 1e-6) << "half, not float: some bin moves";
  const spectral::RelightMatrix m(img.bins, two_lights(), {});
  EXPECT_LT(max_abs_diff(relight_compressed(t, m).xyz, spectral::relight_image(back, m).xyz), 2e-5);
}

// The coefficients are scaled by a power of two into [2^14, 2^15) per layer, so the transport's
// level does not change what is stored: the same half bits for the image times 2^40 and 2^-40
// (beyond half's range either way), the basis scaled exactly. (k fixed at n: the ΔE criterion,
// relative to a white of Y = 1, sees a brighter image differently.)
TEST(CompressedRelight, HalfCoefficientsKeepTheirPrecisionAtAnyLevel) {
  const auto img = smooth_image(24, 16, 16);
  spectral::BasisCriterion all;
  all.max_delta_e = -1.0;
  const CompressedTransport t = compress_transport(img, all);
  for (const CompressedLayer& c : t.lights) {
    float largest = 0.0f;
    for (const std::uint16_t bits : c.coefficients) largest = std::max(largest, std::fabs(float(half(half::FromBits, bits))));
    EXPECT_GE(largest, 16384.0f) << c.name;
    EXPECT_LT(largest, 32768.0f) << c.name;
  }
  for (const int e : {40, -40}) {
    spectral::SpectralImage scaled = img;
    for (auto& layer : scaled.lights)
      for (float& v : layer.data) v = std::ldexp(v, e);
    const CompressedTransport ts = compress_transport(scaled, all);
    for (std::size_t l = 0; l < t.lights.size(); ++l) {
      EXPECT_EQ(ts.lights[l].k, t.lights[l].k);
      EXPECT_EQ(ts.lights[l].coefficients, t.lights[l].coefficients) << "e = " << e;
      const Eigen::MatrixXf expected = t.lights[l].basis * std::ldexp(1.0f, e);
      EXPECT_EQ(ts.lights[l].basis, expected) << "e = " << e;
    }
  }
}

TEST(CompressedRelight, EqualsExactRelightOfTheReconstructedSpectra) {
  const auto img = smooth_image(40, 30, 16);
  const CompressedTransport t = compress_transport(img);
  for (const CompressedLayer& c : t.lights) {
    EXPECT_GE(c.k, 1);
    EXPECT_LT(c.k, 16) << "smooth spectra compress";
    ASSERT_EQ(c.errors.size(), 4u);
    for (const auto& e : c.errors) EXPECT_LE(e.percentile, 0.5) << c.name << " " << e.light;
  }
  const spectral::SpectralImage back = reconstructed(img, t);
  spectral::RelightOptions opts;
  opts.exposure_ev = 0.5;
  opts.adapt_to_d65 = true;
  const spectral::RelightMatrix m(img.bins, two_lights(), opts);
  EXPECT_LT(max_abs_diff(relight_compressed(t, m).xyz, spectral::relight_image(back, m).xyz), 2e-5);
  // A light that is off contributes nothing.
  const spectral::RelightMatrix off(img.bins, {parse_light_spec("off"), parse_light_spec("F11")}, {});
  spectral::SpectralImage only_back = back;
  for (float& v : only_back.lights[0].data) v = 0.0f;
  EXPECT_LT(max_abs_diff(relight_compressed(t, off).xyz, spectral::relight_image(only_back, off).xyz), 2e-5);
}

TEST(CompressedRelight, IndependentOfTheThreadCount) {
  const auto img = smooth_image(64, 48, 16);
  const CompressedTransport t = compress_transport(img);
  const spectral::RelightMatrix m(img.bins, two_lights(), {});
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
  const spectral::RelightMatrix m(img.bins, {parse_light_spec("D65")}, {});
  EXPECT_THROW(relight_compressed(t, m), spectral::RuntimeError);
}

TEST(DisplayEncoder8, BakedSrgbWritesWhatAnEightBitPngHolds) {
  const auto img = smooth_image(96, 64, 16);
  const spectral::RelightMatrix m(img.bins, two_lights(), {});
  spectral::XyzImage xyz = spectral::relight_image(img, m);
  // Dark, bright, out-of-gamut and non-finite colours too.
  for (std::size_t i = 0; i < 600; ++i) xyz.xyz[i] *= std::pow(10.0f, -3.0f + 0.01f * static_cast<float>(i));
  xyz.xyz[3 * 700] = -0.2f;
  xyz.xyz[3 * 701 + 1] = std::numeric_limits<float>::quiet_NaN();
  xyz.xyz[3 * 702 + 2] = std::numeric_limits<float>::infinity();
  spectral::OutputOptions opts;
  const spectral::DisplayTransform display(opts.display);
  const DisplayEncoder8 encoder(display);
  EXPECT_TRUE(encoder.baked());
  std::vector<std::uint8_t> fast(xyz.xyz.size());
  encoder.encode(xyz.xyz.data(), xyz.pixel_count(), fast.data());

  const fs::path dir = spectral::test::scratch_dir("encoder8");
  spectral::write_output_image(dir / "a.png", xyz, opts, {});
  auto in = OIIO::ImageInput::open((dir / "a.png").string());
  ASSERT_TRUE(in);
  std::vector<std::uint8_t> png(fast.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, png.data()));
  in->close();
  const auto [differ, worst] = code_diff(png, fast);
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

// The step table's code (one entry read, one compare of the low bits) against the thresholds
// themselves: exactly the number of thresholds ≤ v, on both sides of every step, over 40 octaves
// (both clamps) and for negatives, for sRGB and for a display whose curve is only a clamp.
TEST(DisplayEncoder8, StepTableCodeIsExactlyTheThresholdCount) {
  spectral::DisplayOptions linear;
  linear.colour_space = "Linear sRGB";
  for (const auto& options : {spectral::DisplayOptions{}, linear}) {
    const spectral::DisplayTransform display(options);
    const DisplayEncoder8 encoder(display);
    ASSERT_TRUE(encoder.baked());
    const DisplayEncoder8::StepTable& t = encoder.step_table();
    ASSERT_FALSE(t.empty());
    EXPECT_LE(t.entries[0].size(), 16384u);
    auto table_code = [&](int c, float v) { return static_cast<int>(t.code(c, v)); };
    for (int c = 0; c < 3; ++c) {
      const float* thr = encoder.thresholds(c);
      auto count = [&](float v) { return int(std::upper_bound(thr + 1, thr + 256, std::max(v, 0.0f)) - (thr + 1)); };
      int steps = 0;
      for (int j = 1; j < 256; ++j) {
        if (!std::isfinite(thr[j]) || thr[j] <= 0.0f) continue;
        ++steps;
        EXPECT_EQ(table_code(c, thr[j]), count(thr[j])) << "at threshold " << j << " of channel " << c;
        const float below = std::nextafter(thr[j], 0.0f);
        EXPECT_EQ(table_code(c, below), count(below)) << "below threshold " << j << " of channel " << c;
      }
      EXPECT_GT(steps, 200) << "a curve with steps";
      std::uint64_t state = 12345;
      for (int i = 0; i < 200000; ++i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        const float v = std::ldexp(static_cast<float>(state >> 40) / 16777216.0f, static_cast<int>(state % 41) - 30);
        ASSERT_EQ(table_code(c, v), count(v)) << v;
        ASSERT_EQ(table_code(c, -v), count(0.0f)) << -v;
      }
    }
  }
}

TEST(LightWeights, SkipsLightsThatAreOffAndChecksTheShape) {
  const auto bins = spectral::BinLayout::linear(400.0, 700.0, 8);
  const spectral::RelightMatrix m(bins, {parse_light_spec("off"), parse_light_spec("D65")}, {});
  const std::vector<spectral::LightWeights> on = spectral::light_weights(m, 2, 8, "image");
  ASSERT_EQ(on.size(), 1u);
  EXPECT_EQ(on[0].light, 1);
  ASSERT_EQ(on[0].weights.size(), 24u);
  EXPECT_FLOAT_EQ(on[0].weights[8 + 3], static_cast<float>(m.light(1)(1, 3)));  // Y row, bin 3
  EXPECT_THROW(spectral::light_weights(m, 3, 8, "image"), spectral::RuntimeError);
  EXPECT_THROW(spectral::light_weights(m, 2, 9, "image"), spectral::RuntimeError);
}

// The fused frame (coefficients → 8-bit codes per row, display matrix folded into the weights)
// against relight_compressed_into + DisplayEncoder8::encode: the same codes but for float rounding.
TEST(DisplayEncoder8, FusedFrameEqualsRelightThenEncode) {
  const auto img = smooth_image(203, 61, 16);  // a width that is no multiple of any SIMD width
  const CompressedTransport t = compress_transport(img);
  const spectral::DisplayTransform display(spectral::DisplayOptions{});
  const DisplayEncoder8 encoder(display);
  ASSERT_TRUE(encoder.baked());
  ASSERT_FALSE(encoder.step_table().empty()) << "the sRGB curve gets the step table";
  for (const auto& lights : {two_lights(), std::vector<LightSpec>{parse_light_spec("off"), parse_light_spec("F11*3")}}) {
    spectral::RelightOptions o;
    o.exposure_ev = 0.7;
    const spectral::RelightMatrix m(img.bins, lights, o);
    std::vector<float> xyz(3 * img.pixel_count());
    relight_compressed_into(t, m, xyz.data());
    std::vector<std::uint8_t> ref(xyz.size()), fused(xyz.size()), fused1(xyz.size());
    encoder.encode(xyz.data(), img.pixel_count(), ref.data());
    relight_compressed_to_display8(t, m, encoder, fused.data());
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
      relight_compressed_to_display8(t, m, encoder, fused1.data());
    }
    EXPECT_EQ(fused, fused1) << "independent of the thread count";
    const auto [differ, worst] = code_diff(ref, fused);
    EXPECT_LE(worst, 1);
    EXPECT_LE(differ, ref.size() / 1000) << differ << " of " << ref.size();
    std::size_t saturated = 0;
    for (const std::uint8_t v : fused) saturated += v == 255;
    EXPECT_LT(saturated, fused.size()) << "not all white";
  }
}

// The first k coefficients of each layer of a k = n transport (its basis' first k columns).
CompressedTransport truncated(const CompressedTransport& full, int k) {
  CompressedTransport t = full;
  for (CompressedLayer& c : t.lights) {
    const auto n = static_cast<std::size_t>(c.k);
    std::vector<std::uint16_t> kept(full.pixel_count() * static_cast<std::size_t>(k));
    for (std::size_t p = 0; p < full.pixel_count(); ++p)
      std::copy_n(c.coefficients.begin() + static_cast<std::ptrdiff_t>(p * n), k, kept.begin() + static_cast<std::ptrdiff_t>(p * static_cast<std::size_t>(k)));
    c.coefficients = std::move(kept);
    c.basis = Eigen::MatrixXf(c.basis.leftCols(k));
    c.k = k;
  }
  return t;
}

// Every k path of the fused row (de-interleaved half loads for k = 1..4, a converted row and
// gathers beyond) at every SIMD level this machine runs: against relight_compressed_into + encode,
// the same codes but for float rounding (the folded matrix); between the levels, the same bytes.
// relight_compressed_into's half → float rows: the same floats at every level.
TEST(DisplayEncoder8, FusedFrameOnEverySimdLevelAndEveryKSameBytes) {
  const auto img = smooth_image(203, 61, 16);  // a width that is no multiple of any SIMD width
  spectral::BasisCriterion all;
  all.max_delta_e = -1.0;
  const CompressedTransport full = compress_transport(img, all);
  const spectral::DisplayTransform display(spectral::DisplayOptions{});
  const DisplayEncoder8 encoder(display);
  ASSERT_FALSE(encoder.step_table().empty());
  const spectral::RelightMatrix m(img.bins, {parse_light_spec("D65*0.8"), parse_light_spec("F11")}, {});
  const std::vector<spectral::SimdLevel> levels = detail::kernel_simd_levels(spectral::SimdKernel::CompressedFrame);
  ASSERT_FALSE(levels.empty());
  for (const int k : {1, 2, 3, 4, 5, 16}) {
    const CompressedTransport t = truncated(full, k);
    std::vector<float> xyz(3 * img.pixel_count());
    relight_compressed_into(t, m, xyz.data());
    std::vector<std::uint8_t> ref(xyz.size()), fused(xyz.size()), first;
    encoder.encode(xyz.data(), img.pixel_count(), ref.data());
    for (const spectral::SimdLevel level : levels) {
      const spectral::ForcedSimdLevel forced(spectral::SimdKernel::CompressedFrame, level);
      const std::string name(spectral::simd_level_name(level));
      std::fill(fused.begin(), fused.end(), std::uint8_t{0});
      relight_compressed_to_display8(t, m, encoder, fused.data());
      const auto [differ, worst] = code_diff(ref, fused);
      EXPECT_LE(worst, 1) << "k = " << k << " at " << name;
      EXPECT_LE(differ, ref.size() / 1000) << "k = " << k << " at " << name << ": " << differ;
      if (first.empty())
        first = fused;
      else
        EXPECT_EQ(code_diff(first, fused).differ, 0u) << "k = " << k << " at " << name;
    }
    for (const spectral::SimdLevel level : detail::kernel_simd_levels(spectral::SimdKernel::HalfToFloat)) {
      const spectral::ForcedSimdLevel forced(spectral::SimdKernel::HalfToFloat, level);
      std::vector<float> again(xyz.size());
      relight_compressed_into(t, m, again.data());
      EXPECT_EQ(std::memcmp(again.data(), xyz.data(), xyz.size() * sizeof(float)), 0)
          << "k = " << k << " at " << spectral::simd_level_name(level);
    }
    std::size_t distinct = 0;
    for (std::size_t i = 1; i < ref.size(); ++i) distinct += ref[i] != ref[i - 1];
    EXPECT_GT(distinct, ref.size() / 10) << "an image, not a flat colour";
  }
}

// The same bytes at every level where float rounding would show: 1.5 million codes from random
// coefficients (k = 3 and k = 6: the de-interleaved and the gathered paths), enough that a level
// rounding its sums differently changes some (FMA on AVX2 and AVX-512, as before issue 26, changed
// 2 codes here against the baseline's; FMA in the red channel alone, 1).
TEST(DisplayEncoder8, FusedFrameSameBytesAtEveryLevelOnAMillionCodes) {
  CompressedTransport t;
  t.width = 1024;
  t.height = 512;
  t.bins = spectral::BinLayout::linear(400.0, 700.0, 16);
  std::mt19937 rng(2026);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const int k : {3, 6}) {
    CompressedLayer layer;
    layer.name = "l" + std::to_string(k);
    const Eigen::MatrixXf basis = Eigen::MatrixXf::NullaryExpr(16, k, [&] { return 0.25f * u(rng); });
    std::vector<float> c(t.pixel_count() * static_cast<std::size_t>(k));
    for (float& v : c) v = u(rng);
    set_half_coefficients(layer, basis, c);
    t.lights.push_back(std::move(layer));
  }
  const spectral::DisplayTransform display(spectral::DisplayOptions{});
  const DisplayEncoder8 encoder(display);
  const spectral::RelightMatrix m(t.bins, {parse_light_spec("D65"), parse_light_spec("F11*0.5")}, {});
  std::vector<std::uint8_t> first, codes(3 * t.pixel_count());
  for (const spectral::SimdLevel level : detail::kernel_simd_levels(spectral::SimdKernel::CompressedFrame)) {
    const spectral::ForcedSimdLevel forced(spectral::SimdKernel::CompressedFrame, level);
    relight_compressed_to_display8(t, m, encoder, codes.data());
    if (first.empty())
      first = codes;
    else
      EXPECT_EQ(code_diff(first, codes).differ, 0u) << spectral::simd_level_name(level);
  }
  std::size_t distinct = 0;
  for (std::size_t i = 1; i < first.size(); ++i) distinct += first[i] != first[i - 1];
  EXPECT_GT(distinct, first.size() / 10) << "not a flat colour";
}

// prizma-relight compress --compact: the file relights (from its coefficients alone) within the
// stated bound of the exact relight, for each light alone under each test light.
TEST(CompressFile, CompactFileRelitWithinTheBound) {
  const fs::path dir = spectral::test::scratch_dir("compress");
  const auto img = smooth_image(48, 40, 16);
  spectral::write_spectral_exr(dir / "in.exr", img);
  CompressFileOptions options;
  options.compact = true;
  options.criterion.max_delta_e = 0.5;
  const CompressedTransport stored = compress_spectral_exr(dir / "in.exr", dir / "compact.exr", options);
  spectral::ExrReadOptions read;
  read.read_coefficients = true;
  read.allow_compact = true;
  spectral::SpectralImage back = spectral::read_spectral_exr(dir / "compact.exr", read);
  ASSERT_TRUE(back.compact());
  for (std::size_t l = 0; l < back.lights.size(); ++l) {
    EXPECT_EQ(back.lights[l].coefficients.k, stored.lights[l].k);
    EXPECT_LT(stored.lights[l].k, 16);
    EXPECT_EQ(back.lights[l].coefficients.errors.size(), 4u);
  }
  RelightSession compact(std::move(back), "compact.exr");
  ASSERT_NE(compact.coefficients(), nullptr);
  RelightSession exact(img, "in.exr");
  ASSERT_EQ(exact.coefficients(), nullptr);
  for (const char* light : {"D65", "A", "F11", "gaussian:450:20"}) {
    for (std::size_t l = 0; l < 2; ++l) {
      const std::string other = l == 0 ? "back" : "key";
      const std::string self = l == 0 ? "key" : "back";
      for (RelightSession* s : {&compact, &exact}) {
        s->set_light(self, light);
        s->set_light(other, "off");
      }
      const spectral::XyzImage& a = exact.xyz();
      const spectral::XyzImage& b = compact.xyz();
      const Eigen::Vector3d white = exact.matrix().mix_white_xyz();
      std::vector<double> de(a.pixel_count());
      for (std::size_t p = 0; p < de.size(); ++p)
        de[p] = spectral::delta_e2000(spectral::xyz_to_lab(a.at(static_cast<int>(p % 48), static_cast<int>(p / 48)), white),
                                      spectral::xyz_to_lab(b.at(static_cast<int>(p % 48), static_cast<int>(p / 48)), white));
      std::sort(de.begin(), de.end());
      const double p99 = de[static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(de.size()))) - 1];
      EXPECT_LE(p99, 0.5 + 1e-3) << self << " under " << light;
      EXPECT_GT(p99, 0.0) << "the compact file is not the exact one";
    }
  }
  // probe gives the bins the coefficients make.
  const ProbeResult probe = compact.probe(3, 4);
  ASSERT_EQ(probe.bins.size(), 2u);
  ASSERT_EQ(probe.bins[0].size(), 16u);
  EXPECT_NEAR(probe.bins[0][5], img.lights[0].data[(4 * 48 + 3) * 16 + 5], 0.02);
  // A compact file cannot be relit exactly; the kept-bins file can.
  spectral::SpectralImage again = spectral::read_spectral_exr(dir / "compact.exr", read);
  EXPECT_THROW(RelightSession(std::move(again), "compact.exr", true), spectral::InputError);
  options.compact = false;
  compress_spectral_exr(dir / "in.exr", dir / "full.exr", options);
  RelightSession full_exact(spectral::read_spectral_exr(dir / "full.exr", read), "full.exr", true);
  EXPECT_EQ(full_exact.coefficients(), nullptr);
  RelightSession original(img, "in.exr");
  EXPECT_EQ(full_exact.xyz().xyz, original.xyz().xyz);
  fs::remove_all(dir);
}

TEST(CompressFile, RefusesACompactInputABadBoundAndAFluorescentFile) {
  const fs::path dir = spectral::test::scratch_dir("compress-refuse");
  spectral::write_spectral_exr(dir / "in.exr", smooth_image(16, 8, 8));
  CompressFileOptions options;
  options.compact = true;
  compress_spectral_exr(dir / "in.exr", dir / "compact.exr", options);
  try {
    compress_spectral_exr(dir / "compact.exr", dir / "again.exr", options);
    FAIL();
  } catch (const spectral::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("compact file"), std::string::npos) << e.what();
  }
  options.criterion.max_delta_e = 0.0;
  EXPECT_THROW(compress_spectral_exr(dir / "in.exr", dir / "zero.exr", options), spectral::InputError);
  EXPECT_FALSE(fs::exists(dir / "again.exr") || fs::exists(dir / "zero.exr"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace prizma::relight
