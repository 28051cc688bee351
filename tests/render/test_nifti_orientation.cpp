// NIfTI orientation (issue 13 part 6): small files written with libnifti with a known sform or qform;
// the loader reorders the voxels to +x→R, +y→A, +z→S, prefers the sform, says what it did, and a
// flipped axis moves a bright (here: absorbing) voxel to the mirrored pixel of a render.
#include <gtest/gtest.h>
#include <nifti1_io.h>

#include <cmath>
#include <numbers>

#include "prizma/render/render.h"
#include "prizma/render/volume.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using testing::ScratchDir;

struct Xform {
  int code = 0;
  mat44 m{};  // sform: index → world (RAS, mm)
};

mat44 affine(std::array<std::array<float, 4>, 3> rows) {
  mat44 m{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m.m[r][c] = rows[r][c];
  m.m[3][3] = 1.0f;
  return m;
}

// Voxel i (file order, x fastest) holds value_of(i); uint8; pixdim `spacing`.
void write_oriented(const std::filesystem::path& path, std::array<int, 3> dims, std::array<float, 3> spacing,
                    const Xform& sform, int qform_code, std::array<float, 4> quatern_bcd_qfac,
                    const std::vector<std::uint8_t>& values) {
  int d[8] = {3, dims[0], dims[1], dims[2], 1, 1, 1, 1};
  nifti_image* nim = nifti_make_new_nim(d, DT_UINT8, 1);
  ASSERT_NE(nim, nullptr);
  nim->dx = nim->pixdim[1] = spacing[0];
  nim->dy = nim->pixdim[2] = spacing[1];
  nim->dz = nim->pixdim[3] = spacing[2];
  nim->sform_code = sform.code;
  nim->sto_xyz = sform.m;
  nim->qform_code = qform_code;
  nim->quatern_b = quatern_bcd_qfac[0];
  nim->quatern_c = quatern_bcd_qfac[1];
  nim->quatern_d = quatern_bcd_qfac[2];
  nim->qfac = quatern_bcd_qfac[3];
  ASSERT_EQ(nifti_set_filenames(nim, path.c_str(), 0, 1), 0);
  ASSERT_EQ(values.size(), nim->nvox);
  std::copy(values.begin(), values.end(), static_cast<std::uint8_t*>(nim->data));
  nifti_image_write(nim);
  nifti_image_free(nim);
}

std::vector<std::uint8_t> index_values(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(i + 1);
  return v;
}

TEST(NiftiOrientation, SformFlippedXMirrorsTheVoxels) {
  ScratchDir dir;
  const std::array<int, 3> dims{4, 3, 2};
  // srow_x = [−1 0 0 …]: file +i points to the patient's Left.
  write_oriented(dir / "las.nii", dims, {1, 1, 1}, {1, affine({{{-1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}})}, 0,
                 {0, 0, 0, 1}, index_values(24));
  const Volume vol = load_nifti_volume(dir / "las.nii");
  EXPECT_EQ(vol.dims, dims);
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) EXPECT_EQ(vol.at(x, y, z), static_cast<float>((z * 3 + y) * 4 + (3 - x) + 1));
  EXPECT_NE(vol.orientation.find("(sform)"), std::string::npos) << vol.orientation;
  EXPECT_NE(vol.orientation.find("+i→L +j→A +k→S"), std::string::npos) << vol.orientation;
  EXPECT_NE(vol.orientation.find("+x→R +y→A +z→S"), std::string::npos) << vol.orientation;
}

TEST(NiftiOrientation, SformPermutationReordersAxesAndSpacing) {
  // A sagittal acquisition: file i → Superior, j → Right, k → Anterior (spacing 2, 0.5, 1).
  ScratchDir dir;
  write_oriented(dir / "sag.nii", {2, 3, 4}, {2.0f, 0.5f, 1.0f},
                 {1, affine({{{0, 0.5f, 0, 0}, {0, 0, 1, 0}, {2, 0, 0, 0}}})}, 0, {0, 0, 0, 1}, index_values(24));
  const Volume vol = load_nifti_volume(dir / "sag.nii");
  EXPECT_EQ(vol.dims, (std::array<int, 3>{3, 4, 2}));
  EXPECT_EQ(vol.spacing, (std::array<double, 3>{0.5, 1.0, 2.0}));
  for (int z = 0; z < 2; ++z)       // S ← i
    for (int y = 0; y < 4; ++y)     // A ← k
      for (int x = 0; x < 3; ++x)   // R ← j
        EXPECT_EQ(vol.at(x, y, z), static_cast<float>((y * 3 + x) * 2 + z + 1)) << x << " " << y << " " << z;
  EXPECT_NE(vol.orientation.find("+i→S +j→R +k→A"), std::string::npos) << vol.orientation;
}

TEST(NiftiOrientation, QformWhenNoSformAndSformPreferred) {
  // Quaternion (b, c, d) = (0, 0, 1): 180° about z, so +i → L and +j → P.
  ScratchDir dir;
  write_oriented(dir / "q.nii", {2, 2, 1}, {1, 1, 1}, {}, 1, {0, 0, 1, 1}, index_values(4));
  const Volume q = load_nifti_volume(dir / "q.nii");
  EXPECT_EQ(q.at(0, 0, 0), 4.0f);  // file voxel (1, 1)
  EXPECT_EQ(q.at(1, 1, 0), 1.0f);
  EXPECT_NE(q.orientation.find("(qform)"), std::string::npos) << q.orientation;
  EXPECT_NE(q.orientation.find("+i→L +j→P"), std::string::npos) << q.orientation;
  // Both present, disagreeing: the sform (identity here) wins.
  write_oriented(dir / "both.nii", {2, 2, 1}, {1, 1, 1}, {2, affine({{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}})}, 1,
                 {0, 0, 1, 1}, index_values(4));
  const Volume b = load_nifti_volume(dir / "both.nii");
  EXPECT_EQ(b.at(0, 0, 0), 1.0f);
  EXPECT_NE(b.orientation.find("(sform)"), std::string::npos) << b.orientation;
  EXPECT_NE(b.orientation.find("kept"), std::string::npos) << b.orientation;
  // Neither: file order, and the log says so.
  write_oriented(dir / "none.nii", {2, 2, 1}, {1, 1, 1}, {}, 0, {0, 0, 1, 1}, index_values(4));
  const Volume n = load_nifti_volume(dir / "none.nii");
  EXPECT_EQ(n.at(0, 0, 0), 1.0f);
  EXPECT_NE(n.orientation.find("none"), std::string::npos) << n.orientation;
}

// Renders a 4×1×1 volume whose file voxel 0 absorbs, by default seen from above (+z = S) with +x to
// the right: returns the index of the darkest of the 4 pixels.
int darkest_pixel(const ScratchDir& dir, const std::string& file, const std::string& position = "[0, 0, 2]",
                  const std::string& up = "[0, 1, 0]") {
  dir.write("s.json", R"({"volume": {"type": "nifti", "path": ")" + file + R"(", "interpolation": "nearest"},
    "materials": [{"range": [50, 1000], "albedo": 0, "extinction": 20}],
    "camera": {"type": "orthographic", "position": )" + position + R"(, "look_at": [0, 0, 0], "up": )" + up + R"(,
               "ortho_height": 0.25, "width": 4, "height": 1},
    "lights": [{"name": "env", "direction": [0, 0, 0]}], "bins": "linear:400:700:1", "samples": 16, "seed": 1})");
  const auto img = render(load_scene(dir / "s.json"));
  int best = 0;
  for (int px = 1; px < 4; ++px)
    if (img.lights[0].data[px] < img.lights[0].data[best]) best = px;
  EXPECT_LT(img.lights[0].data[best], 0.05f);  // e^{−20·0.25} ≈ 0.007
  return best;
}

TEST(NiftiOrientation, FlippedAxisMovesTheVoxelToTheMirroredPixel) {
  ScratchDir dir;
  const std::vector<std::uint8_t> values{200, 0, 0, 0};
  const mat44 ras = affine({{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}});
  const mat44 las = affine({{{-1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}});
  write_oriented(dir / "ras.nii", {4, 1, 1}, {1, 1, 1}, {1, ras}, 0, {0, 0, 0, 1}, values);
  write_oriented(dir / "las.nii", {4, 1, 1}, {1, 1, 1}, {1, las}, 0, {0, 0, 0, 1}, values);
  EXPECT_EQ(darkest_pixel(dir, "ras.nii"), 0);  // +i → R: voxel 0 has the least x, the left column
  EXPECT_EQ(darkest_pixel(dir, "las.nii"), 3);  // +i → L: voxel 0 is the right-most (largest x)
  const Scene s = load_scene(dir / "s.json");
  EXPECT_NE(s.volume_note.find("NIfTI orientation (sform)"), std::string::npos) << s.volume_note;
}

TEST(NiftiOrientation, SeenFromTheFrontThePatientsLeftIsOnTheImagesRight) {
  // docs/scene-format.md: a RAS file whose voxel 0 (the least x: the patient's left-most) absorbs.
  // The front of the patient is anterior, +y: a camera there looking toward −y with up +z (S) faces
  // the patient and sees the patient's left on the image's right, as when facing a person; from
  // behind (−y) it is on the left.
  ScratchDir dir;
  write_oriented(dir / "ras.nii", {4, 1, 1}, {1, 1, 1}, {1, affine({{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}})}, 0,
                 {0, 0, 0, 1}, {200, 0, 0, 0});
  EXPECT_EQ(darkest_pixel(dir, "ras.nii", "[0, 2, 0]", "[0, 0, 1]"), 3);
  EXPECT_EQ(darkest_pixel(dir, "ras.nii", "[0, -2, 0]", "[0, 0, 1]"), 0);
}

TEST(NiftiOrientation, AnObliqueFileIsSnappedWithAWarningEveryRender) {
  // An sform turned 10° about the superior axis: the axes snap to R, A, S and the volume's
  // warnings (printed by prizma-render without --verbose, returned by prizma.render) say by how much.
  ScratchDir dir;
  const float c = std::cos(10.0f * std::numbers::pi_v<float> / 180.0f), s = std::sin(10.0f * std::numbers::pi_v<float> / 180.0f);
  write_oriented(dir / "oblique.nii", {2, 2, 2}, {1, 1, 1}, {1, affine({{{c, -s, 0, 0}, {s, c, 0, 0}, {0, 0, 1, 0}}})}, 0,
                 {0, 0, 0, 1}, index_values(8));
  const Volume vol = load_nifti_volume(dir / "oblique.nii");
  ASSERT_EQ(vol.warnings.size(), 1u);
  EXPECT_EQ(vol.warnings[0], (dir / "oblique.nii").string() +
                                 ": NIfTI orientation: the sform is oblique (a file axis is 10.0° from the nearest "
                                 "anatomical axis); its axes were snapped to the nearest (file +i→R +j→A +k→S), not "
                                 "resampled, so the volume is rotated by up to 10.0° from the patient's frame");
  EXPECT_NE(vol.orientation.find("oblique axes snapped"), std::string::npos) << vol.orientation;
  write_oriented(dir / "straight.nii", {2, 2, 2}, {1, 1, 1}, {1, affine({{{-1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}})},
                 0, {0, 0, 0, 1}, index_values(8));
  EXPECT_TRUE(load_nifti_volume(dir / "straight.nii").warnings.empty());
}

}  // namespace
}  // namespace prizma::render
