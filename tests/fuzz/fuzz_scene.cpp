// libFuzzer target: load_scene on arbitrary text written to a temporary scene.json.
// The scene's folder also holds a tiny raw volume (tiny_2x2x2_uint8.raw), a tiny NIfTI (tiny.nii)
// and a CSV spectrum (f.csv) so that valid scenes reach the volume loaders and spectrum parser.
// Inputs whose JSON names a path with '/' or '\' are skipped (file access stays in the scratch
// folder), and so are procedural volumes above kMaxResolution voxels a side or without a
// resolution (legitimate but large allocations, not bugs). InputError is the expected answer to a bad scene; any other
// exception, a crash, undefined behaviour or a scene that breaks the Scene invariants is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "prizma/render/scene.h"

namespace {

constexpr std::size_t kMaxInputBytes = 16 * 1024;
constexpr double kMaxResolution = 64;

// True when the JSON names a path outside the scratch folder or asks for a costly volume.
bool skipped(const nlohmann::json& j, std::string_view key = {}) {
  if (j.is_string()) {
    const auto& s = j.get_ref<const std::string&>();
    return s.find('/') != std::string::npos || s.find('\\') != std::string::npos;
  }
  if (j.is_number()) {
    const double v = j.get<double>();
    return (key == "resolution" || key == "size" || key == "n") && !(v <= kMaxResolution);
  }
  if (j.is_object()) {
    // A procedural volume without a resolution gets the default 128³: slow under ASan.
    const auto type = j.find("type");
    if (type != j.end() && *type == "procedural" && !j.contains("resolution")) return true;
    for (const auto& item : j.items()) {
      if (skipped(item.value(), item.key())) return true;
    }
  }
  if (j.is_array()) {
    for (const auto& v : j) {
      if (skipped(v, key)) return true;
    }
  }
  return false;
}

void check_scene(const prizma::render::Scene& s) {
  const auto& m = s.medium;
  for (int a = 0; a < 3; ++a) {
    PRIZMA_FUZZ_CHECK(m.dims[a] > 0, "medium dims[%d] = %d", a, m.dims[a]);
    PRIZMA_FUZZ_CHECK(std::isfinite(m.bounds_min[a]) && std::isfinite(m.bounds_max[a]) &&
                          m.bounds_min[a] < m.bounds_max[a],
                      "bounds on axis %d: [%g, %g]", a, m.bounds_min[a], m.bounds_max[a]);
  }
  PRIZMA_FUZZ_CHECK(m.material.size() == m.voxel_count() && m.density.size() == m.voxel_count(),
                    "%zu materials, %zu densities for %zu voxels", m.material.size(), m.density.size(),
                    m.voxel_count());
  for (std::size_t i = 0; i < m.voxel_count(); ++i) {
    PRIZMA_FUZZ_CHECK(m.material[i] == prizma::render::Medium::kEmpty || m.material[i] < m.materials.size(),
                      "voxel %zu has material %u of %zu", i, static_cast<unsigned>(m.material[i]),
                      m.materials.size());
    PRIZMA_FUZZ_CHECK(std::isfinite(m.density[i]) && m.density[i] >= 0.0f, "voxel %zu density %g", i,
                      static_cast<double>(m.density[i]));
  }
  PRIZMA_FUZZ_CHECK(!s.lights.empty(), "no lights");
  PRIZMA_FUZZ_CHECK(s.camera.width > 0 && s.camera.height > 0, "camera %d x %d", s.camera.width, s.camera.height);
  PRIZMA_FUZZ_CHECK(s.settings.sample_end > s.settings.sample_begin && s.settings.sample_begin >= 0,
                    "samples [%lld, %lld)", static_cast<long long>(s.settings.sample_begin),
                    static_cast<long long>(s.settings.sample_end));
  PRIZMA_FUZZ_CHECK(s.settings.bins.size() >= 1, "no bins");
}

void write_scene_folder(const std::filesystem::path& dir) {
  prizma::fuzz::write_file(dir / "tiny_2x2x2_uint8.raw", std::string_view("\x00\x40\x80\xff\x10\x20\x30\x40", 8));
  prizma::fuzz::write_file(dir / "f.csv", "nm,value\n380,0.1\n500,0.5\n780,0.9\n");
  // NIfTI-1 single file: 348-byte header, 4 bytes of extension flags, then 2×2×2 uint8 voxels.
  std::string nii(352, '\0');
  auto put_i16 = [&](std::size_t at, std::int16_t v) { std::memcpy(nii.data() + at, &v, 2); };
  auto put_i32 = [&](std::size_t at, std::int32_t v) { std::memcpy(nii.data() + at, &v, 4); };
  auto put_f32 = [&](std::size_t at, float v) { std::memcpy(nii.data() + at, &v, 4); };
  put_i32(0, 348);
  put_i16(40, 3);  // dim[0..3]
  put_i16(42, 2);
  put_i16(44, 2);
  put_i16(46, 2);
  put_i16(70, 2);  // datatype uint8
  put_i16(72, 8);  // bitpix
  for (int a = 1; a <= 3; ++a) put_f32(76 + 4 * a, 1.0f);  // pixdim
  put_f32(108, 352.0f);  // vox_offset
  std::memcpy(nii.data() + 344, "n+1\0", 4);
  nii += std::string("\x00\x40\x80\xff\x10\x20\x30\x40", 8);
  prizma::fuzz::write_file(dir / "tiny.nii", nii);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInputBytes) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false,
                                                 /*ignore_comments=*/true);
  if (!j.is_discarded() && skipped(j)) return 0;

  static const prizma::fuzz::ScratchDir dir("scene");
  static const bool prepared = (write_scene_folder(dir.path()), true);
  (void)prepared;
  const auto path = dir.path() / "scene.json";
  prizma::fuzz::write_file(path, text);
  prizma::fuzz::accepts("load_scene", [&] { check_scene(prizma::render::load_scene(path)); });
  return 0;
}
