#pragma once
// The synthetic ColorChecker chart of docs/relight.md's examples: the 24 ColorChecker Classic
// patches (reflectance bin averages of libspectral's cc:1 … cc:24, 32 bins over 380–700 nm) on a
// dark surround, 172×116 pixels, with two light layers: "key" falling off to the right (default
// D65) and "back", a rim light rising toward the right edge (default off). Installed as
// share/prizma/examples/colorchecker.exr; the relight end-to-end tests write the same file.
#include <filesystem>

namespace prizma::relight {

// Writes the chart as a Prizma spectral EXR (write_spectral_exr: atomic, checksummed).
void write_colorchecker_chart(const std::filesystem::path& path);

}  // namespace prizma::relight
