#pragma once
// Display transforms through OpenColorIO: from CIE XYZ (the relighter's output, D65-relative white
// at Y = 1) to a display or a linear working space. The processor is built once and applied to
// whole images.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace prizma::spectral {

struct DisplayOptions {
  // Config: empty = $OCIO if set, else data/ocio/config.ocio.
  std::filesystem::path config;
  // A display name of the config ("sRGB", "Display P3", "Rec.2020") with its default view, or,
  // with `colour_space` set, a plain colour space conversion instead ("ACEScg", "Linear sRGB",
  // "CIE-XYZ-D65").
  std::string display = "sRGB";
  std::string view;          // empty = the display's default view
  std::string colour_space;  // non-empty: convert to this colour space instead of a display
};

class DisplayTransform {
 public:
  // Throws InputError naming the config, display or colour space when it does not exist (listing the
  // valid ones).
  explicit DisplayTransform(const DisplayOptions& opts);
  ~DisplayTransform();
  DisplayTransform(DisplayTransform&&) noexcept;
  DisplayTransform& operator=(DisplayTransform&&) noexcept;

  // In-place: interleaved XYZ → display RGB (float, 3 channels per pixel), any number of pixels.
  // Thread-safe (const).
  void apply(float* xyz_interleaved, std::size_t pixel_count) const;
  // The config file that was used and the names chosen, for --verbose output.
  const std::filesystem::path& config_path() const;
  std::string description() const;
  // Displays and colour spaces the config offers.
  std::vector<std::string> displays() const;
  std::vector<std::string> colour_spaces() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

// The default config: $OCIO if set and non-empty, else data_file("ocio/config.ocio").
std::filesystem::path default_ocio_config();

}  // namespace prizma::spectral
