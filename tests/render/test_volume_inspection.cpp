// prizma-render inspect's numbers (issue 25 item 9): the statistics of a volume whose values are
// known, counted exactly: range, exact zeros, non-finite voxels, the histogram of the values ≠ 0,
// and the voxels each material's range takes with the renderer's first-match rule.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "prizma/render/volume_inspection.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

InspectedVolume ramp() {
  // 10 voxels: 0, 0, 1 … 7, NaN.
  InspectedVolume in;
  in.volume.dims = {10, 1, 1};
  in.volume.values = {0, 0, 1, 2, 3, 4, 5, 6, 7, std::numeric_limits<float>::quiet_NaN()};
  in.volume.source = "ramp";
  in.from_scene = true;
  in.normalisation = {0.0, 7.0};
  in.transfer.materials.resize(2);
  in.transfer.materials[0].name = "low";
  in.transfer.materials[1].name = "high";
  MaterialRule low, high;
  low.value_lo = 1.0;
  low.value_hi = 4.0;
  low.material = 0;
  high.value_lo = 4.0;  // 4 is low's too: first match wins
  high.value_hi = 6.0;
  high.material = 1;
  in.transfer.rules = {low, high};
  return in;
}

TEST(VolumeInspection, CountsValuesZerosHistogramAndMaterialsExactly) {
  const InspectedVolume in = ramp();
  const VolumeStatistics st = volume_statistics(in, 7);
  EXPECT_EQ(st.voxels, 10u);
  EXPECT_EQ(st.non_finite, 1u);
  EXPECT_EQ(st.zeros, 2u);
  EXPECT_EQ(st.min, 0.0);
  EXPECT_EQ(st.max, 7.0);
  EXPECT_DOUBLE_EQ(st.mean, 28.0 / 9.0);
  // Values 1 … 7 over [1, 7] in 7 bins of width 6/7: value v in bin ⌊(v − 1)·7/6⌋ (1→0, 2→1, 3→2,
  // 4→3, 5→4, 6→5), 7 in the last, closed bin.
  EXPECT_EQ(st.histogram_lo, 1.0);
  EXPECT_EQ(st.histogram_hi, 7.0);
  EXPECT_EQ(st.counts, (std::vector<std::uint64_t>{1, 1, 1, 1, 1, 1, 1}));
  EXPECT_EQ(volume_statistics(in, 2).counts, (std::vector<std::uint64_t>{3, 4}));  // [1, 4), [4, 7]
  // low takes 1, 2, 3, 4; high 5, 6 (4 went to low); 0, 0, 7 and NaN are empty space.
  EXPECT_EQ(st.rule_voxels, (std::vector<std::uint64_t>{4, 2}));
  EXPECT_EQ(st.unassigned, 4u);
  const std::string report = inspection_report(in, st);
  EXPECT_NE(report.find("low   [1, 4] (normalised [0.142857, 0.571429]): 4 voxels (40.0 %)"), std::string::npos) << report;
  EXPECT_NE(report.find("high  [4, 6] (normalised [0.571429, 0.857143]): 2 voxels (20.0 %)"), std::string::npos) << report;
  EXPECT_NE(report.find("no material: 4 voxels (40.0 %)"), std::string::npos) << report;
  EXPECT_NE(report.find("2 exactly 0 (20.0 %), 1 not finite"), std::string::npos) << report;
}

TEST(VolumeInspection, AVolumeFileNeedsAKnownExtension) {
  const testing::ScratchDir dir;
  const auto p = dir.write("notes.txt", "x");
  try {
    load_for_inspection(p);
    FAIL() << "no error";
  } catch (const spectral::InputError& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ": not a scene or volume file this can inspect (known: .json, "
                                                  ".nii, .nii.gz, .raw, .vdb)");
  }
}

}  // namespace
}  // namespace prizma::render
