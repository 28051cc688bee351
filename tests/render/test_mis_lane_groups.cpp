// Spectral MIS's lane groups (RenderSettings::mis_lane_groups, docs/renderer.md "Lane groups"): the
// bins in G runs of neighbouring bins, a sample one path per run. The map's runs and heroes, the
// auto rule (resolve_mis_lane_groups) on Rayleigh extinction and its limits, and what a render with
// groups writes. The closed forms under groups are in test_spectral_mis.cpp (kGroupings).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "prizma/render/render.h"
#include "prizma/render/resume.h"
#include "prizma/render/scene.h"
#include "prizma/render/wavelength_map.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;
using testing::box_scene;
using testing::make_material;

TEST(MisLaneGroups, RunsTileTheBinsAndEachTakesItsHeroesInTurn) {
  for (const int n : {6, 12, 32, 33}) {
    const spectral::BinLayout bins = spectral::BinLayout::linear(400, 700, n);
    for (const int g : {2, 3, 4, 5}) {
      const WavelengthMap map(LaneMode::AllBins, bins, true, g);
      ASSERT_EQ(map.groups(), g);
      EXPECT_EQ(map.group_begin(0), 0);
      EXPECT_EQ(map.group_begin(g), n);
      for (int k = 0; k < g; ++k) {
        EXPECT_GE(map.group_size(k), n / g) << n << " bins, " << g << " groups, run " << k;
        EXPECT_LE(map.group_size(k), n / g + 1) << n << " bins, " << g << " groups, run " << k;
        std::vector<float> lambda(static_cast<std::size_t>(n), 0.0f);
        for (const std::int64_t start : {0, 7}) {
          std::set<int> heroes;
          for (std::int64_t s = start; s < start + map.group_size(k); ++s) {
            Rng rng(5, 11, static_cast<std::uint64_t>(s));
            const WavelengthDraw d = map.draw(rng, lambda.data(), {.seed = 5, .pixel = 11, .sample = s}, k);
            ASSERT_EQ(d.first, map.group_begin(k));
            ASSERT_EQ(d.lanes, map.group_size(k));
            ASSERT_GE(d.hero, 0);
            ASSERT_LT(d.hero, d.lanes);
            heroes.insert(d.first + d.hero);
            for (int i = 0; i < d.lanes; ++i) {  // the run's own wavelengths, lane 0 at its first bin
              EXPECT_GE(lambda[i], bins.lo_nm(d.first + i) - 1e-3);
              EXPECT_LE(lambda[i], bins.hi_nm(d.first + i) + 1e-3);
            }
            // to_bins writes the run's bins and nothing else.
            std::vector<float> lanes(static_cast<std::size_t>(d.lanes));
            for (int i = 0; i < d.lanes; ++i) lanes[i] = static_cast<float>(i + 1);
            std::vector<double> out(static_cast<std::size_t>(n), -7.0);
            map.to_bins(lanes.data(), d, out.data());
            const auto [b0, b1] = map.bin_range(d);
            EXPECT_EQ(b0, d.first);
            EXPECT_EQ(b1, d.first + d.lanes);
            for (int b = 0; b < n; ++b)
              EXPECT_EQ(out[b], b >= b0 && b < b1 ? b - b0 + 1.0 : -7.0) << "bin " << b;
          }
          EXPECT_EQ(static_cast<int>(heroes.size()), map.group_size(k)) << n << " bins, " << g << " groups, run " << k;
          EXPECT_EQ(*heroes.begin(), map.group_begin(k));
        }
      }
    }
  }
  // One group is every bin on one path; without a hero (spectral tracking) there are no groups.
  const spectral::BinLayout bins = spectral::BinLayout::linear(400, 700, 12);
  const WavelengthMap one(LaneMode::AllBins, bins, true, 1), tracking(LaneMode::AllBins, bins, false, 4);
  EXPECT_EQ(tracking.groups(), 1);
  EXPECT_EQ(WavelengthMap(LaneMode::AllBins, bins, true, 40).groups(), 12);  // clamped to the bins
  std::vector<float> lambda(12);
  Rng rng(1, 2, 3);
  const WavelengthDraw d = one.draw(rng, lambda.data(), {.seed = 1, .pixel = 2, .sample = 3});
  EXPECT_EQ(d.first, 0);
  EXPECT_EQ(d.lanes, 12);
  EXPECT_EQ(d.hero, one.hero_lane(1, 2, 3));
}

// A box of one material with σt ∝ (550/λ)⁴ (Rayleigh; tabulated every 5 nm over 360–830 nm), n bins
// over 400–700 nm.
Scene rayleigh_box(int n) {
  std::vector<double> l, y;
  for (double x = 360.0; x <= 830.0; x += 5.0) {
    l.push_back(x);
    y.push_back(8.0 * std::pow(550.0 / x, 4.0));
  }
  Scene s = box_scene(make_material(Spectrum::constant(0.95), Spectrum(l, y), Spectrum::constant(0.0)));
  s.settings.bins = spectral::BinLayout::linear(400, 700, n);
  return s;
}

// rayleigh_box with the lane groups' auto rule (the default).
int auto_groups(Scene s) {
  s.settings.mis_lane_groups = 0;
  return resolve_mis_lane_groups(s);
}

TEST(MisLaneGroups, AutoRuleKeepsEachRunsExtinctionWithinTwoAndAHalfAndRunsOfThreeBins) {
  EXPECT_EQ(resolve_mis_lane_groups(rayleigh_box(32)), auto_groups(rayleigh_box(32)));  // auto is the default
  // 32 bins of Rayleigh air (9.4× over 400–700 nm): three runs of 10–11 bins hold the bin averages
  // within (489.1/404.7)⁴ = 2.13×, two runs of 16 not ((545.3/404.7)⁴ = 3.30×): 3 groups (bench_peer).
  EXPECT_EQ(auto_groups(rayleigh_box(32)), 3);
  // 12 bins (the cube's layout): runs of 4 within (487.5/412.5)⁴ = 1.95×, of 6 not (2.89×): 3.
  EXPECT_EQ(auto_groups(rayleigh_box(12)), 3);
  // 30 bins over 380–780 nm (λ⁻⁴: 17.7×): three runs of 10 reach (506.7/386.7)⁴ = 2.95×, four of
  // 7–8 bins (466.7/386.7)⁴ = 2.12× at most: 4.
  Scene wide = rayleigh_box(30);
  wide.settings.bins = spectral::BinLayout::linear(380, 780, 30);
  EXPECT_EQ(auto_groups(wide), 4);
  // The rule's floor: never runs of fewer than 3 bins (4 bins: one group).
  EXPECT_EQ(auto_groups(rayleigh_box(4)), 1);
  // An extinction that drops to 0 in some bins cannot be held within any ratio by a run across
  // the edge: the most groups the floor allows.
  Scene edge = box_scene(make_material(Spectrum::constant(0.5), Spectrum({400.0, 549.0, 551.0, 700.0}, {0.0, 0.0, 2.0, 2.0}),
                                       Spectrum::constant(0.0)));
  edge.settings.bins = spectral::BinLayout::linear(400, 700, 32);
  edge.settings.wavelength_sampling = WavelengthSampling::SpectralMis;
  EXPECT_EQ(auto_groups(edge), 10);
  // A count given is kept (clamped to the bins); spectral tracking and grey media have none.
  Scene s = rayleigh_box(32);
  s.settings.mis_lane_groups = 1;
  EXPECT_EQ(resolve_mis_lane_groups(s), 1);
  s.settings.mis_lane_groups = 7;
  EXPECT_EQ(resolve_mis_lane_groups(s), 7);
  s.settings.mis_lane_groups = 100;
  EXPECT_EQ(resolve_mis_lane_groups(s), 32);
  s.settings.wavelength_sampling = WavelengthSampling::SpectralTracking;
  EXPECT_EQ(resolve_mis_lane_groups(s), 1);
  Scene grey = box_scene(make_material(Spectrum::constant(0.9), Spectrum::constant(2.0), Spectrum::constant(0.0)));
  EXPECT_EQ(auto_groups(grey), 1);
}

TEST(MisLaneGroups, ARenderTracesOnePathPerGroupAndEveryBinGetsItsShare) {
  // 12 bins in 3 groups: 3 paths per sample; every bin of every pixel is written (none left at 0
  // by a group that did not run), and the same render with one group differs (other paths).
  Scene s = rayleigh_box(12);
  s.lights.push_back(testing::directional_light("sun", {0.3, 1.0, 0.2}));
  s.settings.wavelength_sampling = WavelengthSampling::SpectralMis;
  s.settings.sample_end = 8;
  s.settings.write_variance = true;
  RenderStats grouped_stats, one_stats;
  s.settings.mis_lane_groups = 3;
  const auto grouped = render(s, {}, &grouped_stats);
  s.settings.mis_lane_groups = 1;
  const auto one = render(s, {}, &one_stats);
  EXPECT_EQ(grouped_stats.paths, 3 * one_stats.paths);
  const std::size_t nb = 12;
  for (std::size_t l = 0; l < grouped.lights.size(); ++l)
    for (std::size_t p = 0; p < grouped.pixel_count(); ++p)
      for (std::size_t b = 0; b < nb; ++b) {
        const float v = grouped.lights[l].data[p * nb + b];
        ASSERT_TRUE(std::isfinite(v));
        if (l == 0) {
          EXPECT_GT(v, 0.0f) << "environment, pixel " << p << " bin " << b;  // every path sees some sky
        }
      }
  EXPECT_FALSE(testing::same_bits(grouped, one));
}

// A file records the groups its samples were traced with (prizma:misLaneGroups), and --resume and
// merge keep to them whatever `auto` resolves to in this build: a file of spectral MIS without the
// attribute (written before lane groups) continues with one path for all bins, the samples a
// one-group render takes, bit for bit; shards of different groups are refused (such a file counts
// as one group).
TEST(MisLaneGroups, FilesRecordTheirGroupsAndResumeAndMergeKeepThem) {
  const testing::ScratchDir dir;
  // tests/e2e/render/tiny.json's medium: Gaussian extinction over 6 bins, 2 groups under auto.
  const auto scene_path = dir.write("tiny.json", R"({
    "volume": {"type": "procedural", "name": "cube_sphere", "resolution": 16},
    "materials": [
      {"name": "haze", "range": [50, 150], "albedo": 0.9, "extinction": {"spectrum": "gaussian:450:200", "scale": 3}},
      {"name": "core", "range": [200, 255], "albedo": 0.5, "extinction": 10}
    ],
    "camera": {"type": "orthographic", "position": [0, 0, 2], "look_at": [0, 0, 0], "up": [0, 1, 0],
               "ortho_height": 1.2, "width": 6, "height": 6},
    "lights": [{"name": "side", "direction": [1, 0, 0]}, {"name": "sky", "direction": [0, 0, 0]}],
    "bins": "linear:400:700:6", "samples": 4, "seed": 3, "output": "tiny.exr"
  })");
  Scene scene = load_scene(scene_path);
  ASSERT_EQ(resolve_wavelength_sampling(scene), WavelengthSampling::SpectralMis);
  ASSERT_EQ(resolve_mis_lane_groups(scene), 2);
  scene.settings.sample_end = 2;
  spectral::SpectralImage part = render(scene);
  EXPECT_EQ(part.info.mis_lane_groups, 2);
  auto resumed_groups = [&](int recorded, const char* name) {
    part.info.mis_lane_groups = recorded;
    const auto file = dir.path() / name;
    spectral::write_spectral_exr(file, part);
    EXPECT_EQ(spectral::read_spectral_exr(file).info.mis_lane_groups, recorded);
    const ResumePlan plan = plan_resume(ResumeRequest{file, scene_path, {}, 4, true});
    EXPECT_EQ(plan.scene.settings.sample_begin, 2);
    return plan;
  };
  EXPECT_EQ(resumed_groups(2, "part.exr").scene.settings.mis_lane_groups, 2);
  const ResumePlan old = resumed_groups(0, "before-groups.exr");
  EXPECT_EQ(old.scene.settings.mis_lane_groups, 1);
  // The samples it adds are a one-group render's.
  Scene one = load_scene(scene_path);
  one.settings.mis_lane_groups = 1;
  one.settings.sample_begin = 2;
  one.settings.sample_end = 4;
  const auto added = render(old.scene);
  EXPECT_EQ(added.info.mis_lane_groups, 1);
  EXPECT_TRUE(testing::same_bits(added, render(one)));
  // Shards of different groups are not merged; a file without the attribute is one group.
  part.info.mis_lane_groups = 0;
  EXPECT_EQ(merge_shards({part, added}).info.sample_range, "0:4");
  part.info.mis_lane_groups = 2;
  try {
    merge_shards({part, added});
    ADD_FAILURE() << "shards of 2 and 1 lane groups merged";
  } catch (const spectral::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lane groups"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace prizma::render
