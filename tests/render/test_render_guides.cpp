// The guide layers of --features (docs/spectral-exr.md, "Guide layers"): independent of the lights'
// spectra (and but for hit_light*, of their directions), the
// same bits whatever the thread count, a render without them unchanged, merged like variance; the
// first-hit layers (hit_guides.h) deterministic, and their closed form in a box of constant density.
#include <gtest/gtest.h>

#include <cmath>

#include "prizma/render/camera.h"
#include "prizma/render/hit_guides.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/render.h"
#include "prizma/spectral/guide_names.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

using testing::box_scene;
using testing::chromatic_scene;
using testing::directional_light;
using testing::grey_material;

const spectral::GuideLayer& guide(const spectral::SpectralImage& img, const std::string& name) {
  for (const auto& g : img.guides)
    if (g.name == name) return g;
  throw std::runtime_error("no guide " + name);
}

TEST(RenderGuides, DepthAndScatterFractionAreWrittenAndBounded) {
  Scene s = chromatic_scene(16);
  s.settings.write_guides = true;
  const spectral::SpectralImage img = render(s);
  ASSERT_EQ(img.guides.size(), 2u + hit_guide_names(s).size());
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
  // Other light directions change the transport, and of the guides only the first-hit transmittance
  // toward the directional lights (hit_light*; no light's spectrum enters any guide).
  Scene relit = s;
  for (auto& light : relit.lights) light.direction = -light.direction;
  const spectral::SpectralImage other = render(relit);
  ASSERT_EQ(other.guides.size(), one.guides.size());
  for (std::size_t k = 0; k < one.guides.size(); ++k) {
    SCOPED_TRACE(one.guides[k].name);
    if (one.guides[k].name.rfind("hit_light", 0) == 0)
      EXPECT_NE(other.guides[k].value, one.guides[k].value);
    else
      EXPECT_EQ(other.guides[k], one.guides[k]);
  }
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
    ASSERT_EQ(with.guides.size(), 2u + hit_guide_names(s).size());
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

// The first-hit layers are not Monte Carlo: the same bits at any samples, seed, thread count and
// sample range, and a merge of shards keeps them as they are.
TEST(RenderGuides, TheFirstHitLayersAreTheSameWhateverTheSamplesSeedThreadsAndShards) {
  Scene s = chromatic_scene(4);
  s.settings.write_guides = true;
  s.settings.threads = 1;
  const auto hits = [](const spectral::SpectralImage& img) {
    std::vector<spectral::GuideLayer> out;
    for (const auto& g : img.guides)
      if (spectral::exact_guide(g.name)) out.push_back(g);
    return out;
  };
  const auto base = hits(render(s));
  ASSERT_EQ(base.size(), 9u);  // depth, normal x/y/z, albedo, density, albedo x/z, the sun's transmittance
  for (std::size_t k = 0; k < base.size(); ++k) EXPECT_EQ(base[k].name, hit_guide_names(s)[k]);
  EXPECT_EQ(base.back().name, "hit_light1");  // lights[0] is the environment
  s.settings.sample_end = 16;
  s.settings.seed = 7;
  s.settings.threads = 2;
  const auto full = render(s);
  EXPECT_EQ(hits(full), base);
  s.settings.sample_begin = 16;
  s.settings.sample_end = 20;
  const auto more = render(s);
  EXPECT_EQ(hits(more), base);
  EXPECT_EQ(hits(merge_shards({full, more})), base);
  // The Monte Carlo guides do change with the seed (so the comparison above is not vacuous).
  EXPECT_NE(full.guides.front().value, more.guides.front().value);
  // The box's medium is hit: the depth is inside (0, 1) somewhere, and the pixels do not all agree.
  bool inside = false;
  for (float d : base[0].value) inside = inside || (d > 0.0f && d < 1.0f);
  EXPECT_TRUE(inside);
}

// A box of constant density seen straight down (box_scene: every ray enters through the top face
// z = 0.5 and crosses depth 1): optical depth 1 lies 1/σt below the face, so hit_depth = (1/σt)/√3
// (the unit box's diagonal); the normal is the top face's, +z; the albedo the material's, the
// density σt·√3, and the transmittance toward a sun straight above e^−1 (the same 1/σt back up). In the
// half x < 0 the medium is removed: those rays leave without a hit (depth 1, normal and
// albedo 0), and only the pixel columns at the boundary have a spread (a variance) between their
// sub-pixel rays.
TEST(RenderGuides, TheFirstHitInABoxOfConstantDensityIsAtOneOverSigmaT) {
  for (const double sigma_t : {4.0, 100.0}) {  // inside (gradient 0: facing the camera) and at the face
    SCOPED_TRACE(sigma_t);
    Scene s = box_scene(grey_material(0.8, sigma_t), 8, 15, 1);  // the middle column straddles x = 0
    s.lights.push_back(directional_light("sun", {0, 0, 1}));
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 4; ++x) s.medium.material[(static_cast<std::size_t>(z) * 8 + y) * 8 + x] = Medium::kEmpty;
    const CameraModel camera(s.camera);
    const PathTracer tracer(s, s.settings.bins.min_nm(), s.settings.bins.max_nm(), true);
    const auto g = hit_guides(s, camera, tracer);
    ASSERT_EQ(g.size(), 9u);
    EXPECT_EQ(g[8].name, "hit_light1");  // lights[0] is box_scene's environment
    const double depth = 1.0 / sigma_t / std::sqrt(3.0);
    for (int y = 0; y < 15; ++y)
      for (int x = 0; x < 15; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * 15 + x;
        const Eigen::Vector3d centre = camera.generate(x + 0.5, y + 0.5).origin;  // pixels 0.053 wide, sub-pixel rays ±0.013
        const double wx = centre.x(), wy = centre.y();
        SCOPED_TRACE(::testing::Message() << "pixel " << x << ", " << y << " at x " << wx);
        if (wx < -0.03) {  // every sub-pixel ray in the empty half
          EXPECT_EQ(g[0].value[p], 1.0f);
          for (int k = 1; k < 9; ++k) EXPECT_EQ(g[k].value[p], 0.0f);
          for (int k = 0; k < 9; ++k) EXPECT_EQ(g[k].variance[p], 0.0f);
        } else if (wx > 0.03) {
          EXPECT_NEAR(g[0].value[p], depth, 1e-6);
          EXPECT_NEAR(g[4].value[p], 0.8, 1e-6);
          EXPECT_NEAR(g[5].value[p], sigma_t * std::sqrt(3.0), 1e-4 * sigma_t);
          EXPECT_NEAR(g[6].value[p], 0.8, 1e-6);  // a grey albedo: x̄- and z̄-weighted alike
          EXPECT_NEAR(g[7].value[p], 0.8, 1e-6);
          EXPECT_NEAR(g[8].value[p], std::exp(-1.0), 1e-6);
          // More than a voxel (0.125) from the removed half and from the box's sides (x, y = ±0.5):
          // the top face's normal.
          if (wx > 0.125 + 0.03 && wx < 0.375 - 0.03 && std::abs(wy) < 0.375 - 0.03) {
            EXPECT_NEAR(g[1].value[p], 0.0, 1e-9);
            EXPECT_NEAR(g[2].value[p], 0.0, 1e-9);
            EXPECT_NEAR(g[3].value[p], 1.0, 1e-9);
            EXPECT_EQ(g[0].variance[p], 0.0f);
          }
        } else {  // the boundary column: half its sub-pixel rays hit
          EXPECT_NEAR(g[0].value[p], 0.5 * (1.0 + depth), 1e-6);
          EXPECT_GT(g[0].variance[p], 0.0f);
        }
      }
  }
}

}  // namespace
}  // namespace prizma::render
