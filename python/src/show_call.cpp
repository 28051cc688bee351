// What shows an image from Python (docs/python.md, "Showing an image"): the PNG bytes of
// Image._repr_png_ (Jupyter's rich display), and where the prizma-relight that prizma.serve runs is.
//
// The PNG is the one `prizma-relight FILE -o x.png` writes: RelightSession::save, the tool's own
// writer (OpenColorIO display, ICC profile and cICP, prizma:* metadata), into a private temporary
// folder (mkdtemp: mode 0700, only this user can look into it) that is removed before returning.
// Writing through the tool's path rather than an in-memory writer keeps one PNG encoder: the bytes
// Jupyter shows decode to the pixels of the tool's file.
#include <pybind11/pybind11.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include "module_parts.h"
#include "native_call.h"
#include "prizma/relight/relight_session.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/installed_prefix.h"

namespace prizma::python {

namespace {

namespace fs = std::filesystem;

// A folder made by mkdtemp under the system's temporary folder, removed with what it holds.
class PrivateTemporaryFolder {
 public:
  PrivateTemporaryFolder() {
    std::string pattern = (fs::temp_directory_path() / "prizma-png-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      const std::error_code ec(errno, std::generic_category());
      throw spectral::RuntimeError(pattern + ": cannot make a temporary folder: " + ec.message());
    }
    m_path = pattern;
  }
  ~PrivateTemporaryFolder() {
    std::error_code ec;  // nothing to report from a destructor; the folder is private to this user
    fs::remove_all(m_path, ec);
  }
  PrivateTemporaryFolder(const PrivateTemporaryFolder&) = delete;
  PrivateTemporaryFolder& operator=(const PrivateTemporaryFolder&) = delete;
  const fs::path& path() const { return m_path; }

 private:
  fs::path m_path;
};

std::string read_whole_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw spectral::RuntimeError(path.string() + ": cannot read back the PNG just written");
  return bytes;
}

}  // namespace

py::bytes relight_png(relight::RelightSession& session) {
  std::string bytes;
  {
    const WithoutGil released;
    const PrivateTemporaryFolder folder;
    const fs::path png = folder.path() / "image.png";
    session.relight();
    session.save(png, "image");
    bytes = read_whole_file(png);
  }
  return py::bytes(bytes);
}

std::string relight_tool_path() {
  // The installed tree's tool first (the module and the tool of one install go together), then the
  // one built beside this module in the build tree; empty when neither exists.
  std::error_code ec;
  if (const fs::path prefix = spectral::installed_prefix(); !prefix.empty()) {
    const fs::path installed = prefix / PRIZMA_INSTALL_BINDIR / "prizma-relight";
    if (fs::is_regular_file(installed, ec)) return installed.string();
  }
  const fs::path built(PRIZMA_BUILD_RELIGHT_TOOL);
  if (fs::is_regular_file(built, ec)) return built.string();
  return {};
}

}  // namespace prizma::python
