#include "prizma/relight/relight_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/default_lights.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/version.h"

namespace prizma::relight {

namespace {

using spectral::InputError;

Eigen::Vector3d xyz_to_srgb_encoded(const Eigen::Vector3d& xyz) {
  const Eigen::Vector3d lin = spectral::xyz_to_linear_srgb(xyz);
  Eigen::Vector3d enc;
  // srgb_encode maps negatives to 0; keep the sign so out-of-gamut colours stay visible in probes.
  for (int c = 0; c < 3; ++c) enc[c] = std::copysign(spectral::srgb_encode(std::abs(lin[c])), lin[c]);
  return enc;
}

}  // namespace

RelightSession::RelightSession(const std::filesystem::path& spectral_exr)
    : RelightSession(spectral::read_spectral_exr(spectral_exr), spectral_exr.string()) {}

RelightSession::RelightSession(spectral::SpectralImage image, std::string source, bool exact)
    : m_image(std::move(image)), m_source(std::move(source)) {
  if (m_image.lights.empty()) throw InputError(m_source, "no transport layers");
  if (m_image.has_coefficients()) {
    if (exact && m_image.compact()) {
      throw InputError(m_source, "compact file: it holds only spectral-basis coefficients, not the transport bins, so "
                                 "it cannot be relit exactly (relight it without --exact, or use the file it was made from)");
    }
    if (exact) {
      for (auto& layer : m_image.lights) layer.coefficients = spectral::LayerCoefficients{};
    } else {
      m_compressed = std::make_unique<CompressedTransport>(take_coefficients(m_image, m_source));
    }
  }
  std::vector<std::string> layer_names;
  for (const auto& layer : m_image.lights) layer_names.push_back(layer.name);
  spectral::check_light_records(m_image.info.light_records, layer_names, m_source);  // images made in memory
  m_defaults = spectral::default_lights(m_image, m_source);
  RelightSettings settings;
  settings.lights = m_defaults.lights;
  apply(std::move(settings));
}

RelightSession::~RelightSession() = default;

int RelightSession::light_index(std::string_view name, const std::string& input) const {
  for (std::size_t l = 0; l < light_names().size(); ++l)
    if (light_names()[l] == name) return static_cast<int>(l);
  std::string known;
  for (const auto& n : light_names()) known += (known.empty() ? "" : ", ") + n;
  throw InputError(input, "no light \"" + std::string(name) + "\" in " + m_source + " (its lights: " + known + ")");
}

void RelightSettings::validate(const RelightSettingNames& names) const {
  relight.validate(names.exposure);
  output.validate(names.bit_depth);
}

void RelightSession::apply(RelightSettings settings, const RelightSettingNames& names) {
  if (settings.lights.size() != m_image.lights.size()) {
    throw InputError("lights", "expected " + std::to_string(m_image.lights.size()) + " lights, got " +
                                   std::to_string(settings.lights.size()));
  }
  settings.validate(names);
  // Build everything first; commit only when all of it succeeded.
  spectral::RelightMatrix matrix(m_image.bins, settings.lights, settings.relight);
  if (!settings.output.display.colour_space.empty())
    spectral::check_output_options(spectral::OutputFormat::Exr, settings.output);

  // The display transform is built when first needed (EXR XYZ output needs no OCIO config).
  spectral::DisplayOptions display_options = settings.output.display;
  display_options.colour_space.clear();
  if (display_options.config != m_display_options.config || display_options.display != m_display_options.display ||
      display_options.view != m_display_options.view) {
    m_display.reset();
  }
  m_settings = std::move(settings);
  m_matrix = std::move(matrix);
  m_display_options = display_options;
  m_dirty = true;
}

void RelightSession::set_every_light(std::vector<LightSpec>& lights, const LightSpec& given) const {
  if (lights.size() != light_names().size()) {
    throw InputError("lights", "expected " + std::to_string(light_names().size()) + " lights, got " +
                                   std::to_string(lights.size()));
  }
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const LightSpec& now = lights[l];
    const bool placeholder = m_defaults.placeholder_in_place(l, now);
    lights[l] = spectral::at_light_scale(given, placeholder || !now.off ? now.scale : 0.0);
  }
}

void RelightSession::set_light(std::string_view name, std::string_view spec) {
  RelightSettings s = m_settings;
  const std::string input = name.empty() ? "light" : "light " + std::string(name);
  const LightSpec light = parse_light_spec(spec, {input, {}});
  if (name.empty()) {
    set_every_light(s.lights, light);
  } else {
    s.lights[static_cast<std::size_t>(light_index(name, "light"))] = light;
  }
  apply(std::move(s));
}

void RelightSession::set_exposure(double exposure_ev) {
  RelightSettings s = m_settings;
  s.relight.exposure_ev = exposure_ev;
  apply(std::move(s));
}

void RelightSession::set_cmf(spectral::Observer cmf) {
  RelightSettings s = m_settings;
  s.relight.cmf = cmf;
  apply(std::move(s));
}

void RelightSession::set_display(const std::string& display) {
  RelightSettings s = m_settings;
  s.output.display.display = display;
  s.output.display.view.clear();
  spectral::DisplayOptions check = s.output.display;
  check.colour_space.clear();
  spectral::DisplayTransform validate(check);  // throws InputError for unknown displays
  apply(std::move(s));
}

void RelightSession::check_lights_usable() const {
  // A layer whose recorded spectrum cannot be used is refused while its placeholder is in place.
  for (std::size_t l = 0; l < m_defaults.names.size(); ++l) {
    if (!m_defaults.placeholder_in_place(l, m_settings.lights[l])) continue;
    m_defaults.require_usable(l, m_source, "; give this light a spectrum (--light " + m_defaults.names[l] + "=SPEC)");
  }
}

double RelightSession::relight() {
  check_lights_usable();
  if (!m_dirty) return 0.0;
  const auto start = std::chrono::steady_clock::now();
  m_xyz.width = m_image.width;
  m_xyz.height = m_image.height;
  m_xyz.xyz.resize(3 * m_image.pixel_count());
  if (!m_image.reradiation.empty() && (m_reradiation.per_light.empty() || m_reradiation.cmf != m_matrix.options().cmf))
    m_reradiation = spectral::reradiation_weights(m_image, m_matrix.options().cmf);  // once per observer
  if (m_compressed) {
    relight_compressed_into(*m_compressed, m_matrix, m_xyz.xyz.data());
  } else {
    spectral::relight_into(m_image, m_matrix, m_xyz.xyz.data(), m_image.reradiation.empty() ? nullptr : &m_reradiation);
  }
  m_dirty = false;
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

const spectral::XyzImage& RelightSession::xyz() {
  relight();
  return m_xyz;
}

const spectral::DisplayTransform& RelightSession::display() {
  if (!m_display) m_display = std::make_unique<spectral::DisplayTransform>(m_display_options);
  return *m_display;
}

void RelightSession::check_pixel(int x, int y, const std::string& input) const {
  if (x < 0 || y < 0 || x >= m_image.width || y >= m_image.height) {
    throw InputError(input, "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") outside the " +
                                std::to_string(m_image.width) + "×" + std::to_string(m_image.height) + " image");
  }
}

ProbeResult RelightSession::probe(int x, int y) {
  check_pixel(x, y, "probe");
  ProbeResult r;
  r.x = x;
  r.y = y;
  const std::size_t n = static_cast<std::size_t>(m_image.bins.size());
  const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(m_image.width) + static_cast<std::size_t>(x);
  const std::size_t np = m_image.reradiation.size();
  for (std::size_t l = 0; l < m_image.lights.size(); ++l) {
    const auto& layer = m_image.lights[l];
    if (layer.data.empty() && m_compressed) {  // compact: the bins as the coefficients give them, B·c
      const Eigen::VectorXf t = reconstructed_spectrum(m_compressed->lights[l], p);
      r.bins.emplace_back(t.data(), t.data() + t.size());
      continue;
    }
    r.bins.emplace_back(layer.data.begin() + static_cast<std::ptrdiff_t>(p * n),
                        layer.data.begin() + static_cast<std::ptrdiff_t>((p + 1) * n));
    if (np > 0)
      r.reradiation.emplace_back(layer.reradiation.begin() + static_cast<std::ptrdiff_t>(p * np),
                                 layer.reradiation.begin() + static_cast<std::ptrdiff_t>((p + 1) * np));
  }
  r.xyz = xyz().at(x, y);
  r.lab = spectral::xyz_to_lab(r.xyz, spectral::white_d65());
  r.srgb = xyz_to_srgb_encoded(r.xyz);
  return r;
}

CompareResult RelightSession::compare(int x1, int y1, int x2, int y2, int radius) {
  check_pixel(x1, y1, "compare");
  check_pixel(x2, y2, "compare");
  // A radius beyond the image's larger side covers nothing more; a larger one is a typo (and
  // cx + radius would overflow).
  const int max_radius = std::max(m_image.width, m_image.height);
  if (radius < 0 || radius > max_radius) {
    throw InputError("compare", "radius must be between 0 and " + std::to_string(max_radius) + ", not " +
                                    std::to_string(radius));
  }
  const spectral::XyzImage& img = xyz();
  // Mean XYZ over the (2r+1)² square around (cx, cy), clipped to the image (never empty: the centre
  // is inside).
  auto mean = [&](int cx, int cy) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (int y = std::max(0, cy - radius); y <= std::min(img.height - 1, cy + radius); ++y)
      for (int x = std::max(0, cx - radius); x <= std::min(img.width - 1, cx + radius); ++x, ++count)
        sum += img.at(x, y);
    return Eigen::Vector3d(sum / count);
  };
  CompareResult r;
  r.xyz1 = mean(x1, y1);
  r.xyz2 = mean(x2, y2);
  r.lab1 = spectral::xyz_to_lab(r.xyz1, spectral::white_d65());
  r.lab2 = spectral::xyz_to_lab(r.xyz2, spectral::white_d65());
  r.delta_e2000 = spectral::delta_e2000(r.lab1, r.lab2);
  return r;
}

void RelightSession::save(const std::filesystem::path& path, const std::string& input, spectral::OutputGroup* group) {
  spectral::write_output_image(path, xyz(), m_settings.output, metadata(), input, group);
}

spectral::ImageMetadata RelightSession::metadata() const {
  spectral::ImageMetadata md =
      spectral::relight_metadata("prizma-relight " + spectral::prizma_version(), m_source, light_names(),
                                 m_settings.lights, m_settings.relight, m_settings.output, m_image.bins);
  if (m_compressed) md.emplace_back("prizma:relitFrom", "spectral-basis coefficients");
  return md;
}

std::string RelightSession::describe_lights() const {
  std::string out;
  for (std::size_t l = 0; l < light_names().size(); ++l) {
    out += light_names()[l] + ": " + m_settings.lights[l].text + " (default " + m_defaults.lights[l].text + ")\n";
  }
  return out;
}

}  // namespace prizma::relight
