#pragma once
// RelightSession: one spectral image loaded once, relit again and again as the lights, exposure,
// CMF or display change (the interactive mode and batch files run on it; tests drive it directly).
#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/relight/compressed_relight.h"
#include "prizma/relight/light_spec.h"
#include "prizma/spectral/output_image.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/xyz_image.h"
#include "prizma/spectral/default_lights.h"
#include "prizma/spectral/display.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::relight {

// How a front end names the settings in its errors: as the user gave them ("--exposure" on the
// command line, "batch.json: outputs[0].exposure" in a batch file, "state: exposure" from the page).
struct RelightSettingNames {
  std::string exposure = "exposure";
  std::string bit_depth = "bit depth";
};

// Everything that decides an output image besides the transport.
struct RelightSettings {
  std::vector<LightSpec> lights;  // one per layer, in the image's layer order
  spectral::RelightOptions relight;
  spectral::OutputOptions output;

  // The limits every front end shares, checked here only: the exposure (finite, within ±64 stops,
  // RelightOptions::validate) and the bit depth (8 or 16, OutputOptions::validate). Throws
  // InputError naming the value as `names` says.
  void validate(const RelightSettingNames& names = {}) const;
};

// What `probe X Y` reports about one pixel.
struct ProbeResult {
  int x = 0, y = 0;
  std::vector<std::vector<float>> bins;  // per layer, the transport bins at the pixel
  // Bispectral files: per layer the pixel's off-diagonal M[out][in], one value per pair of
  // image().reradiation (empty otherwise).
  std::vector<std::vector<float>> reradiation;
  Eigen::Vector3d xyz;                   // relit, exposure included
  Eigen::Vector3d lab;                   // CIELAB, D65 white (Y = 1)
  Eigen::Vector3d srgb;                  // sRGB (IEC 61966-2-1) encoded, unclamped
};

// What `compare` reports: the mean colours of two (2r+1)² regions (clipped to the image) and their
// CIEDE2000 difference.
struct CompareResult {
  Eigen::Vector3d xyz1, xyz2, lab1, lab2;
  double delta_e2000 = 0.0;
};

class RelightSession {
 public:
  // Reads the spectral EXR (InputError naming the path when it is not one). Lights start at their
  // defaults: the file's prizma:lights spectrum for each layer, else D65.
  explicit RelightSession(const std::filesystem::path& spectral_exr);
  // Takes an image already in memory; `source` names it in messages and metadata. When the image
  // carries spectral-basis coefficients (read with ExrReadOptions::read_coefficients; a compact file
  // has nothing else) the session relights from them (relight_compressed_into), unless `exact`, which
  // relights from the bins and is refused (InputError) for a compact file.
  RelightSession(spectral::SpectralImage image, std::string source, bool exact = false);
  ~RelightSession();

  const spectral::SpectralImage& image() const { return m_image; }
  // The coefficients relit instead of the bins, or null (docs/relight.md, "Compressed transport").
  const CompressedTransport* coefficients() const { return m_compressed.get(); }
  const std::string& source() const { return m_source; }
  // Layer names as users type them ("T" for an unnamed single layer).
  const std::vector<std::string>& light_names() const { return m_defaults.names; }
  // The layer's index; throws InputError (input `input`) listing the file's lights when unknown.
  int light_index(std::string_view name, const std::string& input = "--light") const;
  // Per layer, the default light (file's prizma:lights spectrum, else D65). A recorded spectrum that
  // cannot be parsed here (a CSV left on the rendering machine) does not stop the file from opening:
  // its default is an "off" placeholder with the recorded text, and relight() throws InputError
  // naming the light until the user gives that light a spectrum.
  const std::vector<LightSpec>& default_lights() const { return m_defaults.lights; }

  const RelightSettings& settings() const { return m_settings; }
  // Replaces every setting at once; validates (RelightSettings::validate with `names`, then builds the
  // matrix and display) before committing, so a failure leaves the session as it was.
  void apply(RelightSettings settings, const RelightSettingNames& names = {});
  // Sets `given` on every layer of `lights` (settings().lights, or settings being built from them),
  // as every all-lights form means it (--light SPEC, a batch file's "lights": "SPEC", the shell's
  // `light SPEC`, prizma.relight(lights=SPEC)): a spec that says its scale as it is, a bare one at
  // each layer's scale in `lights` (spectral::at_light_scale: a light that is off stays off; a
  // recorded spectrum that cannot be read here lends the factors it was recorded with).
  void set_every_light(std::vector<LightSpec>& lights, const LightSpec& given) const;
  // Convenience setters (same all-or-nothing rule). An empty name sets every layer (set_every_light).
  void set_light(std::string_view name, std::string_view spec);
  void set_exposure(double exposure_ev);
  void set_cmf(spectral::Observer cmf);
  void set_display(const std::string& display);

  // Relights with the current settings when anything changed; returns the time it took in ms
  // (0 when nothing changed).
  double relight();
  const spectral::XyzImage& xyz();
  const spectral::RelightMatrix& matrix() const { return m_matrix; }
  // The display transform for the current settings (built on first use after a change; throws
  // InputError when the config or display does not exist).
  const spectral::DisplayTransform& display();

  ProbeResult probe(int x, int y);
  CompareResult compare(int x1, int y1, int x2, int y2, int radius = 0);
  // Writes the current image (format by extension), with metadata(): atomically, or into `group`
  // (the run's outputs, appearing at its commit()). InputError names `input` (the option, the shell
  // command or the page's field) for a path that cannot be written, one the run reads among them.
  void save(const std::filesystem::path& path, const std::string& input = "--output",
            spectral::OutputGroup* group = nullptr);
  // Attributes describing how the image was made.
  spectral::ImageMetadata metadata() const;
  // One line per layer: "name: spec".
  std::string describe_lights() const;

 private:
  void check_pixel(int x, int y, const std::string& input) const;
  void check_lights_usable() const;

  spectral::SpectralImage m_image;
  std::string m_source;
  spectral::DefaultLights m_defaults;  // names, default lights and why any cannot be used (default_lights.h)
  RelightSettings m_settings;
  spectral::RelightMatrix m_matrix;
  std::unique_ptr<spectral::DisplayTransform> m_display;
  spectral::DisplayOptions m_display_options;
  spectral::XyzImage m_xyz;
  spectral::ReradiationWeights m_reradiation;  // bispectral images: K per observer (relight_image.h)
  std::unique_ptr<CompressedTransport> m_compressed;
  bool m_dirty = true;
};

}  // namespace prizma::relight
