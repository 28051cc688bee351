// SampleRange, prizma:renderOptions and the merge tolerance that resumed and sharded renders are
// held to (docs/distributed.md states these figures).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>

#include "prizma/render/render.h"
#include "prizma/render/resume.h"
#include "prizma/render/sample_range.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

using spectral::InputError;
using spectral::Spectrum;

std::string input_error(auto&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(SampleRange, ParsesAndFormats) {
  EXPECT_EQ(SampleRange::parse("0:64", "x"), (SampleRange{0, 64}));
  EXPECT_EQ(SampleRange::parse("64:128", "x").size(), 64);
  EXPECT_EQ((SampleRange{3, 9}).to_string(), "3:9");
  for (const char* bad : {"", ":", "5:2", "2:2", "-1:4", "1:", ":4", "1:4x", " 1:4", "+1:4", "1:4,5:6",
                          "0:9223372036854775808", "0:4611686018427387905"})
    EXPECT_THROW(SampleRange::parse(bad, "--samples"), InputError) << bad;
  EXPECT_EQ(SampleRange::parse("0:4611686018427387904", "x").end, kMaxSampleIndex);
}

TEST(SampleRange, StartingAtRefusesOverflowWithTheReason) {
  EXPECT_EQ(SampleRange::starting_at(24, 40, "--spp"), (SampleRange{24, 64}));
  const std::string e = input_error([] {
    SampleRange::starting_at(2, std::numeric_limits<std::int64_t>::max(), "--spp");
  });
  EXPECT_NE(e.find("must be 1 to 2^40 samples per pixel, got 9223372036854775807"), std::string::npos) << e;
  const std::string f = input_error([] { SampleRange::starting_at(kMaxSampleIndex - 3, 4, "--spp"); });
  EXPECT_NE(f.find("largest sample index"), std::string::npos) << f;
  EXPECT_THROW(SampleRange::starting_at(0, 0, "--spp"), InputError);
  EXPECT_THROW(SampleRange::starting_at(0, -3, "--spp"), InputError);
}

TEST(SampleRange, ListsJoinAndKeepGaps) {
  const auto r = parse_sample_ranges("16:24,0:8,8:16", "x");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(format_sample_ranges(r), "0:24");
  EXPECT_EQ(format_sample_ranges({{0, 8}, {16, 24}}), "0:8,16:24");
  EXPECT_EQ(join_sample_ranges({{16, 24}, {0, 8}}).size(), 2u);
  EXPECT_THROW(parse_sample_ranges("0:8,", "x"), InputError);
  EXPECT_THROW(parse_sample_ranges("0:8;8:9", "x"), InputError);
}

TEST(RenderOverrides, JsonRoundTrip) {
  RenderOverrides o;
  o.width = 64;
  o.height = 32;
  o.bins = "linear:400:700:4";
  o.seed = std::numeric_limits<std::uint64_t>::max();  // beyond double: stored as a string
  o.wavelength_sampling = "single";
  o.sampler = "sobol";
  o.target_error = 0.01;
  o.no_majorant_grid = true;
  o.variance = true;
  o.half = true;
  o.samples = SampleRange{64, 128};
  EXPECT_EQ(overrides_from_json(overrides_to_json(o), "f"), o);
  EXPECT_EQ(overrides_from_json(overrides_to_json(RenderOverrides{}), "f"), RenderOverrides{});
  EXPECT_EQ(overrides_to_json(RenderOverrides{}), "{}");
  for (const char* bad : {"[]", "{\"width\":-3}", "{\"width\":1.5}", "{\"colour\":1}", "{\"seed\":\"-1\"}",
                          "{\"samples\":\"4:2\"}", "{\"half\":1}", "not json"})
    EXPECT_THROW(overrides_from_json(bad, "f.exr: prizma:renderOptions"), InputError) << bad;
}

Scene chromatic_scene(std::int64_t spp) {
  Scene s = testing::chromatic_scene(spp);
  s.settings.write_variance = true;
  return s;
}

// Distance in units in the last place between two finite floats of the same sign.
std::int64_t ulps(float a, float b) {
  return std::abs(static_cast<std::int64_t>(std::bit_cast<std::int32_t>(a)) -
                  static_cast<std::int64_t>(std::bit_cast<std::int32_t>(b)));
}

// The merge tolerance. A shard stores means as float (rounded, relative ≤ 2⁻²⁴); merge recombines
// them in double and rounds once more, so a merged mean is within 3·2⁻²⁴ of the one render's and at
// most 2 float ulps away (all transport values are ≥ 0: no cancellation). Variances are recombined
// from float means and variances (Chan et al.); their error is relative to the variance.
TEST(MergeTolerance, ShardsAndResumedRendersMatchOneRender) {
  const std::int64_t n = 64;
  Scene s = chromatic_scene(n);
  const auto full = render(s);
  std::int64_t worst_ulps = 0;
  double worst_var = 0.0;
  for (const std::vector<std::int64_t>& cuts :
       {std::vector<std::int64_t>{0, 32, 64}, {0, 5, 21, 40, 64}, {0, 1, 2, 3, 63, 64}, {0, 48, 64}}) {
    std::vector<spectral::SpectralImage> shards;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
      s.settings.sample_begin = cuts[k];
      s.settings.sample_end = cuts[k + 1];
      shards.push_back(render(s));
    }
    std::reverse(shards.begin(), shards.end());
    const auto merged = merge_shards(shards);
    ASSERT_EQ(merged.info.sample_range, "0:64");
    for (std::size_t l = 0; l < full.lights.size(); ++l) {
      for (std::size_t k = 0; k < full.lights[l].data.size(); ++k) {
        const float f = full.lights[l].data[k], m = merged.lights[l].data[k];
        ASSERT_GE(f, 0.0f);
        worst_ulps = std::max(worst_ulps, ulps(f, m));
        const double v = full.lights[l].variance[k], mv = merged.lights[l].variance[k];
        if (v > 0) worst_var = std::max(worst_var, std::abs(mv - v) / v);
      }
    }
  }
  std::cout << "merge tolerance measured: means " << worst_ulps << " ulp, variances relative " << worst_var
            << "\n";
  EXPECT_LE(worst_ulps, 2);
  EXPECT_LE(worst_var, 1e-5);
}

// Low-noise pixels: the variance far below mean² (here 1e-17 of it, below what a float mean
// resolves). Recombining through Σx² − n·mean² (the merge before Chan's formula, in double) cancels
// all digits there; merging two hand-made shards must still give the variance of their union.
TEST(MergeTolerance, VarianceOfLowNoisePixelsSurvivesTheMerge) {
  auto shard = [](float mean, float var_of_mean, std::int64_t n, std::int64_t begin) {
    spectral::SpectralImage img;
    img.width = img.height = 1;
    img.bins = spectral::BinLayout::parse("linear:400:700:1", "bins");
    img.lights.resize(1);
    img.lights[0].name = "env";
    img.lights[0].data = {mean};
    img.lights[0].variance = {var_of_mean};
    img.info.is_prizma = true;
    img.info.samples = n;
    img.info.sample_range = SampleRange{begin, begin + n}.to_string();
    return img;
  };
  const std::int64_t n = 1000;
  const auto a = shard(1.0f, 1e-20f, n, 0), b = shard(1.0000002f, 2e-20f, n, n);
  // The exact variance of the mean of the union, from the same float inputs.
  const long double ma = a.lights[0].data[0], mb = b.lights[0].data[0], N = 2.0L * n;
  const long double m = (ma + mb) / 2.0L;
  const long double m2 = (n - 1.0L) * n * a.lights[0].variance[0] + (n - 1.0L) * n * b.lights[0].variance[0] +
                         n * (ma - m) * (ma - m) + n * (mb - m) * (mb - m);
  const double expected = static_cast<double>(m2 / (N - 1.0L) / N);
  const auto merged = merge_shards({a, b});
  EXPECT_NEAR(merged.lights[0].variance[0], expected, 1e-5 * expected);
  EXPECT_NEAR(merged.lights[0].data[0], static_cast<double>(m), 1e-7);
}

TEST(MergeTolerance, NamesShardsByFile) {
  Scene s = chromatic_scene(4);
  s.settings.write_variance = false;
  const auto a = render(s);
  s.settings.seed = 99;
  s.settings.sample_begin = 4;
  s.settings.sample_end = 8;
  const auto b = render(s);
  const std::string e = input_error([&] { merge_shards({a, b}, {"a.exr", "b.exr"}); });
  EXPECT_EQ(e.rfind("b.exr: seed differs from a.exr", 0), 0u) << e;
  const std::string o = input_error([&] { merge_shards({a, a}, {"a.exr", "c.exr"}); });
  EXPECT_EQ(o.rfind("c.exr: samples 0:4 overlap samples 0:4 of a.exr", 0), 0u) << o;
}

TEST(MergeTolerance, MergedOptionsKeepTheUnionAsTarget) {
  Scene s = chromatic_scene(4);
  auto a = render(s);
  s.settings.sample_begin = 4;
  s.settings.sample_end = 8;
  auto b = render(s);
  a.info.render_options = "{\"width\":12,\"samples\":\"0:4\"}";
  b.info.render_options = "{\"width\":12,\"samples\":\"4:8\"}";
  EXPECT_EQ(merge_shards({a, b}).info.render_options, "{\"samples\":\"0:8\",\"width\":12}");
  b.info.render_options = "{\"width\":13,\"samples\":\"4:8\"}";
  EXPECT_EQ(merge_shards({a, b}).info.render_options, "");
}

}  // namespace
}  // namespace prizma::render
