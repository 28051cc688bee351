// Determinism and sample bookkeeping of render(): thread count, shards and merge, interruption,
// adaptive stopping.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>

#include "prizma/render/render.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;

using testing::chromatic_scene;
using testing::same_bits;

TEST(RenderDeterminism, ThreadCountDoesNotChangeABit) {
  Scene s = chromatic_scene(16);
  s.settings.threads = 1;
  const auto one = render(s);
  s.settings.threads = 2;
  const auto two = render(s);
  s.settings.threads = 0;
  RenderCallbacks cb;
  cb.samples_per_pass = 3;  // different pass blocking too
  const auto all = render(s, cb);
  EXPECT_TRUE(same_bits(one, two));
  EXPECT_TRUE(same_bits(one, all));
  s.settings.seed = 8;
  EXPECT_FALSE(same_bits(one, render(s)));  // the comparison can fail
}

TEST(RenderDeterminism, ShardsMergeToTheFullRender) {
  Scene s = chromatic_scene(16);
  const auto full = render(s);
  s.settings.sample_begin = 0;
  s.settings.sample_end = 8;
  const auto a = render(s);
  s.settings.sample_begin = 8;
  s.settings.sample_end = 16;
  const auto b = render(s);
  EXPECT_EQ(b.info.sample_range, "8:16");
  const auto merged = merge_shards({b, a});
  EXPECT_EQ(merged.info.samples, 16);
  EXPECT_EQ(merged.info.sample_range, "0:16");
  for (std::size_t l = 0; l < full.lights.size(); ++l)
    for (std::size_t k = 0; k < full.lights[l].data.size(); ++k) {
      const double f = full.lights[l].data[k];
      ASSERT_NEAR(merged.lights[l].data[k], f, 1e-6 * std::abs(f) + 1e-9);
      // Variance of the mean rebuilt from the shards' sums: float rounding of the inputs only.
      const double v = full.lights[l].variance[k];
      ASSERT_NEAR(merged.lights[l].variance[k], v, 1e-3 * v + 1e-9);
    }
}

TEST(RenderDeterminism, MergeRefusesMismatchedShards) {
  Scene s = chromatic_scene(4);
  const auto a = render(s);
  EXPECT_THROW(merge_shards({a, a}), spectral::InputError);  // overlapping ranges
  EXPECT_THROW(merge_shards({}), spectral::InputError);
  s.settings.sample_begin = 4;
  s.settings.sample_end = 8;
  auto b = render(s);
  EXPECT_NO_THROW(merge_shards({a, b}));
  auto c = b;
  c.info.scene_hash = "other";
  EXPECT_THROW(merge_shards({a, c}), spectral::InputError);
  c = b;
  c.info.seed = 99;
  EXPECT_THROW(merge_shards({a, c}), spectral::InputError);
  c = b;
  c.lights[1].name = "moon";
  EXPECT_THROW(merge_shards({a, c}), spectral::InputError);
  s.settings.bins = spectral::BinLayout::linear(400, 700, 5);
  EXPECT_THROW(merge_shards({a, render(s)}), spectral::InputError);
  s = chromatic_scene(4);
  s.camera.width = 10;
  s.settings.sample_begin = 4;
  s.settings.sample_end = 8;
  EXPECT_THROW(merge_shards({a, render(s)}), spectral::InputError);
}

TEST(RenderDeterminism, CancelKeepsCompletedPasses) {
  Scene s = chromatic_scene(16);
  std::atomic<bool> cancel{false};
  RenderCallbacks cb;
  cb.samples_per_pass = 4;
  cb.cancel = &cancel;
  int calls = 0;
  cb.progress = [&](const RenderProgress& p) {
    ++calls;
    EXPECT_EQ(p.samples_total, 16);
    if (p.samples_done >= 8) cancel = true;
  };
  RenderStats stats;
  const auto partial = render(s, cb, &stats);
  EXPECT_TRUE(stats.interrupted);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(partial.info.samples, 8);
  EXPECT_EQ(partial.info.sample_range, "0:8");
  s.settings.sample_end = 8;
  EXPECT_TRUE(same_bits(partial, render(s)));
}

TEST(RenderDeterminism, TargetErrorStopsConvergedPixels) {
  // A camera wider than the box: rays that miss see exactly 1 with zero variance and stop after the
  // minimum count; the result still does not depend on threads.
  Scene s = chromatic_scene(64);
  s.camera.ortho_height = 2.0;
  s.settings.target_error = 1e-3;
  s.settings.threads = 1;
  RenderStats stats;
  const auto one = render(s, {}, &stats);
  EXPECT_GT(stats.pixels_converged, 0);
  EXPECT_LT(stats.paths, 12 * 12 * 64);
  s.settings.threads = 2;
  EXPECT_TRUE(same_bits(one, render(s)));
}

TEST(RenderDeterminism, InfoRecordsProvenance) {
  Scene s = chromatic_scene(4);
  s.settings.seed = 42;
  const auto img = render(s);
  EXPECT_EQ(img.info.samples, 4);
  EXPECT_EQ(img.info.sample_range, "0:4");
  EXPECT_EQ(img.info.seed, 42);
  EXPECT_EQ(img.info.scene_hash, "test");
  EXPECT_EQ(img.info.wavelength_sampling, "spectral-mis");  // auto, resolved: the estimator that ran
  EXPECT_FALSE(img.info.version.empty());
  ASSERT_EQ(img.lights.size(), 2u);
  EXPECT_EQ(img.lights[0].name, "env");
  EXPECT_EQ(img.lights[1].name, "sun");
  const auto lights = lights_from_image(img);
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[1].direction, Eigen::Vector3d(0.5, 1, 0.2));
  EXPECT_EQ(lights[0].spectrum_spec, "E");
}

TEST(RenderDeterminism, RejectsEmptySampleRangeAndNoLights) {
  Scene s = chromatic_scene(4);
  s.settings.sample_end = 0;
  EXPECT_THROW(render(s), spectral::InputError);
  s = chromatic_scene(4);
  s.lights.clear();
  EXPECT_THROW(render(s), spectral::InputError);
}

// The Sobol' sampler (rng.h): its points depend on (seed, pixel, sample) only.
TEST(RenderDeterminism, SobolSamplerIsThreadAndShardInvariant) {
  Scene s = chromatic_scene(16);
  s.settings.sampler = Sampler::Sobol;
  s.settings.threads = 1;
  const auto one = render(s);
  s.settings.threads = 2;
  const auto two = render(s);
  RenderCallbacks cb;
  cb.samples_per_pass = 3;
  EXPECT_TRUE(same_bits(one, two));
  EXPECT_TRUE(same_bits(one, render(s, cb)));
  Scene independent = s;
  independent.settings.sampler = Sampler::Independent;
  EXPECT_FALSE(same_bits(one, render(independent)));  // the sampler is in use

  s.settings.sample_end = 5;  // shards not aligned to a power of two
  const auto a = render(s);
  s.settings.sample_begin = 5;
  s.settings.sample_end = 16;
  const auto b = render(s);
  const auto merged = merge_shards({b, a});
  EXPECT_EQ(merged.info.sample_range, "0:16");
  for (std::size_t l = 0; l < one.lights.size(); ++l)
    for (std::size_t k = 0; k < one.lights[l].data.size(); ++k) {
      const double f = one.lights[l].data[k];
      ASSERT_NEAR(merged.lights[l].data[k], f, 1e-6 * std::abs(f) + 1e-9);
    }
}

}  // namespace
}  // namespace prizma::render
