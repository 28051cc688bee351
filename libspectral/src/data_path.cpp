#include "prizma/spectral/data_path.h"

#include <cstdlib>
#include <system_error>

#include "prizma/spectral/error.h"
#include "prizma/spectral/installed_prefix.h"

namespace prizma::spectral {

namespace {

bool is_dir(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_directory(p, ec);
}

}  // namespace

std::filesystem::path data_dir() {
  // 1. Explicit override.
  if (const char* env = std::getenv("PRIZMA_DATA_DIR"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env);
  }
  // 2. Installed layout, relative to the tool or the Python module (installed_prefix.h:
  //    <prefix>/bin/<exe> → <prefix>/share/prizma): an installed tree works wherever it is moved,
  //    and does not depend on the source tree.
  std::filesystem::path installed;
  if (const std::filesystem::path prefix = installed_prefix(); !prefix.empty()) {
#ifdef PRIZMA_INSTALL_DATA_FROM_PREFIX
    installed = (prefix / PRIZMA_INSTALL_DATA_FROM_PREFIX).lexically_normal();
#else
    installed = prefix / "share" / "prizma";
#endif
    if (is_dir(installed)) return installed;
  }
  // 3. The source tree's data/ recorded at build time (running from the build tree).
#ifdef PRIZMA_SOURCE_DATA_DIR
  {
    const std::filesystem::path source_dir(PRIZMA_SOURCE_DATA_DIR);
    if (!source_dir.empty() && is_dir(source_dir)) return source_dir;
  }
#endif
  if (!installed.empty()) return installed;
  return std::filesystem::path("share") / "prizma";
}

std::filesystem::path data_file(const std::filesystem::path& relative) {
  const auto p = data_dir() / relative;
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) {
    throw RuntimeError(p.string() + ": data file not found (set PRIZMA_DATA_DIR to Prizma's data folder)");
  }
  return p;
}

}  // namespace prizma::spectral
