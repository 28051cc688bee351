#pragma once
// Spectrum spec strings, the one parser every tool uses:
//   D65 D50 A E F2 F11 LED-B1…LED-B5 LED-BH1 LED-RGB1 LED-V1 LED-V2   named CIE illuminants
//   cc:<patch> / cc:<1..24>       ColorChecker Classic reflectance (Ohta / ISO 17321-1), e.g. cc:dark-skin
//   blackbody:3200K               Planck radiator, peak normalised to 1
//   gaussian:550:20               centre, FWHM in nm, peak 1
//   box:500:560                   1 inside [500, 560] nm, 0 outside
//   csv:path/to/file.csv          two columns (nm, value), optional header, '#' comments
//   0.5                           a constant
//   SPEC*0.5                      any of the above scaled
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/spectral/spectrum.h"

namespace prizma::spectral {

// The values the quantity a spectrum describes may take. Nearly every one is ≥ 0 (lights,
// reflectances, albedo, extinction, emission, a dye's absorption and emission); the
// Henyey–Greenstein anisotropy g is signed (backward scattering, g < 0).
enum class SpectrumValues { NonNegative, Signed };

struct SpecContext {
  // What the spec came from, used in error messages ("--light key", "scene.json: materials[0].albedo").
  std::string input = "spectrum";
  // Relative csv: paths resolve against this folder (the scene file's folder); empty = cwd.
  std::filesystem::path base_dir;
  // The quantity's sign: NonNegative refuses a negative constant or csv: value, Signed takes them.
  // (A negative factor, SPEC*-1, is a difference spectrum and always parses: the consumer checks.)
  SpectrumValues values = SpectrumValues::NonNegative;
};

// Parses a spec string. Throws InputError naming ctx.input and the offending text; an unknown name
// lists the valid ones.
Spectrum parse_spectrum(std::string_view spec, const SpecContext& ctx = {});
// Names accepted by parse_spectrum for named illuminants (D65, …) and ColorChecker patches (cc:…).
std::vector<std::string> named_illuminants();
std::vector<std::string> colorchecker_patches();
// Reads a two-column CSV spectrum (see above) of a quantity with the given sign. Throws InputError
// naming the file and line.
Spectrum read_spectrum_csv(const std::filesystem::path& path, SpectrumValues values = SpectrumValues::NonNegative);
// Writes a two-column CSV with a header, atomically.
void write_spectrum_csv(const std::filesystem::path& path, const Spectrum& s, std::string_view value_name = "value");

}  // namespace prizma::spectral
