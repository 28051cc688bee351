#pragma once
// Where Prizma finds data/ (CIE tables, OCIO config): $PRIZMA_DATA_DIR if set, else the installed
// data of the tree this code is installed in (<prefix>/share/prizma of installed_prefix.h, for the
// tools and the Python module alike, when that folder exists), else the source tree's data/
// recorded at build time (running from the build tree).
#include <filesystem>

namespace prizma::spectral {

std::filesystem::path data_dir();
// data_dir()/relative, throwing RuntimeError naming the path when it does not exist.
std::filesystem::path data_file(const std::filesystem::path& relative);

}  // namespace prizma::spectral
