#pragma once
// Where an installed Prizma tree begins, found from the file this code runs in, so that a tree
// moved as a whole still finds its data (share/prizma) and its modules (lib/prizma):
//   a tool:              <prefix>/<bindir>/prizma-render            (bindir from CMAKE_INSTALL_BINDIR, "bin")
//   the Python module:   <prefix>/lib/python3.X/site-packages/prizma/_prizma.so  (or dist-packages)
#include <filesystem>

namespace prizma::spectral {

// The file holding libspectral's code in this process: the executable, or the shared object it is
// linked into (the Python module's _prizma.so), as an absolute path. Empty when it cannot be told.
std::filesystem::path code_file();

// The prefix that code_file() sits under if it is installed (the layouts above). Computed from the
// path alone: whether anything is installed there is the caller's to check (from the build tree it
// names a folder with no share/prizma). Empty when code_file() is.
std::filesystem::path installed_prefix();

// installed_prefix()/lib/prizma: where `cmake --install` puts the modules loaded on first use
// (libprizma_imageio.so, libprizma_vdb.so). Empty when installed_prefix() is.
std::filesystem::path installed_module_dir();

}  // namespace prizma::spectral
