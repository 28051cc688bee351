#pragma once
// The version of Prizma, for --version and the files' prizma:version.
#include <string>

namespace prizma::spectral {

// Version string "0.1.0 (git abc1234)".
std::string prizma_version();

}  // namespace prizma::spectral
