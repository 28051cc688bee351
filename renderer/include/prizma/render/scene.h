#pragma once
// Scene: everything a render needs, validated. load_scene() reads the JSON scene file
// (docs/scene-format.md); tests may also build a Scene in code.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "prizma/render/environment_map.h"
#include "prizma/render/event_probability.h"
#include "prizma/render/material_rule.h"
#include "prizma/render/rng.h"
#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::render {

// Fluorescence of a material (docs/fluorescence.md): an extra absorption coefficient σf per scene
// unit at density 1 (added to the extinction), the spectrum of the re-emitted photons (normalised by
// the renderer to unit area over its table, so any scale may be given) and the quantum yield q, the
// fraction of absorbed photons re-emitted, isotropically.
struct Fluorescence {
  spectral::Spectrum absorption = spectral::Spectrum::constant(0.0);
  spectral::Spectrum emission = spectral::Spectrum::constant(0.0);
  double quantum_yield = 0.0;
};

// One material of the transfer function. Spectra are evaluated at each path's own wavelengths.
struct Material {
  std::string name;
  spectral::Spectrum albedo;           // single-scattering albedo, in [0, 1]
  spectral::Spectrum sigma_t_per_unit;  // extinction per scene unit at density 1, ≥ 0
  spectral::Spectrum anisotropy;       // Henyey–Greenstein g, in (−1, 1)
  // Emitted radiance Le at density 1, ≥ 0 (source term σa·density·Le, as in pbrt-v4); it reaches the
  // image through the scene's emission light layer (Light::emission).
  spectral::Spectrum emission = spectral::Spectrum::constant(0.0);
  bool fluorescent = false;  // the material fluoresces (the scene's "fluorescence" field)
  Fluorescence fluorescence;
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
  // Point, sphere and spot lights (docs/scene-format.md, "Point, sphere and spot lights"): unit
  // radiant intensity at unit white (1 W/sr on the axis of a spot), direction unused.
  bool is_point = false;
  Eigen::Vector3d position{0, 0, 0};
  double radius = 0.0;                         // > 0: a sphere of the same total power (4π), ≥ 0
  Eigen::Vector3d spot_direction{0, 0, 0};     // unit spot axis; zero = not a spot
  double spot_cone_deg = 0.0;                  // spot: half-angle where the intensity reaches 0, (0, 180]
  double spot_falloff_deg = 0.0;               // spot: width of the smooth edge inside the cone, [0, cone]
  // Environment-map light: the lat-long image's luminance as radiance (docs/scene-format.md).
  std::shared_ptr<const EnvironmentMap> environment_map;
  std::string environment_file;                // as given in the scene (for the render's metadata)
  double rotation_deg = 0.0;
  // How an environment map is sampled: Auto = next-event estimation and phase sampling combined by
  // MIS, or phase sampling alone when the image is constant (exactly the uniform environment's
  // estimator); Mis and PhaseOnly force one (tests).
  enum class EnvironmentSampling { Auto, Mis, PhaseOnly };
  EnvironmentSampling environment_sampling = EnvironmentSampling::Auto;
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
  Auto,              // by the scene (resolve_wavelength_sampling, render.h)
  SpectralTracking,  // every path carries all bins (Kutz et al. 2017)
  Single,            // VPT: one random wavelength per path, feeding one bin
  SpectralMis,       // every path carries all bins, sampled for one hero bin, weighted by spectral MIS
};

struct RenderSettings {
  spectral::BinLayout bins;           // default 16 × 25 nm over 380–780
  std::int64_t sample_begin = 0;      // render samples [sample_begin, sample_end) of every pixel
  std::int64_t sample_end = 64;
  std::uint64_t seed = 1;
  int max_bounces = -1;               // −1 = unlimited (Russian roulette); ≥ 0 = cap
  WavelengthSampling wavelength_sampling = WavelengthSampling::Auto;
  Sampler sampler = Sampler::Independent;  // where a path's first random numbers come from (rng.h)
  // Spectral tracking's collision event probabilities (event_probability.h); Auto: chosen from the
  // materials' spectra when the tracer is built.
  EventProbabilities event_probabilities = EventProbabilities::Auto;
  // Spectral MIS's lane groups (resolve_mis_lane_groups, render.h): 0 = auto (the default), 1 = every
  // bin on one path, G = the bins in G runs of neighbouring bins, one path per run and sample.
  int mis_lane_groups = 0;
  double target_error = 0.0;          // > 0: stop a pixel once its relative standard error ≤ this
  bool use_majorant_grid = true;
  int threads = 0;                    // 0 = all cores
  bool write_variance = false;
  bool write_guides = false;          // --features: guide layers for the denoiser (film.h)
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
  std::vector<std::string> warnings;  // problems noticed in inputs that were still read (Volume::warnings)
};

// A command-line override of one scene field (prizma-render -D KEY=VALUE).
struct SceneOverride {
  std::string key;    // field path: "camera.fov_deg", "lights.side.spectrum", "materials[1].albedo"
  std::string value;  // text: a string field takes it as it is, other fields as JSON
};
// "camera.fov_deg=30" → {key, value}; InputError (input "-D TEXT") without '=' or with no key.
SceneOverride parse_scene_override(const std::string& text);

// Reads and validates a scene file. Errors are InputError with input "<file>: <field path>", e.g.
// "scene.json: materials[1].extinction.scale: must be > 0". Paths are relative to the scene file.
// `overrides` are applied to the file's JSON first, then validated by the same checks; an error in
// an overridden field names it as "-D <field path>". They are part of the scene's hash.
Scene load_scene(const std::filesystem::path& path, const std::vector<SceneOverride>& overrides = {});
// The same for a scene's JSON text held in memory (the Python module's render(dict)): errors name
// `input` ("scene: materials[0].albedo: …") and relative paths resolve against `base_dir`.
Scene load_scene_text(const std::string& text, const std::string& input, const std::filesystem::path& base_dir,
                      const std::vector<SceneOverride>& overrides = {});

// A command-line value for an integer scene field ("camera.width", "camera.height", "samples",
// "seed", "max_bounces"), checked exactly as load_scene checks the field (same type, same range).
// `text` is what the user typed; errors are InputError with input `option` ("--width").
std::int64_t scene_integer_override(const std::string& text, const std::string& field, const std::string& option);
// The same for "seed" (an integer in [0, 2^64 − 1]).
std::uint64_t scene_seed_override(const std::string& text, const std::string& option);

}  // namespace prizma::render
