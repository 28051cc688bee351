// The guide layers of --features (docs/spectral-exr.md, "Guide layers"): light-independent, the
// same bits whatever the thread count, a render without them unchanged, merged like variance.
#include <gtest/gtest.h>

#include "prizma/render/render.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

using testing::chromatic_scene;

const spectral::GuideLayer& guide(const spectral::SpectralImage& img, const std::string& name) {
  for (const auto& g : img.guides)
    if (g.name == name) return g;
  throw std::runtime_error("no guide " + name);
}

TEST(RenderGuides, DepthAndScatterFractionAreWrittenAndBounded) {
  Scene s = chromatic_scene(16);
  s.settings.write_guides = true;
  const spectral::SpectralImage img = render(s);
  ASSERT_EQ(img.guides.size(), 2u);
  const auto& depth = guide(img, "depth");
  const auto& scatter = guide(img, "scatter");
  ASSERT_EQ(depth.value.size(), img.pixel_count());
  ASSERT_EQ(scatter.variance.size(), img.pixel_count());
  bool some_scatter = false, some_miss = false;
  for (std::size_t p = 0; p < img.pixel_count(); ++p) {
    EXPECT_GE(depth.value[p], 0.0f);
    EXPECT_LE(depth.value[p], 1.0f);
    EXPECT_GE(scatter.value[p], 0.0f);
    EXPECT_LE(scatter.value[p], 1.0f);
    // A pixel whose paths never scatter has depth 1 exactly and no variance.
    if (scatter.value[p] == 0.0f) {
      EXPECT_EQ(depth.value[p], 1.0f);
    }
    some_scatter = some_scatter || scatter.value[p] > 0.0f;
    some_miss = some_miss || scatter.value[p] < 1.0f;
    // The fraction's variance of the mean is the binomial one, f(1 − f)/(n − 1) (the sample variance / n).
    const double f = scatter.value[p], n = static_cast<double>(img.info.samples);
    EXPECT_NEAR(scatter.variance[p], f * (1.0 - f) / (n - 1.0), 1e-6);
  }
  EXPECT_TRUE(some_scatter);
  EXPECT_TRUE(some_miss);
}

TEST(RenderGuides, LightIndependentThreadIndependentAndNothingElseChanges) {
  Scene s = chromatic_scene(8);
  s.settings.write_variance = true;
  const spectral::SpectralImage plain = render(s);
  s.settings.write_guides = true;
  s.settings.threads = 1;
  const spectral::SpectralImage one = render(s);
  s.settings.threads = 2;
  const spectral::SpectralImage two = render(s);
  EXPECT_EQ(one.guides, two.guides);
  EXPECT_TRUE(plain.guides.empty());
  for (std::size_t l = 0; l < plain.lights.size(); ++l) {  // the transport is the same bits
    EXPECT_EQ(one.lights[l].data, plain.lights[l].data);
    EXPECT_EQ(one.lights[l].variance, plain.lights[l].variance);
  }
  // Other light spectra and directions change the transport, never the guides.
  Scene relit = s;
  for (auto& light : relit.lights) light.direction = -light.direction;
  const spectral::SpectralImage other = render(relit);
  EXPECT_EQ(other.guides, one.guides);
  EXPECT_NE(other.lights.front().data, one.lights.front().data);
}

// The guides are recorded in the tracer's one loop, which spectral MIS shares with spectral tracking
// and single-wavelength tracing: every mode writes them, bounded, and none changes a transport bit.
TEST(RenderGuides, EveryWavelengthSamplingModeWritesThemAndKeepsTheTransport) {
  for (const WavelengthSampling mode :
       {WavelengthSampling::SpectralTracking, WavelengthSampling::SpectralMis, WavelengthSampling::Single}) {
    SCOPED_TRACE(static_cast<int>(mode));
    Scene s = chromatic_scene(8);
    s.settings.wavelength_sampling = mode;
    s.settings.write_variance = true;
    const spectral::SpectralImage plain = render(s);
    s.settings.write_guides = true;
    const spectral::SpectralImage with = render(s);
    ASSERT_EQ(with.guides.size(), 2u);
    for (std::size_t l = 0; l < plain.lights.size(); ++l) {
      EXPECT_EQ(with.lights[l].data, plain.lights[l].data);
      EXPECT_EQ(with.lights[l].variance, plain.lights[l].variance);
    }
    const auto& depth = guide(with, "depth");
    const auto& scatter = guide(with, "scatter");
    bool some_scatter = false;
    for (std::size_t p = 0; p < with.pixel_count(); ++p) {
      EXPECT_GE(depth.value[p], 0.0f);
      EXPECT_LE(depth.value[p], 1.0f);
      EXPECT_GE(scatter.value[p], 0.0f);
      EXPECT_LE(scatter.value[p], 1.0f);
      some_scatter = some_scatter || (scatter.value[p] > 0.0f && depth.value[p] < 1.0f);
    }
    EXPECT_TRUE(some_scatter);
  }
}

TEST(RenderGuides, ShardsMergeToTheFullRender) {
  Scene s = chromatic_scene(16);
  s.settings.write_guides = true;
  const auto full = render(s);
  s.settings.sample_end = 6;
  const auto a = render(s);
  s.settings.sample_begin = 6;
  s.settings.sample_end = 16;
  const auto b = render(s);
  const auto merged = merge_shards({a, b});
  ASSERT_EQ(merged.guides.size(), full.guides.size());
  for (std::size_t g = 0; g < full.guides.size(); ++g)
    for (std::size_t p = 0; p < full.pixel_count(); ++p) {
      EXPECT_NEAR(merged.guides[g].value[p], full.guides[g].value[p], 1e-6);
      EXPECT_NEAR(merged.guides[g].variance[p], full.guides[g].variance[p], 1e-3 * full.guides[g].variance[p] + 1e-9);
    }
  // A shard without guides: the merge leaves them out.
  s.settings.write_guides = false;
  s.settings.sample_begin = 16;
  s.settings.sample_end = 20;
  EXPECT_TRUE(merge_shards({a, b, render(s)}).guides.empty());
}

}  // namespace
}  // namespace prizma::render
