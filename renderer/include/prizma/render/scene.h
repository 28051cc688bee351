#pragma once
// Scene: everything a render needs, validated. load_scene() reads the JSON scene file
// (docs/scene-format.md); tests may also build a Scene in code.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "prizma/render/material_rule.h"
#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::render {

// One material of the transfer function. Spectra are evaluated at each path's own wavelengths.
struct Material {
  std::string name;
  spectral::Spectrum albedo;           // single-scattering albedo, in [0, 1]
  spectral::Spectrum sigma_t_per_unit;  // extinction per scene unit at density 1, ≥ 0
  spectral::Spectrum anisotropy;       // Henyey–Greenstein g, in (−1, 1)
  // Emitted radiance Le at density 1, ≥ 0 (source term σa·density·Le, as in pbrt-v4); it reaches the
  // image through the scene's emission light layer (Light::emission).
  spectral::Spectrum emission = spectral::Spectrum::constant(0.0);
};

// How the tracer reads the volume at a point: the nearest voxel's classification (blocks), or the
// raw value interpolated trilinearly between voxel centres and then classified.
enum class Interpolation { Nearest, Trilinear };

// A cut-away plane: the medium is removed where dot(normal, p) > offset (p in world units, the
// box's frame); normal is unit length. Points with dot(normal, p) ≤ offset keep their medium.
struct ClipPlane {
  Eigen::Vector3d normal{0, 0, 1};
  double offset = 0.0;
};

// The medium the tracer sees: a box in world space split into voxels, each holding a material
// index (or kEmpty) and a density multiplier (the classification at the voxel centre). With
// Nearest a voxel is a homogeneous cell; with Trilinear the tracer interpolates `value` (raw values
// at voxel centres, clamped to the edge voxels) and classifies the result with `rules`.
struct Medium {
  static constexpr std::uint16_t kEmpty = 0xFFFF;
  std::array<int, 3> dims{0, 0, 0};
  Eigen::Vector3d bounds_min{-0.5, -0.5, -0.5};  // world-space box; largest side 1 by default
  Eigen::Vector3d bounds_max{0.5, 0.5, 0.5};
  std::vector<std::uint16_t> material;  // per voxel, x fastest
  std::vector<float> density;           // per voxel, ≥ 0
  std::vector<Material> materials;
  Interpolation interpolation = Interpolation::Nearest;
  std::vector<float> value;          // Trilinear: raw value per voxel, x fastest (non-finite = empty)
  std::vector<MaterialRule> rules;   // Trilinear: value → material and density, first match wins
  // Volume::block_range carried over (Volume::kBlockVoxels³ blocks); empty = read the voxels.
  std::vector<std::array<float, 2>> block_range;
  std::vector<ClipPlane> clip;       // cut-aways: medium removed on the positive side of any plane

  // True when p lies on the removed side of some clip plane.
  bool clipped(const Eigen::Vector3d& p) const {
    for (const ClipPlane& c : clip)
      if (c.normal.dot(p) > c.offset) return true;
    return false;
  }

  std::size_t voxel_count() const { return static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]; }
};

struct Light {
  std::string name;                // letters, digits, '_' and '-'; unique in a scene
  Eigen::Vector3d direction{0, 0, 0};  // toward the light; the zero vector = uniform environment
  double angular_size_deg = 0.0;   // directional lights only: full apex angle of the cone, 0 = delta
  std::string spectrum_spec = "D65";  // default spectrum, used only for previews
  // The emission layer: the radiance emitted by the medium's materials (Material::emission) at unit
  // white; direction and angular size unused. At most one per scene.
  bool emission = false;
};

enum class CameraType { Perspective, Orthographic };

struct Camera {
  CameraType type = CameraType::Perspective;
  Eigen::Vector3d position{0, 0, 2};
  Eigen::Vector3d look_at{0, 0, 0};
  Eigen::Vector3d up{0, 1, 0};
  double fov_y_deg = 57.29577951308232;  // VPT's 1 rad
  double ortho_height = 1.5;             // world units visible vertically (orthographic)
  int width = 256;
  int height = 256;
};

enum class WavelengthSampling {
  SpectralTracking,  // every path carries all bins (Kutz et al. 2017)
  Single,            // VPT: one random wavelength per path, feeding one bin
};

struct RenderSettings {
  spectral::BinLayout bins;           // default 16 × 25 nm over 380–780
  std::int64_t sample_begin = 0;      // render samples [sample_begin, sample_end) of every pixel
  std::int64_t sample_end = 64;
  std::uint64_t seed = 1;
  int max_bounces = -1;               // −1 = unlimited (Russian roulette); ≥ 0 = cap
  WavelengthSampling wavelength_sampling = WavelengthSampling::SpectralTracking;
  double target_error = 0.0;          // > 0: stop a pixel once its relative standard error ≤ this
  bool use_majorant_grid = true;
  int threads = 0;                    // 0 = all cores
  bool write_variance = false;
  // Test/benchmark mode: multiply each light's radiance by its default spectrum at the path's
  // wavelengths (the light "folded into the rendering", as VPT does) instead of unit white.
  bool fold_light_spectra = false;
};

struct Scene {
  Medium medium;
  std::vector<Light> lights;
  Camera camera;
  RenderSettings settings;
  std::filesystem::path output;  // default output (scene's "output"), resolved against the scene folder
  std::string hash;              // hash of the scene file text and the volume bytes
  std::filesystem::path source;  // the scene file
  std::string volume_note;       // for the render's log: the volume's orientation, if any (Volume::orientation)
};

// Reads and validates a scene file. Errors are InputError with input "<file>: <field path>", e.g.
// "scene.json: materials[1].extinction.scale: must be > 0". Paths are relative to the scene file.
Scene load_scene(const std::filesystem::path& path);

// A command-line value for an integer scene field ("camera.width", "camera.height", "samples",
// "seed", "max_bounces"), checked exactly as load_scene checks the field (same type, same range).
// `text` is what the user typed; errors are InputError with input `option` ("--width").
std::int64_t scene_integer_override(const std::string& text, const std::string& field, const std::string& option);
// The same for "seed" (an integer in [0, 2^64 − 1]).
std::uint64_t scene_seed_override(const std::string& text, const std::string& option);

}  // namespace prizma::render
