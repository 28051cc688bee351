// write_preview(): an 8-bit sRGB picture of a transport image under its lights' default spectra.
#include <cmath>

#include "prizma/render/render.h"
#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/image_io.h"
#include "prizma/spectral/output_group.h"

namespace prizma::render {

void write_preview(const std::filesystem::path& path, const spectral::SpectralImage& image,
                   const std::vector<Light>& lights, const PreviewOptions& opts) {
  const int nb = image.bins.size();
  const auto& cmf = spectral::ColorMatching::get(spectral::Observer::Cie1931_2deg);
  // Per light: 3×n weights of its default spectrum (exact bin integrals), read as prizma-relight
  // reads a light: normalised so that a perfect white has Y = 1, then the spec's trailing scale
  // ("D65*0.2" stays a fifth as bright).
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> weights, rerad;  // rerad: XYZ ← bispectral pairs
  for (std::size_t l = 0; l < image.lights.size(); ++l) {
    std::string spec = "D65";
    for (const Light& light : lights)
      if (light.name == image.lights[l].name) spec = light.spectrum_spec;
    spectral::SpecContext ctx{"lights[" + std::to_string(l) + "].spectrum", opts.spectrum_base_dir};
    const spectral::LightSpectrum light = spectral::parse_light_spectrum(spec, ctx);
    weights.push_back(spectral::relight_weights(cmf, light, image.bins));
    rerad.push_back(spectral::reradiation_pair_xyz(image, cmf, light));  // fluorescent: the re-radiated light
  }
  const std::size_t np = image.reradiation.size();
  const double scale = std::exp2(opts.exposure_ev);
  const std::size_t pixels = image.pixel_count();
  std::vector<unsigned char> rgb8(pixels * 3);
  for (std::size_t p = 0; p < pixels; ++p) {
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
    for (std::size_t l = 0; l < image.lights.size(); ++l) {
      const float* t = image.lights[l].data.data() + p * nb;
      for (int i = 0; i < nb; ++i) xyz += weights[l].col(i) * static_cast<double>(t[i]);
      for (std::size_t q = 0; q < np; ++q)
        xyz += rerad[l].col(static_cast<Eigen::Index>(q)) * static_cast<double>(image.lights[l].reradiation[p * np + q]);
    }
    const Eigen::Vector3d lin = spectral::xyz_to_linear_srgb(xyz * scale);
    for (int c = 0; c < 3; ++c) {
      const double e = std::clamp(spectral::srgb_encode(std::clamp(lin[c], 0.0, 1.0)), 0.0, 1.0);
      rgb8[p * 3 + c] = static_cast<unsigned char>(std::lround(e * 255.0));
    }
  }
  spectral::PictureSpec spec;
  spec.width = image.width;
  spec.height = image.height;
  spec.stored = spectral::PicturePixelType::UInt8;
  spec.colour_space = spectral::srgb_picture_colour_space();  // an sRGB ICC profile
  spectral::write_atomically(path, [&](spectral::AtomicOutput& out) {
    spectral::write_picture(out, spec, spectral::PicturePixelType::UInt8, rgb8.data());
  }, opts.group);
}

void check_preview_path(const std::filesystem::path& path, const std::string& input) {
  spectral::check_output_file(path, input);
  std::string reason;
  if (!spectral::can_write_picture(path.string(), reason)) {
    throw spectral::InputError(input, "\"" + path.string() + "\": cannot write this image format (" + reason +
                                          "); use .png");
  }
}

}  // namespace prizma::render
